//! The kernel's entry point for one pixel (WGSL side: the `render` entry point of
//! `shaders/integrator/path.wgsl` for path tracing, `render_bdpt` of
//! `shaders/integrator/bdpt/mod.wgsl` for bidirectional, around the pixel choice and the
//! writes they share in `shaders/integrator/pixel.wgsl`: the kernel compiles the integrator
//! in, where this branches on it): its samples, by the integrator `Params::integrator` names,
//! merged into its statistics.

use crate::cpu::integrator::accumulate::{accumulator_start, add_sample, merge_block};
use crate::cpu::integrator::aov::{aov_mean_add, aov_merge, aov_start, aovs_on, AovMean};
use crate::cpu::integrator::bdpt::bdpt_sample;
use crate::cpu::integrator::bdpt::walk::SampleId;
use crate::cpu::integrator::path::trace_path;
use crate::cpu::integrator::splat::SplatFilm;
use crate::cpu::scene_refs::SceneRefs;
use crate::kernel::types::INTEGRATOR_BDPT;
use glam::Vec3;

/// Running per-pixel statistics: the mean radiance and M2, the sum of squared deviations.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    pub mean: Vec3,
    pub m2: Vec3,
    /// Samples dropped as NaN, infinite or too large (`shaders/integrator/accumulate.wgsl`).
    pub nonfinite: u32,
    /// Mean albedo, normal and depth, when `params.aovs` asks for them.
    pub aov: AovMean,
    /// Adaptive sampling has stopped the pixel: it takes no more samples (the kernel's flag in
    /// the w of the pixel's M2).
    pub stopped: bool,
}

/// The kernel's entry point for one pixel: `params.sample_count` samples starting at
/// `params.sample_start`, merged into `stats`, which holds the `params.accumulated_samples`
/// samples before them. Returns the ray segments traced. (The kernel interleaves its samples' segments
/// for SIMD efficiency; each sample's result is the same, and they finish in the same order.)
pub fn render_pixel(
    scene: &SceneRefs,
    px: u32,
    py: u32,
    stats: &mut PixelStats,
    film: &SplatFilm,
) -> u32 {
    let params = scene.params;
    let pixel = py * params.width + px;
    // Adaptive sampling: a pixel the host has stopped takes no more samples (the kernel reads
    // the flag the host sets in the pixel's M2: accumulate.wgsl's `pixel_stopped`).
    if stats.stopped {
        return 0;
    }
    let mut acc = accumulator_start(params.accumulated_samples, stats.mean, stats.m2);
    let mut aov_mean = AovMean::default();
    let mut segments = 0;
    for i in 0..params.sample_count {
        let sample = params.sample_start + i;
        let (radiance, aov) = if params.integrator == INTEGRATOR_BDPT {
            let id = SampleId {
                pixel,
                px,
                py,
                sample,
            };
            let mut aov = aov_start();
            let radiance = bdpt_sample(scene, id, film, &mut aov, &mut segments);
            (radiance, aov)
        } else {
            let path = trace_path(scene, pixel, px, py, sample, &mut segments);
            (path.radiance, path.aov)
        };
        add_sample(&mut acc, radiance, sample);
        if aovs_on(params) {
            aov_mean_add(&mut aov_mean, &aov, i);
        }
    }
    // A batch ended inside a block (the render loop avoids this) keeps the statistics right.
    merge_block(&mut acc);
    stats.mean = acc.mean;
    stats.m2 = acc.m2;
    stats.nonfinite += acc.nonfinite;
    if aovs_on(params) {
        let n_old = params.accumulated_samples as f32;
        aov_merge(&mut stats.aov, &aov_mean, n_old, params.sample_count as f32);
    }
    segments
}
