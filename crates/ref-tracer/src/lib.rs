//! The CPU ground truth: an obvhs BVH, rayon over tiles, deterministic images, and the
//! `env-direct`, `lights` and `path` integrators every GPU approximation is measured against.
//!
//! Architecture invariant: never depends on wgpu. Filled by the `ref-tracer` issue.
