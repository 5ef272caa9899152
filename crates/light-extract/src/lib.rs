//! Decomposes an HDR environment map into a few shadow-casting distant area lights (cones) plus
//! an ambient remainder: centre-surround extraction (paper 000), the emissive split with
//! EnvDirects / EnvIndirects (paper 001), and the median-cut, variance-minimization and
//! importance-sampling baselines.
//!
//! Architecture invariant: knows lights, never wgpu. Filled by the `light-extract` issue.
