//! The winit application: one window, one surface, one renderer. Every redraw is a frame:
//! due actions, a batch of samples, the display pass, the title.

use super::action::{Action, Script};
use super::camera_control;
use super::denoised::{DenoisedView, Snapshot, Update};
use super::display::DisplayPass;
use super::input::InputState;
use super::watch::{load_watched, BackgroundLoad, FileWatch, Loaded};
use super::{ViewOptions, FRAME_TARGET};
use crate::gpu::{GpuContext, GpuRenderer};
use crate::image::format::ImageFormat;
use crate::image::output::Image;
use crate::image::tonemap::{DisplayTransform, Tonemap};
use crate::input_file::FileRead;
use crate::kernel::types::Params;
use crate::kernel::{place_camera, KernelScene};
use crate::render::{BatchSizer, Renderer};
use crate::scene::{Camera, RenderOverrides, Scene, MAX_IMAGE_PIXELS, MAX_SPP};
use anyhow::{anyhow, Context, Result};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// How often the title's statistics are refreshed (every frame would flicker).
const TITLE_INTERVAL: Duration = Duration::from_millis(250);
/// Exposure range in stops; beyond it every pixel is black or white anyway.
const EXPOSURE_LIMIT: f32 = 20.0;
/// How long the test-only `wait-edit` action waits for the scene file to change.
const WAIT_FOR_EDIT_LIMIT: Duration = Duration::from_secs(60);

pub fn run(
    event_loop: EventLoop<()>,
    scene: Scene,
    kernel: KernelScene,
    reads: Vec<FileRead>,
    mut options: ViewOptions,
) -> Result<()> {
    // Progressive rendering never idles: the image refines while nothing happens.
    event_loop.set_control_flow(ControlFlow::Poll);
    let script = std::mem::take(&mut options.script);
    let display = options.display;
    let mut app = App {
        watch: {
            let mut watch = FileWatch::new(&options.scene);
            watch.adopt(reads, true);
            watch
        },
        loader: BackgroundLoad::new(&options.scene).with_model(options.model.clone()),
        sizer: BatchSizer::new(FRAME_TARGET),
        file_camera: scene.camera.clone(),
        camera: scene.camera.clone(),
        scene,
        kernel,
        options,
        script,
        camera_moved: false,
        restarted: true,
        display,
        aovs: false,
        denoised: DenoisedView::default(),
        generation: 0,
        denoise_note: None,
        input: InputState::default(),
        gpu: None,
        pending_size: None,
        frame: 0,
        started: Instant::now(),
        last_frame_start: None,
        scene_error: None,
        title: TitleStats::new(),
        result: Ok(()),
        finished: false,
    };
    event_loop.run_app(&mut app).context("window event loop")?;
    app.result
}

/// The window and everything that renders into it.
struct Gpu {
    window: Arc<Window>,
    instance: wgpu::Instance,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: &'static GpuContext,
    renderer: GpuRenderer<'static>,
    display: DisplayPass,
    /// The denoised image, uploaded for the display pass (per pixel vec4s).
    denoised_buffer: Option<wgpu::Buffer>,
    /// Whether the display pass reads `denoised_buffer` (else the renderer's mean).
    showing_denoised: bool,
}

struct App {
    options: ViewOptions,
    script: Script,
    /// The last scene that loaded, its image size set to the window's.
    scene: Scene,
    /// `scene` as the kernel reads it, with the camera the file gives (see [`App::params`]).
    kernel: KernelScene,
    /// The camera the scene file says; a reload adopts the file's camera only if it changed,
    /// so editing a material does not throw away where the user flew to.
    file_camera: Camera,
    camera: Camera,
    camera_moved: bool,
    /// The accumulation restarted: the next frame is a 1-spp preview.
    restarted: bool,
    /// The tone curve and the exposure (which + and - change).
    display: DisplayTransform,
    /// The kernel accumulates the denoiser's AOVs: from the first D on (turning them off again
    /// would compile another kernel and restart for nothing).
    aovs: bool,
    denoised: DenoisedView,
    /// Counts the accumulation's restarts, so a denoise of an older one is known as stale.
    generation: u64,
    /// Why D cannot denoise, for the title, once it was pressed without OIDN.
    denoise_note: Option<String>,
    sizer: BatchSizer,
    input: InputState,
    watch: FileWatch,
    /// Edits noticed by `watch` are read here, off the event loop.
    loader: BackgroundLoad,
    gpu: Option<Gpu>,
    pending_size: Option<PhysicalSize<u32>>,
    frame: u64,
    started: Instant,
    last_frame_start: Option<Instant>,
    /// Short note for the title while the scene file on disk is broken.
    scene_error: Option<String>,
    title: TitleStats,
    result: Result<()>,
    finished: bool,
}

