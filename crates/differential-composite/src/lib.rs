//! Synthetic objects and their soft shadows composited into a photograph of a real scene
//! (paper 003, Sections 7-9; Debevec 1998).
//!
//! - [`object`]: the synthetic objects (built in, or a glTF model fitted to the scene) and
//!   their simplified shadow meshes.
//! - [`compositor`]: what the interactive compositor knows of the scene (each pixel's receiver,
//!   transfers in RGB) and each frame's representatives with their radiance transfers (HDR)
//!   and intensity transfers (LDR).
//! - [`ldr`]: the intensity transfers of the two-set split (Figure 4) and their error under
//!   random occlusion (Figure 3).
//! - [`cpu`]: masks by ray casting and the subtraction, the reference compositor.
//! - [`gpu`]: the interactive compositor: shadow maps, masks, darkening and resolve on wgpu.
//! - [`metrics`]: errors in 8-bit codes.
//!
//! The capture, the truth and Debevec's render (path traced) and the measuring are the harness
//! crate `trade`'s (`trade::session`, `trade::offline`, `trade::composite_rows`): this crate
//! traces no rays of its own; it asks a `real_scene::Visibility` the caller fills.
//!
//! **Architecture invariant:** the compositor reads the real scene only through its
//! reconstruction (`real_scene::RealScene` as the model, the photograph, the camera response);
//! the real scene itself is only the truth's.

pub mod compositor;
pub mod cpu;
pub mod gpu;
pub mod ldr;
pub mod metrics;
pub mod object;

pub use compositor::{Compositor, FrameTransfers, ObjectProbe, PixelRef, RepTransfer};
pub use metrics::{CodeError, code_error};
pub use object::{BUILTIN_OBJECTS, MODEL_SIZE, ObjectPlacement, Shape, SyntheticObject};

/// Which framebuffer the compositor subtracts in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Radiance transfers subtracted from the HDR photograph, then the camera response.
    Hdr,
    /// Intensity transfers (codes) subtracted from the 8-bit photograph.
    Ldr,
}

/// Errors of compositing.
#[derive(Debug, thiserror::Error)]
pub enum CompositeError {
    /// An object name that is not built in.
    #[error("unknown object {0:?}; built in: sphere, box")]
    UnknownObject(String),
    /// A parameter out of range.
    #[error("invalid parameter: {0}")]
    Parameter(String),
    /// The real scene refused (unknown name, a map missing or not wanted).
    #[error(transparent)]
    Scene(#[from] real_scene::RealSceneError),
    /// A model that could not be imported (the message names the file).
    #[error(transparent)]
    Model(#[from] scene::SceneError),
    /// The shaft hierarchy could not be built.
    #[error(transparent)]
    Build(#[from] shaft_hierarchy::BuildError),
}
