//! The viewer's state: the scene, the camera, the renderer and the window, and the steps
//! that open, rebuild and close them.

use super::surface::{bind_renderer, pick_format, Gpu};
use crate::gpu::{GpuContext, GpuRenderer};
use crate::image::tonemap::DisplayTransform;
use crate::kernel::types::Params;
use crate::kernel::{place_camera, KernelScene};
use crate::render::BatchSizer;
use crate::scene::{Camera, Integrator, RenderOverrides, Scene, MAX_IMAGE_PIXELS};
use crate::viewer::action::Script;
use crate::viewer::denoised::DenoisedView;
use crate::viewer::display::DisplayPass;
use crate::viewer::input::InputState;
use crate::viewer::watch::{BackgroundLoad, FileWatch};
use crate::viewer::ViewOptions;
use anyhow::{anyhow, Context, Result};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

/// How often the title's statistics are refreshed (every frame would flicker).
pub(super) const TITLE_INTERVAL: Duration = Duration::from_millis(250);
/// Exposure range in stops; beyond it every pixel is black or white anyway.
pub(super) const EXPOSURE_LIMIT: f32 = 20.0;
/// How long the test-only `wait-edit` action waits for the scene file to change.
pub(super) const WAIT_FOR_EDIT_LIMIT: Duration = Duration::from_secs(60);

pub(super) struct App {
    pub(super) options: ViewOptions,
    pub(super) script: Script,
    /// The last scene that loaded, its image size set to the window's.
    pub(super) scene: Scene,
    /// `scene` as the kernel reads it, with the camera the file gives (see [`App::params`]).
    pub(super) kernel: KernelScene,
    /// The camera the scene file says; a reload adopts the file's camera only if it changed,
    /// so editing a material does not throw away where the user flew to.
    pub(super) file_camera: Camera,
    pub(super) camera: Camera,
    pub(super) camera_moved: bool,
    /// The integrator the scene file says; like the camera, a reload adopts it only if it
    /// changed, so an edit keeps the integrator I switched to.
    pub(super) file_integrator: Integrator,
    /// The integrator the window shows (I switches it live).
    pub(super) integrator: Integrator,
    /// The accumulation restarted: the next frame is a 1-spp preview.
    pub(super) restarted: bool,
    /// The tone curve and the exposure (which + and - change).
    pub(super) display: DisplayTransform,
    /// The kernel accumulates the denoiser's AOVs: from the first D on (turning them off again
    /// would compile another kernel and restart for nothing).
    pub(super) aovs: bool,
    pub(super) denoised: DenoisedView,
    /// Counts the accumulation's restarts, so a denoise of an older one is known as stale.
    pub(super) generation: u64,
    /// Why D cannot denoise, for the title, once it was pressed without OIDN.
    pub(super) denoise_note: Option<String>,
    /// Why I cannot switch to the other integrator, for the title, after a refused switch.
    pub(super) integrator_note: Option<String>,
    pub(super) sizer: BatchSizer,
    pub(super) input: InputState,
    pub(super) watch: FileWatch,
    /// Edits noticed by `watch` are read here, off the event loop.
    pub(super) loader: BackgroundLoad,
    pub(super) gpu: Option<Gpu>,
    pub(super) pending_size: Option<PhysicalSize<u32>>,
    pub(super) frame: u64,
    pub(super) started: Instant,
    pub(super) last_frame_start: Option<Instant>,
    /// Short note for the title while the scene file on disk is broken.
    pub(super) scene_error: Option<String>,
    pub(super) title: TitleStats,
    pub(super) result: Result<()>,
    pub(super) finished: bool,
}

/// The largest image of the window's aspect that the renderer accepts (the window may be
/// bigger than one accumulation buffer can hold; the display pass stretches it).
pub(super) fn fit_image_size(size: PhysicalSize<u32>) -> (u32, u32) {
    let (w, h) = (size.width.max(1) as u64, size.height.max(1) as u64);
    if w * h <= MAX_IMAGE_PIXELS {
        return (w as u32, h as u32);
    }
    let scale = (MAX_IMAGE_PIXELS as f64 / (w * h) as f64).sqrt();
    (
        ((w as f64 * scale) as u32).max(1),
        ((h as f64 * scale) as u32).max(1),
    )
}

/// `<stem>-NNN.<ext>` in the working directory, the first that does not exist yet.
pub(super) fn next_free_name(scene: &Path, ext: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "view".into());
    (1..)
        .map(|n| PathBuf::from(format!("{stem}-{n:03}.{ext}")))
        .find(|p| !p.exists())
        .expect("an unused name")
}

impl App {
    pub(super) fn log(&self, line: serde_json::Value) {
        if self.options.log_frames {
            crate::outln!("{line}");
        }
    }

    pub(super) fn image_size(&self) -> (u32, u32) {
        (self.scene.render.width, self.scene.render.height)
    }

    /// The kernel's parameters for the current camera, image size and AOVs.
    pub(super) fn params(&self) -> Params {
        let mut params = self.kernel.params;
        place_camera(&mut params, &self.camera);
        params.aovs = self.aovs as u32;
        params
    }

