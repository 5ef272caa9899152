//! Lights gated on the GPU: which lights need a shadow pass (a visible receiver faces them and
//! Weber's law does not find them negligible) stays where [`crate::ReceiverReduction`] found it,
//! and each light's draws and dispatches are indirect, their arguments zeroed by a one-workgroup
//! pass (`crates/gpu/shaders/gate.wgsl`) when it needs none. The CPU records every light without
//! waiting for the reduction; a skipped light costs the gate pass and the clears of its passes,
//! not their draws. What was skipped is read back after the frame ([`crate::PendingStats`]).

use crate::context::Gpu;
use std::ops::Range;

/// A reduction's result left on the GPU: what gates lights and what techniques that fit their
/// work to the receivers (orthographic maps' focus) read, without a readback.
#[derive(Clone, Debug)]
pub struct GpuStats {
    pub(crate) stats: wgpu::Buffer,
    pub(crate) weber: Option<wgpu::Buffer>,
    pub(crate) gate: wgpu::ComputePipeline,
    pub(crate) first: u32,
    // each gated light's arguments, parameters and bind group, kept from frame to frame
    pub(crate) slots: std::sync::Arc<crate::Slots<GateSlot>>,
}

/// One gated light's resources ([`crate::Slots`]): its argument words (grown to the most a
/// light has used), its parameters and the bind group over them and the reduction's buffers.
#[derive(Debug)]
pub(crate) struct GateSlot {
    args: wgpu::Buffer,
    params: wgpu::Buffer,
    bind: crate::Keyed<(wgpu::Buffer, wgpu::Buffer, wgpu::Buffer), wgpu::BindGroup>,
}

impl GpuStats {
    /// Word of the visible points' count in [`GpuStats::buffer`].
    pub const COUNT_WORD: u32 = 6;
    /// First of the 4 words (xyz, then their count as a float) of the visible points' mean.
    pub const MEAN_WORD: u32 = 44;
    /// Word of the bits of the 95th percentile of the points' distances to the mean.
    pub const RADIUS_WORD: u32 = 48;

    /// The reduction's statistics, as `crates/gpu/shaders/receivers.wgsl` lays them out (words at
    /// [`GpuStats::COUNT_WORD`], [`GpuStats::MEAN_WORD`], [`GpuStats::RADIUS_WORD`]).
    #[must_use]
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.stats
    }

    /// The same result for a sub-list of the reduction's lights starting at `first`: light `k`
    /// of the sub-list is light `first + k` of the reduction (paper 001's EnvIndirects after its
    /// EnvDirects).
    #[must_use]
    pub fn starting_at(&self, first: u32) -> Self {
        Self { first: self.first + first, ..self.clone() }
    }

    /// The gate of light `k` (of the lights the reduction was given, counted from
    /// [`GpuStats::starting_at`]).
    #[must_use]
    pub fn gate(&self, k: u32) -> Gate<'_> {
        Gate { stats: self, light: self.first + k }
    }
}

/// One light's gate: see the module's documentation.
#[derive(Clone, Copy, Debug)]
pub struct Gate<'a> {
    stats: &'a GpuStats,
    light: u32,
}

/// An indirect call's arguments, before the gate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Indirect {
    /// `draw(vertices, instances)`.
    Draw {
        /// The vertices.
        vertices: Range<u32>,
        /// The instances.
        instances: Range<u32>,
    },
    /// `dispatch_workgroups(x, y, z)`.
    Dispatch([u32; 3]),
}

impl Indirect {
    /// One instance of `vertices`.
    #[must_use]
    pub fn draw(vertices: Range<u32>) -> Self {
        Self::Draw { vertices, instances: 0..1 }
    }
}

/// A light's indirect arguments after its gate, one 16-byte slot per call in the order given.
pub struct GatedArgs {
    buffer: wgpu::Buffer,
}

impl GatedArgs {
    /// Slot bytes: a draw's 4 words (a dispatch uses 3).
    const SLOT: u64 = 16;

