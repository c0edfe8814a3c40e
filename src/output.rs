//! Images: the running mean of a render, written as PNG (display) or EXR (linear radiance).
//! Every write is atomic: a temporary file in the same folder, then a rename.

use anyhow::{Context, Result};
use image::{ImageBuffer, Rgb, Rgb32FImage};
use std::path::Path;

/// Linear RGB radiance, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Clamped to [0, 1], sRGB-encoded, 8 bits.
    Png,
    /// Linear float32 RGB, unclamped.
    Exr,
}

impl ImageFormat {
    /// The format an output path asks for, by its extension.
    pub fn from_path(path: &Path) -> Result<ImageFormat, String> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("exr") => Ok(ImageFormat::Exr),
            _ => Err(format!(
                "{}: unknown image format; use a .png or .exr file name",
                path.display()
            )),
        }
    }
}

/// A path an image can be written to: a known format, in a folder that exists. Checked before
/// rendering, so a bad path fails at once instead of after the render.
pub fn check_output_path(path: &Path) -> Result<(), String> {
    ImageFormat::from_path(path)?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(format!(
                "{}: the output folder {} does not exist",
                path.display(),
                dir.display()
            ));
        }
    }
    Ok(())
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
    /// `shaders/accumulate.wgsl`).
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

    /// Writes the image atomically; the format comes from the extension.
    pub fn write(&self, path: &Path) -> Result<()> {
        let format = ImageFormat::from_path(path).map_err(anyhow::Error::msg)?;
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let mut builder = tempfile::Builder::new();
        builder.prefix(".glint-").suffix(".tmp");
        // tempfile's default is 0600; an image is an ordinary file (the umask still applies).
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
        let tmp = builder
            .tempfile_in(dir)
            .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
        let image_format = match format {
            ImageFormat::Png => image::ImageFormat::Png,
            ImageFormat::Exr => image::ImageFormat::OpenExr,
        };
        let result = match format {
            ImageFormat::Png => {
                ImageBuffer::<Rgb<u8>, _>::from_raw(self.width, self.height, self.to_srgb8())
                    .expect("pixel count matches the size")
                    .save_with_format(tmp.path(), image_format)
            }
            ImageFormat::Exr => {
                let data: Vec<f32> = self.pixels.iter().flatten().copied().collect();
                Rgb32FImage::from_raw(self.width, self.height, data)
                    .expect("pixel count matches the size")
                    .save_with_format(tmp.path(), image_format)
            }
        };
        result.with_context(|| format!("cannot encode {}", path.display()))?;
        tmp.persist(path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(())
    }

    /// Reads a linear EXR (as written by [`Image::write`]).
    pub fn read_exr(path: &Path) -> Result<Image> {
        let img = image::open(path)
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