/// Samples/s and frame time over the last title interval.
struct TitleStats {
    since: Instant,
    paths: u64,
    frames: u32,
}

impl TitleStats {
    fn new() -> TitleStats {
        TitleStats {
            since: Instant::now(),
            paths: 0,
            frames: 0,
        }
    }
}

/// The largest image of the window's aspect that the renderer accepts (the window may be
/// bigger than one accumulation buffer can hold; the display pass stretches it).
fn fit_image_size(size: PhysicalSize<u32>) -> (u32, u32) {
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
fn next_free_name(scene: &Path, ext: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "view".into());
    (1..)
        .map(|n| PathBuf::from(format!("{stem}-{n:03}.{ext}")))
        .find(|p| !p.exists())
        .expect("an unused name")
}

/// The surface format: 8-bit RGBA/BGRA, sRGB-encoding ones first (the hardware encodes).
fn pick_format(formats: &[wgpu::TextureFormat]) -> Option<wgpu::TextureFormat> {
    use wgpu::TextureFormat::*;
    [Bgra8UnormSrgb, Rgba8UnormSrgb, Bgra8Unorm, Rgba8Unorm]
        .into_iter()
        .find(|f| formats.contains(f))
        .or_else(|| formats.first().copied())
}

impl App {
    fn log(&self, line: serde_json::Value) {
        if self.options.log_frames {
            crate::outln!("{line}");
        }
    }

    fn image_size(&self) -> (u32, u32) {
        (self.scene.render.width, self.scene.render.height)
    }

    /// The kernel's parameters for the current camera, image size and AOVs.
    fn params(&self) -> Params {
        let mut params = self.kernel.params;
        place_camera(&mut params, &self.camera);
        params.aovs = self.aovs as u32;
        params
    }

    /// The kernel's view of the current scene and camera.
    fn kernel_scene(&self) -> KernelScene {
        KernelScene {
            params: self.params(),
            ..self.kernel.clone()
        }
    }

    /// Turns denoising on or off (D); without OIDN, says why once and shows the raw image.
    fn toggle_denoise(&mut self) -> Result<()> {
        match self.denoised.toggle() {
            Ok(on) => {
                if on && !self.aovs {
                    // The albedo and normal guides are accumulated from the start on.
                    self.aovs = true;
                    self.rebuild_renderer()?;
                }
                self.log(json!({"event": "denoise", "on": on, "frame": self.frame}));
            }
            Err(e) => {
                if self.denoise_note.is_none() {
                    crate::errln!("glint view: D shows the raw image: {e:#}");
                    self.denoise_note = Some("no denoiser, see stderr".into());
                }
                self.log(json!({"event": "denoise", "on": false, "frame": self.frame, "error": format!("{e:#}")}));
            }
        }
        self.title.since -= TITLE_INTERVAL;
        Ok(())
    }

    /// Shows a finished denoise, or notes why not.
    fn take_denoised(&mut self, update: Update) {
        match update {
            Update::Nothing => {}
            Update::Show(denoised) => {
                if let Some(gpu) = self.gpu.as_mut() {
                    upload_denoised(gpu, &denoised.image);
                }
                self.log(json!({
                    "event": "denoised",
                    "frame": self.frame,
                    "spp": denoised.snapshot.spp,
                    "seconds": denoised.seconds,
                }));
            }
            Update::Stale(snapshot) => self.log(
                json!({"event": "denoise-discarded", "frame": self.frame, "spp": snapshot.spp}),
            ),
            Update::Failed(e) => {
                crate::errln!("glint view: denoising failed, showing the raw image: {e:#}");
                self.denoise_note = Some("denoising failed, see stderr".into());
                self.log(json!({"event": "denoise", "on": false, "frame": self.frame, "error": format!("{e:#}")}));
                self.title.since -= TITLE_INTERVAL;
            }
        }
    }

