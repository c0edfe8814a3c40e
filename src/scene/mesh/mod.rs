//! Triangle meshes from OBJ (`tobj`), glTF (`gltf`) and PLY (`ply-rs-bw`) files: read, checked,
//! transformed into the scene, and their own materials mapped to glint's (README.md has the
//! table). Everything is checked here, before rendering: unreadable or malformed files, vertices
//! that are not finite, indices out of range, meshes left with no triangles.
//!
//! One file per format (`obj.rs`, `ply.rs`, and glTF's folder `gltf/`, whose `mod.rs` lists its
//! files), each yielding the parts in `parts.rs`, its material values passing `checks.rs`;
//! which parts are stored once rather than copied in `reuse.rs`; this file turns parts into
//! scene triangles and instanced meshes.

mod checks;
mod gltf;
mod obj;
mod parts;
mod ply;
mod reuse;
mod tangents;

pub use self::gltf::cameras::{gltf_camera, no_such_camera, FileCamera};
pub use self::gltf::lights::{gltf_lights, unit, LUMENS_PER_WATT};
pub use self::gltf::{ExtensionSupport, GLTF_EXTENSIONS};

// What the format readers (obj.rs, ply.rs, gltf/) take from here.
use checks::{check_emission, check_ior, check_normal_scale, check_reflectance};
pub(super) use parts::{FileTextures, Geometry, ImageSource, MeshFile, MeshPart};

use super::texture::{Sampling, TextureSet, TextureUse};
use super::{InstancedMesh, Material, MaterialKind, Triangle};
use crate::input_file::{read_regular_file, MESH_FILE_LIMIT};
use glam::{Mat3, Mat4, Vec3, Vec4};
use std::path::Path;
use std::rc::Rc;

/// The most triangles one scene may hold: every BVH reference must fit 30 bits, and far fewer
/// fit any GPU's storage binding anyway.
pub const MAX_TRIANGLES: usize = 1 << 28;

/// The most triangles one `[[meshes]]` entry may copy in all, counting every placement (its
/// `instances`, and a glTF file's reused meshes) of what is not stored once: about what one
/// mesh file within the 1 GiB file limit can hold (a binary PLY of a closed mesh, ~25 bytes a
/// triangle). Without this a small file placed many times could ask for far more memory than
/// any mesh file could.
pub const MAX_PLACED_TRIANGLES: usize = 1 << 25;

/// The most instances a scene's instanced meshes may have in all: their transforms
/// (`kernel::types::Instance`, 112 bytes each) fill one 128 MiB binding at about 1.2·10⁶.
pub const MAX_INSTANCES: usize = 1 << 20;

/// Triangle `t` moved by `matrix`: its vertices, its normals through the inverse transpose of
/// the linear part (renormalised), its tangents through the linear part, as [`load_placed`]
/// places a file's triangles.
pub fn placed(t: &Triangle, matrix: &Mat4) -> Triangle {
    let linear = Mat3::from_mat4(*matrix);
    let normal_matrix = linear.inverse().transpose();
    Triangle {
        vertices: t.vertices.map(|v| matrix.transform_point3(v)),
        normals: t
            .normals
            .map(|n| n.map(|n| (normal_matrix * n).normalize_or_zero())),
        tangents: t
            .tangents
            .map(|c| c.map(|tangent| tangents::placed_tangent(&linear, tangent))),
        ..t.clone()
    }
}

/// Whether `path` names a glTF file (`.gltf`, `.glb`), by its extension.
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| matches!(e.to_string_lossy().to_lowercase().as_str(), "gltf" | "glb"))
}

/// The start of the error for a part without a material (a model file gives those parts a
/// default material instead, `src/scene/model.rs`).
pub const NO_MATERIAL: &str = "the file gives no material for these triangles";

/// Where a mesh goes in the scene: scale, then rotate about x, y, z (degrees), then translate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshTransform {
    pub scale: Vec3,
    pub rotate_degrees: Vec3,
    pub translate: Vec3,
}

