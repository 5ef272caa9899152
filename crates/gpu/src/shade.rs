//! The shading pass and the visibility layers it reads: one R8Unorm layer per light, written by
//! a shadow technique (or left at 1 for unshadowed light).

use crate::ambient::{DfgTable, PrefilteredMap, SpecularAmbient};
use crate::context::{Gpu, GpuError};
use crate::gbuffer::GBuffer;
use crate::geometry::SceneGeometry;
use crate::target::layer_view;
use envmap_sphere::{EnvMap, Sh9};
use glam::Vec3;
use wgpu::util::DeviceExt;

/// How the shading pass draws a light: its drawing data, derived from what the light *is*
/// (`From<&scene::DistantLight>`, `From<&scene::PointLight>`; a sphere light is shaded as the
/// point at its centre, which is exact for a uniform sphere above a receiver's horizon).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadeLight {
    /// A distant cone light of uniform radiance: the diffuse lobe gets the cone's exact
    /// irradiance (the closed form for a uniform disk or sphere light, the part below the
    /// surface's horizon left out); a GGX lobe sharper than the cone its representative point
    /// (the cone's direction closest to the mirror direction, with the lobe widened by the
    /// cone's size to keep its energy), a lobe as wide as the cone a 16-point quadrature of the
    /// cone (the horizon left out), a blend between. Half-angle 0 is a directional light.
    Distant {
        /// Unit direction towards the light.
        direction: Vec3,
        /// Irradiance at normal incidence: radiance × solid angle.
        irradiance: Vec3,
        /// Half-angle of the cone, radians, in [0, pi/2].
        half_angle: f32,
    },
    /// A point light.
    Point {
        /// Position in metres.
        position: Vec3,
        /// Intensity, W/sr.
        intensity: Vec3,
    },
}

impl From<&scene::DistantLight> for ShadeLight {
    fn from(l: &scene::DistantLight) -> Self {
        ShadeLight::Distant {
            direction: l.direction,
            irradiance: l.radiance * l.solid_angle,
            half_angle: l.half_angle().min(std::f32::consts::FRAC_PI_2),
        }
    }
}

impl From<&scene::PointLight> for ShadeLight {
    fn from(l: &scene::PointLight) -> Self {
        ShadeLight::Point { position: l.position, intensity: l.intensity }
    }
}

/// What lights a frame.
#[derive(Clone, Copy, Default)]
pub struct ShadeParams<'a> {
    /// The lights, in the order of the visibility layers.
    pub lights: &'a [ShadeLight],
    /// Ambient radiance as SH9 (its irradiance lights the diffuse lobe, unshadowed).
    pub ambient: Option<&'a Sh9>,
    /// What misses see; black without.
    pub background: Option<&'a Background>,
    /// The ambient map prefiltered for the specular lobe (split sum); without it only the
    /// lights reach the specular lobe.
    pub specular_ambient: Option<&'a SpecularAmbient>,
    /// Only the lights: no emission from emitting materials (a pass whose output is added to
    /// an image already shaded with it, as the split frame's indirect lights are).
    pub lights_only: bool,
}

/// One visibility layer per light, screen-sized, 1 = lit.
pub struct VisibilityLayers {
    /// R8Unorm 2D array.
    pub texture: wgpu::Texture,
}

impl VisibilityLayers {
    /// Format of the layers.
    pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

    /// `layers` layers of `width` × `height`, all lit (1); waits for the clear.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] beyond the adapter's limits.
    pub fn new(gpu: &Gpu, width: u32, height: u32, layers: u32) -> Result<Self, GpuError> {
        let vis = Self::allocate(gpu, width, height, layers)?;
        let mut encoder = gpu.encoder("visibility clear");
        vis.record_clear(&mut encoder);
        gpu.submit_and_wait(encoder)?;
        Ok(vis)
    }

    /// `layers` layers of `width` × `height` (at least one), contents undefined until
    /// [`VisibilityLayers::record_clear`] or a technique writes them.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] beyond the adapter's limits.
    pub fn allocate(gpu: &Gpu, width: u32, height: u32, layers: u32) -> Result<Self, GpuError> {
        let texture = crate::target::render_target(gpu, "visibility", (width, height, layers.max(1)), Self::FORMAT)?;
        Ok(Self { texture })
    }

    /// Records setting every layer to lit (1).
    pub fn record_clear(&self, encoder: &mut wgpu::CommandEncoder) {
        for layer in 0..self.texture.depth_or_array_layers() {
            let view = layer_view(&self.texture, layer);
            encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("visibility clear"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
        }
    }

    /// Size of a layer.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.texture.width(), self.texture.height())
    }

