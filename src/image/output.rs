//! Images: the running mean of a render, written as PNG (display) or EXR (linear radiance).
//! Every write is atomic: a temporary file in the same folder, then a rename.

use crate::image::atomic_write::write_atomically;
use crate::image::format::ImageFormat;
use crate::input_file::{read_regular_file, IMAGE_FILE_LIMIT};
use anyhow::{Context, Result};
use image::{ImageBuffer, ImageResult, Rgb, Rgb32FImage};
use std::io::{Seek, Write};
use std::path::Path;

/// Linear RGB radiance, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

/// A path an image can be written to: a known format, in a folder where files can be created.
/// Checked before rendering, so a bad path fails at once instead of after the render. A
/// command with more than one file should use [`crate::image::output_check::OutputSet`], which also
/// refuses outputs that are the same file or one of the inputs.
pub fn check_output_path(path: &Path) -> Result<(), String> {
    crate::image::output_check::OutputSet::new()
        .image("output", path)
        .check()
        .map_err(|e| e.0)
}

/// The sRGB transfer function of a linear value in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.0031308 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// How a pixel with a NaN channel shows in a PNG: magenta.
pub const NAN_PIXEL: [u8; 3] = [255, 0, 255];

/// A display byte: clamped to [0, 1], sRGB-encoded, rounded. NaN shows as black here; whole
/// images mark NaN pixels with [`NAN_PIXEL`] instead ([`Image::to_srgb8`]).
pub fn srgb_byte(linear: f32) -> u8 {
    let clamped = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    (srgb_encode(clamped) * 255.0).round() as u8
}

impl Image {
    /// Display bytes; a pixel with a NaN channel shows as magenta, never as black, so that a
    /// broken pixel cannot pass for a dark one (renders never produce NaN: see
    /// `shaders/integrator/accumulate.wgsl`).
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| {
                if p.iter().any(|c| c.is_nan()) {
                    NAN_PIXEL
                } else {
                    p.map(srgb_byte)
                }
            })
            .collect()
    }

    /// Writes the image atomically (see [`crate::image::atomic_write`]); the format comes from the
    /// extension.
    pub fn write(&self, path: &Path) -> Result<()> {
        let format = ImageFormat::from_path(path).map_err(anyhow::Error::msg)?;
        write_atomically(path, |w| self.encode(format, w))
    }

    /// Encodes the image as `format` into `w`.
    pub fn encode<W: Write + Seek>(&self, format: ImageFormat, w: &mut W) -> ImageResult<()> {
        match format {
            ImageFormat::Png => {
                ImageBuffer::<Rgb<u8>, _>::from_raw(self.width, self.height, self.to_srgb8())
                    .expect("pixel count matches the size")
                    .write_to(w, image::ImageFormat::Png)
            }
            ImageFormat::Exr => {
                let data: Vec<f32> = self.pixels.iter().flatten().copied().collect();
                Rgb32FImage::from_raw(self.width, self.height, data)
                    .expect("pixel count matches the size")
                    .write_to(w, image::ImageFormat::OpenExr)
            }
        }
    }

    /// Reads a linear EXR (as written by [`Image::write`]). Anything else is refused, whatever
    /// its name: a PNG holds clamped sRGB bytes, and reading it as radiance would compare
    /// different quantities. Only a regular file up to [`IMAGE_FILE_LIMIT`] is read.
    pub fn read_exr(path: &Path) -> Result<Image> {
        let bytes = read_regular_file(path, IMAGE_FILE_LIMIT, "image file")
            .map_err(|m| anyhow::anyhow!("{}: {m}", path.display()))?;
        let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .with_context(|| format!("cannot read {}", path.display()))?;
        match reader.format() {
            Some(image::ImageFormat::OpenExr) => {}
            other => {
                let kind = other.map_or("not an image glint knows".to_string(), |f| {
                    format!("a {f:?} image")
                });
                return Err(anyhow::anyhow!(
                    "{}: {kind}, not an OpenEXR file; compare needs linear .exr renders (render -o FILE.exr), since a PNG is clamped and sRGB-encoded",
                    path.display()
                ));
            }
        }
        let img = reader
            .decode()
            .with_context(|| format!("cannot read {}", path.display()))?
            .into_rgb32f();
        Ok(Image {
            width: img.width(),
            height: img.height(),
            pixels: img.pixels().map(|p| p.0).collect(),
        })
    }

    /// Mean of every channel of every pixel.
    pub fn mean(&self) -> f64 {
        let sum: f64 = self.pixels.iter().flatten().map(|&v| v as f64).sum();
        sum / (self.pixels.len() * 3).max(1) as f64
    }
}
