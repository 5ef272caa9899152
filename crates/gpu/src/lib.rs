//! The shared GPU layer: a wgpu device (on machines without a GPU, Mesa's lavapipe on Vulkan),
//! offscreen targets and readback, GPU timestamps, WGSL composition, and the raster renderer
//! that mirrors `scene`'s BRDF: a G-buffer pass and a shading pass lit by distant cone lights,
//! point lights and SH9 ambient, each light's shadow given as a screen-space visibility layer.
//!
//! Shadow techniques (`shadowmap-paraboloid`, `penumbra-wedge`) fill those layers from the
//! G-buffer; the shading pass does not know how a layer was made.
//!
//! # The modules
//! Device creation with wgpu, or a caller's device wrapped (`Gpu::from_device`), every submission,
//! wait, readback and pipeline counted (`GpuCounters`: what a real-time frame is judged by)
//! (`context`: the best adapter present — discrete, integrated, virtual, CPU, Vulkan first, OpenGL
//! last — or the one named by `--adapter` / `ENVSHADOW_ADAPTER` (`cpu` for lavapipe);
//! `CLIP_DISTANCES` and timestamp queries when present; an error naming `mesa-vulkan-drivers` when
//! there is no adapter, one listing the adapters when none matches the name), offscreen targets and
//! layer views (`target`), readback (`readback`), timing (`timer`: GPU timestamps, else wall time,
//! always stated), WGSL composition (`shader`: `// requires:` lines prepend library files),
//! full-screen passes (`fullscreen`), scene geometry on the GPU (`geometry`: shaded vertices;
//! position-only triangle soup in chunks with bounding spheres for per-view culling), and the
//! deferred raster renderer: the G-buffer (`gbuffer`: reversed, infinite Z, so a float depth buffer
//! resolves a scene of any scale to the same relative precision near and far; `from_depth`: a
//! renderer's own depth texture and view made into one) and the view it was seen from (`view`:
//! `View`, the renderer's view and projection matrices of any camera, perspective, off-centre,
//! jittered, left-handed or orthographic, of which `scene::Camera` is one maker;
//! `conservative_bounds` clips a box to its frustum), and the shading pass (`shade`) lit by distant
//! cone lights (the diffuse lobe by the cone's exact irradiance, `scene::cone_cosine_integral`; GGX
//! by a representative point), point lights and SH9 ambient, with the map as `Background`; passes
//! build their pipelines once and render per frame. The BRDF mirrors `scene::brdf` in
//! `crates/gpu/shaders/brdf.wgsl`. Each light's shadow arrives as one screen-space visibility layer
//! (`VisibilityLayers`): the shading pass does not know how a shadow technique made it. The one interface
//! of shadow techniques lives here (`technique`): `ShadowTechnique::record(gpu, encoder, receivers,
//! light, layer)` records a light's passes into the caller's encoder (no submission, wait or
//! mapping; scratch targets reused from light to light); `LightShape` (distant cone or sphere) and
//! `Receivers` (the G-buffer, its points, bounds and focus); `record_visibility` is the frame loop
//! that records every light into one encoder, skipping lights no visible receiver faces, and those
//! `weber_negligible` finds under Weber's 2 % of every visible receiver's unshadowed irradiance,
//! and reports why (`render_visibility`: the same loop measured, every light in one submission,
//! each between GPU timestamps of its own, or an even share of its wall time without them; no light
//! has a submission of its own); every pass has a `record` form (`GBufferPass::record`,
//! `ShadingPass::record_texture`, `UpsamplePass::record`, `record_split`,
//! `VisibilityLayers::record_clear`, `GBuffer::record_points`), an object moves by a transform
//! (`SceneGeometry::set_transform`, `ShadowGeometry::set_transform`; `placement` places the
//! object-space vertices on the GPU in the caller's encoder) or has its deformed vertices written
//! in place (`SceneGeometry::update_object`, `ShadowGeometry::update`); `slots` keeps per-light
//! resources from frame to frame (`Slots`: the k-th light of a submission gets the k-th slot's
//! buffers, rewritten with `queue.write_buffer`, and bind groups, `Keyed` by what they bind; it
//! starts over at each submission, `Gpu::epoch`, which `Gpu::submit` or a renderer's
//! `Gpu::mark_submitted` advances), and a frame's G-buffer goes into `GBufferTargets` made once per
//! size (`GBufferPass::record_into`), its shaded and upsampled images into `SplitTargets`
//! (`ShadingPass::record_into`, `UpsamplePass::record_into`, `SplitFrame::targets`; shading and
//! upsampling keep their uniforms in `Slots` too); the library makes every buffer, bind group and
//! texture through `Gpu::create_buffer` and its siblings, which count them (`GpuCounters`);
//! `receivers` reduces a G-buffer's receivers on the GPU (`ReceiverReduction`: bounds, count,
//! focus, the lights they face, Weber's test; a few hundred bytes mapped back, tested against the
//! CPU `Receivers`), and `Receivers::from_stats` makes the techniques' receivers from it once read;
//! in a frame it stays on the GPU (`gate`: `PendingStats::on_gpu` gives a `GpuStats`,
//! `Receivers::on_gpu` pairs it with what the CPU knows, `conservative_bounds` of the scene and the
//! view; `GpuStats::gate(k)` is light k's gate, through which a technique issues every draw and
//! dispatch (`Calls`, `Indirect`): a one-workgroup pass zeroes the arguments of a light no visible
//! receiver faces or Weber's law finds negligible, so the CPU never waits for the reduction;
//! `PendingStats::map` and `MappedStats::finish` read what was skipped once the frame is done);
//! `PrecomputedVisibility` writes visibility computed elsewhere (the ray-traced truth row of
//! `validate`). `accumulate` is the additive float target (Rg32Float, Rg16Float without
//! `FLOAT32_BLENDABLE`) and the resolve pass techniques that sum passes share. The ambient is
//! signed (a residual's): SH9 irradiance unclamped on the diffuse lobe, and on the specular lobe
//! the split sum (`ambient`: the map prefiltered on the CPU per roughness level by filtered
//! importance sampling, our GGX's directional albedo tabulated as F0 scale and bias, looked up
//! along Frostbite's dominant direction). Paper 001's frame (`split`): the EnvDirects shaded at
//! full resolution with the ambient, the EnvIndirects from a G-buffer at 1 / scale with their own
//! shadow technique, joined by joint bilateral upsampling (`upsample`: normal, relative depth and
//! albedo Gaussians, weights taken relative to the window's best sample). The one recorded frame
//! (`lit_frame`: `LitFrame::render`) puts them together for any pair of techniques: G-buffers into
//! targets made once, the receivers reduced and left on the GPU, every light gated, the split
//! shading, two submissions and no wait; `LitFrame::render_reference` (a measuring wrapper that
//! waits for the receivers) gives the references tests hold it to, and `LitSettings::time_lights`
//! times each light between timestamps for measurement. Every frame of the project draws through
//! it: the benches' frame (and so `cargo xtask frame`), the trade's environment-lit, point-light
//! and banding frames, and validate's GPU rows (with `ReferenceReceivers::CpuPoints`, the original
//! CPU reduction). Interleaved light sets are the same frame once per set, each gathered into one
//! image over a pixel tile (`LitFrame::render_interleaved`; `interleave`: the tile and
//! `InterleavePass`, which records the gathering with each set count's parameters made once).
//! Supersampling for measurement (`supersample`: `RotatedGrid` rolls the camera by
//! atan(1/k) and renders a lattice of k² + 1 samples per pixel with distinct offsets on both axes,
//! resolved by exact integer arithmetic: an ordered grid quantizes every horizontal edge's coverage
//! to 1/k).
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
pub use interleave::{InterleavePass, MAX_SETS, interleave_set, interleave_tile};
pub use lit_frame::{
    FrameLights, FrameShadows, InterleavedImage, LitFrame, LitSettings, ReferenceReceivers, RenderedFrame,
};
pub use readback::{
    MappingRead, PendingRead, read_buffer, read_mapped, read_mapped_all, read_texture_f32, read_texture_rgba,
};
pub use receivers::{MappedStats, PendingStats, ReceiverReduction, ReceiverStats, WeberInput};
pub use shade::{Background, HDR_FORMAT, ShadeLight, ShadeParams, ShadingPass, VisibilityLayers, read_hdr};
pub use slots::{Keyed, MAX_SLOTS_PER_SUBMISSION, Slots};
pub use split::{SplitFrame, SplitImage, SplitPasses, SplitSettings, SplitTargets, indirect_camera, record_split};
pub use supersample::RotatedGrid;
pub use target::{layer_view, render_target};
pub use technique::{
    LightShape, LightStamps, PrecomputedVisibility, Receivers, ShadowPassReport, ShadowTechnique, WEBER_FRACTION,
    WEBER_MAX_RECEIVERS, culled_totals, record_visibility, render_visibility, skip_reasons, totals, weber_negligible,
};
pub use timer::{Clock, StageStamps};
pub use upsample::{JointBilateral, UpsamplePass};
pub use view::{View, conservative_bounds};
