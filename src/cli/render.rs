//! `glint render`.

use super::model::ModelArgs;
use super::post::PostArgs;
use super::render_writer::RenderWriter;
use super::sample_range::{self, SampleRangeArgs};
use crate::cpu::integrator::renderer::CpuRenderer;
use crate::error::InputError;
use crate::gpu::{GpuContext, GpuRenderer, TraversalChoice};
use crate::image::format::ImageFormat;
use crate::image::output_check::OutputSet;
use crate::kernel::types::Params;
use crate::kernel::KernelScene;
use crate::render::adaptive::{Adaptive, DEFAULT_MIN_SPP};
use crate::render::batch_means;
use crate::render::interrupt::{self, Interrupted};
use crate::render::partial::{format_range, settings_hash, PartialInfo};
use crate::render::{
    relative_error, render_progressive, BatchSizer, Renderer, StopRules, MIN_SPP_FOR_TARGET_ERROR,
};
use crate::scene::model::ModelScene;
use crate::scene::model_toml::model_toml;
use crate::scene::{
    Integrator, LightSampler, RenderOverrides, Sampler, Scene, MAX_BOUNCES_LIMIT, MAX_IMAGE_SIDE,
    MAX_SPP,
};
use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Wanted duration of one GPU submission: short enough for a desktop GPU's watchdog and a
/// responsive progress bar, long enough that per-batch overhead stays small.
const BATCH_TARGET: Duration = Duration::from_millis(250);

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (TOML), or a model file (.glb, .gltf, .obj, .ply) to render as a scene.
    pub scene: PathBuf,
    /// Output image: .png (clamped, sRGB) or .exr (linear float32 radiance). Default: <scene stem>.png
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Samples per pixel (overrides [render] spp).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP as i64), allow_negative_numbers = true)]
    pub spp: Option<u32>,
    /// Image width in pixels (overrides [render] width).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64), allow_negative_numbers = true)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides [render] height).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64), allow_negative_numbers = true)]
    pub height: Option<u32>,
    /// Scattering events per path (overrides [render] max_bounces).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=MAX_BOUNCES_LIMIT as i64), allow_negative_numbers = true)]
    pub max_bounces: Option<u32>,
    /// Random seed (overrides [render] seed).
    #[arg(long, allow_negative_numbers = true)]
    pub seed: Option<u32>,
    /// Next-event estimation with multiple importance sampling (overrides [render] light_sampling).
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub light_sampling: Option<bool>,
    /// Where each sample's random numbers come from (overrides [render] sampler; default
    /// independent): independent numbers, or Owen-scrambled Sobol points (lower error).
    #[arg(long, value_enum)]
    pub sampler: Option<Sampler>,
    /// How path tracing's next-event estimation picks an emitter (overrides [render]
    /// light_sampler; default power): a light tree, by each emitter's bound on what it sends
    /// to the shading point, or an alias table by power alone.
    #[arg(long, value_enum)]
    pub light_sampler: Option<LightSampler>,
    /// The light transport estimator (overrides [render] integrator; default path): path
    /// tracing, or bidirectional path tracing (caustics).
    #[arg(long, value_enum)]
    pub integrator: Option<Integrator>,
    /// Render on the CPU reference.
    #[arg(long, conflicts_with = "gpu")]
    pub cpu: bool,
    /// Render on a Vulkan GPU or fail; without it, no GPU means a CPU render.
    #[arg(long)]
    pub gpu: bool,
    /// How the GPU kernel finds hits: the device's ray queries (hardware), glint's own BVH
    /// (software), or auto: hardware where the device has ray queries, but not on lavapipe
    /// (no faster there). The CPU reference always uses its BVH.
    #[arg(long, value_enum, default_value_t = TraversalChoice::Auto)]
    pub traversal: TraversalChoice,
    /// Stop at the first batch boundary after this many seconds and write what is done.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds, allow_negative_numbers = true)]
    pub time_limit: Option<f64>,
    /// Also write the variance of each pixel's mean (σ²/n per channel, linear) to this .exr.
    /// With --integrator bdpt it is estimated from batch means (light tracing splats into any
    /// pixel, so a pixel's own samples do not show it): the spread of the means of the sample
    /// blocks 1, 1, 2, 4, …, 32, then every 64.
    #[arg(long, value_name = "FILE.exr")]
    pub variance: Option<PathBuf>,
    /// Stop at the first batch boundary where the image's relative standard error,
    /// √(mean of the variance image) / (mean of the image), is at most E (checked from 8 spp on).
    /// --spp is then the upper bound, and --time-limit still holds. On a black image (mean 0)
    /// the relative error is undefined, so it never stops the render (a note says so).
    /// With --adaptive, E is instead each pixel's target (see there). With --integrator bdpt the
    /// variance image comes from batch means (see --variance), and --adaptive is refused.
    #[arg(long, value_name = "E", value_parser = parse_target_error, allow_negative_numbers = true)]
    pub target_error: Option<f64>,
    /// Adaptive sampling: after --adaptive-min-spp samples, a pixel stops taking samples once
    /// its estimated relative error, √(mean over channels of σ²/(μ² + 0.01)) with σ² the
    /// variance of its mean, and its 3×3 neighbours' are at most --target-error. --spp is then
    /// each pixel's cap; the render ends when every pixel has stopped or reached it (or at
    /// --time-limit), and the time goes to the pixels that are still noisy.
    #[arg(long, requires = "target_error")]
    pub adaptive: bool,
    /// Samples every pixel takes before adaptive sampling may stop it.
    #[arg(long, value_name = "N", requires = "adaptive", default_value_t = DEFAULT_MIN_SPP,
          value_parser = clap::value_parser!(u32).range(2..=MAX_SPP as i64), allow_negative_numbers = true)]
    pub adaptive_min_spp: u32,
    /// Print a JSON summary on stdout at the end. Its "seconds" is the time spent rendering
    /// batches only: start-up, scene upload, shader compilation and file writes are not in it
    /// ("wall_seconds" is the whole command).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub post: PostArgs,
    #[command(flatten)]
    pub model: ModelArgs,
    /// Model files: write the scene glint builds from the file as a scene file (TOML) on
    /// stdout, and render nothing.
    #[arg(long)]
    pub print_scene: bool,
    #[command(flatten)]
    pub range: SampleRangeArgs,
    /// Refresh the output with the running image (a resumable partial file for .exr) every
    /// this many seconds; 0: after every batch.
    #[arg(long, value_name = "SECONDS", value_parser = sample_range::parse_interval, default_value = "3")]
    pub checkpoint_interval: Duration,
}

