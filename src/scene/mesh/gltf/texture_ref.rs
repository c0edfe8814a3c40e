//! A material's texture references (glTF `textureInfo`s, normal textures) as the images they
//! sample and how: the UV set, the texture's sampler (wrap modes, filter) and
//! KHR_texture_transform, each checked.

use super::document::exists;
use crate::kernel::types::{TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_MIRROR, TEXTURE_WRAP_REPEAT};
use crate::scene::mesh::check_normal_scale;
use crate::scene::texture::Sampling;
use gltf::json;
use json::texture::{MagFilter, WrappingMode};
use json::validation::Checked;

/// A normal map's image (an index into `images`), how it is sampled, and its scale.
pub(super) type NormalImage = ((usize, Sampling), f32);

/// What reading one material's texture references takes: the document, the material's index
/// (which messages name) and where warnings about the references glint ignores go.
pub(super) struct TextureRefs<'a> {
    root: &'a json::Root,
    /// The material's index, which the fields in messages start from.
    index: usize,
    warnings: &'a mut Vec<String>,
    /// The normal maps' own warnings, pushed after every other image's (by `finish`).
    normal_map_warnings: Vec<String>,
}

impl<'a> TextureRefs<'a> {
    pub(super) fn new(root: &'a json::Root, index: usize, warnings: &'a mut Vec<String>) -> Self {
        TextureRefs {
            root,
            index,
            warnings,
            normal_map_warnings: Vec::new(),
        }
    }

    /// The image (an index into `images`) that texture reference `info`, at `field` of the
    /// material, samples and how; `None` without a reference or when glint ignores it (it
    /// warns).
    pub(super) fn image(
        &mut self,
        info: Option<&json::texture::Info>,
        field: &str,
    ) -> Result<Option<(usize, Sampling)>, String> {
        let Some(info) = info else {
            return Ok(None);
        };
        let field = format!("materials[{}].{field}", self.index);
        let root = self.root;
        let t = exists(info.index.value(), root.textures.len(), "texture")
            .map_err(|e| format!("{field}.index: {e}"))?;
        let transform = info
            .extensions
            .as_ref()
            .and_then(|e| e.texture_transform.as_ref());
        // KHR_texture_transform's texCoord overrides the reference's.
        let tex_coord = transform
            .and_then(|t| t.tex_coord)
            .unwrap_or(info.tex_coord);
        if tex_coord > 1 {
            self.warnings.push(format!(
                "{field}: on TEXCOORD_{tex_coord}; glint reads TEXCOORD_0 and TEXCOORD_1 only, so \
                 the texture is ignored"
            ));
            return Ok(None);
        }
        let mut sampling = Sampling {
            uv_set: tex_coord,
            ..Sampling::default()
        };
        if let Some(s) = root.textures[t].sampler {
            let s = exists(s.value(), root.samplers.len(), "sampler")
                .map_err(|e| format!("textures[{t}].sampler: {e}"))?;
            let sampler = &root.samplers[s];
            sampling.wrap = wrap_modes(sampler, s)?;
            // Without mipmaps, the magnification filter decides.
            sampling.nearest = sampler.mag_filter == Some(Checked::Valid(MagFilter::Nearest));
        }
        if let Some(t) = transform {
            sampling.transform = uv_transform(t);
            if !sampling.transform.iter().flatten().all(|c| c.is_finite()) {
                return Err(format!(
                    "{field}.extensions.KHR_texture_transform: not finite"
                ));
            }
        }
        Ok(Some((root.textures[t].source.value(), sampling)))
    }

    /// A normal map (normalTexture, or the coat's clearcoatNormalTexture at `path`) and its
    /// scale. One on TEXCOORD_1 is ignored, with a warning pushed after the other images'.
    pub(super) fn normal_image(
        &mut self,
        n: &json::material::NormalTexture,
        path: &str,
    ) -> Result<Option<NormalImage>, String> {
        let field = format!("materials[{}].{path}", self.index);
        check_normal_scale(
            &format!("material{}", self.index),
            &format!("{field}.scale"),
            n.scale,
        )?;
        // The crate keeps a normal texture's extensions unparsed.
        let transform = n
            .extensions
            .as_ref()
            .and_then(|e| e.others.get("KHR_texture_transform"))
            .map(|v| {
                serde_json::from_value(v.clone())
                    .map_err(|e| format!("{field}.extensions.KHR_texture_transform: {e}"))
            })
            .transpose()?;
        let info = json::texture::Info {
            index: n.index,
            tex_coord: n.tex_coord,
            extensions: Some(json::extensions::texture::Info {
                texture_transform: transform,
                others: Default::default(),
            }),
            extras: Default::default(),
        };
        Ok(match self.image(Some(&info), path)? {
            // Tangents (the file's or MikkTSpace's) follow TEXCOORD_0.
            Some((_, sampling)) if sampling.uv_set != 0 => {
                self.normal_map_warnings.push(format!(
                    "{field}: on TEXCOORD_1; glint reads normal maps on TEXCOORD_0 only, so the \
                     texture is ignored"
                ));
                None
            }
            i => i.map(|i| (i, n.scale)),
        })
    }

    /// Pushes the normal maps' warnings, after every other image's, once the material's images
    /// are read.
    pub(super) fn finish(self) {
        self.warnings.extend(self.normal_map_warnings);
    }
}

/// Sampler `s`'s wrapS and wrapT as glint's wrap modes.
fn wrap_modes(sampler: &json::texture::Sampler, s: usize) -> Result<[u32; 2], String> {
    let wrap = |mode: Checked<WrappingMode>, name: &str| match mode {
        Checked::Valid(WrappingMode::Repeat) => Ok(TEXTURE_WRAP_REPEAT),
        Checked::Valid(WrappingMode::ClampToEdge) => Ok(TEXTURE_WRAP_CLAMP),
        Checked::Valid(WrappingMode::MirroredRepeat) => Ok(TEXTURE_WRAP_MIRROR),
        Checked::Invalid => Err(format!("samplers[{s}].{name}: not a glTF wrap mode")),
    };
    Ok([
        wrap(sampler.wrap_s, "wrapS")?,
        wrap(sampler.wrap_t, "wrapT")?,
    ])
}

/// KHR_texture_transform's offset, rotation and scale as the matrix glint's UVs are
/// multiplied by (rows u and v, the last column the offset); not checked to be finite.
fn uv_transform(t: &json::extensions::texture::TextureTransform) -> [[f32; 3]; 2] {
    let [ox, oy] = t.offset.0;
    let [sx, sy] = t.scale.0;
    let (sin, cos) = t.rotation.0.sin_cos();
    // glTF's uv' = T R S uv, R rotating the UVs counterclockwise as the extension's text says,
    // drawn with glTF's v down: u' = cos sx u + sin sy v + ox, v' = −sin sx u + cos sy v + oy.
    // (The GLSL snippet in the extension's README has the opposite sign; Khronos'
    // TextureTransformTest, whose markers say which way is right, and three.js follow the
    // text.) Here in glint's coordinates, whose v is 1 − glTF's.
    [
        [cos * sx, -sin * sy, ox + sin * sy],
        [sin * sx, cos * sy, 1.0 - cos * sy - oy],
    ]
}
