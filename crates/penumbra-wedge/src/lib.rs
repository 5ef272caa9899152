//! Soft shadows of spherical (distant cone) area lights rendered with penumbra wedges (paper 000).
//!
//! Filled by a later issue.