/// Longest `--time-limit`: about 31 years, far inside what a `Duration` holds (1.8e19 s).
const MAX_TIME_LIMIT_SECONDS: f64 = 1e9;

fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .parse()
        .map_err(|_| format!("{s:?} is not a number of seconds"))?;
    if !(0.0..=MAX_TIME_LIMIT_SECONDS).contains(&v) {
        return Err(format!(
            "must be a number of seconds in [0, {MAX_TIME_LIMIT_SECONDS:e}], got {s}"
        ));
    }
    Ok(v)
}

fn parse_on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("expected on or off, got {s:?}")),
    }
}

fn parse_target_error(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if !v.is_finite() || v <= 0.0 {
        return Err(format!("must be a finite number > 0, got {s}"));
    }
    Ok(v)
}

/// Either a GPU renderer or, where there is none, the CPU reference.
fn open_gpu(args: &RenderArgs, integrator: Integrator) -> Result<Option<GpuContext>> {
    if args.cpu {
        return Ok(None);
    }
    if integrator == Integrator::Bdpt && !args.gpu {
        // The kernel renders it, but on lavapipe no faster than the CPU reference
        // (docs/src/reference/integrators.md, "On the GPU"): the CPU unless --gpu asks.
        return Ok(None);
    }
    match GpuContext::new() {
        Ok(ctx) => Ok(Some(ctx)),
        Err(e) if args.gpu => Err(anyhow::Error::new(e).context("--gpu was given")),
        Err(e) => {
            crate::errln!("glint: {e}; rendering on the CPU reference instead");
            Ok(None)
        }
    }
}

