//! Triangle meshes from OBJ (`tobj`), glTF (`gltf`) and PLY (`ply-rs-bw`) files: read, checked,
//! transformed into the scene, and their own materials mapped to glint's (README.md has the
//! table). Everything is checked here, before rendering: unreadable or malformed files, vertices
//! that are not finite, indices out of range, meshes left with no triangles.
//!
//! One file per format (`obj.rs`, `ply.rs`, and glTF's folder `gltf/`, whose `mod.rs` lists its
//! files), each yielding the parts in `parts.rs`, its material values passing `checks.rs`. This
//! file loads a `[[meshes]]` entry in steps: the file read by its format, each part checked and
//! given its scene material (`prepare.rs`, the file's own materials through
//! `file_materials.rs`, normal maps' tangents through `tangents.rs`), which parts are stored
//! once rather than copied (`reuse.rs`), and both placed (`placement.rs`).

mod checks;
mod file_materials;
mod gltf;
mod obj;
mod parts;
mod placement;
mod ply;
mod prepare;
mod reuse;
mod tangents;

pub use self::gltf::cameras::{gltf_camera, no_such_camera, FileCamera};
pub use self::gltf::lights::{gltf_lights, unit, LUMENS_PER_WATT};
pub use self::gltf::{ExtensionSupport, GLTF_EXTENSIONS};
pub use placement::{placed, MeshTransform};

// What the format readers (obj.rs, ply.rs, gltf/) take from here.
use checks::{check_emission, check_ior, check_normal_scale, check_reflectance};
pub(super) use parts::{FileTextures, Geometry, ImageSource, MeshFile, MeshPart};

use super::texture::TextureSet;
use super::{InstancedMesh, Material, Triangle};
use crate::input_file::{read_regular_file, MESH_FILE_LIMIT};
use glam::Mat4;
use placement::Placer;
use std::path::Path;

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

/// Whether `path` names a glTF file (`.gltf`, `.glb`), by its extension.
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| matches!(e.to_string_lossy().to_lowercase().as_str(), "gltf" | "glb"))
}

/// The start of the error for a part without a material (a model file gives those parts a
/// default material instead, `src/scene/model.rs`).
pub const NO_MATERIAL: &str = "the file gives no material for these triangles";

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
    let file = read_file(path, shown)?;
    let mut warnings = file_warnings(&file, shown);
    let prepared = prepare::prepare_parts(
        &file,
        path,
        shown,
        material,
        smooth,
        scene_materials,
        textures,
    )?;
    let two_level: Vec<bool> = prepared
        .iter()
        .map(|p| scene_materials[p.material as usize].two_level())
        .collect();
    let plan =
        reuse::plan(&file.parts, placements, &two_level).map_err(|e| format!("{shown}: {e}"))?;
    placement::check_copy_count(&file, &plan, placements.len(), shown)?;
    let mut placer = Placer {
        file: &file,
        prepared: &prepared,
        shown,
        degenerate: 0,
    };
    let triangles = placer.copies(placements, &plan.copied)?;
    let instanced = placer.stored_once(plan.stored_once, triangles.len())?;
    let degenerate = placer.degenerate;
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

/// The mesh file read by the reader its extension names (`.obj`, `.gltf`, `.glb`, `.ply`);
/// another extension, or no file, is an error.
fn read_file(path: &Path, shown: &str) -> Result<MeshFile, String> {
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
    match extension.as_str() {
        "obj" => obj::read_obj(path),
        "ply" => ply::read_ply(path),
        _ => self::gltf::read_gltf(path),
    }
    .map_err(|e| format!("{shown}: {e}"))
}

/// The file's warnings, each a line naming it.
fn file_warnings(file: &MeshFile, shown: &str) -> Vec<String> {
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
    warnings
}

/// A reader's message on one line: runs of whitespace (newlines, tabs) become one space.
fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// How messages name a part before their text: its name and a colon, or nothing.
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
