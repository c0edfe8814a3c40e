//! The wavefront layout (`shaders/wavefront.wgsl`): the path loop as a sequence of stage
//! dispatches over queues of live paths, instead of one kernel that loops.

use super::binding::{bind_buffers, compute_bind_group_layout, compute_pipeline_with_groups};
use crate::shader_types::{Params, WaveControl, WaveParams, WavePath, WaveShadow};
use anyhow::{anyhow, Result};

/// Workgroup size of the stage kernels (`WAVE_WORKGROUP` in WGSL).
const WAVE_WORKGROUP: u32 = 64;

/// Paths in flight per wave, at most: enough to fill the device, few enough that the path
/// buffer (80 bytes a path) stays small.
pub const DEFAULT_WAVE_PATHS: u32 = 1 << 18;

/// The stage pipelines and their queues, for one image size.
pub struct Wavefront {
    generate: wgpu::ComputePipeline,
    extend: wgpu::ComputePipeline,
    shadow: wgpu::ComputePipeline,
    setup: wgpu::ComputePipeline,
    accumulate: wgpu::ComputePipeline,
    /// `stage_groups[p]` reads queue p and appends to queue 1 - p.
    stage_groups: [wgpu::BindGroup; 2],
    dispatch_group: wgpu::BindGroup,
    dispatch_sizes: wgpu::Buffer,
    wave_params: wgpu::Buffer,
    /// Samples per pixel in a full wave.
    samples_per_wave: u32,
    pixels: u32,
}

impl Wavefront {
    /// Pipelines and buffers for `params`'s image size, sharing the megakernel's scene bind
    /// group (group 0, `scene_layout`) and shader `module`. A wave holds at most `wave_paths`
    /// paths (whole pixels' worth, at least one sample per pixel).
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        module: &wgpu::ShaderModule,
        params: &Params,
        wave_paths: u32,
    ) -> Result<Wavefront> {
        let pixels = params.width * params.height;
        let samples_per_wave = (wave_paths / pixels).max(1);
        let paths = pixels as u64 * samples_per_wave as u64;
        let max_binding = device.limits().max_storage_buffer_binding_size;
        let path_bytes = paths * size_of::<WavePath>() as u64;
        let max_groups = device.limits().max_compute_workgroups_per_dimension as u64;
        if path_bytes > max_binding || paths.div_ceil(WAVE_WORKGROUP as u64) > max_groups {
            return Err(anyhow!(
                "a {}×{} image is too large for the wavefront layout on this device",
                params.width,
                params.height
            ));
        }
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let path_buffer = buffer("wave paths", path_bytes, storage);
        let queues = [
            buffer("wave queue 0", paths * 4, storage),
            buffer("wave queue 1", paths * 4, storage),
        ];
        let shadow_queue = buffer(
            "wave shadow queue",
            paths * size_of::<WaveShadow>() as u64,
            storage,
        );
        let control = buffer("wave control", size_of::<WaveControl>() as u64, storage);
        let wave_params = buffer(
            "wave params",
            size_of::<WaveParams>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let batch_mean = buffer("wave batch mean", pixels as u64 * 16, storage);
        let batch_m2 = buffer("wave batch m2", pixels as u64 * 16, storage);
        let dispatch_sizes = buffer(
            "wave dispatch sizes",
            32,
            storage | wgpu::BufferUsages::INDIRECT,
        );

        use wgpu::BufferBindingType as T;
        let read_write = T::Storage { read_only: false };
        let stage_layout = compute_bind_group_layout(
            device,
            "wave stages",
            &[
                (0, read_write),
                (1, T::Storage { read_only: true }),
                (2, read_write),
                (3, read_write),
                (4, read_write),
                (5, T::Uniform),
                (6, read_write),
                (7, read_write),
            ],
        );
        let stage_group = |p: usize| {
            bind_buffers(
                device,
                "wave stages",
                &stage_layout,
                &[
                    (0, &path_buffer),
                    (1, &queues[p]),
                    (2, &queues[1 - p]),
                    (3, &shadow_queue),
                    (4, &control),
                    (5, &wave_params),
                    (6, &batch_mean),
                    (7, &batch_m2),
                ],
            )
        };
        let dispatch_layout =
            compute_bind_group_layout(device, "wave dispatch", &[(0, read_write)]);
        let dispatch_group = bind_buffers(
            device,
            "wave dispatch",
            &dispatch_layout,
            &[(0, &dispatch_sizes)],
        );
        // The stages that dispatch indirectly must not see the dispatch sizes bound as
        // storage, so only the setup stage's layout has group 2.
        let stages = [scene_layout, &stage_layout];
        let pipeline = |entry: &str, layouts: &[&wgpu::BindGroupLayout]| {
            compute_pipeline_with_groups(device, entry, layouts, module, entry)
        };
        Ok(Wavefront {
            generate: pipeline("wave_generate", &stages),
            extend: pipeline("wave_extend", &stages),
            shadow: pipeline("wave_shadow", &stages),
            setup: pipeline(
                "wave_setup",
                &[scene_layout, &stage_layout, &dispatch_layout],
            ),
            accumulate: pipeline("wave_accumulate", &stages),
            stage_groups: [stage_group(0), stage_group(1)],
            dispatch_group,
            dispatch_sizes,
            wave_params,
            samples_per_wave,
            pixels,
        })
    }

    /// The waves that trace `params.sample_count` samples per pixel from `params.sample_start`.
    pub fn plan(&self, params: &Params) -> Vec<WaveParams> {
        let mut waves = Vec::new();
        let mut done = 0;
        while done < params.sample_count {
            let spp = self.samples_per_wave.min(params.sample_count - done);
            waves.push(WaveParams {
                sample_first: params.sample_start + done,
                samples_per_pixel: spp,
                batch_done: done,
                last_wave: (done + spp == params.sample_count) as u32,
            });
            done += spp;
        }
        waves
    }

    /// Uploads `wave`'s parameters (they take effect at the next submit).
    pub fn write_wave(&self, queue: &wgpu::Queue, wave: &WaveParams) {
        queue.write_buffer(&self.wave_params, 0, bytemuck::bytes_of(wave));
    }

    /// Records one wave's stages into `pass`, which has the scene bound as group 0.
    pub fn record(
        &self,
        pass: &mut wgpu::ComputePass,
        params: &Params,
        wave: &WaveParams,
        shadows: bool,
    ) {
        let paths = self.pixels * wave.samples_per_pixel;
        let groups = |n: u32| n.div_ceil(WAVE_WORKGROUP);
        pass.set_pipeline(&self.generate);
        pass.set_bind_group(1, &self.stage_groups[1], &[]);
        pass.dispatch_workgroups(groups(paths), 1, 1);
        for bounce in 0..=params.max_bounces {
            let stage_group = &self.stage_groups[(bounce % 2) as usize];
            pass.set_pipeline(&self.extend);
            pass.set_bind_group(1, stage_group, &[]);
            if bounce == 0 {
                pass.dispatch_workgroups(groups(paths), 1, 1);
            } else {
                pass.dispatch_workgroups_indirect(&self.dispatch_sizes, 0);
            }
            pass.set_pipeline(&self.setup);
            pass.set_bind_group(2, &self.dispatch_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            if shadows {
                pass.set_pipeline(&self.shadow);
                pass.dispatch_workgroups_indirect(&self.dispatch_sizes, 16);
            }
        }
        pass.set_pipeline(&self.accumulate);
        pass.dispatch_workgroups(groups(self.pixels), 1, 1);
    }
}
