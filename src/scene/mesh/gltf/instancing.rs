//! glTF's `EXT_mesh_gpu_instancing`: a node that places its mesh once per element of its
//! `TRANSLATION`, `ROTATION` and `SCALE` accessors (each optional, all of one count). Each
//! instance's transform is the node's world transform times the instance's T·R·S, as a
//! node's own. Like nodes that reuse a mesh, the instances share its geometry, read once
//! (`primitives.rs`), and are stored once where its material allows (`reuse.rs`), else copied. Attributes whose names start
//! with `_` are the application's own and are ignored, as the extension allows.

use super::accessor::Decoder;
use super::document::exists;
use glam::{Mat4, Quat, Vec3};
use gltf::json;
use json::accessor::Type;

pub(super) const EXTENSION: &str = "EXT_mesh_gpu_instancing";

/// The accessors of node `i`'s instances, checked: (TRANSLATION, ROTATION, SCALE) and their
/// common count, or `None` when the node does not use the extension. Errors name the field.
pub(super) struct Attributes {
    translation: Option<usize>,
    rotation: Option<usize>,
    scale: Option<usize>,
    pub(super) count: usize,
}

pub(super) fn attributes(root: &json::Root, i: usize) -> Result<Option<Attributes>, String> {
    let node = &root.nodes[i];
    let Some(value) = node
        .extensions
        .as_ref()
        .and_then(|e| e.others.get(EXTENSION))
    else {
        return Ok(None);
    };
    let field = format!("nodes[{i}].extensions.{EXTENSION}.attributes");
    let Some(listed) = value.get("attributes").and_then(|a| a.as_object()) else {
        return Err(format!(
            "{field}: missing, or not an object of accessor indices"
        ));
    };
    let mut out = Attributes {
        translation: None,
        rotation: None,
        scale: None,
        count: 0,
    };
    let mut count: Option<(usize, &str)> = None;
    for (name, index) in listed {
        let slot = match name.as_str() {
            "TRANSLATION" => &mut out.translation,
            "ROTATION" => &mut out.rotation,
            "SCALE" => &mut out.scale,
            _ if name.starts_with('_') => continue,
            _ => {
                return Err(format!(
                    "{field}.{name}: not an attribute of the extension (TRANSLATION, ROTATION, \
                     SCALE, or the application's own, starting with `_`)"
                ))
            }
        };
        let a = index
            .as_u64()
            .ok_or_else(|| format!("{field}.{name}: must be an accessor index, got {index}"))?;
        let a = exists(a as usize, root.accessors.len(), "accessor")
            .map_err(|e| format!("{field}.{name}: {e}"))?;
        let n = root.accessors[a].count.0 as usize;
        match count {
            Some((first, first_name)) if first != n => {
                return Err(format!(
                    "{field}.{name}: accessors[{a}] holds {n} elements, but {first_name}'s holds \
                     {first}; every attribute needs one per instance"
                ))
            }
            _ => count = Some((n, name)),
        }
        *slot = Some(a);
    }
    let Some((count, _)) = count else {
        return Err(format!(
            "{field}: names none of TRANSLATION, ROTATION and SCALE"
        ));
    };
    out.count = count;
    Ok(Some(out))
}

/// Each instance's transform relative to its node, T·R·S, in the accessors' order. Every
/// one must be finite; the rotation is read as the file gives it, as a node's is.
pub(super) fn transforms(
    attributes: &Attributes,
    node: usize,
    decoder: &mut Decoder,
) -> Result<Vec<Mat4>, String> {
    let n = attributes.count;
    let field = format!("nodes[{node}].extensions.{EXTENSION}.attributes");
    let translations = match attributes.translation {
        Some(a) => decoder
            .layout(a, Type::Vec3, false)
            .and_then(|l| l.floats::<3>())
            .map_err(|e| format!("{field}.TRANSLATION: {e}"))?,
        None => vec![[0.0; 3]; n],
    };
    let rotations = match attributes.rotation {
        Some(a) => decoder
            .layout(a, Type::Vec4, false)
            .and_then(|l| l.floats::<4>())
            .map_err(|e| format!("{field}.ROTATION: {e}"))?,
        None => vec![[0.0, 0.0, 0.0, 1.0]; n],
    };
    let scales = match attributes.scale {
        Some(a) => decoder
            .layout(a, Type::Vec3, false)
            .and_then(|l| l.floats::<3>())
            .map_err(|e| format!("{field}.SCALE: {e}"))?,
        None => vec![[1.0; 3]; n],
    };
    (0..n)
        .map(|k| {
            let m = Mat4::from_scale_rotation_translation(
                Vec3::from(scales[k]),
                Quat::from_array(rotations[k]),
                Vec3::from(translations[k]),
            );
            if m.is_finite() {
                Ok(m)
            } else {
                Err(format!("{field}: instance {k}'s transform is not finite"))
            }
        })
        .collect()
}
