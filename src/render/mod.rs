//! Progressive rendering, the same for every device: batches of samples per pixel, sized so
//! each submission stays short (a real GPU's watchdog kills long ones), until the sample
//! count or the time limit is reached.

pub mod accumulation;
pub mod adaptive;
pub mod batch_means;
pub mod bench;
pub mod interrupt;
pub mod merge;
pub mod partial;

use crate::image::aov::Aovs;
use crate::image::output::Image;
use crate::kernel::schedule::next_block_end;
use crate::render::accumulation::Accumulation;
use crate::render::adaptive::Adaptive;
use anyhow::{anyhow, Result};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A device that accumulates per-pixel radiance statistics.
pub trait Renderer {
    /// Adds `count` samples to every pixel. Their global sample indices continue from
    /// [`Renderer::first_sample`] + [`Renderer::samples`], and the random stream depends on the
    /// index, never on the batching.
    fn add_samples(&mut self, count: u32) -> Result<()>;
    /// Samples per pixel accumulated so far.
    fn samples(&self) -> u32;
    /// The global index of the first accumulated sample: 0, or where a partial render
    /// (`--samples A..B`) or a resumed one starts.
    fn first_sample(&self) -> u32;
    /// The accumulators: mean and M2 over [`Renderer::samples`] samples per pixel.
    fn read_accumulation(&mut self) -> Result<Accumulation>;
    /// Replaces the accumulators with `state`, the statistics of the global samples
    /// `first_sample..first_sample + state.count` (none: empty); later samples continue after
    /// them. Its pixels with fewer than `state.count` samples were stopped and stay stopped.
    fn load_accumulation(&mut self, first_sample: u32, state: Option<&Accumulation>) -> Result<()>;
    /// The mean radiance per pixel.
    fn read_mean(&mut self) -> Result<Image>;
    /// The variance of each pixel's mean estimate (σ²/n per channel, n the pixel's own count,
    /// from the unbiased sample variance); zero before two samples.
    fn read_variance(&mut self) -> Result<Image>;
    /// The mean albedo, normal and depth per pixel, for the denoiser; an error unless the
    /// scene's `Params::aovs` asked for them.
    fn read_aovs(&mut self) -> Result<Aovs> {
        Err(anyhow!("this renderer does not accumulate AOVs"))
    }
    /// Forgets all samples (the first sample stays where it was); every pixel takes samples
    /// again.
    fn reset(&mut self) -> Result<()>;
    /// Adaptive sampling: the pixels where `stop` is true (one flag per pixel, row 0 at the
    /// top) take no more samples; they keep their statistics and their count. A stopped pixel
    /// stays stopped until a reset or a load.
    fn stop_pixels(&mut self, stop: &[bool]) -> Result<()>;
    /// Each pixel's own sample count: [`Renderer::samples`] unless it was stopped earlier.
    fn pixel_counts(&self) -> Vec<u32>;
    /// Pixels still taking samples.
    fn active_pixels(&self) -> usize;
    /// Ray segments traced since the last reset (camera, bounce and shadow rays), where the
    /// renderer counts them (the GPU one only when instrumented).
    fn segments_traced(&self) -> Option<u64> {
        None
    }
    /// Device time of the last batch's kernel, where the device measures it (GPU timestamp
    /// queries, when instrumented).
    fn last_kernel_time(&self) -> Option<Duration> {
        None
    }
    /// Samples dropped since the last reset because they were NaN, infinite or too large
    /// (`shaders/integrator/accumulate.wgsl`); each counted as black.
    fn nonfinite_samples(&self) -> u64;
    /// Adapter name, or "cpu".
    fn device_name(&self) -> String;
    fn backend_name(&self) -> String;
}

/// Refuses an accumulation whose image size is not the renderer's.
pub fn check_size(params: &crate::kernel::types::Params, state: &Accumulation) -> Result<()> {
    let pixels = params.width as usize * params.height as usize;
    if (state.width, state.height) != (params.width, params.height)
        || state.mean.len() != pixels
        || state.m2.len() != pixels
        || state.counts.len() != pixels
        || state.counts.iter().any(|&n| n > state.count)
    {
        anyhow::bail!(
            "cannot load a {}×{} accumulation into a {}×{} render",
            state.width,
            state.height,
            params.width,
            params.height
        );
    }
    Ok(())
}

