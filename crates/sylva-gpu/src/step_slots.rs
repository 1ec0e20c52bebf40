//! Per-step parameters for many steps in one compute pass: a kernel that reads its step's
//! parameters from a buffer binding would otherwise need a copy into that buffer, and a pass
//! of its own, per step. [`StepSlots`] writes a submission's parameters once, copies up to
//! [`StepSlots::len`] of them into as many *slots* (one storage-offset alignment apart)
//! before a pass, and the k-th step of the pass binds slot k ([`StepSlots::binding`]), so
//! its bind groups are made once.

use crate::GpuContext;
use crate::kernel::upload;
use bytemuck::Pod;

/// Slots of step parameters of type `T` (see the module docs).
#[derive(Debug)]
pub struct StepSlots<T> {
    /// The current submission's parameters, one per `stride` bytes.
    staging: wgpu::Buffer,
    capacity: usize,
    /// `count` slots, bound by the steps of a pass.
    slots: wgpu::Buffer,
    count: usize,
    /// Bytes from one slot to the next: `T` rounded up to the storage-offset alignment.
    stride: u64,
    _t: std::marker::PhantomData<T>,
}

impl<T: Pod> StepSlots<T> {
    /// `count` slots, each holding `initial`.
    pub fn new(ctx: &GpuContext, label: &'static str, count: usize, initial: T) -> Result<Self, crate::GpuError> {
        let align = ctx.device.limits().min_storage_buffer_offset_alignment as u64;
        let stride = (std::mem::size_of::<T>() as u64).div_ceil(align) * align;
        Ok(Self {
            staging: staging(ctx, label, stride, count),
            capacity: count,
            slots: upload(ctx, label, &strided(&vec![initial; count], stride))?,
            count,
            stride,
            _t: std::marker::PhantomData,
        })
    }

    /// Steps per pass: the number of slots.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there are no slots.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Slot `slot`'s binding.
    pub fn binding(&self, slot: usize) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.slots,
            offset: slot as u64 * self.stride,
            size: std::num::NonZeroU64::new(std::mem::size_of::<T>() as u64),
        })
    }

    /// Writes a submission's parameters (queued before it).
    pub fn write(&mut self, ctx: &GpuContext, params: &[T]) {
        if params.len() > self.capacity {
            self.staging = staging(ctx, "step parameters", self.stride, params.len());
            self.capacity = params.len();
        }
        ctx.queue.write_buffer(&self.staging, 0, &strided(params, self.stride));
    }

    /// Records the copy of the written parameters `first..first + count` into slots
    /// `0..count` (`count` at most [`Self::len`]), before the pass that reads them.
    pub fn copy(&self, encoder: &mut wgpu::CommandEncoder, first: usize, count: usize) {
        debug_assert!(count <= self.count);
        let stride = self.stride;
        encoder.copy_buffer_to_buffer(&self.staging, first as u64 * stride, &self.slots, 0, count as u64 * stride);
    }
}

/// `params` laid out one per `stride` bytes (the gaps zero).
fn strided<T: Pod>(params: &[T], stride: u64) -> Vec<u8> {
    let size = std::mem::size_of::<T>();
    let mut bytes = vec![0u8; params.len() * stride as usize];
    for (chunk, p) in bytes.chunks_exact_mut(stride as usize).zip(params) {
        chunk[..size].copy_from_slice(bytemuck::bytes_of(p));
    }
    bytes
}

/// A buffer for `count` steps' parameters at `stride` bytes, filled by writes and read by
/// copies.
fn staging(ctx: &GpuContext, label: &'static str, stride: u64, count: usize) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: stride * count.max(1) as u64,
        usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
