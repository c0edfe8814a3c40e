//! Progressive rendering, the same for every device: batches of samples per pixel, sized so
//! each submission stays short (a real GPU's watchdog kills long ones), until the sample
//! count or the time limit is reached.

use crate::output::Image;
use anyhow::Result;
use std::time::{Duration, Instant};

/// A device that accumulates per-pixel radiance sums.
pub trait Renderer {
    /// Adds `sample_count` samples to every pixel, with global sample indices starting at
    /// `sample_start` (the random stream depends on the index, never on the batching).
    fn add_samples(&mut self, sample_start: u32, sample_count: u32) -> Result<()>;
    /// The per-pixel radiance sums so far.
    fn read_sums(&mut self) -> Result<Vec<[f32; 3]>>;
    /// Forgets all samples.
    fn reset(&mut self) -> Result<()>;
    /// Adapter name, or "cpu".
    fn device_name(&self) -> String;
    fn backend_name(&self) -> String;
}

/// The mean radiance image from per-pixel sums of `spp` samples.
pub fn mean_image(width: u32, height: u32, sums: &[[f32; 3]], spp: u32) -> Image {
    let scale = 1.0 / spp.max(1) as f32;
    Image {
        width,
        height,
        pixels: sums.iter().map(|s| s.map(|c| c * scale)).collect(),
    }
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
}

impl StopReason {
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::SamplesReached => "spp",
            StopReason::TimeLimit => "time-limit",
        }
    }
}

/// The state after each batch, for progress reports and checkpoints.
pub struct BatchReport {
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
}

/// Renders up to `spp` samples per pixel, stopping at the first batch boundary after
/// `time_limit`. `after_batch` sees every batch (progress bars, checkpoints).
pub fn render_progressive(
    renderer: &mut dyn Renderer,
    spp: u32,
    time_limit: Option<Duration>,
    sizer: &mut BatchSizer,
    mut after_batch: impl FnMut(&mut dyn Renderer, &BatchReport) -> Result<()>,
) -> Result<RenderStats> {
    let started = Instant::now();
    let mut spp_done = 0u32;
    let mut render_time = Duration::ZERO;
    let mut stop_reason = StopReason::SamplesReached;
    while spp_done < spp {
        let count = sizer.spp_per_batch.min(spp - spp_done);
        let batch_start = Instant::now();
        renderer.add_samples(spp_done, count)?;
        let took = batch_start.elapsed();
        render_time += took;
        spp_done += count;
        sizer.update(count, took);
        after_batch(
            renderer,
            &BatchReport {
                spp_done,
                spp_target: spp,
                render_time,
                last_batch_spp: count,
                last_batch_time: took,
            },
        )?;
        if spp_done < spp && time_limit.is_some_and(|limit| started.elapsed() >= limit) {
            stop_reason = StopReason::TimeLimit;
            break;
        }
    }
    Ok(RenderStats {
        spp: spp_done,
        render_time,
        stop_reason,
    })
}

/// Renders exactly `spp` samples in batches of `batch` and returns the mean image: the simple
/// path for tests and tools that want no progress reporting.
pub fn render_image(
    renderer: &mut dyn Renderer,
    width: u32,
    height: u32,
    spp: u32,
    batch: u32,
) -> Result<Image> {
    let mut done = 0;
    while done < spp {
        let count = batch.max(1).min(spp - done);
        renderer.add_samples(done, count)?;
        done += count;
    }
    Ok(mean_image(width, height, &renderer.read_sums()?, spp))
}