/// Picks the next batch's samples per pixel from the last batch's duration.
#[derive(Clone, Debug)]
pub struct BatchSizer {
    /// Wanted duration of one batch.
    pub target: Duration,
    pub spp_per_batch: u32,
    pub max_spp_per_batch: u32,
}

impl BatchSizer {
    pub fn new(target: Duration) -> BatchSizer {
        BatchSizer {
            target,
            spp_per_batch: 1,
            max_spp_per_batch: 1024,
        }
    }

    /// Scales the batch towards the target duration, at most doubling or halving each time
    /// so one slow or fast outlier cannot swing it far.
    pub fn update(&mut self, spp: u32, took: Duration) {
        let per_sample = took.as_secs_f64() / spp.max(1) as f64;
        let ideal = if per_sample > 0.0 {
            self.target.as_secs_f64() / per_sample
        } else {
            f64::INFINITY
        };
        let next = ideal.clamp(spp as f64 / 2.0, spp as f64 * 2.0);
        self.spp_per_batch = (next as u32).clamp(1, self.max_spp_per_batch);
    }
}

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    SamplesReached,
    TimeLimit,
    TargetError,
    /// SIGINT or SIGTERM (see [`StopRules::interrupted`]).
    Interrupted,
}

impl StopReason {
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::SamplesReached => "spp",
            StopReason::TimeLimit => "time-limit",
            StopReason::TargetError => "target-error",
            StopReason::Interrupted => "interrupted",
        }
    }
}

/// Fewest samples per pixel before `--target-error` may stop a render: the image-wide
/// variance estimate is unbiased from 2 samples on, but a few more keep a lucky start (no
/// path has found the light yet) from looking converged.
pub const MIN_SPP_FOR_TARGET_ERROR: u32 = 8;

/// The image's relative standard error: √(mean of the variance image) / (mean of the image),
/// both over all pixels and channels. `None` when the image is black (no scale to relate to).
pub fn relative_error(mean: &Image, variance: &Image) -> Option<f64> {
    let m = mean.mean();
    (m > 0.0).then(|| variance.mean().max(0.0).sqrt() / m)
}

/// When to stop besides reaching the sample count.
#[derive(Clone, Copy, Debug, Default)]
pub struct StopRules {
    /// Stop at the first batch boundary after this long.
    pub time_limit: Option<Duration>,
    /// Stop at the first batch boundary where [`relative_error`] ≤ this (unless `adaptive`,
    /// which takes its own target).
    pub target_error: Option<f64>,
    /// Adaptive sampling: pixels stop taking samples as they converge
    /// (`src/render/adaptive.rs`), and the render stops when none is left.
    pub adaptive: Option<Adaptive>,
    /// Stop before the next batch once this is set (by a signal handler).
    pub interrupted: Option<&'static AtomicBool>,
}

/// The state after each batch, for progress reports and checkpoints.
pub struct BatchReport {
    /// The image's relative standard error, when a target error asks for it.
    pub relative_error: Option<f64>,
    pub spp_done: u32,
    pub spp_target: u32,
    /// Time spent in batches only.
    pub render_time: Duration,
    pub last_batch_spp: u32,
    pub last_batch_time: Duration,
    /// Pixels still taking samples (all of them unless adaptive sampling stopped some).
    pub active_pixels: usize,
}

pub struct RenderStats {
    pub spp: u32,
    /// Time spent in batches only: no start-up, shader compilation, readback or file writes.
    pub render_time: Duration,
    pub stop_reason: StopReason,
    /// The relative error at the last check (only measured with a target error).
    pub relative_error: Option<f64>,
}

