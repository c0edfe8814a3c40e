//! Each part of a mesh file made ready to place, in the file's order: its geometry checked
//! (once per geometry, however many parts use it), its scene material found, and the tangents
//! its normal maps need (read or made once per geometry).

use super::file_materials::FileMaterials;
use super::{part_prefix, tangents, Geometry, MeshFile, MeshPart, NO_MATERIAL};
use crate::scene::texture::TextureSet;
use crate::scene::Material;
use glam::Vec4;
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::rc::Rc;

/// What placing a part needs besides its geometry and matrix, found once per part.
pub(super) struct PreparedPart {
    pub(super) material: u32,
    /// Whether its triangles are shaded smooth with the file's vertex normals.
    pub(super) use_normals: bool,
    /// Per triangle, the tangent at each corner (for normal maps).
    pub(super) corners: Option<Rc<Vec<[Vec4; 3]>>>,
}

/// Per geometry, the tangents at its triangles' corners.
type TangentCache = HashMap<*const Geometry, Rc<Vec<[Vec4; 3]>>>;

/// Every part of `file` checked and prepared, in the file's order. `material` is the
/// `[[meshes]]` entry's; without one the file's own become scene materials as parts use them.
/// `smooth` shades with the file's vertex normals where it has them.
pub(super) fn prepare_parts(
    file: &MeshFile,
    path: &Path,
    shown: &str,
    material: Option<u32>,
    smooth: bool,
    scene_materials: &mut Vec<Material>,
    textures: &mut TextureSet,
) -> Result<Vec<PreparedPart>, String> {
    let mut file_materials = FileMaterials::new(file, path, shown);
    let mut prepared = Vec::with_capacity(file.parts.len());
    let mut checked = HashSet::new();
    let mut tangent_cache = TangentCache::new();
    for part in &file.parts {
        let use_normals = smooth && !part.geometry.normals.is_empty();
        if checked.insert(Rc::as_ptr(&part.geometry)) {
            check_geometry(part, use_normals, shown)?;
        }
        let material = match material {
            Some(m) => m,
            None => {
                let Some(index) = part.material else {
                    return Err(format!(
                        "{shown}: {}{NO_MATERIAL}; set `material` in [[meshes]]",
                        part_prefix(&part.name)
                    ));
                };
                file_materials.scene_material(index, scene_materials, textures)?
            }
        };
        let scene_material = &scene_materials[material as usize];
        // Normal maps (the coat's too) need tangents at every corner.
        let corners = if scene_material.has_normal_map() {
            Some(corner_tangents(
                part,
                scene_material,
                shown,
                &mut tangent_cache,
            )?)
        } else {
            None
        };
        prepared.push(PreparedPart {
            material,
            use_normals,
            corners,
        });
    }
    Ok(prepared)
}

/// `part`'s geometry checked: every vertex finite, every index in range, and (when its
/// normals are used) every vertex normal finite.
fn check_geometry(part: &MeshPart, use_normals: bool, shown: &str) -> Result<(), String> {
    let geometry = &*part.geometry;
    let count = geometry.positions.len();
    if let Some(i) = geometry.positions.iter().position(|p| !p.is_finite()) {
        return Err(format!(
            "{shown}: {}vertex {i} is not finite: {}",
            part_prefix(&part.name),
            geometry.positions[i]
        ));
    }
    for (f, idx) in geometry.indices.iter().enumerate() {
        if let Some(&bad) = idx.iter().find(|&&i| i as usize >= count) {
            return Err(format!(
                "{shown}: {}face {f} refers to vertex {bad}, but there are only {count} vertices",
                part_prefix(&part.name)
            ));
        }
    }
    if use_normals {
        if let Some(i) = geometry.normals.iter().position(|n| !n.is_finite()) {
            return Err(format!(
                "{shown}: {}vertex normal {i} is not finite: {}",
                part_prefix(&part.name),
                geometry.normals[i]
            ));
        }
    }
    Ok(())
}

/// The tangents at the corners of `part`'s triangles, for `material`'s normal maps: read or
/// made (tangents.rs) the first time its geometry asks. Without texture coordinates to lay
/// the map out, an error.
fn corner_tangents(
    part: &MeshPart,
    material: &Material,
    shown: &str,
    cache: &mut TangentCache,
) -> Result<Rc<Vec<[Vec4; 3]>>, String> {
    let geometry = &*part.geometry;
    if geometry.uvs.len() != geometry.positions.len() {
        return Err(format!(
            "{shown}: {}material {:?} has a normal map, but these triangles have no texture \
             coordinates (TEXCOORD_0) to lay it out",
            part_prefix(&part.name),
            material.name
        ));
    }
    Ok(cache
        .entry(Rc::as_ptr(&part.geometry))
        .or_insert_with(|| Rc::new(tangents::corner_tangents(geometry).unwrap_or_default()))
        .clone())
}
