//! `glint view`: the renderer of `glint render` plus a window. Each frame adds a batch of
//! samples with the same [`crate::gpu::GpuRenderer`] and shows the running mean through a
//! display pass; input moves the camera and restarts the accumulation.
//!
//! Parts: [`action`] (what input asks for), [`input`] (winit events → actions),
//! [`camera_control`] (the camera math), [`display`] (the display pass), [`denoised`] (the
//! D key's background denoising), [`watch`] (scene file edits), [`app`] (the winit
//! application that ties them together).

pub mod action;
mod app;
pub mod camera_control;
pub mod denoised;
pub mod display;
pub mod input;
pub mod watch;

use crate::error::InputError;
use crate::image::output_check::OutputSet;
use crate::image::tonemap::DisplayTransform;
use crate::scene::model::ModelOptions;
use crate::scene::RenderOverrides;
use action::Script;
use anyhow::Result;
use std::path::PathBuf;

/// What `glint view` was asked to do.
#[derive(Debug, Clone)]
pub struct ViewOptions {
    /// A scene file, or a model file built into a scene with `model`.
    pub scene: PathBuf,
    pub model: ModelOptions,
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Samples per frame; `None` adapts the batch to [`FRAME_TARGET`].
    pub spp_per_frame: Option<u32>,
    /// Quit after this many frames.
    pub frames: Option<u64>,
    /// Written on exit: PNG = what is shown, EXR = the linear mean.
    pub screenshot: Option<PathBuf>,
    /// The tone curve and the starting exposure (`--tonemap`, `--exposure`; keys change the
    /// exposure).
    pub display: DisplayTransform,
    /// Actions injected before given frames (tests).
    pub script: Script,
    /// One JSON line per frame and per event on stdout (tests, measurements).
    pub log_frames: bool,
    /// `--traversal`: how the kernel finds hits, resolved once the device is open.
    pub traversal: crate::gpu::TraversalChoice,
}

/// Wanted duration of a frame's batch of samples: a responsive ~30 frames per second.
pub const FRAME_TARGET: std::time::Duration = std::time::Duration::from_millis(30);

const NO_DISPLAY_HINT: &str = "use `glint render` to render to a file instead";

/// Whether a window system is there to talk to. winit itself fails later with a message that
/// names neither the cause nor the way out, so look first.
fn display_available() -> bool {
    if cfg!(any(target_os = "windows", target_os = "macos")) {
        return true;
    }
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// Runs the viewer until the window closes, Esc, or `frames`.
pub fn run(options: ViewOptions) -> Result<()> {
    let (scene, reads) = watch::load_watched(&options.scene, &options.model);
    let scene = scene.map_err(InputError::from)?;
    let scene = scene
        .with_overrides(&RenderOverrides {
            width: options.width,
            height: options.height,
            ..Default::default()
        })
        .map_err(|m| InputError(format!("{}: {m}", options.scene.display())))?;
    OutputSet::new()
        .input("the scene file", &options.scene)
        .image_opt("--screenshot", options.screenshot.as_deref())
        .check()?;
    if !display_available() {
        return Err(InputError(format!(
            "no display: glint view opens a window, but neither DISPLAY nor WAYLAND_DISPLAY is set; {NO_DISPLAY_HINT}"
        ))
        .into());
    }
    // Built once here (the BVH, the environment map's tables), and again only when the scene
    // file changes; a camera move rewrites the camera's parameters alone.
    let kernel = scene.try_kernel_scene()?;
    let event_loop = winit::event_loop::EventLoop::new().map_err(|e| {
        InputError(format!(
            "no display: glint view cannot connect to the window system ({e}); {NO_DISPLAY_HINT}"
        ))
    })?;
    app::run(event_loop, scene, kernel, reads, options)
}
