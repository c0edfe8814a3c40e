//! `[materials.NAME]`: each material's kind, colour, emission and textures, and references to
//! materials by name. The kinds and which fields each takes are in `kinds.rs`, the `pbr` kind's
//! parameters and layers in `pbr.rs`, textures and normal maps in `maps.rs`, alpha in
//! `alpha.rs`.

mod alpha;
mod kinds;
mod maps;
mod pbr;

use super::fields::{fail, non_negative, radiance_in_range, real, FieldError};
use crate::scene::file::{MaterialToml, Real, RoughnessToml, Triple, S};
use crate::scene::limits::{MAX_IOR, MIN_IOR};
use crate::scene::texture::{TextureSet, TextureUse};
use crate::scene::{Material, MaterialKind};
use glam::Vec3;
use maps::{normal_map, texture};
use std::collections::BTreeMap;
use std::path::Path;

/// The scene's materials (mesh files add their own), the textures they use, and their indices
/// by name.
pub(super) struct Materials {
    pub(super) list: Vec<Material>,
    pub(super) textures: TextureSet,
    index_of: BTreeMap<String, u32>,
}

impl Materials {
    /// The index of the material called `name`.
    pub(super) fn index(&self, name: &str) -> Option<u32> {
        self.index_of.get(name).copied()
    }

    /// The index of the material `m` names; an unknown name fails at `field`.
    pub(super) fn reference(&self, m: &S<String>, field: String) -> Result<u32, FieldError> {
        self.index_of.get(m.get_ref()).copied().ok_or_else(|| {
            let known: Vec<_> = self.index_of.keys().map(|k| format!("{k:?}")).collect();
            FieldError {
                span: Some(m.span()),
                field,
                message: format!(
                    "unknown material {:?}; defined materials: {}",
                    m.get_ref(),
                    if known.is_empty() {
                        "none".into()
                    } else {
                        known.join(", ")
                    }
                ),
            }
        })
    }
}

/// The `[materials]` tables, with textures read relative to `folder`.
pub(super) fn validate_materials(
    toml: &BTreeMap<String, S<MaterialToml>>,
    folder: &Path,
) -> Result<Materials, FieldError> {
    let mut materials = Vec::new();
    let mut textures = TextureSet::default();
    let mut index_of = BTreeMap::new();
    for (name, m) in toml {
        index_of.insert(name.clone(), materials.len() as u32);
        materials.push(validate_material(name, m.get_ref(), folder, &mut textures)?);
    }
    Ok(Materials {
        list: materials,
        textures,
        index_of,
    })
}

