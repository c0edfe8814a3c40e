//! Benchmark instrumentation of the GPU renderer: the number of ray segments the kernel
//! traced and, where the device has timestamp queries, the kernel's device time, read back
//! after every batch (`glint bench`; renders leave it off).

use super::context::GpuContext;
use anyhow::Result;

/// Timestamp queries and the segment count, read after each batch.
pub struct Instruments {
    /// Two timestamps around the render pass, where the device supports them.
    pub timestamps: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    /// Counter and timestamps land here for readback: [segments: u32, pad: u32, t0: u64, t1: u64].
    readback: wgpu::Buffer,
    pub segments: u64,
    pub last_kernel_time: Option<std::time::Duration>,
}

impl Instruments {
    pub fn new(ctx: &GpuContext) -> Instruments {
        let device = &ctx.device;
        let timestamps = ctx
            .features
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("kernel time"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                });
                let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("kernel time resolve"),
                    size: 16,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                (set, resolve)
            });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("instrument readback"),
            size: 24,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Instruments {
            timestamps,
            readback,
            segments: 0,
            last_kernel_time: None,
        }
    }

    /// Reads the segment counter (`counter_buffer`) and timestamps of the submission just
    /// made, and clears the counter; returns the kernel's device time (zero where it is not
    /// measured).
    pub fn read(
        &mut self,
        ctx: &GpuContext,
        counter_buffer: &wgpu::Buffer,
    ) -> Result<std::time::Duration> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(counter_buffer, 0, &self.readback, 0, 8);
        if let Some((_, resolve)) = &self.timestamps {
            encoder.copy_buffer_to_buffer(resolve, 0, &self.readback, 8, 16);
        }
        encoder.clear_buffer(counter_buffer, 0, None);
        ctx.queue.submit([encoder.finish()]);
        let (segments, t0, t1) = ctx.read_mapped(&self.readback, |bytes| {
            let words: &[u32] = bytemuck::cast_slice(&bytes[..8]);
            let stamps: &[u64] = bytemuck::cast_slice(&bytes[8..24]);
            (words[0], stamps[0], stamps[1])
        })?;
        self.segments += segments as u64;
        if self.timestamps.is_some() && t1 > t0 {
            let ns = (t1 - t0) as f64 * ctx.queue.get_timestamp_period() as f64;
            return Ok(std::time::Duration::from_nanos(ns as u64));
        }
        Ok(std::time::Duration::ZERO)
    }
}
