//! A renderer of its own that embeds penumbra wedges: it makes its own wgpu device, keeps its
//! own vertex and index buffers, draws its own G-buffer and its own shading, and asks the
//! toolkit only for the lights of an HDR map (`light-extract`), the receivers' statistics
//! (`gpu::ReceiverReduction`) and one visibility layer per light (`Wedges::record` into its
//! encoder). A box slides over the ground for a few frames; each frame is written as a PNG under
//! `target/examples/moving_box/`.
//!
//! ```text
//! cargo run --release -p penumbra-wedge --example moving_box [-- MAP.exr|MAP.hdr]
//! ```

use glam::{Mat4, Vec3};
use gpu::{Gpu, LightShape, ReceiverReduction, Receivers, ShadeLight, VisibilityLayers, WEBER_FRACTION, WeberInput};
use penumbra_wedge::{WedgeSettings, Wedges};
use std::error::Error;
use std::path::{Path, PathBuf};
use wgpu::util::DeviceExt;

/// The renderer's vertex: position, shading normal (zero: flat), object.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    object: u32,
}

/// The shading pass's lighting: the ambient's irradiance (unshadowed) and the light count.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Lighting {
    ambient: [f32; 4],
    count: [u32; 4],
}

/// Object `k`'s vertices.
fn vertices_of(k: usize, m: &scene::Mesh) -> Vec<Vertex> {
    m.positions
        .iter()
        .enumerate()
        .map(|(i, p)| Vertex {
            position: p.to_array(),
            normal: m.normals.as_ref().map_or([0.0; 3], |n| n[i].to_array()),
            object: k as u32,
        })
        .collect()
}

/// The renderer's G-buffer pass and shading pass: what a deferred renderer already has. The
/// G-buffer is written as `gpu::GBuffer` documents it (world position with the object index in
/// w, -1 where nothing was hit; normals facing the camera; reversed depth).
const SHADER: &str = r"
struct View { view_proj: mat4x4<f32>, eye: vec4<f32> }
@group(0) @binding(0) var<uniform> view: View;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) object: u32,
}

@vertex
fn gbuffer_vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>, @location(2) object: u32) -> VsOut {
    return VsOut(view.view_proj * vec4<f32>(p, 1.0), p, n, object);
}

struct GOut { @location(0) position: vec4<f32>, @location(1) normal: vec4<f32>, @location(2) geometric: vec4<f32> }

@fragment
fn gbuffer_fs(v: VsOut) -> GOut {
    var ng = normalize(cross(dpdx(v.world), dpdy(v.world)));
    if dot(ng, view.eye.xyz - v.world) < 0.0 { ng = -ng; }
    var ns = select(ng, normalize(v.normal), length(v.normal) > 0.0);
    if dot(ns, ng) < 0.0 { ns = -ns; }
    return GOut(vec4<f32>(v.world, f32(v.object)), vec4<f32>(ns, 0.0), vec4<f32>(ng, 0.0));
}

struct Light { direction: vec4<f32>, irradiance: vec4<f32> }
struct Lighting { ambient: vec4<f32>, count: vec4<u32> }
@group(0) @binding(1) var<uniform> lighting: Lighting;
@group(0) @binding(2) var<storage, read> lights: array<Light>;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
@group(0) @binding(5) var visibility: texture_2d_array<f32>;

@vertex
fn shade_vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn shade_fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let g = textureLoad(g_position, pixel, 0);
    if g.w < 0.0 { return vec4<f32>(0.02, 0.02, 0.03, 1.0); }
    let n = textureLoad(g_normal, pixel, 0).xyz;
    let albedo = select(vec3<f32>(0.8), vec3<f32>(0.8, 0.3, 0.2), g.w > 0.5);
    var e = lighting.ambient.rgb;
    for (var k = 0u; k < lighting.count.x; k++) {
        let v = textureLoad(visibility, pixel, i32(k), 0).r;
        e += v * lights[k].irradiance.rgb * max(dot(n, lights[k].direction.xyz), 0.0);
    }
    // exposed so that the unshadowed ground is mid-grey
    return vec4<f32>(albedo / 3.14159265 * e * lighting.ambient.w, 1.0);
}
";