    /// A render-target view of one layer (for a shadow technique to write).
    #[must_use]
    pub fn layer(&self, layer: u32) -> wgpu::TextureView {
        layer_view(&self.texture, layer)
    }

    /// Number of layers.
    #[must_use]
    pub fn layers(&self) -> u32 {
        self.texture.depth_or_array_layers()
    }

    /// Reads one layer back, row-major, values in [0, 1].
    ///
    /// # Errors
    /// GPU failures.
    pub fn read(&self, gpu: &Gpu, layer: u32) -> Result<Vec<f32>, GpuError> {
        crate::readback::read_texture_f32(gpu, &self.texture, layer)
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct LightUniform {
    position_or_direction: [f32; 4],
    value: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadeUniform {
    eye: [f32; 4],
    right: [f32; 4],
    down: [f32; 4],
    corner: [f32; 4],
    counts: [u32; 4],
    ambient_info: [u32; 4],
    // cos and sin of the background's turn, then of the specular ambient's
    turn: [f32; 4],
    sh: [[f32; 4]; 9],
}

/// The shading pass: pipeline built once, run per frame.
pub struct ShadingPass {
    pipeline: wgpu::RenderPipeline,
    // bound when a frame has no background (the shader then returns black)
    no_background: Background,
    // bound when a frame has no specular ambient (the shader then skips it)
    no_specular: SpecularAmbient,
    // each shading of a submission's uniforms and bind group, kept from frame to frame
    slots: crate::Slots<ShadeSlot>,
}

/// One shading's resources: its uniform, its lights and the bind group over them and what
/// it reads (the lights' length, the materials, the G-buffer, visibility, background and
/// specular textures).
struct ShadeSlot {
    uniform: wgpu::Buffer,
    lights: wgpu::Buffer,
    bind: crate::Keyed<(u64, [wgpu::Buffer; 3], [wgpu::Texture; 7]), wgpu::BindGroup>,
}

/// Output format of the shading pass: linear HDR radiance.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

impl ShadingPass {
    /// Builds the pipeline.
    ///
    /// # Errors
    /// GPU failures.
    pub fn new(gpu: &Gpu) -> Result<Self, GpuError> {
        let module = crate::shader::module(&gpu.device, "shade", include_str!("../shaders/shade.wgsl"), &[]);
        let pipeline = crate::fullscreen::pipeline(gpu, "shade", &module, HDR_FORMAT);
        let none = PrefilteredMap { levels: vec![EnvMap::constant(1, 1, Vec3::ZERO)] };
        let no_specular = SpecularAmbient::upload(gpu, &none, &DfgTable { size: 1, values: vec![[0.0; 2]] })?;
        Ok(Self {
            pipeline,
            no_background: Background::from_texels(gpu, (1, 1), &[[0.0; 4]])?,
            no_specular,
            slots: crate::Slots::new(),
        })
    }

    /// Shades `gbuffer` and returns the linear HDR image, row-major from the top-left.
    ///
    /// # Errors
    /// As [`ShadingPass::render_texture`].
    pub fn render(
        &self,
        gpu: &Gpu,
        geometry: &SceneGeometry,
        gbuffer: &GBuffer,
        params: &ShadeParams,
        visibility: &VisibilityLayers,
    ) -> Result<Vec<Vec3>, GpuError> {
        let output = self.render_texture(gpu, geometry, gbuffer, params, visibility)?;
        read_hdr(gpu, &output)
    }

    /// Shades `gbuffer` into a new [`HDR_FORMAT`] texture of its size, left on the GPU, and
    /// waits for it.
    ///
    /// # Errors
    /// As [`ShadingPass::record_texture`]; GPU failures.
    pub fn render_texture(
        &self,
        gpu: &Gpu,
        geometry: &SceneGeometry,
        gbuffer: &GBuffer,
        params: &ShadeParams,
        visibility: &VisibilityLayers,
    ) -> Result<wgpu::Texture, GpuError> {
        let mut encoder = gpu.encoder("shade");
        let output = self.record_texture(gpu, &mut encoder, geometry, gbuffer, params, visibility)?;
        gpu.submit_and_wait(encoder)?;
        Ok(output)
    }

    /// Records shading `gbuffer` into a new [`HDR_FORMAT`] texture of its size, without
    /// submitting.
    ///
    /// # Errors
    /// As [`ShadingPass::record_into`]; [`GpuError::TooLarge`] for an image beyond the limits.
    pub fn record_texture(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        gbuffer: &GBuffer,
        params: &ShadeParams,
        visibility: &VisibilityLayers,
    ) -> Result<wgpu::Texture, GpuError> {
        let (w, h) = gbuffer.size();
        let output = crate::target::render_target(gpu, "shaded", (w, h, 1), HDR_FORMAT)?;
        self.record_into(gpu, encoder, geometry, gbuffer, params, visibility, &output)?;
        Ok(output)
    }

    /// Records shading `gbuffer` into `output` (an [`HDR_FORMAT`] render target of its size,
    /// e.g. [`crate::render_target`]'s, made once by the caller), without submitting. Its
    /// uniforms and bind group are made once and rewritten frame after frame
    /// ([`crate::Slots`]).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when `visibility` has fewer layers than lights;
    /// [`GpuError::Failed`] for an `output` of another size or format.
    #[allow(clippy::too_many_arguments)]
    pub fn record_into(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        gbuffer: &GBuffer,
        params: &ShadeParams,
        visibility: &VisibilityLayers,
        output: &wgpu::Texture,
    ) -> Result<(), GpuError> {
        let (w, h) = gbuffer.size();
        if (params.lights.len() as u32) > visibility.layers() {
            return Err(GpuError::TooLarge {
                what: "lights for the visibility layers",
                size: params.lights.len() as u64,
                limit: visibility.layers().into(),
            });
        }
        if (output.width(), output.height()) != (w, h) || output.format() != HDR_FORMAT {
            return Err(GpuError::Failed(format!(
                "shading a {w}x{h} G-buffer into a {}x{} {:?} target (wants {HDR_FORMAT:?})",
                output.width(),
                output.height(),
                output.format()
            )));
        }
        let rays = gbuffer.view.rays();
        let sh =
            params.ambient.map_or([[0.0f32; 4]; 9], |a| a.irradiance_coefficients().map(|c| c.extend(0.0).to_array()));
        let (bw, bh) = params.background.map_or((0, 0), |b| b.size);
        let background = &params.background.unwrap_or(&self.no_background).texture;
        let uniform = ShadeUniform {
            eye: gbuffer.view.toward_viewer().to_array(),
            right: rays.right.extend(0.0).to_array(),
            down: rays.down.extend(0.0).to_array(),
            corner: rays.corner.extend(0.0).to_array(),
            counts: [
                params.lights.len() as u32,
                u32::from(params.ambient.is_some()) | u32::from(!params.lights_only) << 1,
                bw,
                bh,
            ],
            ambient_info: params.specular_ambient.map_or([0; 4], |s| [s.size.0, s.size.1, s.size.2, s.table_size]),
            turn: {
                let (sb, cb) = params.background.map_or(0.0, Background::turn).sin_cos();
                let (ss, cs) = params.specular_ambient.map_or(0.0, SpecularAmbient::turn).sin_cos();
                [cb, sb, cs, ss]
            },
            sh,
        };
        let mut lights: Vec<LightUniform> = params
            .lights
            .iter()
            .map(|l| match *l {
                ShadeLight::Distant { direction, irradiance, half_angle } => LightUniform {
                    position_or_direction: direction.normalize_or_zero().extend(0.0).to_array(),
                    value: irradiance.extend(half_angle.clamp(0.0, std::f32::consts::FRAC_PI_2)).to_array(),
                },
                ShadeLight::Point { position, intensity } => LightUniform {
                    position_or_direction: position.extend(1.0).to_array(),
                    value: intensity.extend(0.0).to_array(),
                },
            })
            .collect();
        if lights.is_empty() {
            lights.push(bytemuck::Zeroable::zeroed());
        }
        let light_bytes: &[u8] = bytemuck::cast_slice(&lights);
        let specular = params.specular_ambient.unwrap_or(&self.no_specular);
        let textures = [
            gbuffer.position.clone(),
            gbuffer.normal.clone(),
            gbuffer.geometric_normal.clone(),
            visibility.texture.clone(),
            background.clone(),
            specular.levels.clone(),
            specular.table.clone(),
        ];
        let make = || ShadeSlot {
            uniform: crate::slots::writable_buffer(
                gpu,
                "shade params",
                wgpu::BufferUsages::UNIFORM,
                std::mem::size_of::<ShadeUniform>() as u64,
            ),
            // grown to the frame's lights by its first write
            lights: crate::slots::writable_buffer(gpu, "lights", wgpu::BufferUsages::STORAGE, 256),
            bind: crate::Keyed::default(),
        };
        // past the slots a submission may hold, this shading's own (made for it alone)
        let bind = self.slots.next_or_own(gpu, make, |slot| {
            gpu.queue.write_buffer(&slot.uniform, 0, bytemuck::bytes_of(&uniform));
            crate::slots::write_grown(gpu, &mut slot.lights, "lights", wgpu::BufferUsages::STORAGE, light_bytes);
            let bytes = light_bytes.len() as u64;
            let key =
                (bytes, [slot.lights.clone(), geometry.materials.clone(), geometry.texels.clone()], textures.clone());
            let (uniform, light_buf) = (&slot.uniform, &slot.lights);
            slot.bind
                .get(key, || {
                    let views = [&textures[0], &textures[1], &textures[2]].map(|t| t.create_view(&Default::default()));
                    let array = wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2Array),
                        ..Default::default()
                    };
                    let vis_view = textures[3].create_view(&array);
                    let background_view = textures[4].create_view(&array);
                    let levels_view = textures[5].create_view(&array);
                    let table_view = textures[6].create_view(&Default::default());
                    gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("shade"),
                        layout: &self.pipeline.get_bind_group_layout(0),
                        entries: &[
                            wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                            wgpu::BindGroupEntry { binding: 1, resource: crate::slots::binding_of(light_buf, bytes) },
                            wgpu::BindGroupEntry { binding: 2, resource: geometry.materials.as_entire_binding() },
                            wgpu::BindGroupEntry {
                                binding: 3,
                                resource: wgpu::BindingResource::TextureView(&views[0]),
                            },
                            wgpu::BindGroupEntry {
                                binding: 4,
                                resource: wgpu::BindingResource::TextureView(&views[1]),
                            },
                            wgpu::BindGroupEntry {
                                binding: 5,
                                resource: wgpu::BindingResource::TextureView(&views[2]),
                            },
                            wgpu::BindGroupEntry {
                                binding: 6,
                                resource: wgpu::BindingResource::TextureView(&vis_view),
                            },
                            wgpu::BindGroupEntry {
                                binding: 7,
                                resource: wgpu::BindingResource::TextureView(&background_view),
                            },
                            wgpu::BindGroupEntry {
                                binding: 8,
                                resource: wgpu::BindingResource::TextureView(&levels_view),
                            },
                            wgpu::BindGroupEntry {
                                binding: 9,
                                resource: wgpu::BindingResource::TextureView(&table_view),
                            },
                            wgpu::BindGroupEntry { binding: 10, resource: geometry.texels.as_entire_binding() },
                        ],
                    })
                })
                .clone()
        });
        let out_view = output.create_view(&Default::default());
        crate::fullscreen::record(encoder, &self.pipeline, &bind, &out_view, wgpu::LoadOp::Clear(wgpu::Color::BLACK));
        Ok(())
    }
}

