//! One frame: due actions, a batch of samples, the display pass, and the title's statistics.

use super::state::*;
use super::surface::{present, show_denoised};
use crate::image::tonemap::Tonemap;
use crate::render::Renderer;
use crate::scene::{Integrator, RenderOverrides, MAX_SPP};
use crate::viewer::denoised::Snapshot;
use anyhow::{anyhow, Result};
use serde_json::json;
use std::time::Instant;
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;

impl App {
    pub(super) fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
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

    pub(super) fn update_title(&mut self, spp: u32) {
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
        if self.integrator != Integrator::Path {
            title += &format!(" · {}", self.integrator.name());
        }
        if self.denoised.is_on() {
            title += " · denoised";
            if let Some(shown) = self.denoised.shown() {
                title += &format!(" ({} spp)", shown.spp);
            }
        }
        for note in [&self.scene_error, &self.denoise_note, &self.integrator_note]
            .into_iter()
            .flatten()
        {
            title += &format!(" · {note}");
        }
        gpu.window.set_title(&title);
        self.log(json!({"event": "title", "title": title}));
        self.title = TitleStats::new();
    }

    /// Configures the surface for a new window size and, if the image size changes with it,
    /// restarts at the new size.
    pub(super) fn apply_resize(&mut self, size: PhysicalSize<u32>) -> Result<()> {
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
}
