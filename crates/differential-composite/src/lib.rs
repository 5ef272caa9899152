//! Removes the light a synthetic object occludes from a background photograph: differential
//! rendering in HDR, and with LDR intensity transfers (paper 003).
//!
//! Filled by a later issue.
