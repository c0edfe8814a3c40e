//! The scene's textures on the host: images read once per file (the same file used twice is
//! loaded once), checked, and laid out as the kernel reads them (`shaders/texture.wgsl`): one
//! descriptor per texture and every image's texels in one array, bottom row first, so texture
//! coordinates (v up) index rows directly.

use super::image::{load_linear_image, Encoding};
use crate::shader_types::{Texture, TEXTURE_CHECKER, TEXTURE_IMAGE};
use glam::Vec3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Most texels of all textures together: the descriptors index them with a u32.
pub const MAX_TOTAL_TEXELS: u64 = u32::MAX as u64;

/// What a texture is read for, which decides its decoding and the range its texels must lie in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureUse {
    /// A reflectance: sRGB-decoded (PNG, JPEG), every channel in [0, 1].
    Color,
    /// Metal roughness: linear (not sRGB-decoded), the first channel in [0, 1].
    Roughness,
}

/// Every texture of a scene, as the kernel reads them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TextureSet {
    pub descriptors: Vec<Texture>,
    /// Linear RGB (w unused), image after image, each bottom row first.
    pub texels: Vec<[f32; 4]>,
    /// Images already loaded, by canonical path and use.
    loaded: HashMap<(PathBuf, TextureUse), u32>,
    /// Warning lines from loading (negative texels clamped), each naming its file; the scene
    /// takes them when it is validated.
    pub warnings: Vec<String>,
}

impl TextureSet {
    pub fn is_empty(&self) -> bool {
        self.descriptors.is_empty()
    }

    /// The texture of the image at `path`, loaded (and checked) the first time it is asked for.
    /// The error is a sentence without the path, for the caller to place.
    pub fn image(&mut self, path: &Path, usage: TextureUse) -> Result<u32, String> {
        let key = (
            path.canonicalize().unwrap_or_else(|_| path.to_owned()),
            usage,
        );
        if let Some(&index) = self.loaded.get(&key) {
            return Ok(index);
        }
        let encoding = match usage {
            TextureUse::Color => Encoding::Srgb,
            TextureUse::Roughness => Encoding::Linear,
        };
        let image = load_linear_image(path, encoding)?;
        if let Some(clamped) = image.clamped {
            self.warnings
                .push(format!("{}: {}", path.display(), clamped.warning()));
        }
        let channels = match usage {
            TextureUse::Color => 3,
            TextureUse::Roughness => 1,
        };
        // Rows from the top (as files store them) to rows from the bottom.
        for y in 0..image.height {
            for x in 0..image.width {
                let texel = image.texel(x, image.height - 1 - y);
                if let Some(&bad) = texel[..channels].iter().find(|c| !(0.0..=1.0).contains(*c)) {
                    return Err(format!(
                        "texel ({x}, {}) (from the top left) is {bad}; a {} texture's values must \
                         be in [0, 1]",
                        image.height - 1 - y,
                        match usage {
                            TextureUse::Color => "color",
                            TextureUse::Roughness => "roughness",
                        }
                    ));
                }
            }
        }
        let first_texel = self.texels.len() as u64;
        let count = image.width as u64 * image.height as u64;
        if first_texel + count > MAX_TOTAL_TEXELS {
            return Err(format!(
                "the scene's textures hold more than {MAX_TOTAL_TEXELS} texels together"
            ));
        }
        self.texels.reserve(count as usize);
        for y in (0..image.height).rev() {
            for x in 0..image.width {
                let [r, g, b] = image.texel(x, y);
                self.texels.push([r, g, b, 0.0]);
            }
        }
        let index = self.push(Texture {
            kind: TEXTURE_IMAGE,
            first_texel: first_texel as u32,
            width: image.width,
            height: image.height,
            ..Default::default()
        });
        self.loaded.insert(key, index);
        Ok(index)
    }

    /// A checker of `colors[0]` (the square at the origin) and `colors[1]`, with `scale`
    /// squares per unit of u and of v.
    pub fn checker(&mut self, colors: [Vec3; 2], scale: f32) -> u32 {
        self.push(Texture {
            kind: TEXTURE_CHECKER,
            color0: colors[0].into(),
            scale,
            color1: colors[1].into(),
            ..Default::default()
        })
    }

    fn push(&mut self, texture: Texture) -> u32 {
        self.descriptors.push(texture);
        self.descriptors.len() as u32 - 1
    }
}