/// Renders up to `spp` samples per pixel, stopping early by `rules`. `after_batch` sees every
/// batch (progress bars, checkpoints).
pub fn render_progressive(
    renderer: &mut dyn Renderer,
    spp: u32,
    rules: StopRules,
    sizer: &mut BatchSizer,
    mut after_batch: impl FnMut(&mut dyn Renderer, &BatchReport) -> Result<()>,
) -> Result<RenderStats> {
    let started = Instant::now();
    let mut render_time = Duration::ZERO;
    let mut stop_reason = StopReason::SamplesReached;
    let mut error = None;
    let first = renderer.first_sample();
    // A resumed render at a checkpoint makes that checkpoint's decision again: the same one,
    // from the same statistics.
    if let Some(adaptive) = rules.adaptive {
        if adaptive.is_checkpoint(first, renderer.samples()) {
            stop_converged(renderer, &adaptive)?;
        }
    }
    while renderer.samples() < spp {
        if rules
            .interrupted
            .is_some_and(|flag| flag.load(Ordering::Relaxed))
        {
            stop_reason = StopReason::Interrupted;
            break;
        }
        if rules.adaptive.is_some() && renderer.active_pixels() == 0 {
            stop_reason = StopReason::TargetError;
            break;
        }
        // Batches end only where the merge schedule's blocks do, so the image's bytes do not
        // depend on the batch sizes, which follow the wall clock (src/kernel/schedule.rs). The
        // blocks are of global sample indices, so a partial render's batches end where a
        // single render's would. Adaptive sampling also ends one at each of its checkpoints.
        let done = first + renderer.samples();
        let mut count = next_block_end(done, sizer.spp_per_batch, first + spp) - done;
        if let Some(adaptive) = rules.adaptive {
            count = count.min(adaptive.until_checkpoint(first, renderer.samples()));
        }
        let batch_start = Instant::now();
        renderer.add_samples(count)?;
        if let Some(adaptive) = rules.adaptive {
            if adaptive.is_checkpoint(first, renderer.samples()) {
                stop_converged(renderer, &adaptive)?;
            }
        }
        let took = batch_start.elapsed();
        render_time += took;
        let spp_done = renderer.samples();
        sizer.update(count, took);
        if rules.target_error.is_some() && spp_done >= MIN_SPP_FOR_TARGET_ERROR {
            error = relative_error(&renderer.read_mean()?, &renderer.read_variance()?);
        }
        let active_pixels = renderer.active_pixels();
        after_batch(
            renderer,
            &BatchReport {
                relative_error: error,
                spp_done,
                spp_target: spp,
                render_time,
                last_batch_spp: count,
                last_batch_time: took,
                active_pixels,
            },
        )?;
        if spp_done >= spp {
            break;
        }
        if rules.adaptive.is_some() {
            if renderer.active_pixels() == 0 {
                stop_reason = StopReason::TargetError;
                break;
            }
        } else if let (Some(target), Some(e)) = (rules.target_error, error) {
            if e <= target {
                stop_reason = StopReason::TargetError;
                break;
            }
        }
        if rules
            .time_limit
            .is_some_and(|limit| started.elapsed() >= limit)
        {
            stop_reason = StopReason::TimeLimit;
            break;
        }
    }
    Ok(RenderStats {
        spp: renderer.samples(),
        render_time,
        stop_reason,
        relative_error: error,
    })
}

/// Adaptive sampling's decision at a checkpoint: stops the pixels that have converged
/// (`src/render/adaptive.rs`), from the accumulated statistics alone.
pub fn stop_converged(renderer: &mut dyn Renderer, adaptive: &Adaptive) -> Result<()> {
    let accumulation = renderer.read_accumulation()?;
    let stop = adaptive::converged(&accumulation, adaptive.target_error);
    renderer.stop_pixels(&stop)
}

/// Adds samples until there are `spp`, in batches of about `batch` (rounded up to the merge
/// schedule's block ends, like [`render_progressive`]'s), and returns the mean image: the
/// simple path for tests and tools that want no progress reporting.
pub fn render_image(renderer: &mut dyn Renderer, spp: u32, batch: u32) -> Result<Image> {
    while renderer.samples() < spp {
        let done = renderer.samples();
        renderer.add_samples(next_block_end(done, batch, spp) - done)?;
    }
    renderer.read_mean()
}