    /// Draws slot `k` (which must hold an [`Indirect::Draw`]).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, k: usize) {
        pass.draw_indirect(&self.buffer, k as u64 * Self::SLOT);
    }

    /// Dispatches slot `k` (which must hold an [`Indirect::Dispatch`]).
    pub fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, k: usize) {
        pass.dispatch_workgroups_indirect(&self.buffer, k as u64 * Self::SLOT);
    }
}

/// One light's calls, issued directly or, with a gate, through its gated slots.
pub struct Calls {
    args: Vec<Indirect>,
    gated: Option<GatedArgs>,
}

impl Calls {
    /// `args` as they are without a gate; otherwise gated in `encoder` (record this before the
    /// passes that issue them).
    #[must_use]
    pub fn new(gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, gate: Option<Gate<'_>>, args: Vec<Indirect>) -> Self {
        let gated = gate.map(|g| g.record(gpu, encoder, &args));
        Self { args, gated }
    }

    /// `args` as they are, with no gate.
    #[must_use]
    pub fn direct(args: Vec<Indirect>) -> Self {
        Self { args, gated: None }
    }

    /// Issues call `k` (an [`Indirect::Draw`]).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, k: usize) {
        match (&self.gated, self.args.get(k)) {
            (Some(g), Some(Indirect::Draw { .. })) => g.draw(pass, k),
            (None, Some(Indirect::Draw { vertices, instances })) => pass.draw(vertices.clone(), instances.clone()),
            _ => {}
        }
    }

    /// Issues call `k` (an [`Indirect::Dispatch`]).
    pub fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, k: usize) {
        match (&self.gated, self.args.get(k)) {
            (Some(g), Some(Indirect::Dispatch(_))) => g.dispatch(pass, k),
            (None, Some(Indirect::Dispatch([x, y, z]))) => pass.dispatch_workgroups(*x, *y, *z),
            _ => {}
        }
    }
}

impl Gate<'_> {
    /// Records the gate of `args` into `encoder`: the returned slots hold them where the light
    /// needs its pass and zeros where it does not. Record it before the passes that use them.
    #[must_use]
    pub fn record(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, args: &[Indirect]) -> GatedArgs {
        let mut words: Vec<u32> = args
            .iter()
            .flat_map(|a| match a {
                Indirect::Draw { vertices, instances } => [
                    vertices.end.saturating_sub(vertices.start),
                    instances.end.saturating_sub(instances.start),
                    vertices.start,
                    instances.start,
                ],
                Indirect::Dispatch([x, y, z]) => [*x, *y, *z, 0],
            })
            .collect();
        if words.is_empty() {
            // storage bindings may not be empty
            words.push(0);
        }
        let params = [self.light, words.len() as u32, u32::from(self.stats.weber.is_some()), 0];
        let weber = self.stats.weber.as_ref().unwrap_or(&self.stats.stats);
        let bytes = 4 * words.len() as u64;
        let make = || {
            let buffer = |label, size, usage| {
                gpu.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage,
                    mapped_at_creation: false,
                })
            };
            let usage = wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
            // room for a few more calls than the first light had: later ones rarely grow it
            let args = buffer("gated arguments", bytes.max(256), usage);
            let params = buffer("gate", 16, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
            GateSlot { args, params, bind: crate::Keyed::default() }
        };
        // past the slots a submission may hold, a light's own resources (made for it alone)
        let (args, bind) = self.stats.slots.next_or_own(gpu, make, |slot| {
            if slot.args.size() < bytes {
                *slot = make();
            }
            gpu.queue.write_buffer(&slot.args, 0, bytemuck::cast_slice(&words));
            gpu.queue.write_buffer(&slot.params, 0, bytemuck::cast_slice(&params));
            let key = (slot.args.clone(), self.stats.stats.clone(), weber.clone());
            let (args, params) = (slot.args.clone(), slot.params.clone());
            let bind = slot.bind.get(key, || {
                gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("gate"),
                    layout: &self.stats.gate.get_bind_group_layout(0),
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: self.stats.stats.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 2, resource: weber.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 3, resource: args.as_entire_binding() },
                    ],
                })
            });
            (args, bind.clone())
        });
        gpu.count_gate_pass();
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("gate"), timestamp_writes: None });
        pass.set_pipeline(&self.stats.gate);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        drop(pass);
        GatedArgs { buffer: args }
    }
}
