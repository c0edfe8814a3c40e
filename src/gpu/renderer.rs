//! The GPU renderer: scene upload, sample batches, readback of the running sums.

use super::acceleration::AccelerationStructure;
use super::binding::{bind_group, compute_layout_entries};
use super::context::GpuContext;
use super::image_buffers::ImageBuffers;
use super::inline_uniforms::params_binding_for;
use super::instruments::Instruments;
use super::loop_budget::{
    bdpt_loop_iterations_per_sample, device_loop_limit, hardware_loop_iterations_per_ray,
    hardware_loop_iterations_per_sample, loop_iterations_per_ray, loop_iterations_per_sample,
    max_samples_per_dispatch, LAVAPIPE_LOOP_LIMIT,
};
use super::tiles::{next_tile, TilePlanner};
use super::traversal::Traversal;
use super::upload::{check_storage_binding_count, ImageSizes, SceneBuffers};
use crate::image::aov::Aovs;
use crate::image::output::Image;
use crate::kernel::source::{
    entry_point_for, render_kernel_source_with_texels, ParamsBinding, WORKGROUP_SIZE,
};
use crate::kernel::texels::TexelBinding;
use crate::kernel::types::{Params, INTEGRATOR_BDPT};
use crate::kernel::variant::{KernelFeatures, KernelVariant, SceneBinding};
use crate::kernel::KernelScene;
use crate::render::accumulation::variance_of_mean;
use crate::render::accumulation::{Accumulation, PixelCounts};
use crate::render::{check_size, Renderer};
use anyhow::{anyhow, Result};
use wgpu::util::DeviceExt;

pub struct GpuRenderer<'a> {
    ctx: &'a GpuContext,
    variant: KernelVariant,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The buffers the kernel accumulates into, and their readback.
    images: ImageBuffers,
    params: Params,
    params_buffer: wgpu::Buffer,
    samples: u32,
    /// Which pixels adaptive sampling has stopped, and at how many samples (the kernel sees a
    /// stopped pixel by the non-zero w of its M2: shaders/integrator/accumulate.wgsl).
    counts: PixelCounts,
    first_sample: u32,
    /// Benchmark instrumentation, off unless asked for: it reads back after every batch.
    instruments: Option<Instruments>,
    tiles: TilePlanner,
    nonfinite: u64,
    /// The device's loop limit (lavapipe: src/gpu/loop_budget.rs).
    loop_limit: Option<u64>,
    /// The scene's worst case of loop iterations per sample (src/gpu/loop_budget.rs).
    loop_iterations: u64,
    /// The hardware traversal's acceleration structure, bound with the kernel (kept alive).
    _acceleration: Option<AccelerationStructure>,
    /// Where the kernel reads texels from (src/kernel/texels.rs).
    texel_binding: TexelBinding,
}

/// The w of a stopped pixel's M2 (shaders/integrator/accumulate.wgsl's `pixel_stopped`).
const STOPPED_FLAG: f32 = 1.0;

/// Wanted duration of one GPU submission: a batch longer than this is split into tiles.
/// Desktop drivers kill submissions after about 2 s; lavapipe has no watchdog.
pub const SUBMISSION_TARGET: std::time::Duration = std::time::Duration::from_millis(250);

/// [`KernelVariant::default_for`] on this device.
fn default_variant(ctx: &GpuContext, scene: &KernelScene) -> KernelVariant {
    let max_uniform = ctx.device.limits().max_uniform_buffer_binding_size;
    KernelVariant::default_for(scene, max_uniform)
}

impl<'a> GpuRenderer<'a> {
    /// A renderer for `scene` with the fastest kernel for it: its objects in uniform buffers
    /// when they fit the device's limit (storage buffers otherwise), and only the features it
    /// uses compiled in; or a kernel shared by scenes where `GLINT_KERNEL_VARIANT=shared`
    /// ([`KernelVariant::default_for`]).
    pub fn new(ctx: &'a GpuContext, scene: &KernelScene) -> Result<GpuRenderer<'a>> {
        Self::with_variant(ctx, scene, default_variant(ctx, scene))
    }

    /// A renderer with [`KernelVariant::for_scene`]'s kernel whatever `GLINT_KERNEL_VARIANT`
    /// says: for tests of that choice.
    pub fn with_fastest_kernel(
        ctx: &'a GpuContext,
        scene: &KernelScene,
    ) -> Result<GpuRenderer<'a>> {
        let max_uniform = ctx.device.limits().max_uniform_buffer_binding_size;
        Self::with_variant(ctx, scene, KernelVariant::for_scene(scene, max_uniform))
    }

