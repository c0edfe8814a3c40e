//! Images read from files, for environment maps and textures: decoded to linear RGB in f32,
//! rows top to bottom (the first texel is the image's top-left corner, as every format and
//! viewer stores it).
//!
//! Colour in 8- and 16-bit formats (PNG, JPEG) is sRGB-encoded by convention and is decoded
//! with the sRGB transfer function when the caller reads colour; data such as roughness is
//! stored linearly. Float formats (EXR, Radiance HDR) hold linear values and are never
//! decoded. Every compression the `exr` crate reads is accepted (all OpenEXR writes but
//! HTJ2K, LJ2K and ZSTD, which are refused by name); lossy ones (DWAA, DWAB, B44, PXR24)
//! leave small negative values near black, which are set to 0 and reported (see
//! [`ClampedNegatives`]).

use crate::exr_header;
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
    /// The alpha channel, one value per texel in the same order (linear: glTF's alpha is never
    /// sRGB-encoded), or empty when the file has none (every texel opaque).
    pub alpha: Vec<f32>,
    /// Negative values the file held, now 0.
    pub clamped: Option<ClampedNegatives>,
}

/// Negative values in a float image (EXR, HDR), set to 0 on load. Lossy EXR compression leaves
/// them near black (Blender's own `forest.exr`, DWAB, holds 784, down to −1.6·10⁻³, beside
/// texels up to 1010): noise, not light, so they are clamped with a warning, not refused. NaN and infinite values are
/// not clamped; the callers refuse them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClampedNegatives {
    /// Channel values clamped (up to 3 per texel).
    pub count: u64,
    pub most_negative: f32,
}

impl ClampedNegatives {
    /// One line for a warning, after the file's name.
    pub fn warning(&self) -> String {
        format!(
            "{} negative value{} (the most negative {:e}) set to 0; lossy EXR compression leaves \
             such values near black",
            self.count,
            if self.count == 1 { "" } else { "s" },
            self.most_negative
        )
    }
}

impl LinearImage {
    pub fn texel(&self, x: u32, y: u32) -> [f32; 3] {
        self.texels[(y * self.width + x) as usize]
    }

    /// Texel (x, y)'s alpha: 1 where the file has no alpha channel.
    pub fn alpha(&self, x: u32, y: u32) -> f32 {
        self.alpha
            .get((y * self.width + x) as usize)
            .copied()
            .unwrap_or(1.0)
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
    decode_linear_image(&bytes, encoding)
}

/// Decodes an image file's bytes (read by [`load_linear_image`], or embedded in a glTF file)
/// with the same checks; the error is a sentence, as there.
pub fn decode_linear_image(bytes: &[u8], encoding: Encoding) -> Result<LinearImage, String> {
    let reader = image::ImageReader::new(Cursor::new(bytes))
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
        .map_err(|e| decode_error(e, bytes, format))?;
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
    let mut reader = image::ImageReader::new(Cursor::new(bytes));
    reader.set_format(format);
    let decoded = reader
        .decode()
        .map_err(|e| decode_error(e, bytes, format))?;
    // Alpha is kept for alpha-tested and blended materials (src/cpu/geometry/alpha.rs); images without
    // it are converted without it, so they cost no more memory than before.
    let alpha = if decoded.color().has_alpha() {
        decoded.to_rgba32f().pixels().map(|p| p[3]).collect()
    } else {
        Vec::new()
    };
    let rgb = decoded.to_rgb32f();
    // to_rgb32f maps integer texels to [0, 1] linearly; the transfer function is ours to apply.
    let decode_srgb = encoding == Encoding::Srgb && !is_float_format(format);
    let mut texels: Vec<[f32; 3]> = rgb
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
    let clamped = clamp_negatives(&mut texels);
    Ok(LinearImage {
        width,
        height,
        texels,
        alpha,
        clamped,
    })
}

/// The decoder's error as a sentence. For an EXR whose compression the `exr` crate cannot read
/// (HTJ2K, ZSTD), it names the compression, which the crate's own message may not.
fn decode_error(e: image::ImageError, bytes: &[u8], format: image::ImageFormat) -> String {
    if format == image::ImageFormat::OpenExr {
        if let Some(compression) = exr_header::compression(bytes)
            .filter(|c| !exr_header::READABLE_COMPRESSIONS.contains(&c.as_str()))
        {
            return format!(
                "cannot decode the image: its EXR compression, {compression}, is not one glint \
                 reads ({})",
                exr_header::READABLE_COMPRESSIONS.join(", ")
            );
        }
    }
    format!("cannot decode the image: {e}")
}

/// Sets every finite negative value to 0 and says how many there were; −∞ and NaN stay.
fn clamp_negatives(texels: &mut [[f32; 3]]) -> Option<ClampedNegatives> {
    let mut count = 0u64;
    let mut most_negative = 0.0f32;
    for c in texels.iter_mut().flatten() {
        if *c < 0.0 && c.is_finite() {
            count += 1;
            most_negative = most_negative.min(*c);
            *c = 0.0;
        }
    }
    (count > 0).then_some(ClampedNegatives {
        count,
        most_negative,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finite_negatives_are_clamped_and_counted() {
        let mut texels = [[1.0, -4.5e-6, 0.0], [-1e-3, f32::NAN, f32::NEG_INFINITY]];
        let clamped = clamp_negatives(&mut texels).unwrap();
        assert_eq!(clamped.count, 2);
        assert_eq!(clamped.most_negative, -1e-3);
        assert_eq!(texels[0], [1.0, 0.0, 0.0]);
        assert_eq!(texels[1][0], 0.0);
        assert!(texels[1][1].is_nan() && texels[1][2] == f32::NEG_INFINITY);
        assert_eq!(clamp_negatives(&mut [[0.0, 1.0, 2.0]]), None);
    }

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
