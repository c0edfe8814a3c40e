//! A glTF file's `KHR_lights_punctual` lights as glint's [`Light`]s, placed by their nodes.
//!
//! A point light sits at its node's origin; spot and directional lights shine along the
//! node's −z axis. glTF gives photometric units: a point or spot light's `intensity` in
//! candela (lm/sr), a directional light's in lux (lm/m²). glint's are radiometric (W/sr,
//! W/m²), and the factor between them is the one Blender's glTF importer uses, so that a file
//! looks the same in both: `PBR_WATTS_TO_LUMENS = 683` lm/W (glTF-Blender-IO,
//! `addons/io_scene_gltf2/blender/com/conversion.py`; applied in
//! `addons/io_scene_gltf2/blender/imp/light.py`, `calc_energy_pointlike`: W = cd · 4π / 683
//! for a Blender point or spot light, whose radiant intensity is W / 4π = cd / 683 W/sr;
//! `calc_energy_directional`: W/m² = lux / 683 for a sun). So glint's intensity is the
//! file's divided by 683, for every kind. A light's `range` is ignored: glint's lights fall
//! off with the inverse square of the distance, as the extension recommends.

use super::document::{exists, read_document};
use super::nodes::placed_nodes;
use crate::scene::light::{Light, LightKind};
use crate::scene::limits::{MAX_COORDINATE, MAX_RADIANCE};
use glam::{DVec3, Mat4, Vec3};
use gltf::json;
use json::extensions::scene::khr_lights_punctual::{self as punctual, Type};
use json::validation::Checked;
use std::path::Path;

/// Lumens per watt: glTF's photometric intensity over glint's radiometric one (Blender's
/// `PBR_WATTS_TO_LUMENS`, see the module's notes).
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The file's punctual lights placed by its default scene's nodes, then by `transform` (a
/// `[[meshes]]` entry's own), and warnings (a light of a type glint does not know is skipped
/// with one). The error is a sentence naming the element, for the caller to put after the
/// file's name.
pub fn gltf_lights(path: &Path, transform: Mat4) -> Result<(Vec<Light>, Vec<String>), String> {
    let (root, _) = read_document(path)?;
    let definitions: &[punctual::Light] = root.as_ref();
    let mut lights = Vec::new();
    let mut unknown = Vec::new();
    let mut placed = placed_nodes(&root)?;
    // Node order: the same file gives the same list whatever the traversal.
    placed.sort_by_key(|p| p.node);
    for p in placed {
        let node = &root.nodes[p.node];
        let Some(reference) = node
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
        else {
            continue;
        };
        let l = exists(reference.light.value(), definitions.len(), "light").map_err(|e| {
            format!(
                "nodes[{}].extensions.KHR_lights_punctual.light: {e}",
                p.node
            )
        })?;
        let field = format!("extensions.KHR_lights_punctual.lights[{l}]");
        let definition = &definitions[l];
        let Checked::Valid(kind) = definition.type_ else {
            if !unknown.contains(&l) {
                unknown.push(l);
            }
            continue;
        };
        lights.push(light(
            definition,
            kind,
            &field,
            p.node,
            transform * p.transform,
        )?);
    }
    let warnings = if unknown.is_empty() {
        Vec::new()
    } else {
        let list: Vec<String> = unknown
            .iter()
            .map(|l| format!("extensions.KHR_lights_punctual.lights[{l}]"))
            .collect();
        vec![format!(
            "{} of a type glint does not know (it knows \"point\", \"spot\", \"directional\"): \
             skipped",
            list.join(", ")
        )]
    };
    Ok((lights, warnings))
}

fn light(
    d: &punctual::Light,
    kind: Type,
    field: &str,
    node: usize,
    transform: Mat4,
) -> Result<Light, String> {
    let color = Vec3::from(d.color);
    if !color.is_finite() || color.min_element() < 0.0 {
        return Err(format!(
            "{field}.color: must be finite and ≥ 0, got {color}"
        ));
    }
    if !(d.intensity >= 0.0 && d.intensity.is_finite()) {
        return Err(format!(
            "{field}.intensity: must be a finite number ≥ 0, got {}",
            d.intensity
        ));
    }
    let intensity = d.intensity / LUMENS_PER_WATT;
    let emitted = color.as_dvec3() * intensity as f64;
    if emitted.max_element() > MAX_RADIANCE {
        return Err(format!(
            "{field}: color × intensity / 683 = {:e} is too bright: at most {MAX_RADIANCE:e} \
             per channel (the numeric range glint supports)",
            emitted.max_element()
        ));
    }
    let position = || {
        let p = transform.transform_point3(Vec3::ZERO);
        if p.abs().max_element() <= MAX_COORDINATE {
            Ok(p)
        } else {
            Err(format!(
                "nodes[{node}]: the light's position {p} is outside ±{MAX_COORDINATE:e} (the \
                 numeric range glint supports)"
            ))
        }
    };
    let direction = || {
        unit(transform.transform_vector3(Vec3::NEG_Z)).ok_or_else(|| {
            format!(
                "nodes[{node}]: the light's direction (the node's −z axis) is zero: its \
                 transform has a zero scale"
            )
        })
    };
    let kind = match kind {
        Type::Point => LightKind::Point {
            position: position()?,
            radius: 0.0,
        },
        Type::Directional => LightKind::Directional {
            direction: direction()?,
            angle: 0.0,
        },
        Type::Spot => {
            let spot = d.spot.clone().unwrap_or_default();
            let (inner, outer) = (spot.inner_cone_angle, spot.outer_cone_angle);
            let quarter_turn = std::f32::consts::FRAC_PI_2;
            if !(0.0..=quarter_turn).contains(&inner) {
                return Err(format!(
                    "{field}.spot.innerConeAngle: must be in [0, π/2] radians, got {inner}"
                ));
            }
            if !(0.0..=quarter_turn).contains(&outer) {
                return Err(format!(
                    "{field}.spot.outerConeAngle: must be in [0, π/2] radians, got {outer}"
                ));
            }
            if outer < inner {
                return Err(format!(
                    "{field}.spot.outerConeAngle: must be at least innerConeAngle ({inner}), \
                     got {outer}"
                ));
            }
            LightKind::Spot {
                position: position()?,
                direction: direction()?,
                inner_angle: inner.to_degrees().min(90.0),
                outer_angle: outer.to_degrees().min(90.0),
            }
        }
    };
    Ok(Light {
        kind,
        color,
        intensity,
    })
}

/// `v` over its length, computed as a scene file's `direction` is (in f64), and repeated
/// until it no longer changes, so that the light written out as a scene file
/// (`glint render --print-scene`) reads back bit for bit the same. `None` for a zero or
/// non-finite vector.
pub fn unit(v: Vec3) -> Option<Vec3> {
    let mut u = v;
    for _ in 0..4 {
        let length = u.as_dvec3().length();
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let next = (u.as_dvec3() / length).as_vec3();
        if next == u {
            break;
        }
        u = next;
    }
    (u.as_dvec3() != DVec3::ZERO).then_some(u)
}
