//! The shared GPU layer: a wgpu device (on machines without a GPU, Mesa's lavapipe on Vulkan),
//! offscreen targets and readback, GPU timestamps, WGSL composition, and the raster renderer
//! that mirrors `scene`'s BRDF: a G-buffer pass and a shading pass lit by distant cone lights,
//! point lights and SH9 ambient, each light's shadow given as a screen-space visibility layer.
//!
//! Shadow techniques (`shadowmap-paraboloid`, later `penumbra-wedge`) fill those layers from the
//! G-buffer; the shading pass does not know how a layer was made.
//!
//! ```no_run
//! let gpu = gpu::Gpu::new().expect("a Vulkan adapter (lavapipe: mesa-vulkan-drivers)");
//! println!("{}", gpu.describe());
//! ```

pub mod accumulate;
pub mod ambient;
mod context;
mod from_depth;
pub mod fullscreen;
mod gate;
mod gbuffer;
mod geometry;
mod interleave;
mod lit_frame;
pub mod placement;
mod readback;
mod receivers;
mod shade;
pub mod shader;
mod slots;
mod split;
mod supersample;
mod target;
mod technique;
mod timer;
mod upsample;
mod view;

pub use ambient::{DfgTable, PrefilterSettings, PrefilteredMap, SpecularAmbient};
pub use context::{ADAPTER_ENV, Gpu, GpuCounters, GpuError, adapters, describe_adapter, pick_adapter};
pub use from_depth::DepthGBufferPass;
pub use gate::{Calls, Gate, GatedArgs, GpuStats, Indirect};
pub use gbuffer::{
    GBUFFER_FORMAT, GBuffer, GBufferPass, GBufferTargets, PointsRead, view_projection, view_projection_infinite,
    view_projection_reverse,
};
pub use geometry::{Chunk, SceneGeometry, ShadowGeometry, scene_triangles};
pub use interleave::{InterleavePass, InterleavedFrame, MAX_SETS, interleave_set, interleave_tile, render_interleaved};
pub use lit_frame::{FrameLights, FrameShadows, LitFrame, LitSettings, ReferenceReceivers, RenderedFrame};
pub use readback::{
    MappingRead, PendingRead, read_buffer, read_mapped, read_mapped_all, read_texture_f32, read_texture_rgba,
};
pub use receivers::{MappedStats, PendingStats, ReceiverReduction, ReceiverStats, WeberInput};
pub use shade::{Background, HDR_FORMAT, ShadeLight, ShadeParams, ShadingPass, Visibility, read_hdr};
pub use slots::{Keyed, MAX_SLOTS_PER_SUBMISSION, Slots};
pub use split::{
    SplitFrame, SplitImage, SplitPasses, SplitSettings, SplitTargets, indirect_camera, record_split, render_split,
};
pub use supersample::RotatedGrid;
pub use target::{layer_view, render_target};
pub use technique::{
    LightShape, LightStamps, PrecomputedVisibility, Receivers, ShadowPassReport, ShadowTechnique, WEBER_FRACTION,
    WEBER_MAX_RECEIVERS, culled_totals, record_visibility, render_visibility, skip_reasons, totals, weber_negligible,
};
pub use timer::Clock;
pub use upsample::{JointBilateral, UpsamplePass};
pub use view::{View, conservative_bounds};