/// The GPU renderer where there is a GPU (with the traversal `--traversal` resolves to), the
/// CPU reference otherwise.
fn make_renderer<'g>(
    args: &RenderArgs,
    gpu: Option<&'g GpuContext>,
    kernel_scene: &KernelScene,
) -> Result<(Box<dyn Renderer + 'g>, Option<crate::gpu::Traversal>)> {
    // The CPU reference traverses its BVH whatever --traversal says.
    let traversal = match gpu {
        Some(ctx) => Some(args.traversal.resolve(ctx)?),
        None => None,
    };
    let renderer: Box<dyn Renderer + 'g> = match (gpu, traversal) {
        (Some(ctx), Some(traversal)) => {
            Box::new(GpuRenderer::with_traversal(ctx, kernel_scene, traversal)?)
        }
        _ => Box::new(CpuRenderer::new(kernel_scene)),
    };
    // Bidirectional renders' variance comes from batch means (src/render/batch_means.rs).
    Ok((
        batch_means::for_params(renderer, &kernel_scene.params),
        traversal,
    ))
}

/// The scene `args` ask for, with their overrides; `None` where `--print-scene` printed it
/// instead.
fn scene_to_render(args: &RenderArgs) -> Result<Option<Scene>> {
    let (scene, model) = args.model.load(&args.scene, args.width, args.height)?;
    let overrides = RenderOverrides {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_bounces: args.max_bounces,
        seed: args.seed,
        light_sampling: args.light_sampling,
        sampler: args.sampler,
        integrator: args.integrator,
        light_sampler: args.light_sampler,
    };
    let scene = scene
        .with_overrides(&overrides)
        .map_err(|m| InputError(format!("{}: {m}", args.scene.display())))?;
    if args.print_scene {
        let Some(model) = model else {
            return Err(InputError(format!(
                "--print-scene writes the scene built from a model file; {} is a scene file \
                 already",
                args.scene.display()
            ))
            .into());
        };
        crate::outln!("{}", model_toml(&ModelScene { scene, ..model }).trim_end());
        return Ok(None);
    }
    Ok(Some(scene))
}

/// A progress bar on a terminal, hidden elsewhere.
fn progress_bar(samples: u64) -> ProgressBar {
    let progress = if std::io::stderr().is_terminal() {
        ProgressBar::with_draw_target(Some(samples), ProgressDrawTarget::stderr())
    } else {
        ProgressBar::hidden()
    };
    progress.set_style(
        ProgressStyle::with_template("{bar:40.cyan/blue} {pos}/{len} spp  {msg}  ETA {eta}")
            .expect("valid template"),
    );
    progress
}

/// What `--json` reports of a finished render, beside the arguments and the renderer.
struct FinishedRun<'a> {
    scene: &'a Scene,
    kernel_scene: &'a KernelScene,
    output: &'a std::path::Path,
    stats: &'a crate::render::RenderStats,
    /// Paths of a resumed file (its samples, all pixels together), not rendered by this run.
    resumed_paths: u64,
    adaptive: Option<Adaptive>,
    relative_error: Option<f64>,
    denoise_seconds: Option<f64>,
    traversal: Option<crate::gpu::Traversal>,
}

