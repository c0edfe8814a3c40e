//! A material's `type` and the parameters of the simple kinds (diffuse, specular, metal,
//! dielectric; `pbr` in `pbr.rs`), and which fields each kind takes.

use super::super::fields::{fail, real, FieldError};
use super::ior_in_range;
use super::pbr::pbr_kind;
use crate::scene::file::{MaterialToml, RoughnessToml, S};
use crate::scene::texture::TextureSet;
use crate::scene::MaterialKind;
use std::path::Path;

/// The kind `type` names, with its parameters checked (a `pbr` material's textures added to
/// `textures`).
pub(super) fn material_kind(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<MaterialKind, FieldError> {
    match m.kind.get_ref().as_str() {
        "diffuse" => Ok(MaterialKind::Diffuse),
        "specular" => Ok(MaterialKind::Specular),
        "metal" => metal_kind(m, field),
        "dielectric" => dielectric_kind(m, field),
        "pbr" => pbr_kind(m, field, folder, textures),
        "interface" => interface_kind(m, field),
        other => fail(
            m.kind.span(),
            field("type"),
            format!(
                "unknown material type {other:?}; known types: \"diffuse\", \"specular\", \"metal\", \"dielectric\", \"pbr\", \"interface\""
            ),
        ),
    }
}

/// A metal's `roughness` (required): a constant in [0, 1] or a texture (read with the other
/// textures; the constant is then unused).
fn metal_kind(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
) -> Result<MaterialKind, FieldError> {
    let r = required(m, &m.roughness, "roughness", "metal", field)?;
    let roughness = match r.get_ref() {
        RoughnessToml::Value(v) => real(&S::new(r.span(), *v), &field("roughness"))?,
        // A texture (read below); the constant is unused.
        RoughnessToml::Other(_) => 1.0,
    };
    if !(0.0..=1.0).contains(&roughness) {
        return fail(
            r.span(),
            field("roughness"),
            format!("must be in [0, 1] (0 = mirror), got {roughness}"),
        );
    }
    Ok(MaterialKind::Metal { roughness })
}

/// A dielectric's `ior` (required).
fn dielectric_kind(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
) -> Result<MaterialKind, FieldError> {
    let ior = ior_in_range(required(m, &m.ior, "ior", "dielectric", field)?, field)?;
    Ok(MaterialKind::Dielectric { ior })
}

/// An interface: a boundary that only separates media, passing light straight through. It is
/// an index-matched, untinted dielectric (which the kernel, where there are media, crosses
/// without counting it as a scattering event: shaders/media/medium.wgsl), so it takes no
/// `ior` nor `color`.
fn interface_kind(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
) -> Result<MaterialKind, FieldError> {
    for (x, name) in [
        (m.ior.as_ref().map(|x| x.span()), "ior"),
        (m.color.as_ref().map(|x| x.span()), "color"),
    ] {
        if let Some(span) = x {
            return fail(
                span,
                field(name),
                "an interface passes light straight through: it takes no ior nor color (use a \
                 dielectric for a refracting boundary)",
            );
        }
    }
    Ok(MaterialKind::Dielectric { ior: 1.0 })
}

/// A field this kind (`what`) of material needs; its absence fails at the material's `type`.
fn required<'a, T>(
    m: &MaterialToml,
    x: &'a Option<S<T>>,
    name: &str,
    what: &str,
    field: &dyn Fn(&str) -> String,
) -> Result<&'a S<T>, FieldError> {
    match x {
        Some(x) => Ok(x),
        None => fail(
            m.kind.span(),
            field(name),
            format!("missing: a {what} needs {name}"),
        ),
    }
}

/// A field that does not apply to the material's kind is most likely a mistake: say so.
pub(super) fn check_fields_apply(
    m: &MaterialToml,
    kind: &MaterialKind,
    field: &dyn Fn(&str) -> String,
) -> Result<(), FieldError> {
    let pbr = matches!(kind, MaterialKind::Pbr { .. });
    for (span, name, applies) in [
        (
            m.roughness.as_ref().map(|r| r.span()),
            "roughness",
            matches!(kind, MaterialKind::Metal { .. } | MaterialKind::Pbr { .. }),
        ),
        (
            m.ior.as_ref().map(|r| r.span()),
            "ior",
            matches!(
                kind,
                MaterialKind::Dielectric { .. } | MaterialKind::Pbr { .. }
            ),
        ),
        (
            m.color.as_ref().map(|r| r.span()),
            "color",
            !matches!(kind, MaterialKind::Pbr { .. }),
        ),
        (m.base_color.as_ref().map(|r| r.span()), "base_color", pbr),
        (m.metallic.as_ref().map(|r| r.span()), "metallic", pbr),
        (m.specular.as_ref().map(|r| r.span()), "specular", pbr),
        (
            m.specular_color.as_ref().map(|r| r.span()),
            "specular_color",
            pbr,
        ),
        (
            m.transmission.as_ref().map(|r| r.span()),
            "transmission",
            pbr,
        ),
        (
            m.attenuation_color.as_ref().map(|r| r.span()),
            "attenuation_color",
            pbr,
        ),
        (
            m.attenuation_distance.as_ref().map(|r| r.span()),
            "attenuation_distance",
            pbr,
        ),
        (m.clearcoat.as_ref().map(|r| r.span()), "clearcoat", pbr),
        (
            m.clearcoat_roughness.as_ref().map(|r| r.span()),
            "clearcoat_roughness",
            pbr,
        ),
        (
            m.clearcoat_normal_map.as_ref().map(|r| r.span()),
            "clearcoat_normal_map",
            pbr,
        ),
        (m.sheen_color.as_ref().map(|r| r.span()), "sheen_color", pbr),
        (
            m.sheen_roughness.as_ref().map(|r| r.span()),
            "sheen_roughness",
            pbr,
        ),
        (
            m.subsurface_color.as_ref().map(|r| r.span()),
            "subsurface_color",
            pbr,
        ),
        (
            m.subsurface_radius.as_ref().map(|r| r.span()),
            "subsurface_radius",
            pbr,
        ),
    ] {
        if let (Some(span), false) = (span, applies) {
            return fail(
                span,
                field(name),
                format!("{name} does not apply to a {} material", m.kind.get_ref()),
            );
        }
    }
    Ok(())
}
