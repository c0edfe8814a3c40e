//! The benchmark behind `glint bench`: a fixed set of renders of the Cornell box (256² and
//! 512², max_bounces 8, light sampling on and off) on the GPU and the CPU reference, each run
//! several times after a warm-up, reported as medians. With mesh sizes, the Cornell box with a
//! generated bumpy sphere of about that many triangles inside instead (256², light sampling
//! on): paths/s against primitive count.

use crate::kernel::variant::SceneBinding;
use crate::kernel::KernelScene;
use crate::render::Renderer;
use crate::scene::stress::StressMesh;
use crate::scene::{RenderOverrides, Scene, Triangle};
use anyhow::Result;
use glam::Vec3;
use std::path::Path;
use std::time::{Duration, Instant};

/// The benchmark scene, built in so the benchmark is the same wherever it runs.
pub const CORNELL_TOML: &str = include_str!("../../scenes/cornell.toml");

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
    /// Triangles of the stress mesh added to the box (0: the plain Cornell box).
    pub mesh_triangles: u32,
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
                        mesh_triangles: 0,
                    }
                } else {
                    BenchCase {
                        device,
                        size,
                        light_sampling,
                        spp,
                        batch_spp,
                        mesh_triangles: 0,
                    }
                });
            }
        }
    }
    out
}

/// The mesh cases: for each size in `mesh_triangles` (0: the plain box), the Cornell box with
/// a stress mesh of about that many triangles, at 256² with light sampling, on each device.
/// `quick` shrinks them as [`cases`] does.
pub fn mesh_cases(mesh_triangles: &[u32], quick: bool) -> Vec<BenchCase> {
    let mut out = Vec::new();
    for device in [BenchDevice::Gpu, BenchDevice::Cpu] {
        for &triangles in mesh_triangles {
            out.push(BenchCase {
                device,
                size: if quick { 32 } else { 256 },
                light_sampling: true,
                spp: if quick { 2 } else { 8 },
                batch_spp: if quick { 1 } else { 2 },
                mesh_triangles: triangles,
            });
        }
    }
    out
}

/// The bumpy sphere (`glint stress-mesh`'s) of about `triangles` triangles, white, standing in
/// the middle of the box clear of its two spheres.
fn add_stress_mesh(scene: &mut Scene, triangles: u32) {
    let mesh = StressMesh::with_triangles(triangles as usize);
    let material = scene
        .materials
        .iter()
        .position(|m| m.name == "white")
        .expect("the Cornell box has a white material") as u32;
    let place = |p: Vec3| p * 80.0 + Vec3::new(278.0, 330.0, 300.0);
    for t in &mesh.indices {
        let [a, b, c] = t.map(|i| i as usize);
        scene.triangles.push(Triangle {
            vertices: [
                place(mesh.positions[a]),
                place(mesh.positions[b]),
                place(mesh.positions[c]),
            ],
            normals: Some([mesh.normals[a], mesh.normals[b], mesh.normals[c]]),
            material,
            uvs: None,
            uvs1: None,
            tangents: None,
            colors: None,
        });
    }
}

/// The case's scene; an error when a mesh's BVH cannot be built.
pub fn case_scene(case: &BenchCase) -> Result<KernelScene> {
    let mut scene = Scene::parse(CORNELL_TOML, Path::new("cornell.toml"))
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
    if case.mesh_triangles > 0 {
        add_stress_mesh(&mut scene, case.mesh_triangles);
    }
    Ok(scene.try_kernel_scene()?)
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
    /// Triangles in the scene (the stress mesh's actual count).
    pub triangles: usize,
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
        triangles: 0,
    })
}