/// `--json`'s one line about a finished render.
fn json_summary(
    args: &RenderArgs,
    run: &FinishedRun,
    renderer: &dyn Renderer,
    started: Instant,
) -> serde_json::Value {
    let seconds = run.stats.render_time.as_secs_f64();
    // This run's paths only, not a resumed file's.
    let counts = renderer.pixel_counts();
    let all_paths: u64 = counts.iter().map(|&n| n as u64).sum();
    let paths = all_paths - run.resumed_paths;
    // Adaptive sampling: its settings, the pixels still taking samples at the end and the
    // mean samples per pixel ("spp" is then the most any pixel took).
    let adaptive = run.adaptive.map(|a| {
        serde_json::json!({
            "target_error": a.target_error,
            "min_spp": a.min_spp,
            "active_pixels": renderer.active_pixels(),
            "mean_spp": all_paths as f64 / counts.len().max(1) as f64,
        })
    });
    serde_json::json!({
        "scene": args.scene.display().to_string(),
        "output": run.output.display().to_string(),
        "width": run.scene.render.width,
        "height": run.scene.render.height,
        "spp": run.stats.spp,
        "max_bounces": run.scene.render.max_bounces,
        "seed": run.scene.render.seed,
        "sampler": run.scene.render.sampler.name(),
        "integrator": run.scene.render.integrator.name(),
        "light_sampler": run.scene.render.light_sampler.name(),
        "paths": paths,
        "adaptive": adaptive,
        "seconds": seconds,
        "paths_per_second": paths as f64 / seconds.max(1e-9),
        "wall_seconds": started.elapsed().as_secs_f64(),
        "stopped_by": run.stats.stop_reason.as_str(),
        // Below 2 spp there is no variance estimate: the error is unknown (null), not 0.
        "relative_error": run.relative_error,
        "nonfinite_samples": renderer.nonfinite_samples(),
        "device": renderer.device_name(),
        "backend": renderer.backend_name(),
        // The GPU's traversal; the CPU reference's is its BVH ("software").
        "traversal": run.traversal.unwrap_or(crate::gpu::Traversal::Software).name(),
        // Stored (an instanced mesh once), then placed (once per instance).
        "triangles": run.kernel_scene.triangles.len(),
        "instances": run.kernel_scene.instances.len(),
        "placed_triangles": run.scene.placed_triangle_count(),
        "bvh_nodes": run.kernel_scene.bvh_nodes.len(),
        "bvh_build_seconds": run.kernel_scene.bvh_build_seconds,
        "scene_bytes": run.kernel_scene.scene_bytes(),
        "denoise_seconds": run.denoise_seconds,
        "samples": [renderer.first_sample(), renderer.first_sample() + run.stats.spp],
    })
}

