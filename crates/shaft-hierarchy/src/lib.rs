//! Decides, fast, which light sources a moving synthetic object can occlude for which receivers:
//! source and receiver patch hierarchies and a shaft hierarchy over line space (paper 003).
//!
//! Filled by a later issue.