    /// Which accumulation the renderer holds now.
    fn snapshot(&self) -> Snapshot {
        Snapshot {
            generation: self.generation,
            spp: self.gpu.as_ref().map_or(0, |g| g.renderer.samples()),
        }
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
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
        display.bind(&ctx.device, renderer.mean_buffer());
        crate::errln!(
            "glint view: {} on {} ({:?}, {:?}); drag to orbit, right-drag to pan, wheel to dolly, arrow keys and Q/E to fly, D to denoise",
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
    fn rebuild_renderer(&mut self) -> Result<()> {
        let kernel_scene = self.kernel_scene();
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        // The same traversal as before: the device has not changed.
        let traversal = gpu.renderer.traversal();
        gpu.renderer = GpuRenderer::with_traversal(gpu.ctx, &kernel_scene, traversal)?;
        gpu.display
            .bind(&gpu.ctx.device, gpu.renderer.mean_buffer());
        gpu.showing_denoised = false;
        self.camera_moved = false;
        self.restarted = true;
        Ok(())
    }

    /// The one place input, scripts and key presses take effect.
    fn apply(&mut self, action: Action, event_loop: &ActiveEventLoop) -> Result<()> {
        let moved = |app: &mut App, camera: Camera| {
            // A move that cannot be rendered (a degenerate basis) is ignored.
            if camera.eye.is_finite() && camera.target.is_finite() && camera.eye != camera.target {
                app.camera = camera;
                app.camera_moved = true;
            }
        };
        match action {
            Action::Orbit { dx, dy } => moved(self, camera_control::orbit(&self.camera, dx, dy)),
            Action::Pan { dx, dy } => {
                let height = self.image_size().1;
                moved(self, camera_control::pan(&self.camera, dx, dy, height))
            }
            Action::Dolly { steps } => moved(self, camera_control::dolly(&self.camera, steps)),
            Action::Fly { right, up, forward } => {
                moved(self, camera_control::fly(&self.camera, right, up, forward))
            }
            Action::Restart => {
                if let Some(gpu) = self.gpu.as_mut() {
                    gpu.renderer.reset()?;
                }
                self.restarted = true;
            }
            Action::Exposure { stops } => {
                self.display.exposure =
                    (self.display.exposure + stops).clamp(-EXPOSURE_LIMIT, EXPOSURE_LIMIT);
            }
            Action::Denoise => self.toggle_denoise()?,
            Action::WaitForDenoise => {
                let update = self.denoised.wait(self.snapshot(), WAIT_FOR_EDIT_LIMIT);
                self.take_denoised(update);
            }
            Action::SavePng => {
                let path = next_free_name(&self.options.scene, "png");
                self.save(&path)?;
            }
            Action::SaveExr => {
                let path = next_free_name(&self.options.scene, "exr");
                self.save(&path)?;
            }
            Action::Reload => self.reload()?,
            Action::Resize { width, height } => {
                if let Some(gpu) = &self.gpu {
                    // The window system answers with a Resized event, handled like a user's.
                    if let Some(size) = gpu
                        .window
                        .request_inner_size(PhysicalSize::new(width, height))
                    {
                        self.pending_size = Some(size);
                    }
                }
            }
            Action::WaitForEdit => {
                self.log(json!({"event": "waiting-for-edit", "frame": self.frame}));
                let deadline = Instant::now() + WAIT_FOR_EDIT_LIMIT;
                while Instant::now() < deadline {
                    if self.watch.changed(true) {
                        self.reload()?;
                        break;
                    }
                    std::thread::sleep(Duration::from_millis(10));
                }
            }
            Action::Quit => self.finish(event_loop),
        }
        Ok(())
    }

    /// Re-reads the scene file now (scripted reloads; edits go through [`BackgroundLoad`]).
    fn reload(&mut self) -> Result<()> {
        let loaded = load_watched(&self.options.scene, &self.options.model);
        self.apply_loaded(loaded)
    }

    /// Adopts a freshly read scene file; a broken file is reported and the last good scene
    /// stays.
    fn apply_loaded(&mut self, (loaded, reads): Loaded) -> Result<()> {
        self.watch.adopt(reads, loaded.is_ok());
        let (width, height) = self.image_size();
        let path = self.options.scene.clone();
        let loaded = match loaded {
            Ok(scene) => scene
                .with_overrides(&RenderOverrides {
                    width: Some(width),
                    height: Some(height),
                    ..Default::default()
                })
                .map_err(|m| format!("{}: {m}", path.display()))
                .and_then(|scene| {
                    let kernel = scene.try_kernel_scene().map_err(|e| e.to_string())?;
                    Ok((scene, kernel))
                })
                .map_err(|message| (message, String::new())),
            Err(e) => {
                let at = e
                    .position
                    .map(|(line, col)| format!(" at line {line}:{col}"))
                    .unwrap_or_default();
                Err((e.to_string(), at))
            }
        };
        match loaded {
            Err((message, at)) => {
                crate::errln!("glint: {message}; keeping the last good scene");
                self.log(
                    json!({"event": "reload", "ok": false, "frame": self.frame, "error": message}),
                );
                self.scene_error = Some(format!("scene error{at}, see stderr"));
                self.title.since -= TITLE_INTERVAL;
            }
            Ok((scene, kernel)) => {
                if scene.camera != self.file_camera {
                    self.file_camera = scene.camera.clone();
                    self.camera = scene.camera.clone();
                }
                self.scene = scene;
                self.kernel = kernel;
                self.rebuild_renderer()?;
                if self.scene_error.take().is_some() {
                    crate::errln!("glint: {} reloaded", path.display());
                }
                self.log(json!({"event": "reload", "ok": true, "frame": self.frame}));
                self.title.since -= TITLE_INTERVAL;
            }
        }
        Ok(())
    }

    /// PNG: what is shown (the mean, or with D on the denoised image of all samples so far,
    /// through the tone curve, sRGB). EXR: the linear mean radiance, as `glint render` writes it.
    fn save(&mut self, path: &Path) -> Result<()> {
        let current = self.snapshot();
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        let png = ImageFormat::from_path(path).map_err(anyhow::Error::msg)? == ImageFormat::Png;
        let image: Image = if png && self.denoised.is_on() {
            let denoised = self.denoised.denoise_now(&mut gpu.renderer, current)?;
            self.display.image(&denoised)
        } else if png {
            self.display.image(&gpu.renderer.read_mean()?)
        } else {
            gpu.renderer.read_mean()?
        };
        image
            .write(path)
            .with_context(|| format!("writing {}", path.display()))?;
        let spp = gpu.renderer.samples();
        crate::errln!("glint view: saved {} ({spp} spp)", path.display());
        self.log(json!({"event": "saved", "path": path.display().to_string(), "spp": spp}));
        Ok(())
    }

    /// Writes the screenshot, if asked for, and ends the event loop; once.
    fn finish(&mut self, event_loop: &ActiveEventLoop) {
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

    fn fail(&mut self, e: anyhow::Error, event_loop: &ActiveEventLoop) {
        if self.result.is_ok() {
            self.result = Err(e);
        }
        self.finished = true;
        event_loop.exit();
    }

    /// Configures the surface for a new window size and, if the image size changes with it,
    /// restarts at the new size.
    fn apply_resize(&mut self, size: PhysicalSize<u32>) -> Result<()> {
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        gpu.config.width = size.width;
        gpu.config.height = size.height;
        gpu.surface.configure(&gpu.ctx.device, &gpu.config);
        let (width, height) = fit_image_size(size);
        if (width, height) == self.image_size() {
            return Ok(());
        }
        self.scene = self
            .scene
            .clone()
            .with_overrides(&RenderOverrides {
                width: Some(width),
                height: Some(height),
                ..Default::default()
            })
            .map_err(|m| anyhow!("cannot render at {width}×{height}: {m}"))?;
        // Only the image size changed: the camera's parameters follow it in params().
        self.kernel.params.width = width;
        self.kernel.params.height = height;
        self.rebuild_renderer()?;
        self.log(json!({"event": "resize", "width": width, "height": height, "frame": self.frame}));
        Ok(())
    }

    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let start = Instant::now();
        let dt = self.last_frame_start.map(|t| start - t).unwrap_or_default();
        for action in self.script.take(self.frame) {
            self.apply(action, event_loop)?;
        }
        if let Some(action) = self.input.fly_step(dt) {
            self.apply(action, event_loop)?;
        }
        if self.watch.changed(false) {
            self.loader.request();
        }
        if let Some(loaded) = self.loader.poll() {
            self.apply_loaded(loaded)?;
        }
        if self.finished {
            return Ok(());
        }
        if let Some(size) = self.pending_size {
            if size.width == 0 || size.height == 0 {
                // Minimised: nothing to show, and the surface cannot have a zero size.
                return Ok(());
            }
            self.pending_size = None;
            self.apply_resize(size)?;
        }
        let moved_params = std::mem::take(&mut self.camera_moved).then(|| self.params());
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        if let Some(params) = moved_params {
            gpu.renderer.set_params(params)?;
            self.restarted = true;
        }
        // Right after a restart, show something at once, whatever the batch size.
        let preview = std::mem::take(&mut self.restarted);
        if preview {
            self.generation += 1;
        }
        let wanted = if preview {
            1
        } else {
            self.options
                .spp_per_frame
                .unwrap_or(self.sizer.spp_per_batch)
        };
        let spp = wanted.min(MAX_SPP - gpu.renderer.samples());
        let batch_start = Instant::now();
        if spp > 0 {
            gpu.renderer.add_samples(spp)?;
        }
        let batch_time = batch_start.elapsed();
        // A preview's single sample says little about the sustained rate.
        if !preview && spp > 0 && self.options.spp_per_frame.is_none() {
            self.sizer.update(spp, batch_time);
        }
        let current = Snapshot {
            generation: self.generation,
            spp: gpu.renderer.samples(),
        };
        let update = self.denoised.update(&mut gpu.renderer, current)?;
        self.take_denoised(update);
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        let denoised = self.denoised.shown().is_some();
        show_denoised(gpu, denoised);
        let image_size = (self.scene.render.width, self.scene.render.height);
        present(gpu, image_size, &self.display)?;
        let total_spp = gpu.renderer.samples();
        let frame_time = start.elapsed();
        let paths = spp as u64 * image_size.0 as u64 * image_size.1 as u64;
        self.log(json!({
            "frame": self.frame,
            "t": self.started.elapsed().as_secs_f64(),
            "spp": total_spp,
            "batch_spp": spp,
            "batch_ms": batch_time.as_secs_f64() * 1e3,
            "frame_ms": frame_time.as_secs_f64() * 1e3,
            "width": image_size.0,
            "height": image_size.1,
            "restarted": preview,
            "denoised": denoised,
        }));
        self.title.paths += paths;
        self.title.frames += 1;
        self.update_title(total_spp);
        self.last_frame_start = Some(start);
        self.frame += 1;
        if self.options.frames.is_some_and(|n| self.frame >= n) {
            self.finish(event_loop);
        }
        Ok(())
    }

    fn update_title(&mut self, spp: u32) {
        let elapsed = self.title.since.elapsed();
        let Some(gpu) = &self.gpu else { return };
        if elapsed < TITLE_INTERVAL || self.title.frames == 0 {
            return;
        }
        let secs = elapsed.as_secs_f64();
        let mut title = format!(
            "glint view · {} · {spp} spp · {:.2} M samples/s · {:.0} ms · exposure {:+.1}",
            self.options
                .scene
                .file_name()
                .map(|n| n.to_string_lossy())
                .unwrap_or_default(),
            self.title.paths as f64 / secs / 1e6,
            secs * 1e3 / self.title.frames as f64,
            self.display.exposure
        );
        if self.display.tonemap != Tonemap::Clamp {
            title += &format!(" · {:?}", self.display.tonemap).to_lowercase();
        }
        if self.denoised.is_on() {
            title += " · denoised";
            if let Some(shown) = self.denoised.shown() {
                title += &format!(" ({} spp)", shown.spp);
            }
        }
        for note in [&self.scene_error, &self.denoise_note]
            .into_iter()
            .flatten()
        {
            title += &format!(" · {note}");
        }
        gpu.window.set_title(&title);
        self.log(json!({"event": "title", "title": title}));
        self.title = TitleStats::new();
    }
}

/// Binds the denoised image to the display pass, or the mean, when that changes.
fn show_denoised(gpu: &mut Gpu, denoised: bool) {
    if denoised == gpu.showing_denoised {
        return;
    }
    let buffer = match (&gpu.denoised_buffer, denoised) {
        (Some(buffer), true) => buffer,
        _ => gpu.renderer.mean_buffer(),
    };
    gpu.display.bind(&gpu.ctx.device, buffer);
    gpu.showing_denoised = denoised && gpu.denoised_buffer.is_some();
}

/// Copies a denoised image to the GPU for the display pass.
fn upload_denoised(gpu: &mut Gpu, image: &Image) {
    let vec4s: Vec<[f32; 4]> = image
        .pixels
        .iter()
        .map(|p| [p[0], p[1], p[2], 0.0])
        .collect();
    let size = size_of_val(vec4s.as_slice()) as u64;
    if gpu
        .denoised_buffer
        .as_ref()
        .is_none_or(|b| b.size() != size)
    {
        gpu.denoised_buffer = Some(gpu.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("denoised"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
        // A new buffer must be bound anew.
        gpu.showing_denoised = false;
    }
    if let Some(buffer) = &gpu.denoised_buffer {
        gpu.ctx
            .queue
            .write_buffer(buffer, 0, bytemuck::cast_slice(&vec4s));
    }
}

/// Shows the bound image on the window; a frame the surface cannot take now is skipped.
fn present(gpu: &mut Gpu, image_size: (u32, u32), display: &DisplayTransform) -> Result<()> {
    let texture = match gpu.surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(t) => t,
        wgpu::CurrentSurfaceTexture::Suboptimal(t) => {
            // Show this one; configure anew before the next.
            draw(gpu, t, image_size, display);
            gpu.surface.configure(&gpu.ctx.device, &gpu.config);
            return Ok(());
        }
        wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
            return Ok(())
        }
        wgpu::CurrentSurfaceTexture::Outdated => {
            gpu.surface.configure(&gpu.ctx.device, &gpu.config);
            return Ok(());
        }
        wgpu::CurrentSurfaceTexture::Lost => {
            gpu.surface = gpu
                .instance
                .create_surface(gpu.window.clone())
                .context("cannot recreate the lost window surface")?;
            gpu.surface.configure(&gpu.ctx.device, &gpu.config);
            return Ok(());
        }
        wgpu::CurrentSurfaceTexture::Validation => {
            let error = gpu.ctx.take_error().unwrap_or_default();
            return Err(anyhow!("cannot get the window's next image: {error}"));
        }
    };
    draw(gpu, texture, image_size, display);
    Ok(())
}

fn draw(
    gpu: &Gpu,
    texture: wgpu::SurfaceTexture,
    image_size: (u32, u32),
    display: &DisplayTransform,
) {
    let view = texture.texture.create_view(&Default::default());
    let mut encoder = gpu.ctx.device.create_command_encoder(&Default::default());
    gpu.display.draw(
        &gpu.ctx.queue,
        &mut encoder,
        &view,
        image_size,
        (gpu.config.width, gpu.config.height),
        display,
    );
    gpu.ctx.queue.submit([encoder.finish()]);
    gpu.window.pre_present_notify();
    gpu.ctx.queue.present(texture);
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_some() || self.finished {
            return;
        }
        if let Err(e) = self.open(event_loop) {
            self.fail(e, event_loop);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let action = match event {
            WindowEvent::CloseRequested => Some(Action::Quit),
            WindowEvent::Resized(size) => {
                self.pending_size = Some(size);
                None
            }
            WindowEvent::RedrawRequested => {
                if !self.finished {
                    if let Err(e) = self.frame(event_loop) {
                        self.fail(e, event_loop);
                    }
                }
                None
            }
            WindowEvent::Focused(false) => {
                self.input.focus_lost();
                None
            }
            WindowEvent::KeyboardInput { event, .. } => self.input.key(
                event.physical_key,
                &event.logical_key,
                event.state,
                event.repeat,
            ),
            WindowEvent::MouseInput { state, button, .. } => {
                self.input.mouse_button(button, state);
                None
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.input.cursor_moved(position.x, position.y)
            }
            WindowEvent::CursorLeft { .. } => {
                self.input.cursor_left();
                None
            }
            WindowEvent::MouseWheel { delta, .. } => self.input.wheel(delta),
            _ => None,
        };
        if let Some(action) = action {
            if let Err(e) = self.apply(action, event_loop) {
                self.fail(e, event_loop);
            }
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(gpu) = &self.gpu {
            if !self.finished {
                gpu.window.request_redraw();
            }
        }
    }
}