    /// The kernel's view of the current scene and camera.
    pub(super) fn kernel_scene(&self) -> KernelScene {
        KernelScene {
            params: self.params(),
            ..self.kernel.clone()
        }
    }

    pub(super) fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let (width, height) = self.image_size();
        let name = self.options.scene.display();
        let window = Arc::new(
            event_loop
                .create_window(
                    Window::default_attributes()
                        .with_title(format!("glint view · {name}"))
                        .with_inner_size(PhysicalSize::new(width, height)),
                )
                .context("cannot open a window")?,
        );
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        desc.flags = wgpu::InstanceFlags::empty().with_env();
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .context("cannot create a Vulkan surface for the window")?;
        let ctx = GpuContext::with_instance(&instance, Some(&surface))?;
        // The renderer borrows the context for its whole life, and the viewer keeps both until
        // the process ends: leaking the context is the simple way to own both in one struct.
        let ctx: &'static GpuContext = Box::leak(Box::new(ctx));
        let caps = surface.get_capabilities(&ctx.adapter);
        let format = pick_format(&caps.formats)
            .ok_or_else(|| anyhow!("{} cannot present to this window", ctx.device_name()))?;
        // Mailbox shows the newest frame without tearing and never blocks the sampling;
        // Fifo (vsync) is what every device offers.
        let present_mode = if caps.present_modes.contains(&wgpu::PresentMode::Mailbox) {
            wgpu::PresentMode::Mailbox
        } else {
            wgpu::PresentMode::Fifo
        };
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            desired_maximum_frame_latency: 2,
            present_mode,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or_default(),
            view_formats: vec![],
        };
        surface.configure(&ctx.device, &config);
        let kernel_scene = self.kernel_scene();
        let traversal = self.options.traversal.resolve(ctx)?;
        let renderer = GpuRenderer::with_traversal(ctx, &kernel_scene, traversal)?;
        let mut display = DisplayPass::new(&ctx.device, format);
        display.bind(
            &ctx.device,
            renderer.mean_buffer(),
            renderer.splat_film().map(|(film, _)| film),
        );
        crate::errln!(
            "glint view: {} on {} ({:?}, {:?}); drag to orbit, right-drag to pan, wheel to dolly, arrow keys and Q/E to fly, D to denoise, I to switch path/bdpt",
            self.options.scene.display(),
            ctx.device_name(),
            format,
            present_mode
        );
        self.gpu = Some(Gpu {
            window,
            instance,
            surface,
            config,
            ctx,
            renderer,
            display,
            denoised_buffer: None,
            showing_denoised: false,
        });
        // The window manager may not grant the size asked for; the image follows the window.
        self.pending_size = Some(size);
        Ok(())
    }

    /// A new renderer for the current scene, camera and size (its objects or size changed).
    pub(super) fn rebuild_renderer(&mut self) -> Result<()> {
        let kernel_scene = self.kernel_scene();
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        // The same traversal as before: the device has not changed.
        let traversal = gpu.renderer.traversal();
        gpu.renderer = GpuRenderer::with_traversal(gpu.ctx, &kernel_scene, traversal)?;
        bind_renderer(gpu);
        gpu.showing_denoised = false;
        self.camera_moved = false;
        self.restarted = true;
        Ok(())
    }

    /// `scene` and `kernel` rendered by `integrator`: the scene's own checks decide whether it
    /// can (bdpt renders no density grids and a bounded number of bounces).
    pub(super) fn with_integrator(
        scene: Scene,
        mut kernel: KernelScene,
        integrator: Integrator,
    ) -> Result<(Scene, KernelScene), String> {
        if scene.render.integrator == integrator {
            return Ok((scene, kernel));
        }
        let scene = scene.with_overrides(&RenderOverrides {
            integrator: Some(integrator),
            ..Default::default()
        })?;
        kernel.params.integrator = integrator.kernel_value();
        Ok((scene, kernel))
    }

    /// Writes the screenshot, if asked for, and ends the event loop; once.
    pub(super) fn finish(&mut self, event_loop: &ActiveEventLoop) {
        if self.finished {
            return;
        }
        self.finished = true;
        if let Some(path) = self.options.screenshot.clone() {
            if let Err(e) = self.save(&path) {
                self.fail(e, event_loop);
            }
        }
        event_loop.exit();
    }

    pub(super) fn fail(&mut self, e: anyhow::Error, event_loop: &ActiveEventLoop) {
        if self.result.is_ok() {
            self.result = Err(e);
        }
        self.finished = true;
        event_loop.exit();
    }
}

/// Samples/s and frame time over the last title interval.
pub(super) struct TitleStats {
    pub(super) since: Instant,
    pub(super) paths: u64,
    pub(super) frames: u32,
}

impl TitleStats {
    pub(super) fn new() -> TitleStats {
        TitleStats {
            since: Instant::now(),
            paths: 0,
            frames: 0,
        }
    }
}