// a program, not the library: it says where its frames went
#[allow(clippy::print_stdout)]
fn main() -> Result<(), Box<dyn Error>> {
    let map = std::env::args().nth(1).map(PathBuf::from);
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/examples/moving_box");
    for path in run(map.as_deref(), &out, 4, (480, 320))? {
        println!("{}", path.display());
    }
    Ok(())
}

/// The scene: a ground, a tall block that stays and a box that moves (object 1).
fn objects() -> Vec<scene::Mesh> {
    vec![
        scene::Mesh::quad(Vec3::new(-4.0, 0.0, 4.0), Vec3::new(8.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -8.0), 1, 1),
        scene::Mesh::cuboid(Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 1.0, 0.5)),
        scene::Mesh::cuboid(Vec3::new(1.2, 0.0, -1.5), Vec3::new(1.7, 2.0, -1.0)),
    ]
}

/// Renders `frames` frames at `size` lit by `map` (the toolkit's default without one) into
/// `out`, and returns the PNGs' paths.
///
/// # Errors
/// No adapter or device; a map that cannot be read; GPU failures.
pub fn run(map: Option<&Path>, out: &Path, frames: usize, (w, h): (u32, u32)) -> Result<Vec<PathBuf>, Box<dyn Error>> {
    // 1. The renderer's own device (with the adapter's limits: this renderer's G-buffer writes
    //    three Rgba32Float targets, 48 colour bytes a sample; WebGPU's defaults allow 32).
    let instance = wgpu::Instance::default();
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let wanted = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::FLOAT32_BLENDABLE | wgpu::Features::CLIP_DISTANCES;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & wanted,
        required_limits: adapter.limits(),
        ..Default::default()
    }))?;
    let gpu = Gpu::from_device(device.clone(), queue.clone(), adapter.get_info());

    // 2. Lights from the map.
    let map = match map {
        Some(p) => envmap_sphere::EnvMap::load(p)?,
        None => envmap_sphere::default_map(),
    };
    let extractor = light_extract::extractor(light_extract::DEFAULT_METHOD, 8).ok_or("unknown method")?;
    let decomposition = extractor.extract(&map)?;
    let shapes: Vec<LightShape> = decomposition.lights.iter().map(|l| LightShape::from(&l.light)).collect();
    let shade: Vec<ShadeLight> = decomposition.lights.iter().map(|l| ShadeLight::from(&l.light)).collect();

    // 3. The renderer's meshes, in its own vertex and index buffers; the same triangles as a
    //    `scene::Scene` for the wedges' casters.
    let meshes = objects();
    let mut indices: Vec<u32> = Vec::new();
    let mut base = 0;
    for m in &meshes {
        indices.extend(m.indices.iter().flatten().map(|i| i + base));
        base += m.positions.len() as u32;
    }
    let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("vertices"),
        contents: bytemuck::cast_slice(
            &meshes.iter().enumerate().flat_map(|(k, m)| vertices_of(k, m)).collect::<Vec<_>>(),
        ),
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
    });
    let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("indices"),
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::INDEX,
    });
    let camera = scene::Camera {
        eye: Vec3::new(0.0, 3.5, 6.0),
        target: Vec3::new(0.0, 0.5, 0.0),
        up: Vec3::Y,
        hfov_degrees: 55.0,
        width: w,
        height: h,
    };
    let mut scene = scene::Scene {
        name: "moving box".into(),
        objects: meshes
            .iter()
            .enumerate()
            .map(|(k, m)| scene::Object {
                name: format!("object {k}"),
                mesh: m.clone(),
                material: scene::Material::lambert(0.8),
            })
            .collect(),
        camera,
        point_lights: Vec::new(),
        textures: Vec::new(),
    };

    // 4. The renderer's passes, and the toolkit's, built once.
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("renderer"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let gformat = gpu::GBUFFER_FORMAT;
    let gbuffer_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("gbuffer"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("gbuffer_vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<Vertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32],
            })],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("gbuffer_fs"),
            compilation_options: Default::default(),
            targets: &[Some(gformat.into()), Some(gformat.into()), Some(gformat.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let shade_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("shade"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("shade_vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("shade_fs"),
            compilation_options: Default::default(),
            targets: &[Some(gpu::HDR_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let mut wedges = Wedges::new(&gpu, &scene, WedgeSettings::default());
    let reduction = ReceiverReduction::new(&gpu);

    // 5. Targets and uniforms, made once for the size.
    let target =
        |label, format| -> Result<wgpu::Texture, gpu::GpuError> { gpu::render_target(&gpu, label, (w, h, 1), format) };
    let position = target("position", gformat)?;
    let normal = target("normal", gformat)?;
    let geometric = target("geometric normal", gformat)?;
    let depth = target("depth", wgpu::TextureFormat::Depth32Float)?;
    let hdr = target("image", gpu::HDR_FORMAT)?;
    let visibility = VisibilityLayers::allocate(&gpu, w, h, shapes.len() as u32)?;
    // the renderer's own matrices (right-handed, reversed infinite depth); the toolkit takes
    // them as they are, jittered or orthographic ones too
    let world_to_view = glam::camera::rh::view::look_at_mat4(camera.eye, camera.target, Vec3::Y);
    let aspect = w as f32 / h as f32;
    let fov_y = 2.0 * ((camera.hfov_degrees.to_radians() * 0.5).tan() / aspect).atan();
    let projection = glam::camera::rh::proj::directx::perspective_infinite_reverse(fov_y, aspect, 1e-3);
    let camera_view = gpu::View::new(world_to_view, projection, (w, h))?;
    let view_proj = camera_view.view_projection();
    let view: Vec<f32> = view_proj.to_cols_array().into_iter().chain(camera.eye.extend(1.0).to_array()).collect();
    let buffer = |label, contents: &[u8], usage| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
    };
    let view_buffer = buffer("view", bytemuck::cast_slice(&view), wgpu::BufferUsages::UNIFORM);
    let ambient = decomposition.ambient_sh.irradiance(Vec3::Y).max(Vec3::ZERO);
    let up: f32 = shade
        .iter()
        .map(|l| match *l {
            ShadeLight::Distant { direction, irradiance, .. } => {
                irradiance.dot(Vec3::ONE) / 3.0 * direction.normalize_or(Vec3::Y).y.max(0.0)
            }
            ShadeLight::Point { .. } => 0.0,
        })
        .sum::<f32>()
        + ambient.dot(Vec3::ONE) / 3.0;
    let exposure = if up > 0.0 { std::f32::consts::PI / (0.8 * up) } else { 1.0 };
    let lighting = Lighting { ambient: ambient.extend(exposure).to_array(), count: [shade.len() as u32, 0, 0, 0] };
    let lighting_buffer = buffer("lighting", bytemuck::bytes_of(&lighting), wgpu::BufferUsages::UNIFORM);
    let mut light_data: Vec<[f32; 8]> = shade
        .iter()
        .map(|l| match *l {
            ShadeLight::Distant { direction, irradiance, .. } => {
                let d = direction.normalize_or(Vec3::Y);
                [d.x, d.y, d.z, 0.0, irradiance.x, irradiance.y, irradiance.z, 0.0]
            }
            ShadeLight::Point { .. } => [0.0; 8],
        })
        .collect();
    light_data.push([0.0; 8]);
    let light_buffer = buffer("lights", bytemuck::cast_slice(&light_data), wgpu::BufferUsages::STORAGE);
    let views = [&position, &normal, &geometric, &hdr].map(|t| t.create_view(&Default::default()));
    let gbuffer_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("gbuffer"),
        layout: &gbuffer_pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: view_buffer.as_entire_binding() }],
    });
    let array =
        wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() };
    let visibility_view = visibility.texture.create_view(&array);
    let shade_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("shade"),
        layout: &shade_pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 1, resource: lighting_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: light_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&views[0]) },
            wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&views[1]) },
            wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&visibility_view) },
        ],
    });
    let depth_view = depth.create_view(&Default::default());

    std::fs::create_dir_all(out)?;
    let mut written = Vec::new();
    let rest = scene.objects[1].mesh.positions.clone();
    for frame in 0..frames {
        // the box moves: the renderer rewrites its own vertices; the wedges take the transform
        let t = frame as f32 / (frames.max(2) - 1) as f32;
        let moved = Mat4::from_translation(Vec3::new(-1.5 + 2.5 * t, 0.0, 0.8 * t));
        scene.objects[1].mesh.positions = rest.iter().map(|p| moved.transform_point3(*p)).collect();
        let first = meshes[0].positions.len() as u64 * std::mem::size_of::<Vertex>() as u64;
        queue.write_buffer(&vertex_buffer, first, bytemuck::cast_slice(&vertices_of(1, &scene.objects[1].mesh)));
        wedges.set_transform(&gpu, 1, glam::Affine3A::from_mat4(moved))?;

        // the renderer's G-buffer, and the toolkit's reduction of it, in one submission
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("gbuffer") });
        {
            let clear = |c: wgpu::Color| wgpu::Operations { load: wgpu::LoadOp::Clear(c), store: wgpu::StoreOp::Store };
            let attachment = |view, c| {
                Some(wgpu::RenderPassColorAttachment { view, depth_slice: None, resolve_target: None, ops: clear(c) })
            };
            let miss = wgpu::Color { r: 0.0, g: 0.0, b: 0.0, a: -1.0 };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gbuffer"),
                color_attachments: &[
                    attachment(&views[0], miss),
                    attachment(&views[1], wgpu::Color::TRANSPARENT),
                    attachment(&views[2], wgpu::Color::TRANSPARENT),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&gbuffer_pipeline);
            pass.set_bind_group(0, &gbuffer_bind, &[]);
            pass.set_vertex_buffer(0, vertex_buffer.slice(..));
            pass.set_index_buffer(index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..indices.len() as u32, 0, 0..1);
        }
        let gbuffer = gpu::GBuffer {
            position: position.clone(),
            normal: normal.clone(),
            geometric_normal: geometric.clone(),
            depth: depth.clone(),
            view: camera_view,
        };
        let weber = WeberInput { lights: &shade, ambient: Some(&decomposition.ambient_sh), fraction: WEBER_FRACTION };
        let pending = reduction.record(&gpu, &mut encoder, &gbuffer, &shapes, Some(weber))?;
        queue.submit([encoder.finish()]);
        // submitted by the renderer, not through `Gpu::submit`: the techniques may now reuse
        // their per-light uniforms for the next frame's lights (gpu::Slots)
        gpu.mark_submitted();

        // every light's visibility recorded into the renderer's encoder, then its shading: the
        // reduction stays on the GPU and gates each light's draws (no wait for it); the wedges
        // are planned for what the CPU knows, the scene's box within the view
        let bounds = gpu::conservative_bounds(scene_box(&scene), &gbuffer.view);
        let receivers = Receivers::on_gpu(&gbuffer, bounds, pending.on_gpu().clone());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        visibility.record_clear(&mut encoder);
        gpu::record_visibility(&gpu, &mut encoder, &wedges, &receivers, &shapes, &[], &visibility)?;
        gpu::fullscreen::record(
            &mut encoder,
            &shade_pipeline,
            &shade_bind,
            &views[3],
            wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        );
        queue.submit([encoder.finish()]);
        gpu.mark_submitted();

        // the example's own output: the frame as an 8-bit PNG
        let pixels = gpu::read_texture_rgba(&gpu, &hdr, 0)?;
        let srgb: Vec<u8> = pixels
            .iter()
            .flat_map(|p| {
                p[..3]
                    .iter()
                    .map(|&c| ((c / (1.0 + c)).clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0 + 0.5) as u8)
                    .collect::<Vec<_>>()
            })
            .collect();
        let path = out.join(format!("frame_{frame}.png"));
        image::save_buffer(&path, &srgb, w, h, image::ExtendedColorType::Rgb8)?;
        written.push(path);
    }
    Ok(written)
}

/// The box around every vertex of `scene`, at the objects' current poses.
fn scene_box(scene: &scene::Scene) -> (Vec3, Vec3) {
    scene
        .objects
        .iter()
        .flat_map(|o| &o.mesh.positions)
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

#[cfg(test)]
mod tests {
    /// The example runs on lavapipe: its frames are written, lit, and the shadow moves with the
    /// box.
    #[test]
    fn the_example_writes_frames_whose_shadow_moves() {
        let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/examples/moving_box_test");
        let _ = std::fs::remove_dir_all(&out);
        let paths = super::run(None, &out, 2, (96, 64)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(paths.len(), 2);
        let frames: Vec<Vec<u8>> = paths
            .iter()
            .map(|p| image::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())).to_rgb8().into_raw())
            .collect();
        assert!(frames[0].iter().any(|&b| b > 40), "a dark frame");
        assert_ne!(frames[0], frames[1], "nothing moved");
    }
}
