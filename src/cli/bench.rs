//! `glint bench`.

use crate::cpu::integrator::renderer::CpuRenderer;
use crate::gpu::{GpuContext, GpuRenderer, Traversal, TraversalChoice};
use crate::kernel::variant::{SceneBinding, SceneCounts};
use crate::render::bench::{case_scene, cases, mesh_cases, run_case, BenchDevice, BenchResult};
use anyhow::Result;
use clap::{Args, ValueEnum};

/// Which scene binding the GPU kernel uses in the benchmark.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SceneBindingChoice {
    /// What `render` uses: uniform buffers when the scene fits, storage buffers otherwise.
    Auto,
    /// Storage buffers (the general kernel).
    Storage,
    /// Uniform buffers sized for the scene.
    Uniform,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Timed runs per configuration (after one warm-up batch); the figures are medians.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub runs: u32,
    /// Benchmark the GPU only.
    #[arg(long, conflicts_with = "cpu_only")]
    pub gpu_only: bool,
    /// Benchmark the CPU reference only.
    #[arg(long)]
    pub cpu_only: bool,
    /// A smoke test: tiny images, 2 spp, for checking that the benchmark runs.
    #[arg(long)]
    pub quick: bool,
    /// Print the figures as JSON on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Where the GPU kernel reads the scene from, to compare the two kernels.
    #[arg(long, value_enum, default_value_t = SceneBindingChoice::Auto)]
    pub scene_binding: SceneBindingChoice,
    /// How the GPU kernel finds hits: hardware (ray queries; overrides --scene-binding),
    /// software (glint's BVH or scan), or auto (as for `render`).
    #[arg(long, value_enum, default_value_t = TraversalChoice::Auto)]
    pub traversal: TraversalChoice,
    /// Instead of the fixed set: the Cornell box with a generated mesh of about this many
    /// triangles (0: none), at 256² with light sampling, for paths/s against primitive count;
    /// e.g. `--mesh-triangles 0,1000,100000,1000000`.
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(0..=4_000_000))]
    pub mesh_triangles: Vec<u32>,
}

pub fn run(args: BenchArgs) -> Result<()> {
    let gpu = if args.cpu_only {
        None
    } else {
        Some(GpuContext::new()?)
    };
    let gpu_name = gpu.as_ref().map(|g| g.device_name());
    let traversal = match &gpu {
        Some(ctx) => Some(args.traversal.resolve(ctx)?),
        None => None,
    };
    if !args.json {
        crate::outln!(
            "GPU: {}   CPU reference: {} threads   (medians of {} runs after a warm-up)",
            gpu_name.as_deref().unwrap_or("none"),
            rayon::current_num_threads(),
            args.runs
        );
    }
    let mut results = Vec::new();
    let all_cases = if args.mesh_triangles.is_empty() {
        cases(args.quick)
    } else {
        mesh_cases(&args.mesh_triangles, args.quick)
    };
    for case in all_cases {
        let scene = case_scene(&case)?;
        let result = match (case.device, &gpu) {
            (BenchDevice::Gpu, Some(ctx)) => {
                let mut renderer = match args.scene_binding {
                    _ if traversal == Some(Traversal::Hardware) => {
                        GpuRenderer::with_traversal(ctx, &scene, Traversal::Hardware)?
                    }
                    SceneBindingChoice::Auto => GpuRenderer::new(ctx, &scene)?,
                    SceneBindingChoice::Storage => {
                        GpuRenderer::with_scene_binding(ctx, &scene, SceneBinding::Storage)?
                    }
                    SceneBindingChoice::Uniform => GpuRenderer::with_scene_binding(
                        ctx,
                        &scene,
                        SceneBinding::Uniform(SceneCounts::of(&scene)),
                    )?,
                };
                renderer.instrument();
                let binding = renderer.scene_binding();
                run_case(&mut renderer, case, args.runs as usize)?.with_scene_binding(binding)
            }
            (BenchDevice::Cpu, _) if !args.gpu_only => {
                run_case(&mut CpuRenderer::new(&scene), case, args.runs as usize)?
            }
            _ => continue,
        };
        let result = BenchResult {
            triangles: scene.triangles.len(),
            ..result
        };
        if !args.json {
            if results.is_empty() {
                crate::outln!("{}", header());
            }
            crate::outln!("{}", row(&result));
        }
        results.push(result);
    }
    if args.json {
        let rows: Vec<_> = results
            .iter()
            .map(|r| {
                serde_json::json!({
                    "device": r.case.device.as_str(),
                    "scene_binding": r.scene_binding.map(|b| b.name()),
                    "traversal": r.scene_binding.map(|b| if b.uses_ray_queries() {
                        Traversal::Hardware.name()
                    } else {
                        Traversal::Software.name()
                    }),
                    "width": r.case.size,
                    "height": r.case.size,
                    "max_bounces": 8,
                    "light_sampling": r.case.light_sampling,
                    "triangles": r.triangles,
                    "spp_per_run": r.case.spp,
                    "spp_per_batch": r.case.batch_spp,
                    "runs": r.runs,
                    "paths_per_second": r.paths_per_second,
                    "rays_per_second": r.rays_per_second,
                    "segments_per_path": r.segments_per_path,
                    "ms_per_batch": r.ms_per_batch,
                    "kernel_ms_per_batch": r.kernel_ms_per_batch,
                })
            })
            .collect();
        crate::outln!(
            "{}",
            serde_json::json!({
                "gpu": gpu_name,
                "gpu_backend": gpu.as_ref().map(|g| g.backend_name()),
                "cpu_threads": rayon::current_num_threads(),
                "results": rows,
            })
        );
    }
    Ok(())
}

fn header() -> String {
    format!(
        "{:<14} {:>9} {:>6} {:>10} {:>14} {:>14} {:>10} {:>10} {:>12}",
        "device",
        "size",
        "light",
        "triangles",
        "paths/s",
        "rays/s",
        "rays/path",
        "ms/batch",
        "kernel ms"
    )
}

fn row(r: &BenchResult) -> String {
    let opt = |v: Option<f64>, scale: f64, digits: usize| {
        v.map_or("-".to_string(), |v| format!("{:.*}", digits, v / scale))
    };
    format!(
        "{:<14} {:>9} {:>6} {:>10} {:>12.2} M {:>12} M {:>10} {:>10.1} {:>12}",
        match r.scene_binding {
            Some(binding) => format!("{} ({})", r.case.device.as_str(), binding.name()),
            None => r.case.device.as_str().to_string(),
        },
        format!("{}²", r.case.size),
        if r.case.light_sampling { "on" } else { "off" },
        r.triangles,
        r.paths_per_second / 1e6,
        opt(r.rays_per_second, 1e6, 2),
        opt(r.segments_per_path, 1.0, 2),
        r.ms_per_batch,
        opt(r.kernel_ms_per_batch, 1.0, 1),
    )
}