/// Reads an [`HDR_FORMAT`] image back as RGB, row-major from the top-left.
///
/// # Errors
/// GPU failures.
pub fn read_hdr(gpu: &Gpu, texture: &wgpu::Texture) -> Result<Vec<Vec3>, GpuError> {
    let rgba = crate::readback::read_texture_rgba(gpu, texture, 0)?;
    Ok(rgba.into_iter().map(|v| Vec3::new(v[0], v[1], v[2])).collect())
}

/// An environment map on the GPU, as what camera rays that miss see: uploaded once, shaded
/// with every frame.
pub struct Background {
    texture: wgpu::Texture,
    size: (u32, u32),
    turn: f32,
}

impl Background {
    /// Uploads `map` (Rgba32Float, read with the bilinear lookup of `EnvMap::lookup`).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for a map beyond the adapter's texture limits.
    pub fn upload(gpu: &Gpu, map: &EnvMap) -> Result<Self, GpuError> {
        Self::from_texels(
            gpu,
            (map.width(), map.height()),
            &map.pixels().iter().map(|p| p.extend(1.0).to_array()).collect::<Vec<_>>(),
        )
    }

    fn from_texels(gpu: &Gpu, (w, h): (u32, u32), texels: &[[f32; 4]]) -> Result<Self, GpuError> {
        gpu.check_texture(w, h, 1)?;
        let texture = gpu.device.create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("background"),
                size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(texels),
        );
        Ok(Self { texture, size: (w, h), turn: 0.0 })
    }

    /// Turns the map about +Y by `radians` (a world direction d sees the map at R(-radians) d):
    /// a viewer's turn of the environment, nothing uploaded again. The lights and the ambient of
    /// the same map turn with it on the caller's side (`DistantLight` directions, `Sh9::rotated`,
    /// `SpecularAmbient::set_turn`).
    pub fn set_turn(&mut self, radians: f32) {
        self.turn = if radians.is_finite() { radians.rem_euclid(std::f32::consts::TAU) } else { 0.0 };
    }

    /// The map's turn about +Y, radians in [0, 2 pi).
    #[must_use]
    pub fn turn(&self) -> f32 {
        self.turn
    }
}
