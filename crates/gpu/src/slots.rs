//! Per-light resources made once and reused from frame to frame. A technique that records
//! several lights into one submission needs each light's uniforms in buffers of their own
//! (`queue.write_buffer` lands before the whole submission runs, so one buffer rewritten from
//! light to light would hold the last light's values for all of them). [`Slots`] hands out one
//! slot a light in the order lights are recorded and starts over at the next submission
//! ([`crate::Gpu::epoch`]): the k-th light of every frame gets the same slot, its buffers and
//! bind groups, updated with `queue.write_buffer`. A frame makes new slots only when it records
//! more lights than any frame before it.

use crate::context::{Gpu, GpuError};
use std::sync::Mutex;

/// The most slots one [`Slots`] hands out between two submissions: more means the caller
/// submits through its own queue without [`Gpu::mark_submitted`], and the slots would grow
/// for ever.
pub const MAX_SLOTS_PER_SUBMISSION: usize = 4096;

/// Resources of type `T`, one a light recorded in a submission; see the module's documentation.
pub struct Slots<T> {
    inner: Mutex<Inner<T>>,
}

struct Inner<T> {
    slots: Vec<T>,
    // the next slot to hand out, and the submission epoch it counts within
    next: usize,
    epoch: u64,
}

impl<T> Inner<T> {
    /// Slot `k` (at most one past the last made), made by `make` when it is new.
    fn slot(&mut self, k: usize, make: impl FnOnce() -> T) -> &mut T {
        if k == self.slots.len() {
            self.slots.push(make());
        }
        &mut self.slots[k]
    }
}

impl<T> Default for Slots<T> {
    fn default() -> Self {
        Self { inner: Mutex::new(Inner { slots: Vec::new(), next: 0, epoch: u64::MAX }) }
    }
}

impl<T> std::fmt::Debug for Slots<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Slots({} made)", self.made())
    }
}

impl<T> Slots<T> {
    /// No slot yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Calls `f` on the next slot of this submission, made by `make` when no frame has used it
    /// before.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] past [`MAX_SLOTS_PER_SUBMISSION`] slots in one submission.
    pub fn next<R>(&self, gpu: &Gpu, make: impl FnOnce() -> T, f: impl FnOnce(&mut T) -> R) -> Result<R, GpuError> {
        let (mut inner, k) = self.claim(gpu);
        let k = k.ok_or(GpuError::TooLarge {
            what: "lights recorded in one submission (submit through Gpu::submit or call Gpu::mark_submitted)",
            size: MAX_SLOTS_PER_SUBMISSION as u64 + 1,
            limit: MAX_SLOTS_PER_SUBMISSION as u64,
        })?;
        Ok(f(inner.slot(k, make)))
    }

    /// As [`Slots::next`], but past [`MAX_SLOTS_PER_SUBMISSION`] slots `f` gets a slot of the
    /// light's own, made for it and dropped after (correct, only not reused).
    pub fn next_or_own<R>(&self, gpu: &Gpu, make: impl FnOnce() -> T, f: impl FnOnce(&mut T) -> R) -> R {
        let (mut inner, k) = self.claim(gpu);
        match k {
            Some(k) => f(inner.slot(k, make)),
            None => {
                drop(inner);
                f(&mut make())
            }
        }
    }

    /// The slots, locked, and the index of this submission's next one (`None` past the limit).
    fn claim(&self, gpu: &Gpu) -> (std::sync::MutexGuard<'_, Inner<T>>, Option<usize>) {
        let mut inner = self.inner.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let epoch = gpu.epoch();
        if inner.epoch != epoch {
            inner.epoch = epoch;
            inner.next = 0;
        }
        let k = inner.next;
        if k >= MAX_SLOTS_PER_SUBMISSION {
            return (inner, None);
        }
        inner.next += 1;
        (inner, Some(k))
    }

    /// Slots made so far.
    #[must_use]
    pub fn made(&self) -> usize {
        self.inner.lock().map_or(0, |i| i.slots.len())
    }
}

/// Writes `data` into `buffer` with `queue.write_buffer`, first replacing the buffer with a
/// larger one (of `usage` and `COPY_DST`, a power of two of at least 256 bytes) when it does
/// not fit: a slot's variable-length data (lights, arguments) grows to the largest frame's and
/// stays there.
pub(crate) fn write_grown(gpu: &Gpu, buffer: &mut wgpu::Buffer, label: &str, usage: wgpu::BufferUsages, data: &[u8]) {
    if buffer.size() < data.len() as u64 {
        *buffer = writable_buffer(gpu, label, usage, (data.len() as u64).max(256).next_power_of_two());
    }
    gpu.queue.write_buffer(buffer, 0, data);
}

/// A `size`-byte buffer of `usage` that `queue.write_buffer` can rewrite (`COPY_DST`): a slot's
/// uniform, or the first of its grown buffers.
pub(crate) fn writable_buffer(gpu: &Gpu, label: &str, usage: wgpu::BufferUsages, size: u64) -> wgpu::Buffer {
    gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A binding of the first `bytes` of `buffer` (at least 4): what a grown buffer binds, so
/// that shaders see the data's length, not the buffer's.
pub(crate) fn binding_of(buffer: &wgpu::Buffer, bytes: u64) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset: 0,
        size: std::num::NonZeroU64::new(bytes.clamp(4, buffer.size())),
    })
}

/// A value kept with the resources it was made from, made again when they change: a bind
/// group with the textures and buffers it binds.
#[derive(Debug)]
pub struct Keyed<K, V> {
    entry: Option<(K, V)>,
}

impl<K, V> Default for Keyed<K, V> {
    fn default() -> Self {
        Self { entry: None }
    }
}

impl<K: PartialEq, V> Keyed<K, V> {
    /// The value for `key`, made by `make` when the key differs from the last one.
    pub fn get(&mut self, key: K, make: impl FnOnce() -> V) -> &V {
        match self.try_get(key, || Ok::<V, std::convert::Infallible>(make())) {
            Ok(v) => v,
            Err(never) => match never {},
        }
    }

    /// As [`Keyed::get`] with a `make` that can fail (then nothing is kept).
    ///
    /// # Errors
    /// `make`'s.
    pub fn try_get<E>(&mut self, key: K, make: impl FnOnce() -> Result<V, E>) -> Result<&V, E> {
        if self.entry.as_ref().is_none_or(|(k, _)| *k != key) {
            self.entry = Some((key, make()?));
        }
        Ok(&self.entry.as_ref().expect("just set").1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyed_values_are_made_again_only_when_their_key_changes() {
        let mut k: Keyed<u32, u32> = Keyed::default();
        let mut made = 0;
        for key in [1, 1, 2, 2, 1] {
            let v = *k.get(key, || {
                made += 1;
                key * 10
            });
            assert_eq!(v, key * 10);
        }
        assert_eq!(made, 3);
    }
}