impl MeshTransform {
    pub fn matrix(&self) -> Mat4 {
        let r = self.rotate_degrees * (std::f32::consts::PI / 180.0);
        Mat4::from_translation(self.translate)
            * Mat4::from_rotation_z(r.z)
            * Mat4::from_rotation_y(r.y)
            * Mat4::from_rotation_x(r.x)
            * Mat4::from_scale(self.scale)
    }
}

/// The triangles of one `[[meshes]]` entry, ready for the scene.
pub(crate) struct LoadedMesh {
    /// Triangles copied into the scene's coordinates.
    pub triangles: Vec<Triangle>,
    /// What is placed two or more times and stored once ([`reuse`]).
    pub instanced: Vec<InstancedMesh>,
    /// One line each, for stderr.
    pub warnings: Vec<String>,
}

/// Reads, checks, transforms and materials one mesh file. `scene_materials` receives the file's
/// own materials when `material` is `None`, named `<file name>/<material name>`.
pub(crate) fn load(
    path: &Path,
    shown: &str,
    transform: &MeshTransform,
    material: Option<u32>,
    smooth: bool,
    scene_materials: &mut Vec<Material>,
    textures: &mut TextureSet,
) -> Result<LoadedMesh, String> {
    load_placed(
        path,
        shown,
        &[transform.matrix()],
        material,
        smooth,
        scene_materials,
        textures,
    )
}