pub fn run(args: RenderArgs) -> Result<()> {
    let started = Instant::now();
    let Some(scene) = scene_to_render(&args)? else {
        return Ok(());
    };
    let range = &args.range;
    args.post.refuse_partial(
        range.samples.is_some() || range.shard.is_some() || range.resume.is_some(),
    )?;
    let mut kernel_scene = scene
        .try_kernel_scene()
        .map_err(|e| InputError(format!("{}: {e}", args.scene.display())))?;
    args.post.configure(&mut kernel_scene.params);
    let settings = &scene.render;
    let (width, height) = (settings.width, settings.height);
    // AOVs leave the image bit for bit the same (tests/suite/aov.rs), so --denoise's --raw file
    // resumes and merges with renders made without them.
    let settings_hash = settings_hash(&KernelScene {
        params: Params {
            aovs: 0,
            ..kernel_scene.params
        },
        ..kernel_scene.clone()
    });
    let plan = sample_range::plan(&args.range, settings.spp, &settings_hash, (width, height))?;
    let output = args.output.clone().unwrap_or_else(|| {
        sample_range::default_output(&args.scene, &plan, &args.range, settings.spp)
    });
    let outputs = OutputSet::new()
        .input("the scene file", &args.scene)
        .image("-o", &output)
        .exr_opt("--variance", args.variance.as_deref());
    args.post.outputs(outputs).check()?;
    if plan.is_partial(settings.spp) && ImageFormat::from_path(&output) != Ok(ImageFormat::Exr) {
        return Err(InputError(format!(
            "{}: a partial render (samples {} of {}) needs an .exr output to hold what a merge needs",
            output.display(),
            format_range(&plan.target),
            settings.spp
        ))
        .into());
    }
    args.post.check()?;

    if scene.render.integrator == Integrator::Bdpt && args.adaptive {
        // Its variance comes from batch means of every pixel's samples (light tracing splats
        // into any pixel), which a pixel that stopped early would not have.
        return Err(InputError(
            "--adaptive is not available with the bdpt integrator (its variance comes from batch means of every pixel's samples); --target-error alone stops the whole render".into(),
        )
        .into());
    }
    // Adaptive sampling's settings: the command's, or a resumed adaptive file's.
    let adaptive = match (args.target_error, &plan.resumed) {
        (Some(target_error), _) if args.adaptive => Some(Adaptive {
            target_error,
            min_spp: args.adaptive_min_spp,
        }),
        (_, Some(resumed)) if resumed.info.adaptive.is_some() && args.target_error.is_none() => {
            let a = resumed.info.adaptive;
            crate::errln!(
                "glint: note: {} was rendered with adaptive sampling; going on with its {}",
                args.range.resume.as_ref().expect("resumed").display(),
                a.expect("adaptive").to_header()
            );
            a
        }
        _ => None,
    };

    let gpu = open_gpu(&args, scene.render.integrator)?;
    let (mut renderer, traversal) = make_renderer(&args, gpu.as_ref(), &kernel_scene)?;

    plan.start(renderer.as_mut())?;
    // With --denoise, -o is the denoised image, written at the end; the mean goes to --raw.
    let writer_output = if args.post.denoise {
        args.post.raw.clone()
    } else {
        Some(output.clone())
    };
    let mut writer = RenderWriter::new(
        writer_output,
        args.variance.clone(),
        args.post.display_transform(),
        PartialInfo {
            ranges: Vec::new(),
            target: plan.target.clone(),
            spp: settings.spp,
            seed: settings.seed,
            settings: settings_hash,
            scene: args.scene.display().to_string(),
            device: renderer.device_name(),
            adaptive,
        },
    );
    let progress = progress_bar(plan.samples_wanted() as u64);
    let pixels = width as f64 * height as f64;
    let mut last_checkpoint = Instant::now();
    let mut sizer = BatchSizer::new(BATCH_TARGET);
    let rules = StopRules {
        time_limit: args.time_limit.map(Duration::from_secs_f64),
        target_error: args.target_error,
        adaptive,
        interrupted: Some(interrupt::install()?),
    };
    let stats = render_progressive(
        renderer.as_mut(),
        plan.samples_wanted(),
        rules,
        &mut sizer,
        |r, report| {
            progress.set_position(report.spp_done as u64);
            let rate = report.last_batch_spp as f64 * pixels / report.last_batch_time.as_secs_f64();
            let mut message = format!("{:.2} M samples/s", rate / 1e6);
            if adaptive.is_some() {
                message += &format!(
                    "  active {:.1}%",
                    100.0 * report.active_pixels as f64 / pixels
                );
            }
            if let Some(e) = report.relative_error {
                message += &format!("  rel. error {:.2}%", 100.0 * e);
            }
            progress.set_message(message);
            if report.spp_done < report.spp_target
                && last_checkpoint.elapsed() >= args.checkpoint_interval
            {
                writer.checkpoint(r)?;
                last_checkpoint = Instant::now();
            }
            Ok(())
        },
    )?;
    progress.finish_and_clear();
    if args.target_error.is_some() && stats.relative_error.is_none() {
        crate::errln!(
            "glint: note: --target-error never applied: the image is black (or below {MIN_SPP_FOR_TARGET_ERROR} spp), so its relative error is undefined"
        );
    }
    let (mean, variance) = writer.finish(renderer.as_mut())?;
    let denoise_seconds = args.post.finish(renderer.as_mut(), &mean, &output)?;
    let first = renderer.first_sample();

    let nonfinite = renderer.nonfinite_samples();
    if nonfinite > 0 {
        crate::errln!(
            "glint: warning: {nonfinite} samples were NaN, infinite or above 1e14 and were \
             dropped (counted as black)"
        );
    }
    if args.json {
        let run = FinishedRun {
            scene: &scene,
            kernel_scene: &kernel_scene,
            output: &output,
            stats: &stats,
            resumed_paths: plan
                .resumed
                .as_ref()
                .map_or(0, |p| p.accumulation.total_samples()),
            adaptive,
            relative_error: (stats.spp >= 2)
                .then(|| relative_error(&mean, &variance))
                .flatten(),
            denoise_seconds,
            traversal,
        };
        crate::outln!("{}", json_summary(&args, &run, renderer.as_ref(), started));
    }
    if let Some(signal) = interrupt::requested() {
        return Err(Interrupted {
            signal,
            message: format!(
                "interrupted by {} at {} spp; wrote samples {} to {} (continue with --resume)",
                interrupt::name(signal),
                stats.spp,
                format_range(&(first..first + stats.spp)),
                output.display()
            ),
        }
        .into());
    }
    Ok(())
}
