//! The window's surface and the display pass: presenting the running mean or the denoised image.

use crate::gpu::{GpuContext, GpuRenderer};
use crate::image::output::Image;
use crate::image::tonemap::DisplayTransform;
use crate::render::Renderer;
use crate::viewer::display::DisplayPass;
use anyhow::{anyhow, Context, Result};
use std::sync::Arc;
use winit::window::Window;

/// The window and everything that renders into it.
pub(super) struct Gpu {
    pub(super) window: Arc<Window>,
    pub(super) instance: wgpu::Instance,
    pub(super) surface: wgpu::Surface<'static>,
    pub(super) config: wgpu::SurfaceConfiguration,
    pub(super) ctx: &'static GpuContext,
    pub(super) renderer: GpuRenderer<'static>,
    pub(super) display: DisplayPass,
    /// The denoised image, uploaded for the display pass (per pixel vec4s).
    pub(super) denoised_buffer: Option<wgpu::Buffer>,
    /// Whether the display pass reads `denoised_buffer` (else the renderer's mean).
    pub(super) showing_denoised: bool,
}

/// The surface format: 8-bit RGBA/BGRA, sRGB-encoding ones first (the hardware encodes).
pub(super) fn pick_format(formats: &[wgpu::TextureFormat]) -> Option<wgpu::TextureFormat> {
    use wgpu::TextureFormat::*;
    [Bgra8UnormSrgb, Rgba8UnormSrgb, Bgra8Unorm, Rgba8Unorm]
        .into_iter()
        .find(|f| formats.contains(f))
        .or_else(|| formats.first().copied())
}

/// Binds the denoised image to the display pass, or the mean, when that changes.
pub(super) fn show_denoised(gpu: &mut Gpu, denoised: bool) {
    if denoised == gpu.showing_denoised {
        return;
    }
    match (&gpu.denoised_buffer, denoised) {
        (Some(buffer), true) => gpu.display.bind(&gpu.ctx.device, buffer, None),
        _ => bind_renderer(gpu),
    }
    gpu.showing_denoised = denoised && gpu.denoised_buffer.is_some();
}

/// Binds the renderer's running mean, and its splat film if it has one, to the display pass.
pub(super) fn bind_renderer(gpu: &mut Gpu) {
    let splats = gpu.renderer.splat_film().map(|(film, _)| film);
    gpu.display
        .bind(&gpu.ctx.device, gpu.renderer.mean_buffer(), splats);
}

/// What one unit of the shown splat film adds to the mean (0 when none is shown): the sums
/// over the splat scale and the samples per pixel, as `Accumulation::mean_image` adds them.
fn splat_weight(gpu: &Gpu) -> f32 {
    match gpu.renderer.splat_film() {
        Some((_, scale)) if !gpu.showing_denoised && gpu.renderer.samples() > 0 => {
            (1.0 / (scale as f64 * gpu.renderer.samples() as f64)) as f32
        }
        _ => 0.0,
    }
}

/// Copies a denoised image to the GPU for the display pass.
pub(super) fn upload_denoised(gpu: &mut Gpu, image: &Image) {
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
pub(super) fn present(
    gpu: &mut Gpu,
    image_size: (u32, u32),
    display: &DisplayTransform,
) -> Result<()> {
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

pub(super) fn draw(
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
        splat_weight(gpu),
    );
    gpu.ctx.queue.submit([encoder.finish()]);
    gpu.window.pre_present_notify();
    gpu.ctx.queue.present(texture);
}
