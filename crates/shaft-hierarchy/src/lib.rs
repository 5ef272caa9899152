//! Decides, fast, which light sources a moving synthetic object can occlude for which receivers:
//! source and receiver patch hierarchies and a shaft hierarchy over line space (paper 003).
//!
//! Built so far: the shaft between two boxes ([`Shaft`]: Haines and Wallace's joint box and
//! joining planes, exactly the boxes' convex hull) and its conservative box test.

mod aabb;
mod hierarchy;
mod shaft;
mod tree;

pub use aabb::Aabb;
pub use hierarchy::{
    BuildError, Kind, Occlusion, Receiver, Representative, Settings, ShaftHierarchy, ShaftNode, Transfers, Traversal,
};
pub use shaft::{Overlap, Plane, Shaft};
pub use tree::{Node, SourceShape, Tree, cone_directions, receiver_octree, source_tree};