/// [`load`] with the file placed once per matrix in `placements` (a `[[meshes]]` entry's
/// `instances`): the file is read and checked once. What is placed two or more times, by the
/// entry or by the file itself (glTF nodes that reuse a mesh, `EXT_mesh_gpu_instancing`), is
/// stored once where its materials allow ([`reuse`] says which); everything else is copied
/// into world-space triangles, placement after placement.
pub(crate) fn load_placed(
    path: &Path,
    shown: &str,
    placements: &[Mat4],
    material: Option<u32>,
    smooth: bool,
    scene_materials: &mut Vec<Material>,
    textures: &mut TextureSet,
) -> Result<LoadedMesh, String> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if !matches!(extension.as_str(), "obj" | "gltf" | "glb" | "ply") {
        return Err(format!(
            "{shown}: unknown mesh format {:?}; known: .obj, .gltf, .glb, .ply",
            if extension.is_empty() {
                "(no extension)".to_string()
            } else {
                format!(".{extension}")
            }
        ));
    }
    if !path.is_file() {
        return Err(format!("{shown}: cannot read the mesh file: no such file"));
    }
    let file = match extension.as_str() {
        "obj" => obj::read_obj(path),
        "ply" => ply::read_ply(path),
        _ => self::gltf::read_gltf(path),
    }
    .map_err(|e| format!("{shown}: {e}"))?;
    let mut warnings: Vec<String> = file
        .warnings
        .iter()
        .map(|w| format!("{shown}: {w}"))
        .collect();
    if file.has_other_textures {
        warnings.push(format!(
            "{shown}: texture maps other than the base colour, metallic-roughness, emission and \
             normal maps (KHR_materials_specular's) are ignored"
        ));
    }
    // The file's materials become scene materials, but only when they are used.
    let mut material_for_file: Vec<Option<u32>> = vec![None; file.materials.len()];
    let stem = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    // Each part checked and given its scene material, in the file's order; a geometry used
    // by many parts is checked once.
    let mut prepared: Vec<PreparedPart> = Vec::with_capacity(file.parts.len());
    let mut checked = std::collections::HashSet::new();
    let mut tangent_cache: std::collections::HashMap<*const Geometry, Rc<Vec<[Vec4; 3]>>> =
        std::collections::HashMap::new();
    for part in &file.parts {
        let geometry = &*part.geometry;
        let first_use = checked.insert(Rc::as_ptr(&part.geometry));
        let count = geometry.positions.len();
        if first_use {
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
        }
        let use_normals = smooth && !geometry.normals.is_empty();
        if use_normals && first_use {
            if let Some(i) = geometry.normals.iter().position(|n| !n.is_finite()) {
                return Err(format!(
                    "{shown}: {}vertex normal {i} is not finite: {}",
                    part_prefix(&part.name),
                    geometry.normals[i]
                ));
            }
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
                match material_for_file[index] {
                    Some(m) => m,
                    None => {
                        let mut m = file.materials[index].clone();
                        let maps = &file.textures[index];
                        let name = m.name.clone();
                        let mut load = |map: &Option<(Rc<ImageSource>, Sampling)>, usage| {
                            map.as_ref()
                                .map(|(source, sampling)| {
                                    let image =
                                        texture(source, usage, path, shown, &name, textures)?;
                                    Ok::<_, String>(textures.sampled(image, sampling))
                                })
                                .transpose()
                        };
                        m.color_texture = load(&maps.color, TextureUse::Color)?;
                        m.roughness_texture =
                            load(&maps.metallic_roughness, TextureUse::MetallicRoughness)?;
                        m.emission_texture = load(&maps.emission, TextureUse::Color)?;
                        if let MaterialKind::Pbr {
                            transmission_texture,
                            layers,
                            ..
                        } = &mut m.kind
                        {
                            *transmission_texture =
                                load(&maps.transmission, TextureUse::Transmission)?;
                            layers.clearcoat_texture =
                                load(&maps.clearcoat, TextureUse::Transmission)?;
                            layers.clearcoat_roughness_texture =
                                load(&maps.clearcoat_roughness, TextureUse::MetallicRoughness)?;
                            layers.sheen_color_texture =
                                load(&maps.sheen_color, TextureUse::Color)?;
                            layers.sheen_roughness_texture =
                                load(&maps.sheen_roughness, TextureUse::SheenRoughness)?;
                            if let Some((map, scale)) = &maps.clearcoat_normal {
                                layers.clearcoat_normal_texture =
                                    load(&Some(map.clone()), TextureUse::Normal)?
                                        .map(|t| (t, *scale));
                            }
                        }
                        if let Some((map, scale)) = &maps.normal {
                            m.normal_texture =
                                load(&Some(map.clone()), TextureUse::Normal)?.map(|t| (t, *scale));
                        }
                        if let Some((color, opacity)) = &maps.color_and_opacity {
                            m.color_texture = Some(
                                textures
                                    .color_and_opacity(color.as_deref(), opacity)
                                    .map_err(|e| format!("material {name:?}: {e}"))?,
                            );
                        }
                        if let Some((roughness, metallic)) = &maps.roughness_and_metallic {
                            m.roughness_texture = Some(
                                textures
                                    .roughness_and_metallic(
                                        roughness.as_deref(),
                                        metallic.as_deref(),
                                    )
                                    .map_err(|e| format!("material {name:?}: {e}"))?,
                            );
                        }
                        m.name = format!("{stem}/{}", m.name);
                        let id = scene_materials.len() as u32;
                        scene_materials.push(m);
                        material_for_file[index] = Some(id);
                        id
                    }
                }
            }
        };
        // Normal maps (the coat's too) need tangents at every corner (tangents.rs), read or
        // made once per geometry.
        let corners = if scene_materials[material as usize].has_normal_map() {
            if geometry.uvs.len() != count {
                return Err(format!(
                    "{shown}: {}material {:?} has a normal map, but these triangles have no \
                     texture coordinates (TEXCOORD_0) to lay it out",
                    part_prefix(&part.name),
                    scene_materials[material as usize].name
                ));
            }
            let key = Rc::as_ptr(&part.geometry);
            Some(
                tangent_cache
                    .entry(key)
                    .or_insert_with(|| {
                        Rc::new(tangents::corner_tangents(geometry).unwrap_or_default())
                    })
                    .clone(),
            )
        } else {
            None
        };
        prepared.push(PreparedPart {
            material,
            use_normals,
            corners,
        });
    }

    let two_level: Vec<bool> = prepared
        .iter()
        .map(|p| scene_materials[p.material as usize].two_level())
        .collect();
    let plan =
        reuse::plan(&file.parts, placements, &two_level).map_err(|e| format!("{shown}: {e}"))?;
    // Copies are counted before any is made: many placements of a large file would otherwise
    // fill the memory before the count is seen.
    let faces: usize = file
        .parts
        .iter()
        .zip(&plan.copied)
        .filter(|(_, copied)| **copied)
        .map(|(p, _)| p.geometry.indices.len())
        .sum();
    let copies = faces.saturating_mul(placements.len());
    // The copied geometry's own triangles, each geometry once: more than those are copies.
    let mut seen = std::collections::HashSet::new();
    let copied_once: usize = file
        .parts
        .iter()
        .zip(&plan.copied)
        .filter(|(p, copied)| **copied && seen.insert(Rc::as_ptr(&p.geometry)))
        .map(|(p, _)| p.geometry.indices.len())
        .sum();
    if copies > MAX_PLACED_TRIANGLES && copies > copied_once {
        return Err(format!(
            "{shown}: {faces} triangles to copy (a mesh the file reuses counted at each use) \
             placed {} time{} are {copies} triangles, more than the {MAX_PLACED_TRIANGLES} one \
             mesh entry may copy; triangles are copied when their material emits light, is \
             alpha-tested or blended, or has a normal map (the two-level structure holds none \
             of those)",
            placements.len(),
            if placements.len() == 1 { "" } else { "s" }
        ));
    }
    let mut triangles = Vec::new();
    let mut degenerate = 0usize;
    let too_many =
        || format!("{shown}: more than {MAX_TRIANGLES} triangles; glint holds at most that many");
    // Placement after placement, each with every copied part in the file's order: one
    // placement is exactly the mesh without instances.
    for scene_matrix in placements {
        for (p, part) in file
            .parts
            .iter()
            .enumerate()
            .filter(|(p, _)| plan.copied[*p])
        {
            place_part(
                part,
                &prepared[p],
                *scene_matrix * part.transform,
                &mut triangles,
                &mut degenerate,
            )
            .map_err(|f| not_finite(shown, part, f))?;
            if triangles.len() > MAX_TRIANGLES {
                return Err(too_many());
            }
        }
    }
    let mut instanced = Vec::new();
    let mut stored = 0usize;
    for unit in plan.stored_once {
        let mut own = Vec::new();
        for (p, matrix) in unit.members {
            let part = &file.parts[p];
            place_part(part, &prepared[p], matrix, &mut own, &mut degenerate)
                .map_err(|f| not_finite(shown, part, f))?;
        }
        stored += own.len();
        if triangles.len() + stored > MAX_TRIANGLES {
            return Err(too_many());
        }
        if !own.is_empty() {
            instanced.push(InstancedMesh {
                triangles: own,
                placements: unit.placements,
            });
        }
    }
    if degenerate > 0 {
        warnings.push(format!(
            "{shown}: skipped {degenerate} degenerate (zero-area) triangle{}",
            if degenerate == 1 { "" } else { "s" }
        ));
    }
    if triangles.is_empty() && instanced.is_empty() {
        return Err(format!(
            "{shown}: the mesh has no triangles{}",
            if degenerate > 0 {
                format!(" (all {degenerate} are degenerate)")
            } else {
                String::new()
            }
        ));
    }
    Ok(LoadedMesh {
        triangles,
        instanced,
        warnings,
    })
}

