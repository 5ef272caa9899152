//! Decides, fast, which light sources a moving synthetic object can occlude for which receivers:
//! source and receiver patch hierarchies and a shaft hierarchy over line space (paper 003).
//!
//! Built so far: the shaft between two boxes ([`Shaft`]: Haines and Wallace's joint box and
//! joining planes, exactly the boxes' convex hull) and its conservative box test.

mod aabb;
mod shaft;

pub use aabb::Aabb;
pub use shaft::{Overlap, Plane, Shaft};
