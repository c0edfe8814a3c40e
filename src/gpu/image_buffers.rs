//! The buffers the render kernel writes and the host clears and reads back: per-pixel running
//! mean and M2, the denoiser's AOVs, the segment and dropped-sample counters, the tile origin,
//! bidirectional path tracing's splat film, and the readback buffers.

use super::upload::Binding;

pub struct ImageBuffers {
    /// Per pixel vec4: running mean radiance (xyz).
    pub mean: wgpu::Buffer,
    /// Per pixel vec4: M2, the sum of squared deviations from the mean (xyz).
    pub m2: wgpu::Buffer,
    /// Per pixel vec4s of the denoiser's AOVs (shaders/integrator/aov.wgsl): albedo and depth,
    /// normal. One vec4 each when the kernel has AOVs compiled out.
    pub aovs: [wgpu::Buffer; 2],
    pub readback: wgpu::Buffer,
    /// The kernel's segment counter (one u32).
    pub counter: wgpu::Buffer,
    /// The origin of the tile a dispatch covers (`shaders/integrator/tiles.wgsl`).
    pub tile: wgpu::Buffer,
    /// The kernel's count of dropped samples (one u32), read and cleared after every batch.
    pub nonfinite: wgpu::Buffer,
    pub nonfinite_readback: wgpu::Buffer,
    /// Bidirectional path tracing's splat film (shaders/integrator/splat.wgsl: per pixel and
    /// channel a 64-bit sum as two u32 words, low first) and its readback; `None` in kernels
    /// without it.
    pub splats: Option<SplatBuffers>,
}

pub struct SplatBuffers {
    pub film: wgpu::Buffer,
    pub readback: wgpu::Buffer,
}

impl ImageBuffers {
    /// Accumulators of `accum_size` bytes, AOV buffers of `aov_size`, and a splat film of
    /// `splat_size` bytes where that is given.
    pub fn new(
        device: &wgpu::Device,
        accum_size: u64,
        aov_size: u64,
        splat_size: Option<u64>,
    ) -> ImageBuffers {
        // Buffers the kernel writes and the host clears and reads back.
        let read_write_buffer = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let readback = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        ImageBuffers {
            counter: read_write_buffer("segments_traced", 8),
            tile: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("tile_origin"),
                size: 16,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            nonfinite: read_write_buffer("nonfinite_samples", 8),
            nonfinite_readback: readback("nonfinite readback", 8),
            mean: read_write_buffer("accum_mean", accum_size),
            m2: read_write_buffer("accum_m2", accum_size),
            aovs: ["aov_albedo_depth", "aov_normal"]
                .map(|label| read_write_buffer(label, aov_size)),
            readback: readback("readback", accum_size),
            splats: splat_size.map(|size| SplatBuffers {
                film: read_write_buffer("splats", size),
                readback: readback("splat readback", size),
            }),
        }
    }

    /// The kernel's bindings of these buffers.
    pub fn bindings(&self) -> Vec<Binding<'_>> {
        let read_write = wgpu::BufferBindingType::Storage { read_only: false };
        let mut bindings = vec![
            (4, read_write, &self.mean),
            (5, read_write, &self.m2),
            (7, read_write, &self.counter),
            (10, read_write, &self.aovs[0]),
            (11, read_write, &self.aovs[1]),
            (16, read_write, &self.nonfinite),
            (17, wgpu::BufferBindingType::Uniform, &self.tile),
        ];
        if let Some(splats) = &self.splats {
            bindings.push((14, read_write, &splats.film));
        }
        bindings
    }
}