/// `[materials.NAME]`, its textures added to `textures`. The checks run in the order the
/// fields' errors are reported: the kind and its parameters, fields that do not apply to it,
/// the colour, the emission, alpha and the normal map. Textures are added in that order too,
/// which fixes their indices.
fn validate_material(
    name: &str,
    m: &MaterialToml,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<Material, FieldError> {
    let field = &|f: &str| format!("materials.{name}.{f}");
    let kind = kinds::material_kind(m, field, folder, textures)?;
    kinds::check_fields_apply(m, &kind, field)?;
    let roughness_texture = roughness_texture(m, field, folder, textures)?;
    let (color, color_texture) = color(m, &kind, field, folder, textures)?;
    let emitted_radiance = emitted_radiance(m, field)?;
    let alpha = alpha::alpha(m, field)?;
    let normal_texture = m
        .normal_map
        .as_ref()
        .map(|n| normal_map(n, &field("normal_map"), folder, textures))
        .transpose()?;
    Ok(Material {
        name: name.to_string(),
        kind,
        color,
        emitted_radiance,
        color_texture,
        roughness_texture,
        emission_texture: None,
        normal_texture,
        alpha,
    })
}

/// A metal's or a `pbr` material's `roughness` given as a texture; `None` for a constant (the
/// kind has read it) or none.
fn roughness_texture(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<Option<u32>, FieldError> {
    match &m.roughness {
        Some(r) => match r.get_ref() {
            RoughnessToml::Other(value) => Ok(Some(texture(
                &S::new(r.span(), value.clone()),
                &field("roughness"),
                folder,
                TextureUse::Roughness,
                textures,
            )?)),
            RoughnessToml::Value(_) => Ok(None),
        },
        None => Ok(None),
    }
}

/// The material's colour (a `pbr` material's is its `base_color`): a reflectance, or a
/// texture (the constant is then unused, 1). Required except for a dielectric, which is clear
/// glass unless tinted.
fn color(
    m: &MaterialToml,
    kind: &MaterialKind,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<(Vec3, Option<u32>), FieldError> {
    let (color_field, color_name) = if matches!(kind, MaterialKind::Pbr { .. }) {
        (&m.base_color, "base_color")
    } else {
        (&m.color, "color")
    };
    let color_texture = match color_field {
        Some(c) if c.get_ref().is_table() => Some(texture(
            c,
            &field(color_name),
            folder,
            TextureUse::Color,
            textures,
        )?),
        _ => None,
    };
    let color = match (color_field, kind) {
        // Textured: the constant is unused.
        (Some(_), _) if color_texture.is_some() => Vec3::ONE,
        (Some(c), _) => reflectance(c, &field(color_name))?,
        // Clear glass unless tinted.
        (None, MaterialKind::Dielectric { .. }) => Vec3::ONE,
        (None, _) => {
            return fail(
                m.kind.span(),
                field(color_name),
                format!("missing: this material needs a {color_name}"),
            );
        }
    };
    Ok((color, color_texture))
}

/// `emission` (a constant: no texture) times `strength` (≥ 0, default 1), the product within
/// the numeric range radiance has.
fn emitted_radiance(m: &MaterialToml, field: &dyn Fn(&str) -> String) -> Result<Vec3, FieldError> {
    let emission = match &m.emission {
        Some(e) if e.get_ref().is_table() => {
            return fail(
                e.span(),
                field("emission"),
                "takes no texture: only color (and a metal's roughness) may be textured",
            )
        }
        Some(e) => non_negative(e, &field("emission"))?,
        None => Vec3::ZERO,
    };
    let strength = match &m.strength {
        Some(s) => {
            let v = real(s, &field("strength"))?;
            if v < 0.0 {
                return fail(s.span(), field("strength"), format!("must be ≥ 0, got {v}"));
            }
            v
        }
        None => 1.0,
    };
    // Each factor may be in range and the product not (1e30 × 1e30): check the product,
    // in f64, where it is exact enough and cannot overflow.
    if let Some(e) = &m.emission {
        let span = m.strength.as_ref().map_or(e.span(), |s| s.span());
        radiance_in_range(
            span,
            &field("emission × strength"),
            emission.as_dvec3() * strength as f64,
        )?;
    }
    Ok(emission * strength)
}

/// A colour that reflects light: every channel in [0, 1].
fn reflectance(c: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
    let color = non_negative(c, field)?;
    if color.max_element() > 1.0 {
        return fail(
            c.span(),
            field,
            format!("a reflectance must be in [0, 1] (more would create energy), got {color}"),
        );
    }
    Ok(color)
}

/// A number in [0, 1].
fn unit_interval(x: &S<Real>, field: &str) -> Result<f32, FieldError> {
    let v = real(x, field)?;
    if !(0.0..=1.0).contains(&v) {
        return fail(x.span(), field, format!("must be in [0, 1], got {v}"));
    }
    Ok(v)
}

/// An index of refraction (`ior`) within the range glint supports.
pub(super) fn ior_in_range(x: &S<Real>, field: &dyn Fn(&str) -> String) -> Result<f32, FieldError> {
    let ior = real(x, &field("ior"))?;
    if !(MIN_IOR..=MAX_IOR).contains(&ior) {
        return fail(
            x.span(),
            field("ior"),
            format!(
                "the index of refraction must be in [{MIN_IOR}, {MAX_IOR}] (the \
                 numeric range glint supports), got {ior}"
            ),
        );
    }
    Ok(ior)
}
