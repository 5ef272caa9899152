//! Shadows of hemispherical and omnidirectional point lights with one or two paraboloid shadow
//! maps (paper 004), with cube and orthographic shadow maps as baselines behind one interface.
//!
//! Filled by the GPU rendering issue.
