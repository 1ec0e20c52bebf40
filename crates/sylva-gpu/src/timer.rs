//! GPU time of a stretch of work, from timestamp queries.
//!
//! A [`GpuTimer`] writes one timestamp at the start of an empty compute pass and one at the
//! end of another. Recorded around work in one encoder ([`GpuTimer::begin`] and
//! [`GpuTimer::end`]), or submitted on their own before and after several submissions
//! ([`GpuTimer::start`] and [`GpuTimer::stop`]), the difference is the time the queue spent
//! from the first pass to the last on the GPU's own clock: it leaves out the CPU's submit
//! and the wait for completion that wall-clock timing includes. Queue submissions run in
//! order, so the stamps bracket everything submitted between them.
//!
//! Compute work is best bracketed by submissions ([`GpuTimer::start`] before, [`GpuTimer::stop`]
//! after): inside one encoder, a driver may run compute passes with no barrier between them
//! and the stamp concurrently (lavapipe does), so the stamps can miss them.
//!
//! Timestamp queries are an optional feature ([`GpuContext::timestamps`]); without them
//! [`GpuTimer::new`] returns `None` and callers fall back to wall clock.

use crate::{GpuContext, GpuError};
use std::time::Duration;

/// Two timestamps and the buffers that bring them back.
#[derive(Debug)]
pub struct GpuTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl GpuTimer {
    /// A timer, or `None` when the device has no timestamp queries.
    pub fn new(ctx: &GpuContext) -> Option<Self> {
        if !ctx.timestamps {
            return None;
        }
        let set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("timer"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let buffer = |label, usage| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            set,
            resolve: buffer("timer resolve", wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer("timer readback", wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
        })
    }

    fn stamp(&self, encoder: &mut wgpu::CommandEncoder, index: u32) {
        let (beginning_of_pass_write_index, end_of_pass_write_index) =
            if index == 0 { (Some(0), None) } else { (None, Some(1)) };
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("timer"),
            timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                query_set: &self.set,
                beginning_of_pass_write_index,
                end_of_pass_write_index,
            }),
        });
    }

    /// Records the first timestamp into `encoder` (before the work to time).
    pub fn begin(&self, encoder: &mut wgpu::CommandEncoder) {
        self.stamp(encoder, 0);
    }

    /// Records the second timestamp into `encoder` (after the work) and copies both out.
    pub fn end(&self, encoder: &mut wgpu::CommandEncoder) {
        self.stamp(encoder, 1);
        encoder.resolve_query_set(&self.set, 0..2, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, 16);
    }

    /// Submits the first timestamp on its own: what is submitted next is timed.
    pub fn start(&self, ctx: &GpuContext) {
        let mut e = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("timer start") });
        self.begin(&mut e);
        ctx.submit([e.finish()]);
    }

    /// Submits the second timestamp on its own, after everything submitted since
    /// [`GpuTimer::start`].
    pub fn stop(&self, ctx: &GpuContext) {
        let mut e = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("timer stop") });
        self.end(&mut e);
        ctx.submit([e.finish()]);
    }

    /// Waits for the GPU and returns the time between the two stamps; `None` when the
    /// stamps did not advance (some drivers return zeros for unsupported stages).
    pub fn read(&self, ctx: &GpuContext) -> Result<Option<Duration>, GpuError> {
        let ticks: [u64; 2] = crate::kernel::map_read(ctx, &self.readback, bytemuck::pod_read_unaligned)?;
        let ns = ticks[1].saturating_sub(ticks[0]) as f64 * ctx.queue.get_timestamp_period() as f64;
        Ok((ns > 0.0).then(|| Duration::from_nanos(ns.round() as u64)))
    }
}