/// What placing a part needs besides its geometry and matrix, found once per part.
struct PreparedPart {
    material: u32,
    /// Whether its triangles are shaded smooth with the file's vertex normals.
    use_normals: bool,
    /// Per triangle, the tangent at each corner (for normal maps).
    corners: Option<Rc<Vec<[Vec4; 3]>>>,
}

/// Adds `part`'s triangles, moved by `matrix`, to `out`; those of zero area after the move
/// are skipped and counted in `degenerate`. A triangle that is not finite after the move is an
/// error: its index.
fn place_part(
    part: &MeshPart,
    prepared: &PreparedPart,
    matrix: Mat4,
    out: &mut Vec<Triangle>,
    degenerate: &mut usize,
) -> Result<(), usize> {
    let geometry = &*part.geometry;
    let count = geometry.positions.len();
    // Normals go through the inverse transpose of the linear part.
    let normal_matrix = Mat3::from_mat4(matrix).inverse().transpose();
    let linear = Mat3::from_mat4(matrix);
    for (f, idx) in geometry.indices.iter().enumerate() {
        let v = idx.map(|i| matrix.transform_point3(geometry.positions[i as usize]));
        let cross = (v[1] - v[0]).cross(v[2] - v[0]);
        let area2 = cross.length();
        if area2.is_nan() || area2 <= 0.0 || !area2.is_finite() {
            if !v.iter().all(|p| p.is_finite()) {
                return Err(f);
            }
            *degenerate += 1;
            continue;
        }
        let normals = prepared
            .use_normals
            .then(|| {
                idx.map(|i| (normal_matrix * geometry.normals[i as usize]).normalize_or_zero())
            })
            // A zero vertex normal cannot shade: the triangle is shaded flat.
            .filter(|n| n.iter().all(|n| *n != Vec3::ZERO));
        let uvs = (geometry.uvs.len() == count).then(|| idx.map(|i| geometry.uvs[i as usize]));
        let uvs1 = (geometry.uvs1.len() == count).then(|| idx.map(|i| geometry.uvs1[i as usize]));
        let colors =
            (geometry.colors.len() == count).then(|| idx.map(|i| geometry.colors[i as usize]));
        let tangents = prepared
            .corners
            .as_ref()
            .and_then(|c| c.get(f))
            .map(|c| c.map(|t| tangents::placed_tangent(&linear, t)));
        out.push(Triangle {
            vertices: v,
            normals,
            material: prepared.material,
            uvs,
            uvs1,
            tangents,
            colors,
        });
    }
    Ok(())
}