    /// A renderer tracing rays with `traversal`: [`GpuRenderer::new`]'s kernel for the
    /// software one, the hardware variant ([`SceneBinding::Hardware`]) for ray queries.
    pub fn with_traversal(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        traversal: Traversal,
    ) -> Result<GpuRenderer<'a>> {
        match traversal {
            Traversal::Software => Self::new(ctx, scene),
            Traversal::Hardware => Self::with_scene_binding(ctx, scene, SceneBinding::Hardware),
        }
    }

    /// A renderer with the scene bound as `scene_binding` says and the scene's features (tests
    /// and benchmarks compare the bindings).
    pub fn with_scene_binding(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        scene_binding: SceneBinding,
    ) -> Result<GpuRenderer<'a>> {
        let features = KernelFeatures::of(scene);
        Self::with_variant(
            ctx,
            scene,
            KernelVariant {
                binding: scene_binding,
                features,
            },
        )
    }

    /// A renderer running the kernel `variant`, which must cover what `scene` uses.
    pub fn with_variant(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        variant: KernelVariant,
    ) -> Result<GpuRenderer<'a>> {
        Self::with_variant_and_texel_window(ctx, scene, variant, u64::MAX)
    }

    /// [`GpuRenderer::new`]'s kernel with texel bindings of at most `window_bytes` (or the
    /// device's limit, if smaller): tests split small textures over several bindings with it
    /// (src/kernel/texels.rs).
    pub fn with_texel_window(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        window_bytes: u64,
    ) -> Result<GpuRenderer<'a>> {
        let variant = default_variant(ctx, scene);
        Self::with_variant_and_texel_window(ctx, scene, variant, window_bytes)
    }

    fn with_variant_and_texel_window(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        variant: KernelVariant,
        window_bytes: u64,
    ) -> Result<GpuRenderer<'a>> {
        if !variant.features.covers(&KernelFeatures::of(scene)) {
            return Err(anyhow!(
                "the kernel variant {variant:?} lacks features the scene uses"
            ));
        }
        let device = &ctx.device;
        let params = scene.params;
        let pixel_count = params.width as u64 * params.height as u64;
        let accum_size = pixel_count * 16;
        let aov_size = if variant.features.aovs {
            accum_size
        } else {
            16
        };
        // The splat film: two u32 words per pixel and channel where the kernel renders
        // bidirectionally, a placeholder where it only could (one with every feature).
        let bdpt = params.integrator == INTEGRATOR_BDPT;
        let splat_size = variant
            .features
            .bdpt
            .then_some(if bdpt { pixel_count * 24 } else { 8 });
        let scene_buffers = SceneBuffers::upload(
            ctx,
            scene,
            &variant,
            window_bytes,
            &ImageSizes {
                accumulation: accum_size,
                aov: aov_size,
                splats: splat_size,
            },
        )?;
        let texel_binding = scene_buffers.texel_binding;
        let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM
                | wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST,
        });
        let images = ImageBuffers::new(device, accum_size, aov_size, splat_size);
        let read_only = wgpu::BufferBindingType::Storage { read_only: true };
        let params_binding = params_binding_for(&ctx.adapter_info);
        let params_type = match params_binding {
            ParamsBinding::Uniform => wgpu::BufferBindingType::Uniform,
            ParamsBinding::Storage => read_only,
        };
        // The hardware traversal's structure: references at 27, the TLAS at 26.
        let acceleration = if variant.binding.uses_ray_queries() {
            Some(super::acceleration::build(ctx, scene)?)
        } else {
            None
        };
        let hardware_buffers: Vec<_> = acceleration
            .iter()
            .map(|a| (27, read_only, &a.references))
            .collect();
        let buffers: Vec<_> = [(0, params_type, &params_buffer)]
            .into_iter()
            .chain(images.bindings())
            .chain(scene_buffers.bindings())
            .chain(hardware_buffers)
            .collect();
        if texel_binding.is_split() {
            check_storage_binding_count(&device.limits(), &buffers)?;
        }
        let tlas = acceleration.as_ref().map(|a| (26, &a.tlas));
        let (bind_group_layout, pipeline) = ctx.compute_pipeline(
            "glint render kernel",
            &render_kernel_source_with_texels(variant, params_binding, texel_binding),
            entry_point_for(params.integrator),
            &compute_layout_entries(&buffers, tlas.map(|(binding, _)| binding)),
        );
        let bind_group = bind_group(device, "scene", &bind_group_layout, &buffers, tlas);
        ctx.wait_idle()?;
        let renderer = GpuRenderer {
            ctx,
            variant,
            pipeline,
            bind_group,
            images,
            params,
            params_buffer,
            samples: 0,
            counts: PixelCounts::new(pixel_count as usize),
            first_sample: 0,
            instruments: None,
            tiles: TilePlanner::new(SUBMISSION_TARGET),
            nonfinite: 0,
            loop_limit: device_loop_limit(&ctx.adapter_info),
            loop_iterations: match (bdpt, variant.binding.uses_ray_queries()) {
                (false, false) => loop_iterations_per_sample(scene),
                (false, true) => hardware_loop_iterations_per_sample(scene),
                (true, false) => {
                    bdpt_loop_iterations_per_sample(&params, loop_iterations_per_ray(scene))
                }
                (true, true) => bdpt_loop_iterations_per_sample(
                    &params,
                    hardware_loop_iterations_per_ray(scene),
                ),
            },
            _acceleration: acceleration,
            texel_binding,
        };
        renderer.warm_up()?;
        Ok(renderer)
    }

    /// Runs the kernel once, on one workgroup and with no samples (it returns at once, leaving
    /// the image untouched), so the driver finishes compiling it now: lavapipe compiles at the
    /// first dispatch (about 1 s with a cold Mesa cache), which would otherwise count as
    /// render time.
    fn warm_up(&self) -> Result<()> {
        let params = Params {
            sample_count: 0,
            ..self.params
        };
        let queue = &self.ctx.queue;
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        queue.submit([encoder.finish()]);
        self.ctx.wait_idle()
    }

    /// Turns on benchmark instrumentation: after every batch, the renderer reads back the
    /// number of ray segments traced and, where the device has timestamp queries, the
    /// kernel's device time. This adds a small readback per batch, so renders leave it off.
    pub fn instrument(&mut self) {
        self.instruments = Some(Instruments::new(self.ctx));
    }

    /// Reads the counter and timestamps of the submission just made, and clears the counter;
    /// returns the kernel's device time (zero where it is not measured).
    fn read_instruments(&mut self) -> Result<std::time::Duration> {
        match &mut self.instruments {
            Some(instruments) => instruments.read(self.ctx, &self.images.counter),
            None => Ok(std::time::Duration::ZERO),
        }
    }

    /// Sets the wanted duration of one GPU submission (default [`SUBMISSION_TARGET`]); batches
    /// that would take longer are split into tiles of pixels. Zero gives the smallest tiles
    /// (one workgroup each), which tests use to check that tiling never changes the image.
    pub fn set_submission_target(&mut self, target: std::time::Duration) {
        self.tiles = TilePlanner::new(target);
    }

    /// The per-pixel mean radiance (vec4 per pixel, xyz used), for display passes that read it
    /// on the GPU without a readback.
    pub fn mean_buffer(&self) -> &wgpu::Buffer {
        &self.images.mean
    }

    /// The splat film the kernel adds bidirectional path tracing's light tracing to, and its
    /// fixed-point scale (`Params::splat_scale`); `None` for path tracing.
    pub fn splat_film(&self) -> Option<(&wgpu::Buffer, f32)> {
        let splats = self.images.splats.as_ref().filter(|_| self.is_bdpt())?;
        Some((&splats.film, self.params.splat_scale))
    }

    /// Where the kernel reads the scene from.
    pub fn scene_binding(&self) -> SceneBinding {
        self.variant.binding
    }

    /// The traversal the kernel runs.
    pub fn traversal(&self) -> Traversal {
        if self.variant.binding.uses_ray_queries() {
            Traversal::Hardware
        } else {
            Traversal::Software
        }
    }

    /// The kernel variant this renderer runs.
    pub fn variant(&self) -> KernelVariant {
        self.variant
    }

    /// Where the kernel reads texels from: one binding, or windows over several.
    pub fn texel_binding(&self) -> TexelBinding {
        self.texel_binding
    }

    /// The kernel parameters in use (camera, size, counts).
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Replaces the camera and render parameters (not the image size or the scene's objects)
    /// and restarts accumulation.
    pub fn set_params(&mut self, params: Params) -> Result<()> {
        let size = (self.params.width, self.params.height);
        if (params.width, params.height) != size {
            return Err(anyhow!(
                "set_params cannot change the image size; make a new renderer"
            ));
        }
        if params.aovs != 0 && !self.variant.features.aovs {
            return Err(anyhow!(
                "set_params cannot turn on AOVs compiled out of the kernel; make a new renderer"
            ));
        }
        if params.integrator != self.params.integrator {
            return Err(anyhow!(
                "set_params cannot change the integrator (its kernel's entry point); make a new renderer"
            ));
        }
        if params.light_sampling != 0 && !self.variant.features.light_sampling {
            return Err(anyhow!(
                "set_params cannot turn on light sampling compiled out of the kernel; make a new renderer"
            ));
        }
        self.params = params;
        self.reset()
    }

    /// Whether the kernel renders bidirectionally (and splats).
    fn is_bdpt(&self) -> bool {
        self.params.integrator == INTEGRATOR_BDPT
    }

    /// The splat film's 64-bit sums (shaders/integrator/splat.wgsl: two u32 words each, low
    /// first, so the bytes are little-endian u64s); empty for path tracing.
    fn read_splats(&self) -> Result<Vec<u64>> {
        let Some(splats) = self.images.splats.as_ref().filter(|_| self.is_bdpt()) else {
            return Ok(Vec::new());
        };
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&splats.film, 0, &splats.readback, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        self.ctx.read_mapped(&splats.readback, |bytes| {
            bytes
                .chunks_exact(8)
                .map(|w| u64::from_le_bytes(w.try_into().expect("8 bytes")))
                .collect()
        })
    }

    /// Each vec4 of `buffer`, which is at most as large as the readback buffer.
    fn read_vec4s(&self, buffer: &wgpu::Buffer) -> Result<Vec<[f32; 4]>> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &self.images.readback, 0, buffer.size());
        self.ctx.queue.submit([encoder.finish()]);
        let size = buffer.size() as usize;
        self.ctx.read_mapped(&self.images.readback, |bytes| {
            bytemuck::cast_slice::<u8, [f32; 4]>(&bytes[..size]).to_vec()
        })
    }

    /// One submission: the batch in `self.params` over the pixels of `tile`, waited for.
    fn submit_tile(&mut self, tile: super::tiles::Tile) -> Result<()> {
        let origin = [tile.x, tile.y, 0, 0];
        self.ctx
            .queue
            .write_buffer(&self.images.tile, 0, bytemuck::bytes_of(&origin));
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        let timestamps = self
            .instruments
            .as_ref()
            .and_then(|i| i.timestamps.as_ref());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("render"),
                timestamp_writes: timestamps.map(|(set, _)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(
                tile.width.div_ceil(WORKGROUP_SIZE.0),
                tile.height.div_ceil(WORKGROUP_SIZE.1),
                1,
            );
        }
        if let Some((set, resolve)) = timestamps {
            encoder.resolve_query_set(set, 0..2, resolve, 0);
        }
        self.ctx.queue.submit([encoder.finish()]);
        self.ctx.wait_idle()
    }

    /// Reads and clears the kernel's counters: dropped samples and invocations cut short.
    fn take_counters(&self) -> Result<[u32; 2]> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(
            &self.images.nonfinite,
            0,
            &self.images.nonfinite_readback,
            0,
            8,
        );
        encoder.clear_buffer(&self.images.nonfinite, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        self.ctx
            .read_mapped(&self.images.nonfinite_readback, |bytes| {
                let words = bytemuck::cast_slice::<u8, u32>(bytes);
                [words[0], words[1]]
            })
    }

    /// Samples `first..first + count` for every pixel, in tiles.
    fn dispatch_samples(&mut self, first: u32, count: u32) -> Result<()> {
        self.params.sample_start = first;
        self.params.accumulated_samples = first - self.first_sample;
        self.params.sample_count = count;
        self.ctx
            .queue
            .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        // Tiles sized so each submission lasts about SUBMISSION_TARGET (src/gpu/tiles.rs).
        let (width, height) = (self.params.width, self.params.height);
        let (mut x, mut y) = (0, 0);
        let mut last_pixels = None;
        let mut kernel_time = std::time::Duration::ZERO;
        while y < height {
            let budget = self.tiles.pixel_budget(count, last_pixels);
            let tile = next_tile(width, height, x, y, budget);
            let started = std::time::Instant::now();
            self.submit_tile(tile)?;
            let took = started.elapsed();
            let pixels = tile.width as u64 * tile.height as u64;
            self.tiles.record(pixels, count, took);
            last_pixels = Some(pixels);
            kernel_time += self.read_instruments()?;
            x += tile.width;
            if x >= width {
                x = 0;
                y += tile.height;
            }
        }
        if let Some(instruments) = &mut self.instruments {
            if instruments.timestamps.is_some() {
                instruments.last_kernel_time = Some(kernel_time);
            }
        }
        Ok(())
    }

    /// The first three floats of each vec4 of `buffer`.
    fn read_vec3s(&self, buffer: &wgpu::Buffer) -> Result<Vec<[f32; 3]>> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &self.images.readback, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        self.ctx.read_mapped(&self.images.readback, |bytes| {
            bytemuck::cast_slice::<u8, [f32; 4]>(bytes)
                .iter()
                .map(|p| [p[0], p[1], p[2]])
                .collect()
        })
    }

    fn image(&self, pixels: Vec<[f32; 3]>) -> Image {
        Image {
            width: self.params.width,
            height: self.params.height,
            pixels,
        }
    }
}

