//! The benchmark behind `glint bench`: a fixed set of renders of the Cornell box (256² and
//! 512², max_bounces 8, light sampling on and off) on the GPU and the CPU reference, each run
//! several times after a warm-up, reported as medians.

use crate::render::Renderer;
use crate::scene::{KernelScene, RenderOverrides, Scene};
use crate::shader::SceneBinding;
use anyhow::Result;
use std::path::Path;
use std::time::{Duration, Instant};

/// The benchmark scene, built in so the benchmark is the same wherever it runs.
pub const CORNELL_TOML: &str = include_str!("../scenes/cornell.toml");

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchDevice {
    Gpu,
    Cpu,
}

impl BenchDevice {
    pub fn as_str(self) -> &'static str {
        match self {
            BenchDevice::Gpu => "gpu",
            BenchDevice::Cpu => "cpu",
        }
    }
}

/// One configuration of the fixed set.
#[derive(Clone, Copy, Debug)]
pub struct BenchCase {
    pub device: BenchDevice,
    pub size: u32,
    pub light_sampling: bool,
    /// Samples per pixel in one run, and per batch (one GPU submission).
    pub spp: u32,
    pub batch_spp: u32,
}

/// The fixed set: `quick` shrinks it to a smoke test (64² and 32², 2 spp) for the test suite.
pub fn cases(quick: bool) -> Vec<BenchCase> {
    let mut out = Vec::new();
    for device in [BenchDevice::Gpu, BenchDevice::Cpu] {
        for (size, spp, batch_spp) in [(256, 32, 8), (512, 8, 2)] {
            for light_sampling in [false, true] {
                out.push(if quick {
                    BenchCase {
                        device,
                        size: size / 8,
                        light_sampling,
                        spp: 2,
                        batch_spp: 1,
                    }
                } else {
                    BenchCase {
                        device,
                        size,
                        light_sampling,
                        spp,
                        batch_spp,
                    }
                });
            }
        }
    }
    out
}

pub fn case_scene(case: &BenchCase) -> KernelScene {
    let scene = Scene::parse(CORNELL_TOML, Path::new("cornell.toml"))
        .expect("the built-in Cornell box is valid")
        .with_overrides(&RenderOverrides {
            width: Some(case.size),
            height: Some(case.size),
            max_bounces: Some(8),
            light_sampling: Some(case.light_sampling),
            seed: Some(0),
            ..Default::default()
        })
        .expect("benchmark sizes are valid");
    scene.kernel_scene()
}

#[derive(Clone, Debug)]
pub struct BenchResult {
    pub case: BenchCase,
    pub runs: usize,
    /// Medians over the runs.
    pub paths_per_second: f64,
    pub rays_per_second: Option<f64>,
    pub ms_per_batch: f64,
    pub kernel_ms_per_batch: Option<f64>,
    /// Ray segments per path (camera, bounce and shadow rays).
    pub segments_per_path: Option<f64>,
    /// The GPU kernel's scene binding (None on the CPU).
    pub scene_binding: Option<SceneBinding>,
}

impl BenchResult {
    pub fn with_scene_binding(self, binding: SceneBinding) -> BenchResult {
        BenchResult {
            scene_binding: Some(binding),
            ..self
        }
    }
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// Runs one case on `renderer`: a warm-up batch (shader compilation, caches), then `runs`
/// renders of `case.spp` samples in batches of `case.batch_spp`, each timed on the host.
pub fn run_case(renderer: &mut dyn Renderer, case: BenchCase, runs: usize) -> Result<BenchResult> {
    renderer.add_samples(case.batch_spp)?;
    renderer.reset()?;
    let paths_per_run = case.size as f64 * case.size as f64 * case.spp as f64;
    let (mut paths_per_second, mut rays_per_second, mut batch_ms, mut kernel_ms, mut segments) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs.max(1) {
        renderer.reset()?;
        let mut elapsed = Duration::ZERO;
        while renderer.samples() < case.spp {
            let count = case.batch_spp.min(case.spp - renderer.samples());
            let start = Instant::now();
            renderer.add_samples(count)?;
            let took = start.elapsed();
            elapsed += took;
            batch_ms.push(took.as_secs_f64() * 1e3);
            if let Some(kernel) = renderer.last_kernel_time() {
                kernel_ms.push(kernel.as_secs_f64() * 1e3);
            }
        }
        paths_per_second.push(paths_per_run / elapsed.as_secs_f64());
        if let Some(count) = renderer.segments_traced() {
            rays_per_second.push(count as f64 / elapsed.as_secs_f64());
            segments.push(count as f64 / paths_per_run);
        }
    }
    Ok(BenchResult {
        case,
        runs: runs.max(1),
        paths_per_second: median(&mut paths_per_second),
        rays_per_second: (!rays_per_second.is_empty()).then(|| median(&mut rays_per_second)),
        ms_per_batch: median(&mut batch_ms),
        kernel_ms_per_batch: (!kernel_ms.is_empty()).then(|| median(&mut kernel_ms)),
        segments_per_path: (!segments.is_empty()).then(|| median(&mut segments)),
        scene_binding: None,
    })
}