/// The error for face `face` of `part`, not finite once placed.
fn not_finite(shown: &str, part: &MeshPart, face: usize) -> String {
    format!(
        "{shown}: {}face {face} is not finite after the transform",
        part_prefix(&part.name)
    )
}

/// The texture of an image a mesh file's material refers to; the error names the material
/// and the image (its file, or the mesh file and element that hold it).
fn texture(
    source: &ImageSource,
    usage: TextureUse,
    mesh_path: &Path,
    shown: &str,
    material: &str,
    textures: &mut TextureSet,
) -> Result<u32, String> {
    match source {
        ImageSource::File(file) => textures
            .image(file, usage)
            .map_err(|e| format!("material {material:?}: texture {}: {e}", file.display())),
        ImageSource::Embedded { element, bytes } => textures
            .embedded_image(mesh_path, element, bytes, usage)
            .map_err(|e| format!("{shown}: material {material:?}: {element}: {e}")),
    }
}

/// A reader's message on one line: runs of whitespace (newlines, tabs) become one space.
fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn part_prefix(name: &str) -> String {
    if name.is_empty() {
        String::new()
    } else {
        format!("{name}: ")
    }
}

/// The bytes of a mesh file, if it is a regular file within [`MESH_FILE_LIMIT`].
fn read_mesh_bytes(path: &Path) -> Result<Vec<u8>, String> {
    read_regular_file(path, MESH_FILE_LIMIT, "mesh file")
}
