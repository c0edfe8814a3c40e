//! Images read from files, for environment maps and textures: decoded to linear RGB in f32,
//! rows top to bottom (the first texel is the image's top-left corner, as every format and
//! viewer stores it).
//!
//! Colour in 8- and 16-bit formats (PNG, JPEG) is sRGB-encoded by convention and is decoded
//! with the sRGB transfer function when the caller reads colour; data such as roughness is
//! stored linearly. Float formats (EXR, Radiance HDR) hold linear values and are never
//! decoded.

use crate::input_file::{format_size, read_regular_file, IMAGE_FILE_LIMIT};
use std::io::Cursor;
use std::path::Path;

/// Most texels one image may hold: 2²⁴ (a 4096×4096 texture, or an 8192×2048 sky), so the
/// decoder's buffers stay within memory. The device's own limit is checked later, with the
/// texel buffer's size (`gpu::limits`).
pub const MAX_IMAGE_TEXELS: u64 = 1 << 24;

/// How integer texels encode their values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Colour: 8/16-bit texels are sRGB-encoded.
    Srgb,
    /// Data (roughness): 8/16-bit texels are linear in [0, 1].
    Linear,
}

/// A decoded image: linear RGB, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 3]>,
}

impl LinearImage {
    pub fn texel(&self, x: u32, y: u32) -> [f32; 3] {
        self.texels[(y * self.width + x) as usize]
    }
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1), from an encoded value in [0, 1]
/// to linear.
pub fn srgb_to_linear(encoded: f32) -> f32 {
    if encoded <= 0.04045 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// Whether the format stores linear floats (EXR, HDR) rather than encoded integers.
fn is_float_format(format: image::ImageFormat) -> bool {
    matches!(
        format,
        image::ImageFormat::OpenExr | image::ImageFormat::Hdr
    )
}

/// Reads and decodes `path` (PNG, JPEG, EXR or Radiance HDR, told apart by content). The
/// error is a sentence without the path, for the caller to place: "cannot decode the image:
/// …", "the image is 0×0", "the image has 2²⁶ texels; the limit is …".
pub fn load_linear_image(path: &Path, encoding: Encoding) -> Result<LinearImage, String> {
    let bytes = read_regular_file(path, IMAGE_FILE_LIMIT, "image file")?;
    let reader = image::ImageReader::new(Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot read the image: {e}"))?;
    let Some(format) = reader.format() else {
        return Err("not a PNG, JPEG, EXR or Radiance HDR image".to_string());
    };
    if !matches!(
        format,
        image::ImageFormat::Png
            | image::ImageFormat::Jpeg
            | image::ImageFormat::OpenExr
            | image::ImageFormat::Hdr
    ) {
        return Err(format!(
            "a {format:?} image; glint reads PNG, JPEG, EXR and Radiance HDR"
        ));
    }
    let (width, height) = reader
        .into_dimensions()
        .map_err(|e| format!("cannot decode the image: {e}"))?;
    if width == 0 || height == 0 {
        return Err(format!(
            "the image is {width}×{height}; it must have texels"
        ));
    }
    let texel_count = width as u64 * height as u64;
    if texel_count > MAX_IMAGE_TEXELS {
        return Err(format!(
            "the image is {width}×{height} ({texel_count} texels); the limit is {MAX_IMAGE_TEXELS} \
             texels ({} of RGB floats)",
            format_size(MAX_IMAGE_TEXELS * 12)
        ));
    }
    let mut reader = image::ImageReader::new(Cursor::new(&bytes));
    reader.set_format(format);
    let decoded = reader
        .decode()
        .map_err(|e| format!("cannot decode the image: {e}"))?;
    let rgb = decoded.to_rgb32f();
    // to_rgb32f maps integer texels to [0, 1] linearly; the transfer function is ours to apply.
    let decode_srgb = encoding == Encoding::Srgb && !is_float_format(format);
    let texels = rgb
        .pixels()
        .map(|p| {
            if decode_srgb {
                [
                    srgb_to_linear(p[0]),
                    srgb_to_linear(p[1]),
                    srgb_to_linear(p[2]),
                ]
            } else {
                [p[0], p[1], p[2]]
            }
        })
        .collect();
    Ok(LinearImage {
        width,
        height,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_decoding_matches_the_standard_at_known_points() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // 0.5 encoded is 0.2140 linear (IEC 61966-2-1).
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        // The linear segment below the knee.
        assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-9);
    }
}
