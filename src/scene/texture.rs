//! The scene's textures on the host: images read once per file (the same file used twice is
//! loaded once), checked, and laid out as the kernel reads them (`shaders/textures/texture.wgsl`): one
//! descriptor per texture and every image's texels in one array, bottom row first, so texture
//! coordinates (v up) index rows directly.

use super::image::{decode_linear_image, load_linear_image, Encoding, LinearImage};
use crate::kernel::types::{
    Texture, TEXTURE_CHECKER, TEXTURE_IMAGE, TEXTURE_NEAREST, TEXTURE_WRAP_REPEAT,
};
use glam::Vec3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Most texels of all textures together: the descriptors index them with a u32.
pub const MAX_TOTAL_TEXELS: u64 = u32::MAX as u64;

/// How a glTF texture reference reads its image: its sampler's wrap modes (`TEXTURE_WRAP_*`,
/// for u and v) and filter, KHR_texture_transform's affine map of (u, v, 1), in glint's
/// texture coordinates (v up), and the texture coordinate set it reads (0, or 1 for glTF's
/// TEXCOORD_1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    pub wrap: [u32; 2],
    pub nearest: bool,
    pub transform: [[f32; 3]; 2],
    pub uv_set: u32,
}

impl Default for Sampling {
    /// Repeat, bilinear, untransformed: what TOML textures use.
    fn default() -> Self {
        Sampling {
            wrap: [TEXTURE_WRAP_REPEAT; 2],
            nearest: false,
            transform: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            uv_set: 0,
        }
    }
}

/// What a texture is read for, which decides its decoding and the range its texels must lie in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureUse {
    /// A reflectance: sRGB-decoded (PNG, JPEG), every channel in [0, 1].
    Color,
    /// Roughness (metal, pbr): linear (not sRGB-decoded), the first channel in [0, 1].
    Roughness,
    /// glTF's metallicRoughnessTexture: linear, roughness in green and metallic in blue, both
    /// in [0, 1].
    MetallicRoughness,
    /// A tangent-space normal map (glTF's normalTexture): linear, every channel in [0, 1].
    Normal,
    /// glTF's transmissionTexture: linear, the first (red) channel in [0, 1].
    Transmission,
    /// OBJ's separate `map_Pr` and `map_Pm` images merged into one on load
    /// ([`TextureSet::roughness_and_metallic`]): roughness in red, metallic in green.
    RoughnessAndMetallic,
    /// glTF's sheenRoughnessTexture: linear, the roughness in its alpha channel (1 where the
    /// file has none) in [0, 1], moved to the first channel as the kernel reads it.
    SheenRoughness,
}

