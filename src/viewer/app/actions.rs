//! What the viewer does when asked: keys and scripted actions, reloads of the scene file, saving the image, denoising.

use super::state::*;
use super::surface::upload_denoised;
use crate::image::format::ImageFormat;
use crate::image::output::Image;
use crate::kernel::KernelScene;
use crate::render::Renderer;
use crate::scene::{Camera, Integrator, RenderOverrides, Scene};
use crate::viewer::action::Action;
use crate::viewer::camera_control;
use crate::viewer::denoised::{Snapshot, Update};
use crate::viewer::watch::{load_watched, Loaded};
use anyhow::{Context, Result};
use serde_json::json;
use std::path::Path;
use std::time::{Duration, Instant};
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;

impl App {
    /// The one place input, scripts and key presses take effect.
    pub(super) fn apply(&mut self, action: Action, event_loop: &ActiveEventLoop) -> Result<()> {
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
            Action::SwitchIntegrator => self.switch_integrator()?,
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
    pub(super) fn reload(&mut self) -> Result<()> {
        let loaded = load_watched(&self.options.scene, &self.options.model);
        self.apply_loaded(loaded)
    }

    /// Adopts a freshly read scene file; a broken file is reported and the last good scene
    /// stays.
    pub(super) fn apply_loaded(&mut self, (loaded, reads): Loaded) -> Result<()> {
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
                let (scene, kernel) = self.keep_integrator(scene, kernel);
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

    /// A reloaded scene, rendered by the integrator switched to unless the file's own changed;
    /// where the switched-to one cannot render the new scene (bdpt and a density grid), the
    /// file's.
    fn keep_integrator(&mut self, scene: Scene, kernel: KernelScene) -> (Scene, KernelScene) {
        let from_file = scene.render.integrator;
        if from_file != self.file_integrator {
            self.file_integrator = from_file;
            self.integrator = from_file;
            return (scene, kernel);
        }
        match App::with_integrator(scene.clone(), kernel.clone(), self.integrator) {
            Ok(switched) => switched,
            Err(e) => {
                self.refuse_integrator(self.integrator, &e);
                self.integrator = from_file;
                (scene, kernel)
            }
        }
    }

    /// Switches between path tracing and bidirectional path tracing (I), restarting the
    /// accumulation; a scene the other cannot render keeps its integrator, and says why.
    pub(super) fn switch_integrator(&mut self) -> Result<()> {
        let wanted = match self.integrator {
            Integrator::Path => Integrator::Bdpt,
            Integrator::Bdpt => Integrator::Path,
        };
        match App::with_integrator(self.scene.clone(), self.kernel.clone(), wanted) {
            Ok((scene, kernel)) => {
                self.scene = scene;
                self.kernel = kernel;
                self.integrator = wanted;
                self.integrator_note = None;
                self.rebuild_renderer()?;
                self.log(json!({"event": "integrator", "integrator": wanted.name(), "frame": self.frame}));
            }
            Err(e) => self.refuse_integrator(wanted, &e),
        }
        self.title.since -= TITLE_INTERVAL;
        Ok(())
    }

    fn refuse_integrator(&mut self, wanted: Integrator, why: &str) {
        crate::errln!("glint view: cannot switch to {}: {why}", wanted.name());
        self.integrator_note = Some(format!("no {}, see stderr", wanted.name()));
        self.log(json!({"event": "integrator", "integrator": self.integrator.name(), "frame": self.frame, "error": why}));
    }

    /// PNG: what is shown (the mean, or with D on the denoised image of all samples so far,
    /// through the tone curve, sRGB). EXR: the linear mean radiance, as `glint render` writes it.
    pub(super) fn save(&mut self, path: &Path) -> Result<()> {
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

    /// Turns denoising on or off (D); without OIDN, says why once and shows the raw image.
    pub(super) fn toggle_denoise(&mut self) -> Result<()> {
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
    pub(super) fn take_denoised(&mut self, update: Update) {
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
    pub(super) fn snapshot(&self) -> Snapshot {
        Snapshot {
            generation: self.generation,
            spp: self.gpu.as_ref().map_or(0, |g| g.renderer.samples()),
        }
    }
}
