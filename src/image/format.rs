//! Which image format a file name asks for.

use std::path::Path;

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
