//! `glint.render`: the CLI's render loop (`render_progressive`, the same batches, so the same
//! bytes) on the device asked for, with the GIL released, Ctrl-C checked between batches, and
//! one GPU device per process.

use crate::gpu_cache::{gpu_context, same_objects, GpuCache};
use crate::images::to_numpy;
use crate::scene::Scene;
use crate::SceneError;
use anyhow::anyhow;
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::error::InputError;
use glint::gpu::{GpuContext, GpuRenderer, Traversal, TraversalChoice};
use glint::kernel::KernelScene;
use glint::render::batch_means::BatchMeans;
use glint::render::{relative_error, render_progressive, BatchSizer, Renderer, StopRules};
use glint::scene::{
    self as scenes, Integrator, LightSampler, RenderOverrides, Sampler, MAX_BOUNCES_LIMIT,
    MAX_IMAGE_SIDE, MAX_SPP,
};
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The CLI's batch duration (src/cli/render.rs): also how long Ctrl-C may wait.
const BATCH_TARGET: Duration = Duration::from_millis(250);

/// `--traversal`'s values.
fn parse_traversal(s: &str) -> PyResult<TraversalChoice> {
    match s {
        "auto" => Ok(TraversalChoice::Auto),
        "hardware" => Ok(TraversalChoice::Hardware),
        "software" => Ok(TraversalChoice::Software),
        _ => Err(PyValueError::new_err(format!(
            "traversal: expected \"auto\", \"hardware\" or \"software\", got {s:?}"
        ))),
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Device {
    Auto,
    Gpu,
    Cpu,
}

impl Device {
    fn parse(s: &str) -> PyResult<Device> {
        match s {
            "auto" => Ok(Device::Auto),
            "gpu" => Ok(Device::Gpu),
            "cpu" => Ok(Device::Cpu),
            _ => Err(PyValueError::new_err(format!(
                "device: expected \"auto\", \"gpu\" or \"cpu\", got {s:?}"
            ))),
        }
    }
}

/// `render_progressive` polls a `&'static` flag; each render takes one from this pool and
/// gives it back, so concurrent renders have their own and none is leaked per call.
static FREE_FLAGS: Mutex<Vec<&'static AtomicBool>> = Mutex::new(Vec::new());

struct StopFlag(&'static AtomicBool);

impl StopFlag {
    fn take() -> StopFlag {
        let flag = FREE_FLAGS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .pop()
            .unwrap_or_else(|| Box::leak(Box::new(AtomicBool::new(false))));
        flag.store(false, Ordering::SeqCst);
        StopFlag(flag)
    }
}

impl Drop for StopFlag {
    fn drop(&mut self) {
        FREE_FLAGS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(self.0);
    }
}

/// An override's value, checked as the CLI's flag is: a bad one is a ValueError.
fn checked(name: &str, value: Option<i64>, min: i64, max: i64) -> PyResult<Option<u32>> {
    match value {
        Some(v) if !(min..=max).contains(&v) => Err(PyValueError::new_err(format!(
            "{name}: must be in {min}..={max}, got {v}"
        ))),
        Some(v) => Ok(Some(v as u32)),
        None => Ok(None),
    }
}

/// What a render gives back, before it becomes Python objects.
struct Rendered {
    mean: glint::image::output::Image,
    variance: Option<glint::image::output::Image>,
    aovs: Option<glint::image::aov::Aovs>,
    /// With denoise: OIDN's image of `mean` and the seconds it took.
    denoised: Option<(glint::image::output::Image, f64)>,
    spp: u32,
    seconds: f64,
    stopped_by: &'static str,
    relative_error: Option<f64>,
    nonfinite_samples: u64,
    device: String,
    backend: String,
    traversal: Traversal,
    /// Whether a GPU render reused the scene's renderer and kernel from its last render.
    kernel_reused: bool,
}

struct Options {
    variance: bool,
    /// Bidirectional: the variance comes from batch means (src/render/batch_means.rs), as
    /// `glint render`'s does.
    batch_means: bool,
    /// Accumulate AOVs (asked for, or for the denoiser).
    aovs: bool,
    denoise: bool,
    time_limit: Option<Duration>,
    progress: bool,
}

/// Renders on `renderer` as `glint render` does, stopping early at `stop`.
fn run(
    renderer: &mut dyn Renderer,
    spp: u32,
    options: &Options,
    stop: &'static AtomicBool,
    signal_error: &mut Option<PyErr>,
) -> anyhow::Result<Rendered> {
    let mut batched;
    let renderer: &mut dyn Renderer = if options.batch_means {
        batched = BatchMeans::new(renderer);
        &mut batched
    } else {
        renderer
    };
    let rules = StopRules {
        time_limit: options.time_limit,
        target_error: None,
        adaptive: None,
        interrupted: Some(stop),
    };
    let mut sizer = BatchSizer::new(BATCH_TARGET);
    let stats = render_progressive(renderer, spp, rules, &mut sizer, |_, report| {
        if options.progress {
            let mut err = std::io::stderr();
            let _ = write!(
                err,
                "\rglint: {}/{} spp",
                report.spp_done, report.spp_target
            );
            let _ = err.flush();
        }
        // Python's own SIGINT handler only notes the signal; running it raises
        // KeyboardInterrupt here, on the main thread (elsewhere this returns Ok).
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            stop.store(true, Ordering::SeqCst);
            *signal_error = Some(e);
        }
        Ok(())
    })?;
    if options.progress {
        let _ = writeln!(std::io::stderr());
    }
    let mean = renderer.read_mean()?;
    let variance = if options.variance || stats.spp >= 2 {
        Some(renderer.read_variance()?)
    } else {
        None
    };
    let relative_error = match (&variance, stats.spp >= 2) {
        (Some(v), true) => relative_error(&mean, v),
        _ => None,
    };
    let aovs = if options.aovs {
        Some(renderer.read_aovs()?)
    } else {
        None
    };
    let denoised = match (&aovs, options.denoise) {
        (Some(aovs), true) => {
            let started = Instant::now();
            let image = glint::image::denoise::oidn()?.denoise(&mean, aovs)?;
            Some((image, started.elapsed().as_secs_f64()))
        }
        _ => None,
    };
    Ok(Rendered {
        aovs,
        denoised,
        variance: if options.variance { variance } else { None },
        mean,
        spp: stats.spp,
        seconds: stats.render_time.as_secs_f64(),
        stopped_by: stats.stop_reason.as_str(),
        relative_error,
        nonfinite_samples: renderer.nonfinite_samples(),
        device: renderer.device_name(),
        backend: renderer.backend_name(),
        traversal: Traversal::Software,
        kernel_reused: false,
    })
}

/// Renders on the GPU, reusing the scene's renderer (and its compiled kernel) when it was
/// made for the same objects, image size and features.
fn run_gpu(
    ctx: &'static GpuContext,
    scene: &Scene,
    (validated, kernel_scene): (&scenes::Scene, &KernelScene),
    traversal: TraversalChoice,
    options: &Options,
    stop: &'static AtomicBool,
    signal_error: &mut Option<PyErr>,
) -> anyhow::Result<Rendered> {
    let traversal = traversal.resolve(ctx)?;
    let mut cache = scene.gpu.lock().unwrap_or_else(|e| e.into_inner());
    let reused = match cache.as_mut() {
        Some(c)
            if (c.aovs || !options.aovs)
                && c.traversal == traversal
                && same_objects(&c.scene, validated) =>
        {
            // Fails where the kernel lacks a feature the new parameters turn on.
            c.renderer.set_params(kernel_scene.params).is_ok()
        }
        _ => false,
    };
    if !reused {
        // Dropped first: two renderers' buffers need not fit the device at once.
        *cache = None;
        *cache = Some(GpuCache {
            renderer: GpuRenderer::with_traversal(ctx, kernel_scene, traversal)?,
            scene: validated.clone(),
            aovs: options.aovs,
            traversal,
        });
    }
    let renderer = &mut cache.as_mut().expect("filled above").renderer;
    let result = run(renderer, validated.render.spp, options, stop, signal_error);
    if result.is_err() {
        // A device error may leave the renderer in any state: the next render makes a new one.
        *cache = None;
    }
    result.map(|r| Rendered {
        kernel_reused: reused,
        traversal,
        ..r
    })
}

/// The compiled half of `glint.render` (python/glint/rendering.py documents it): a dict of
/// the image and the other outputs as H×W×3 float32 NumPy arrays, and the statistics.
#[pyfunction]
#[pyo3(signature = (scene, *, spp=None, width=None, height=None, max_bounces=None, seed=None,
    light_sampling=None, sampler=None, integrator=None, light_sampler=None, device="auto", traversal="auto", variance=false, aovs=false, denoise=false,
    time_limit=None, progress=false))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, Scene>,
    spp: Option<i64>,
    width: Option<i64>,
    height: Option<i64>,
    max_bounces: Option<i64>,
    seed: Option<i64>,
    light_sampling: Option<bool>,
    sampler: Option<&str>,
    integrator: Option<&str>,
    light_sampler: Option<&str>,
    device: &str,
    traversal: &str,
    variance: bool,
    aovs: bool,
    denoise: bool,
    time_limit: Option<f64>,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let wall = Instant::now();
    let device = Device::parse(device)?;
    let traversal = parse_traversal(traversal)?;
    let overrides = RenderOverrides {
        spp: checked("spp", spp, 1, MAX_SPP as i64)?,
        width: checked("width", width, 1, MAX_IMAGE_SIDE as i64)?,
        height: checked("height", height, 1, MAX_IMAGE_SIDE as i64)?,
        max_bounces: checked("max_bounces", max_bounces, 0, MAX_BOUNCES_LIMIT as i64)?,
        seed: checked("seed", seed, 0, u32::MAX as i64)?,
        light_sampling,
        sampler: sampler
            .map(|s| {
                Sampler::from_name(s).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "sampler: expected \"independent\" or \"sobol\", got {s:?}"
                    ))
                })
            })
            .transpose()?,
        integrator: integrator
            .map(|s| {
                Integrator::from_name(s).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "integrator: expected \"path\" or \"bdpt\", got {s:?}"
                    ))
                })
            })
            .transpose()?,
        light_sampler: light_sampler
            .map(|s| {
                LightSampler::from_name(s).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "light_sampler: expected \"tree\" or \"power\", got {s:?}"
                    ))
                })
            })
            .transpose()?,
    };
    let time_limit = match time_limit {
        Some(t) if !(0.0..=1e9).contains(&t) => {
            return Err(PyValueError::new_err(format!(
                "time_limit: must be a number of seconds in [0, 1e9], got {t}"
            )))
        }
        t => t.map(Duration::from_secs_f64),
    };
    if denoise {
        // As `glint render --denoise` checks before rendering: the install step when missing.
        glint::image::denoise::oidn()
            .map_err(|e| PyRuntimeError::new_err(format!("denoise: {e:#}")))?;
    }
    let this = scene.get();
    let source = this.source.display().to_string();
    let validated = this
        .scene
        .clone()
        .with_overrides(&overrides)
        .map_err(|m| PyValueError::new_err(format!("{source}: {m}")))?;
    let bdpt = validated.render.integrator == Integrator::Bdpt;
    let mut kernel_scene = validated
        .try_kernel_scene()
        .map_err(|e| SceneError::new_err(format!("{source}: {e}")))?;
    let options = Options {
        variance,
        batch_means: bdpt,
        aovs: aovs || denoise,
        denoise,
        time_limit,
        progress,
    };
    // As `glint render` sets them without --clamp.
    kernel_scene.params.aovs = options.aovs as u32;
    kernel_scene.params.radiance_clamp = 0.0;

    let mut signal_error = None;
    let result = py.detach(|| {
        let stop = StopFlag::take();
        let gpu = match device {
            Device::Cpu => None,
            // As `glint render` without --gpu: bidirectional runs on the CPU reference.
            Device::Auto if bdpt => None,
            _ => match gpu_context() {
                Ok(ctx) => Some(ctx),
                Err(e) if device == Device::Gpu => {
                    return Err(anyhow!("device=\"gpu\": {e}"));
                }
                Err(_) => None,
            },
        };
        match gpu {
            Some(ctx) => run_gpu(
                ctx,
                this,
                (&validated, &kernel_scene),
                traversal,
                &options,
                stop.0,
                &mut signal_error,
            ),
            None => run(
                &mut CpuRenderer::new(&kernel_scene),
                validated.render.spp,
                &options,
                stop.0,
                &mut signal_error,
            ),
        }
    });
    let rendered = result.map_err(|e| match e.downcast_ref::<InputError>() {
        Some(input) => SceneError::new_err(format!("{source}: {input}")),
        None => PyRuntimeError::new_err(format!("{e:#}")),
    })?;
    // Ctrl-C stopped the render, which returns what it has; any other exception a signal
    // handler raised is the caller's.
    if let Some(e) = signal_error {
        if !e.is_instance_of::<PyKeyboardInterrupt>(py) {
            return Err(e);
        }
    }

    let r = &validated.render;
    let stats = PyDict::new(py);
    let paths = r.width as u64 * r.height as u64 * rendered.spp as u64;
    stats.set_item("scene", &source)?;
    stats.set_item("width", r.width)?;
    stats.set_item("height", r.height)?;
    stats.set_item("spp", rendered.spp)?;
    stats.set_item("max_bounces", r.max_bounces)?;
    stats.set_item("seed", r.seed)?;
    stats.set_item("light_sampling", r.light_sampling)?;
    stats.set_item("sampler", r.sampler.name())?;
    stats.set_item("integrator", r.integrator.name())?;
    stats.set_item("light_sampler", r.light_sampler.name())?;
    stats.set_item("paths", paths)?;
    stats.set_item("seconds", rendered.seconds)?;
    stats.set_item(
        "paths_per_second",
        paths as f64 / rendered.seconds.max(1e-9),
    )?;
    stats.set_item("stopped_by", rendered.stopped_by)?;
    stats.set_item("relative_error", rendered.relative_error)?;
    stats.set_item("nonfinite_samples", rendered.nonfinite_samples)?;
    stats.set_item("device", rendered.device)?;
    stats.set_item("backend", rendered.backend)?;
    stats.set_item("traversal", rendered.traversal.name())?;
    stats.set_item("kernel_reused", rendered.kernel_reused)?;
    stats.set_item("samples", (0u32, rendered.spp))?;

    let out = PyDict::new(py);
    let (image, raw, denoise_seconds) = match rendered.denoised {
        Some((denoised, seconds)) => (denoised, Some(rendered.mean), Some(seconds)),
        None => (rendered.mean, None, None),
    };
    stats.set_item("denoise_seconds", denoise_seconds)?;
    out.set_item("image", to_numpy(py, image))?;
    out.set_item("raw", raw.map(|i| to_numpy(py, i)))?;
    out.set_item("variance", rendered.variance.map(|i| to_numpy(py, i)))?;
    if let Some(a) = rendered.aovs {
        out.set_item("albedo", to_numpy(py, a.albedo))?;
        out.set_item("normal", to_numpy(py, a.normal))?;
        out.set_item("depth", to_numpy(py, a.depth))?;
    }
    stats.set_item("wall_seconds", wall.elapsed().as_secs_f64())?;
    out.set_item("stats", stats)?;
    Ok(out)
}