/// Every texture of a scene, as the kernel reads them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TextureSet {
    pub descriptors: Vec<Texture>,
    /// Linear RGB, image after image, each bottom row first; w is a colour texture's alpha
    /// (unused in the others).
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
        let image = load_linear_image(path, encoding(usage))?;
        self.add(key, &path.display().to_string(), image, usage)
    }

    /// One texture from OBJ's separate roughness (`map_Pr`) and metallic (`map_Pm`) images, as
    /// the kernel reads a roughness texture: x the roughness (each image's first channel), y
    /// the metallic factor, 1 where an image is absent. The metallic image is resampled
    /// (nearest) to the roughness image's size where they differ. The error names the image.
    pub fn roughness_and_metallic(
        &mut self,
        roughness: Option<&Path>,
        metallic: Option<&Path>,
    ) -> Result<u32, String> {
        let canonical = |p: Option<&Path>| {
            p.map(|p| p.canonicalize().unwrap_or_else(|_| p.to_owned()))
                .map_or(String::new(), |p| p.display().to_string())
        };
        // A key no file path has: both paths after a '#'.
        let key = (
            PathBuf::from(format!(
                "#roughness={}#metallic={}",
                canonical(roughness),
                canonical(metallic)
            )),
            TextureUse::RoughnessAndMetallic,
        );
        if let Some(&index) = self.loaded.get(&key) {
            return Ok(index);
        }
        let load = |p: Option<&Path>| {
            p.map(|p| {
                load_linear_image(p, Encoding::Linear)
                    .map_err(|e| format!("texture {}: {e}", p.display()))
            })
            .transpose()
        };
        let (roughness_image, metallic_image) = (load(roughness)?, load(metallic)?);
        let (width, height) = match (&roughness_image, &metallic_image) {
            (Some(i), _) | (None, Some(i)) => (i.width, i.height),
            (None, None) => return Err("no roughness or metallic image".into()),
        };
        let first_channel = |image: &Option<LinearImage>, x: u32, y: u32| {
            image.as_ref().map_or(1.0, |i| {
                // Nearest texel of an image of another size.
                let xi = (u64::from(x) * u64::from(i.width) / u64::from(width)) as u32;
                let yi = (u64::from(y) * u64::from(i.height) / u64::from(height)) as u32;
                i.texel(xi, yi)[0]
            })
        };
        let mut texels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                texels.push([
                    first_channel(&roughness_image, x, y),
                    first_channel(&metallic_image, x, y),
                    1.0,
                ]);
            }
        }
        let clamped = roughness_image
            .as_ref()
            .and_then(|i| i.clamped)
            .or(metallic_image.as_ref().and_then(|i| i.clamped));
        let shown = [roughness, metallic]
            .iter()
            .flatten()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(" and ");
        let image = LinearImage {
            width,
            height,
            texels,
            alpha: Vec::new(),
            clamped,
        };
        self.add(key, &shown, image, TextureUse::RoughnessAndMetallic)
            .map_err(|e| format!("texture {shown}: {e}"))
    }

    /// One colour texture from OBJ's colour (`map_Kd`, sRGB; white where absent) and opacity
    /// (`map_d`: its alpha channel where it has one, else its first channel; linear) images, as the kernel reads a colour texture: the
    /// colour in xyz, the opacity as its alpha. The opacity image is resampled (nearest) to the
    /// colour image's size where they differ. The error names the image.
    pub fn color_and_opacity(
        &mut self,
        color: Option<&Path>,
        opacity: &Path,
    ) -> Result<u32, String> {
        let canonical = |p: &Path| {
            p.canonicalize()
                .unwrap_or_else(|_| p.to_owned())
                .display()
                .to_string()
        };
        // A key no file path has: both paths after a '#'.
        let key = (
            PathBuf::from(format!(
                "#color={}#opacity={}",
                color.map_or(String::new(), canonical),
                canonical(opacity)
            )),
            TextureUse::Color,
        );
        if let Some(&index) = self.loaded.get(&key) {
            return Ok(index);
        }
        let color_image = color
            .map(|p| {
                load_linear_image(p, Encoding::Srgb)
                    .map_err(|e| format!("texture {}: {e}", p.display()))
            })
            .transpose()?;
        let opacity_image = load_linear_image(opacity, Encoding::Linear)
            .map_err(|e| format!("texture {}: {e}", opacity.display()))?;
        let (width, height) = color_image
            .as_ref()
            .map_or((opacity_image.width, opacity_image.height), |i| {
                (i.width, i.height)
            });
        let mut alpha = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                // Nearest texel of an image of another size.
                let xi = (u64::from(x) * u64::from(opacity_image.width) / u64::from(width)) as u32;
                let yi =
                    (u64::from(y) * u64::from(opacity_image.height) / u64::from(height)) as u32;
                // A scalar map's value is its first channel; where the image has an alpha
                // channel (Blender's exporter names map_Kd's RGBA image in map_d), its alpha.
                alpha.push(if opacity_image.alpha.is_empty() {
                    opacity_image.texel(xi, yi)[0]
                } else {
                    opacity_image.alpha(xi, yi)
                });
            }
        }
        let clamped = color_image
            .as_ref()
            .and_then(|i| i.clamped)
            .or(opacity_image.clamped);
        let texels = match color_image {
            Some(i) => i.texels,
            None => vec![[1.0; 3]; alpha.len()],
        };
        let shown = match color {
            Some(c) => format!("{} and {}", c.display(), opacity.display()),
            None => opacity.display().to_string(),
        };
        let image = LinearImage {
            width,
            height,
            texels,
            alpha,
            clamped,
        };
        self.add(key, &shown, image, TextureUse::Color)
            .map_err(|e| format!("texture {shown}: {e}"))
    }

    /// The texture of an image file's bytes embedded in `file` as `element` (a glTF file's
    /// `images[2]`), decoded and checked like an image file the first time it is asked for.
    pub fn embedded_image(
        &mut self,
        file: &Path,
        element: &str,
        bytes: &[u8],
        usage: TextureUse,
    ) -> Result<u32, String> {
        let file = file.canonicalize().unwrap_or_else(|_| file.to_owned());
        let shown = format!("{}: {element}", file.display());
        // A key no file path has: the file's path with the element after a '#'.
        let key = (
            PathBuf::from(format!("{}#{element}", file.display())),
            usage,
        );
        if let Some(&index) = self.loaded.get(&key) {
            return Ok(index);
        }
        let image = decode_linear_image(bytes, encoding(usage))?;
        self.add(key, &shown, image, usage)
    }

    /// Checks a decoded image's texels for `usage` and appends it; `shown` names it in warnings.
    fn add(
        &mut self,
        key: (PathBuf, TextureUse),
        shown: &str,
        image: LinearImage,
        usage: TextureUse,
    ) -> Result<u32, String> {
        if let Some(clamped) = image.clamped {
            self.warnings
                .push(format!("{shown}: {}", clamped.warning()));
        }
        // The channels the use reads.
        let channels = match usage {
            TextureUse::Color | TextureUse::Normal => 0..3,
            TextureUse::Roughness | TextureUse::Transmission => 0..1,
            TextureUse::MetallicRoughness => 1..3,
            TextureUse::RoughnessAndMetallic => 0..2,
            TextureUse::SheenRoughness => 0..0,
        };
        // Rows from the top (as files store them) to rows from the bottom.
        for y in 0..image.height {
            for x in 0..image.width {
                let texel = image.texel(x, image.height - 1 - y);
                // A colour texture's alpha is read too (alpha-tested and blended materials).
                let alpha = match usage {
                    TextureUse::Color | TextureUse::SheenRoughness => {
                        Some(image.alpha(x, image.height - 1 - y))
                    }
                    _ => None,
                };
                if let Some(&bad) = texel[channels.clone()]
                    .iter()
                    .chain(alpha.as_ref())
                    .find(|c| !(0.0..=1.0).contains(*c))
                {
                    return Err(format!(
                        "texel ({x}, {}) (from the top left) is {bad}; a {} texture's values must \
                         be in [0, 1]",
                        image.height - 1 - y,
                        match usage {
                            TextureUse::Color => "color",
                            TextureUse::Roughness => "roughness",
                            TextureUse::MetallicRoughness => "metallic-roughness",
                            TextureUse::RoughnessAndMetallic => "roughness or metallic",
                            TextureUse::Normal => "normal",
                            TextureUse::Transmission => "transmission",
                            TextureUse::SheenRoughness => "sheen roughness",
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
                // Roughness textures as the kernel reads them: x the roughness, y the
                // metallic factor (1 where the texture gives none). A colour texture's w is
                // its alpha (1 where the file has none), which texture_alpha reads.
                self.texels.push(match usage {
                    TextureUse::Color => [r, g, b, image.alpha(x, y)],
                    TextureUse::Normal => [r, g, b, 0.0],
                    TextureUse::Roughness | TextureUse::Transmission => [r, 1.0, 1.0, 0.0],
                    TextureUse::MetallicRoughness => [g, b, 1.0, 0.0],
                    TextureUse::RoughnessAndMetallic => [r, g, 1.0, 0.0],
                    TextureUse::SheenRoughness => [image.alpha(x, y), 1.0, 1.0, 0.0],
                });
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

    /// Texture `base` (an image) looked up with `sampling`: a descriptor of its own sharing the
    /// image's texels, or `base` itself when the sampling is the default.
    pub fn sampled(&mut self, base: u32, sampling: &Sampling) -> u32 {
        if *sampling == Sampling::default() {
            return base;
        }
        let mut texture = self.descriptors[base as usize];
        texture.sampling = sampling.wrap[0]
            | (sampling.wrap[1] << 8)
            | if sampling.nearest { TEXTURE_NEAREST } else { 0 };
        texture.transform_u = sampling.transform[0];
        texture.transform_v = sampling.transform[1];
        texture.uv_set = sampling.uv_set;
        self.push(texture)
    }

    fn push(&mut self, texture: Texture) -> u32 {
        self.descriptors.push(texture);
        self.descriptors.len() as u32 - 1
    }
}

fn encoding(usage: TextureUse) -> Encoding {
    match usage {
        TextureUse::Color => Encoding::Srgb,
        TextureUse::Roughness
        | TextureUse::MetallicRoughness
        | TextureUse::Normal
        | TextureUse::Transmission
        | TextureUse::RoughnessAndMetallic
        | TextureUse::SheenRoughness => Encoding::Linear,
    }
}
