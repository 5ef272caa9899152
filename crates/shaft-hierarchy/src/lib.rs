//! Decides, fast, which light sources a moving synthetic object can occlude for which receivers:
//! source and receiver patch hierarchies and a shaft hierarchy over line space (paper 003).
//!
//! - [`Shaft`]: Haines and Wallace's joint box and joining planes between two boxes (exactly
//!   their convex hull), and its conservative box test.
//! - [`source_tree`] (binary KD-tree, one source a leaf) and [`receiver_octree`].
//! - [`ShaftHierarchy`]: built from the root pair by splitting the larger node, pruning pairs
//!   below 2 % of every reached vertex's radiance; per frame, [`ShaftHierarchy::traverse`] and
//!   [`ShaftHierarchy::representatives`]; [`ShaftHierarchy::validate`] checks its invariants.
//! - [`preprocess`]: the source set, receivers and transfers of a `real_scene::RealScene`.
//!
//! Distant sources (the lights of an environment map) have no position: their end of a shaft
//! is the receiver box moved `reach` along the light's cone of directions, so objects further
//! than `reach` along a light are not found.

mod aabb;
mod hierarchy;
pub mod preprocess;
mod shaft;
mod tree;

pub use aabb::Aabb;
pub use hierarchy::{
    BuildError, Kind, Occlusion, Receiver, Representative, Settings, ShaftHierarchy, ShaftNode, Transfers, Traversal,
};
pub use shaft::{Meet, Overlap, Plane, Shaft, meets};
pub use tree::{Node, SourceShape, Tree, cone_direction_bounds, receiver_octree, source_tree};