impl Renderer for GpuRenderer<'_> {
    fn add_samples(&mut self, count: u32) -> Result<()> {
        // Dispatches of at most this many samples stay within lavapipe's loop limit. They end
        // at multiples of a power of two of samples, fixed by the scene and the device, so
        // where the kernel merges (shaders/integrator/accumulate.wgsl) never depends on the batching;
        // from 64 on those multiples are block ends anyway.
        let per_dispatch = max_samples_per_dispatch(self.loop_iterations, self.loop_limit);
        let step = 1u32 << (31 - per_dispatch.leading_zeros());
        // Global sample indices: a partial render's dispatches end where a single render's do.
        let end = self.first_sample + self.samples + count;
        let mut first = self.first_sample + self.samples;
        while first < end {
            let next = (first / step + 1).saturating_mul(step).min(end);
            self.dispatch_samples(first, next - first)?;
            first = next;
        }
        self.samples = end - self.first_sample;
        let [nonfinite, cut_short] = self.take_counters()?;
        self.nonfinite += nonfinite as u64;
        if cut_short > 0 {
            return Err(anyhow!(
                "the GPU driver ended the kernel early in {cut_short} pixel groups: lavapipe ends \
                 a shader's loops after {LAVAPIPE_LOOP_LIMIT} iterations in all, and one sample of \
                 this scene ({} spheres and quads, {} triangles, {} bounces) can need {} \
                 (render with --cpu)",
                self.params.sphere_count + self.params.quad_count,
                self.params.triangle_count,
                self.params.max_bounces,
                self.loop_iterations
            ));
        }
        Ok(())
    }

    fn samples(&self) -> u32 {
        self.samples
    }

    fn first_sample(&self) -> u32 {
        self.first_sample
    }

    fn read_accumulation(&mut self) -> Result<Accumulation> {
        Ok(Accumulation {
            width: self.params.width,
            height: self.params.height,
            count: self.samples,
            counts: self.counts.counts(self.samples),
            mean: self.read_vec3s(&self.images.mean)?,
            m2: self.read_vec3s(&self.images.m2)?,
            splats: self.read_splats()?,
            splat_scale: self.params.splat_scale,
            batches: 0,
        })
    }

    fn load_accumulation(&mut self, first_sample: u32, state: Option<&Accumulation>) -> Result<()> {
        self.reset()?;
        if let Some(state) = state {
            check_size(&self.params, state)?;
            self.counts.load(&state.counts, state.count);
            let vec4s = |v: &[[f32; 3]], w: &dyn Fn(usize) -> f32| -> Vec<[f32; 4]> {
                v.iter()
                    .enumerate()
                    .map(|(i, p)| [p[0], p[1], p[2], w(i)])
                    .collect()
            };
            let queue = &self.ctx.queue;
            queue.write_buffer(
                &self.images.mean,
                0,
                bytemuck::cast_slice(&vec4s(&state.mean, &|_| 0.0)),
            );
            let stopped = |i: usize| STOPPED_FLAG * self.counts.is_stopped(i) as u32 as f32;
            queue.write_buffer(
                &self.images.m2,
                0,
                bytemuck::cast_slice(&vec4s(&state.m2, &stopped)),
            );
            if let Some(splats) = self.images.splats.as_ref().filter(|_| self.is_bdpt()) {
                let pixels = self.params.width as usize * self.params.height as usize;
                if !state.splats.is_empty() && state.splats.len() != 3 * pixels {
                    return Err(anyhow!(
                        "the splat film holds {} sums, not the 3 per pixel of {pixels} pixels",
                        state.splats.len()
                    ));
                }
                let bytes: Vec<u8> = state.splats.iter().flat_map(|w| w.to_le_bytes()).collect();
                queue.write_buffer(&splats.film, 0, &bytes);
            }
            self.samples = state.count;
        }
        self.first_sample = first_sample;
        self.ctx.wait_idle()
    }

    fn nonfinite_samples(&self) -> u64 {
        self.nonfinite
    }

    fn read_mean(&mut self) -> Result<Image> {
        if self.is_bdpt() {
            // The camera strategies' mean and the splats over the samples per pixel.
            return Ok(self.read_accumulation()?.mean_image());
        }
        Ok(self.image(self.read_vec3s(&self.images.mean)?))
    }

    fn read_variance(&mut self) -> Result<Image> {
        let counts = self.counts.counts(self.samples);
        let m2 = self.read_vec3s(&self.images.m2)?;
        Ok(self.image(
            m2.into_iter()
                .zip(counts)
                .map(|(v, n)| variance_of_mean(v, n))
                .collect(),
        ))
    }

    fn read_aovs(&mut self) -> Result<Aovs> {
        if self.params.aovs == 0 {
            return Err(anyhow!(
                "this render does not accumulate AOVs (Params::aovs is 0)"
            ));
        }
        let albedo_depth = self.read_vec4s(&self.images.aovs[0])?;
        let normal = self.read_vec4s(&self.images.aovs[1])?;
        let (width, height) = (self.params.width, self.params.height);
        Ok(Aovs::from_vec4s(width, height, &albedo_depth, &normal))
    }

    fn reset(&mut self) -> Result<()> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        for buffer in &self.images.aovs {
            encoder.clear_buffer(buffer, 0, None);
        }
        encoder.clear_buffer(&self.images.mean, 0, None);
        encoder.clear_buffer(&self.images.m2, 0, None);
        encoder.clear_buffer(&self.images.counter, 0, None);
        encoder.clear_buffer(&self.images.nonfinite, 0, None);
        if let Some(splats) = &self.images.splats {
            encoder.clear_buffer(&splats.film, 0, None);
        }
        self.ctx.queue.submit([encoder.finish()]);
        self.samples = 0;
        self.counts.reset();
        self.nonfinite = 0;
        if let Some(instruments) = &mut self.instruments {
            instruments.segments = 0;
        }
        self.ctx.wait_idle()
    }

    fn segments_traced(&self) -> Option<u64> {
        self.instruments.as_ref().map(|i| i.segments)
    }

    fn stop_pixels(&mut self, stop: &[bool]) -> Result<()> {
        let newly = self.counts.stop(stop, self.samples);
        if newly.is_empty() {
            return Ok(());
        }
        // The flag is the w of the pixel's M2, which the kernel leaves alone once it is set:
        // rewrite the buffer with its own values and the flags (one readback, one upload).
        let mut m2 = self.read_vec4s(&self.images.m2)?;
        for i in newly {
            m2[i][3] = STOPPED_FLAG;
        }
        self.ctx
            .queue
            .write_buffer(&self.images.m2, 0, bytemuck::cast_slice(&m2));
        self.ctx.wait_idle()
    }

    fn pixel_counts(&self) -> Vec<u32> {
        self.counts.counts(self.samples)
    }

    fn active_pixels(&self) -> usize {
        self.counts.active()
    }

    fn last_kernel_time(&self) -> Option<std::time::Duration> {
        self.instruments.as_ref().and_then(|i| i.last_kernel_time)
    }

    fn device_name(&self) -> String {
        self.ctx.device_name()
    }

    fn backend_name(&self) -> String {
        self.ctx.backend_name()
    }
}
