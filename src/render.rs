//! Progressive rendering, the same for every device: batches of samples per pixel, sized so
//! each submission stays short (a real GPU's watchdog kills long ones), until the sample
//! count or the time limit is reached.

use crate::aov::Aovs;
use crate::output::Image;
use anyhow::{anyhow, Result};
use std::time::{Duration, Instant};

/// A device that accumulates per-pixel radiance statistics.
pub trait Renderer {
    /// Adds `count` samples to every pixel. Their global sample indices continue from
    /// [`Renderer::samples`], and the random stream depends on the index, never on the batching.
    fn add_samples(&mut self, count: u32) -> Result<()>;
    /// Samples per pixel accumulated so far.
    fn samples(&self) -> u32;
    /// The mean radiance per pixel.
    fn read_mean(&mut self) -> Result<Image>;
    /// The variance of each pixel's mean estimate (σ²/n per channel, from the unbiased sample
    /// variance); zero before two samples.
    fn read_variance(&mut self) -> Result<Image>;
    /// The mean albedo, normal and depth per pixel, for the denoiser; an error unless the
    /// scene's `Params::aovs` asked for them.
    fn read_aovs(&mut self) -> Result<Aovs> {
        Err(anyhow!("this renderer does not accumulate AOVs"))
    }
    /// Forgets all samples.
    fn reset(&mut self) -> Result<()>;
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
    /// Adapter name, or "cpu".
    fn device_name(&self) -> String;
    fn backend_name(&self) -> String;
}

/// σ²/n per channel from M2 over n samples: M2 / (n − 1) / n.
pub fn variance_of_mean(m2: [f32; 3], n: u32) -> [f32; 3] {
    if n < 2 {
        return [0.0; 3];
    }
    let scale = 1.0 / ((n as f64 - 1.0) * n as f64);
    m2.map(|v| (v.max(0.0) as f64 * scale) as f32)
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
}

impl StopReason {
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::SamplesReached => "spp",
            StopReason::TimeLimit => "time-limit",
            StopReason::TargetError => "target-error",
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
    /// Stop at the first batch boundary where [`relative_error`] ≤ this.
    pub target_error: Option<f64>,
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
    while renderer.samples() < spp {
        let count = sizer.spp_per_batch.min(spp - renderer.samples());
        let batch_start = Instant::now();
        renderer.add_samples(count)?;
        let took = batch_start.elapsed();
        render_time += took;
        let spp_done = renderer.samples();
        sizer.update(count, took);
        if rules.target_error.is_some() && spp_done >= MIN_SPP_FOR_TARGET_ERROR {
            error = relative_error(&renderer.read_mean()?, &renderer.read_variance()?);
        }
        after_batch(
            renderer,
            &BatchReport {
                relative_error: error,
                spp_done,
                spp_target: spp,
                render_time,
                last_batch_spp: count,
                last_batch_time: took,
            },
        )?;
        if spp_done >= spp {
            break;
        }
        if let (Some(target), Some(e)) = (rules.target_error, error) {
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

/// Adds samples until there are `spp`, in batches of `batch`, and returns the mean image: the
/// simple path for tests and tools that want no progress reporting.
pub fn render_image(renderer: &mut dyn Renderer, spp: u32, batch: u32) -> Result<Image> {
    while renderer.samples() < spp {
        renderer.add_samples(batch.max(1).min(spp - renderer.samples()))?;
    }
    renderer.read_mean()
}
