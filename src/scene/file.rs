//! The scene file as written: serde structs that mirror the TOML, with spans for messages.
//! Integers are accepted where reals are meant; unknown fields are errors.

use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use toml::Spanned;

/// 1-based line and column (in characters) of a byte offset.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, text[line_start..offset].chars().count() + 1)
}

/// A number: TOML integers are accepted where reals are meant (`radius = 90`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Real(pub(super) f64);

impl<'de> Deserialize<'de> for Real {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct RealVisitor;
        impl Visitor<'_> for RealVisitor {
            type Value = Real;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Real, E> {
                Ok(Real(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Real, E> {
                Ok(Real(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Real, E> {
                Ok(Real(v as f64))
            }
        }
        d.deserialize_any(RealVisitor)
    }
}

pub(super) type S<T> = Spanned<T>;

/// A 3-vector as written, any TOML value: [`super::validate`] checks that it is exactly three
/// numbers, where the field's name is known for the message. (serde's `[T; 3]` stops reading
/// after three elements, so `[1, 2, 3, "x"]` would pass with the rest unparsed.)
pub(super) type Triple = toml::Value;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneToml {
    pub(super) camera: Option<S<CameraToml>>,
    pub(super) render: Option<S<RenderToml>>,
    #[serde(default)]
    pub(super) materials: BTreeMap<String, S<MaterialToml>>,
    #[serde(default)]
    pub(super) spheres: Vec<S<SphereToml>>,
    #[serde(default)]
    pub(super) quads: Vec<S<QuadToml>>,
    #[serde(default)]
    pub(super) meshes: Vec<S<MeshToml>>,
    pub(super) environment: Option<S<EnvironmentToml>>,
    #[serde(default)]
    pub(super) lights: Vec<S<LightToml>>,
    #[serde(default)]
    pub(super) media: BTreeMap<String, S<MediumToml>>,
    #[serde(default)]
    pub(super) volumes: Vec<S<VolumeToml>>,
}

/// `[media.NAME]`: a homogeneous medium, as `sigma_a` and `sigma_s` or as `color` (the
/// single-scattering albedo) with `density` or `mean_free_path`; `g` is Henyey–Greenstein's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MediumToml {
    pub(super) sigma_a: Option<S<Triple>>,
    pub(super) sigma_s: Option<S<Triple>>,
    pub(super) color: Option<S<Triple>>,
    pub(super) density: Option<S<Real>>,
    /// A number, or three (one per channel).
    pub(super) mean_free_path: Option<S<toml::Value>>,
    pub(super) g: Option<S<Real>>,
    /// An OpenVDB file (relative to the scene file's folder) whose float grid scales the
    /// coefficients (then per unit density): a heterogeneous medium, placed by `[[volumes]]`.
    pub(super) grid: Option<S<String>>,
    /// The grid's name in the file (default `"density"`).
    pub(super) grid_name: Option<S<String>>,
}

/// `[[volumes]]`: a grid medium placed in the scene, inside an interface box around the
/// grid's active values, moved by `translate`, `rotate` and `scale` as a mesh is.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VolumeToml {
    pub(super) medium: S<String>,
    pub(super) translate: Option<S<Triple>>,
    pub(super) rotate: Option<S<Triple>>,
    pub(super) scale: Option<S<ScaleToml>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraToml {
    /// `eye`, `target`, `up` and `vfov` (or `projection = "orthographic"` and `height`), or
    /// `from` (with `index`).
    pub(super) eye: Option<S<Triple>>,
    pub(super) target: Option<S<Triple>>,
    pub(super) up: Option<S<Triple>>,
    pub(super) vfov: Option<S<Real>>,
    /// `"perspective"` (the default) or `"orthographic"`.
    pub(super) projection: Option<S<String>>,
    /// An orthographic camera's view height, in world units.
    pub(super) height: Option<S<Real>>,
    /// A glTF file (relative to the scene file's folder) whose camera this is.
    pub(super) from: Option<S<String>>,
    /// Which of its cameras (in node order); without it, the first one.
    pub(super) index: Option<S<i64>>,
    pub(super) aperture: Option<S<Real>>,
    pub(super) focus_distance: Option<S<Real>>,
    /// The medium the camera is in (default: `[render] medium`).
    pub(super) medium: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RenderToml {
    pub(super) width: S<i64>,
    pub(super) height: S<i64>,
    pub(super) spp: S<i64>,
    pub(super) max_bounces: S<i64>,
    pub(super) background: Option<S<Triple>>,
    pub(super) seed: Option<S<i64>>,
    pub(super) light_sampling: Option<bool>,
    pub(super) russian_roulette: Option<bool>,
    pub(super) sampler: Option<S<String>>,
    pub(super) light_sampler: Option<S<String>>,
    pub(super) integrator: Option<S<String>>,
    /// The medium that fills the scene outside every object (fog).
    pub(super) medium: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialToml {
    #[serde(rename = "type")]
    pub(super) kind: S<String>,
    pub(super) color: Option<S<Triple>>,
    pub(super) emission: Option<S<Triple>>,
    pub(super) strength: Option<S<Real>>,
    pub(super) roughness: Option<S<RoughnessToml>>,
    pub(super) ior: Option<S<Real>>,
    /// `type = "pbr"` (glTF's metallic-roughness material).
    pub(super) base_color: Option<S<Triple>>,
    pub(super) metallic: Option<S<Real>>,
    pub(super) specular: Option<S<Real>>,
    pub(super) specular_color: Option<S<Triple>>,
    /// KHR_materials_transmission and KHR_materials_volume, for `type = "pbr"`.
    pub(super) transmission: Option<S<Real>>,
    pub(super) attenuation_color: Option<S<Triple>>,
    pub(super) attenuation_distance: Option<S<Real>>,
    /// KHR_materials_clearcoat and KHR_materials_sheen, for `type = "pbr"`: each a constant or
    /// a texture.
    pub(super) clearcoat: Option<S<RoughnessToml>>,
    pub(super) clearcoat_roughness: Option<S<RoughnessToml>>,
    pub(super) sheen_color: Option<S<Triple>>,
    pub(super) sheen_roughness: Option<S<RoughnessToml>>,
    /// Random-walk subsurface scattering, for `type = "pbr"`: the colour the material takes
    /// after many scatterings inside, and the mean free path (one length, or one per
    /// channel); a medium made from them fills every sphere and closed mesh of the material
    /// (`src/scene/validate/media.rs`, `subsurface_media`).
    pub(super) subsurface_color: Option<S<Triple>>,
    pub(super) subsurface_radius: Option<S<toml::Value>>,
    /// The coat's own tangent-space normal map (glTF's clearcoatNormalTexture), in the forms
    /// of `normal_map`.
    pub(super) clearcoat_normal_map: Option<S<toml::Value>>,
    /// Any type, on meshes: `"opaque"` (the default), `"mask"` or `"blend"` (glTF's alphaMode),
    /// the constant `alpha` (which a colour texture's alpha multiplies) and the mask's
    /// `alpha_cutoff`.
    pub(super) alpha_mode: Option<S<String>>,
    pub(super) alpha: Option<S<Real>>,
    pub(super) alpha_cutoff: Option<S<Real>>,
    /// Any type, on meshes: a tangent-space normal map, `"file.png"` or
    /// `{ file = "file.png", scale = s }`.
    pub(super) normal_map: Option<S<toml::Value>>,
}

/// `roughness = 0.3`, or anything else (`{ texture = "…" }`), which validation reads.
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum RoughnessToml {
    Value(Real),
    Other(toml::Value),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SphereToml {
    pub(super) center: S<Triple>,
    pub(super) radius: S<Real>,
    pub(super) material: S<String>,
    /// The medium that fills the sphere.
    pub(super) medium: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct QuadToml {
    pub(super) corner: S<Triple>,
    pub(super) u: S<Triple>,
    pub(super) v: S<Triple>,
    pub(super) material: S<String>,
    /// Refused with a message: a quad bounds no volume.
    pub(super) medium: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshToml {
    /// Relative to the scene file's folder.
    pub(super) file: S<String>,
    pub(super) material: Option<S<String>>,
    pub(super) translate: Option<S<Triple>>,
    pub(super) rotate: Option<S<Triple>>,
    pub(super) scale: Option<S<ScaleToml>>,
    pub(super) smooth: Option<bool>,
    /// Whether the file's punctual lights (glTF `KHR_lights_punctual`) join the scene.
    pub(super) lights: Option<bool>,
    /// Where the mesh is placed, each a table with optional `translate`, `rotate` and `scale`
    /// applied after the mesh's own: any TOML value here, checked in [`super::validate`] where
    /// each instance's index is known for the message.
    pub(super) instances: Option<S<Vec<S<toml::Value>>>>,
    /// The medium that fills the mesh, which must be closed.
    pub(super) medium: Option<S<String>>,
}

/// `scale = 2.0` or `scale = [1.0, 2.0, 1.0]`.
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum ScaleToml {
    Uniform(Real),
    PerAxis([Real; 3]),
}

/// `[environment]`: an equirectangular HDR image lighting the scene from every direction.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EnvironmentToml {
    /// Relative to the scene file's folder; or `preset`.
    pub(super) file: Option<S<String>>,
    /// A map glint generates: `"studio"` (`src/scene/studio.rs`).
    pub(super) preset: Option<S<String>>,
    pub(super) strength: Option<S<Real>>,
    /// Degrees about the up (+y) axis.
    pub(super) rotate: Option<S<Real>>,
}

/// `[[lights]]`: a point, spot or directional light (`src/scene/light.rs`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightToml {
    #[serde(rename = "type")]
    pub(super) kind: S<String>,
    pub(super) position: Option<S<Triple>>,
    pub(super) direction: Option<S<Triple>>,
    pub(super) color: Option<S<Triple>>,
    pub(super) intensity: S<Real>,
    pub(super) inner_angle: Option<S<Real>>,
    pub(super) outer_angle: Option<S<Real>>,
    pub(super) angle: Option<S<Real>>,
    pub(super) radius: Option<S<Real>>,
}
