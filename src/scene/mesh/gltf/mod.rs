//! glTF 2.0 files (`.gltf` with external or embedded buffers, binary `.glb`): the default
//! scene's node hierarchy, triangle-list primitives and their materials.
//!
//! Nothing in the file is trusted before it is checked. The `gltf` crate only parses the JSON
//! and splits a `.glb`; its validation and its accessor reader are not used (both panic on some
//! malformed files, and its reader allocates whatever a sparse accessor's `count` says). Here,
//! before any vertex is read: every index the reader follows is in range; each buffer is read
//! like the mesh file itself (a regular file within the size limit, see `src/input_file.rs`)
//! and its `byteLength` checked against the bytes read; each buffer view lies inside its
//! buffer; each accessor's elements (offset, stride, count, sparse entries) lie inside its
//! buffer view; the node hierarchy is a set of trees (no cycles, one parent at most), so each
//! node is visited once; and the triangles the nodes place and the data decoded stay within
//! bounds set by the file's real size. Each error names the element (`accessors[3]`).
//!
//! In this folder, in the order a file is read: `document.rs` (the JSON and buffers),
//! `extensions.rs`, `nodes.rs` (the hierarchy), `material.rs` and `texture_ref.rs` (its
//! texture references), `primitives.rs` and `accessor.rs` (the vertex data), `instancing.rs`
//! (EXT_mesh_gpu_instancing), and the cameras and punctual lights (`cameras.rs`, `lights.rs`)
//! that hang from the nodes.

mod accessor;
pub(super) mod cameras;
mod document;
mod extensions;
mod instancing;
pub(super) mod lights;
mod material;
mod nodes;
mod primitives;
mod texture_ref;

pub use extensions::{ExtensionSupport, GLTF_EXTENSIONS};

use crate::scene::mesh::{FileTextures, Geometry, ImageSource, MeshFile, MeshPart, MAX_TRIANGLES};
use crate::scene::texture::Sampling;
use crate::scene::Material;
use accessor::Decoder;
use document::{
    check_buffer_views, check_references, exists, image_source, read_buffers, read_document,
    Buffers,
};
use extensions::check_extensions;
use glam::Mat4;
use gltf::json;
use instancing::Attributes;
use material::material;
use nodes::placed_nodes;
use primitives::{mesh_plan, PrimitivePlan};
use std::collections::hash_map::{Entry, HashMap};
use std::path::Path;
use std::rc::Rc;

pub(super) fn read_gltf(path: &Path) -> Result<MeshFile, String> {
    let (root, blob) = read_document(path)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut warnings = Vec::new();
    check_extensions(&root, &mut warnings)?;
    check_references(&root)?;
    let buffers = read_buffers(&root, blob, dir)?;
    check_buffer_views(&root, &buffers)?;
    let instances = instances(&root)?;
    let materials = read_materials(&root, &buffers, dir, &mut warnings)?;
    let plans = plan_meshes(&root, &buffers, &instances)?;
    let parts = place_parts(&root, &buffers, &instances, &plans)?;
    Ok(MeshFile {
        parts,
        materials: materials.materials,
        textures: materials.textures,
        has_other_textures: materials.has_other_textures,
        warnings,
    })
}

/// The file's materials as glint's, with the images their textures read.
struct FileMaterials {
    materials: Vec<Material>,
    textures: Vec<FileTextures>,
    /// Whether a material has a texture glint does not read (a warning).
    has_other_textures: bool,
}

fn read_materials(
    root: &json::Root,
    buffers: &Buffers,
    dir: &Path,
    warnings: &mut Vec<String>,
) -> Result<FileMaterials, String> {
    let mut materials = Vec::new();
    let mut textures = Vec::new();
    let mut has_other_textures = false;
    // Each image read once, however many materials use it.
    let mut images: Vec<Option<Rc<ImageSource>>> = vec![None; root.images.len()];
    for (i, m) in root.materials.iter().enumerate() {
        let (material, maps, other_textures) = material(root, m, i, warnings)?;
        let mut source = |image: Option<(usize, Sampling)>| -> Result<_, String> {
            let Some((i, sampling)) = image else {
                return Ok(None);
            };
            if images[i].is_none() {
                images[i] = Some(Rc::new(image_source(root, buffers, i, dir)?));
            }
            Ok(images[i].clone().map(|image| (image, sampling)))
        };
        textures.push(FileTextures {
            color: source(maps.color)?,
            metallic_roughness: source(maps.metallic_roughness)?,
            emission: source(maps.emission)?,
            transmission: source(maps.transmission)?,
            normal: match maps.normal {
                Some((image, scale)) => source(Some(image))?.map(|s| (s, scale)),
                None => None,
            },
            clearcoat_normal: match maps.clearcoat_normal {
                Some((image, scale)) => source(Some(image))?.map(|s| (s, scale)),
                None => None,
            },
            roughness_and_metallic: None,
            clearcoat: source(maps.clearcoat)?,
            clearcoat_roughness: source(maps.clearcoat_roughness)?,
            sheen_color: source(maps.sheen_color)?,
            sheen_roughness: source(maps.sheen_roughness)?,
            color_and_opacity: None,
        });
        materials.push(material);
        has_other_textures |= other_textures;
    }
    Ok(FileMaterials {
        materials,
        textures,
        has_other_textures,
    })
}

/// Every mesh the nodes place, checked before any is read, by mesh index.
fn plan_meshes(
    root: &json::Root,
    buffers: &Buffers,
    instances: &[Instance],
) -> Result<HashMap<usize, Vec<PrimitivePlan>>, String> {
    // Every primitive the scene places is checked before any is read, and counted: each mesh's
    // triangles once (what is stored once, src/scene/mesh/reuse.rs, costs no more), and the
    // parts made, one per primitive placed, within glint's triangle limit. What is copied per
    // placement is bounded where the materials are known (`load_placed`, MAX_PLACED_TRIANGLES),
    // before any copy is made.
    let mut plans: HashMap<usize, Vec<PrimitivePlan>> = HashMap::new();
    let (mut unique, mut placed_parts) = (0u64, 0u64);
    for instance in instances {
        let plan = match plans.entry(instance.mesh) {
            Entry::Occupied(plan) => plan.into_mut(),
            Entry::Vacant(slot) => {
                let plan = slot.insert(mesh_plan(root, buffers, instance.mesh)?);
                unique += plan.iter().map(|p| p.triangles.max(1)).sum::<u64>();
                plan
            }
        };
        let copies = instance
            .gpu_instances
            .as_ref()
            .map_or(1, |a| a.count as u64);
        placed_parts += plan.len() as u64 * copies;
        if unique.max(placed_parts) > MAX_TRIANGLES as u64 {
            return Err(format!(
                "nodes[{}]: the scene's nodes place more than {MAX_TRIANGLES} {}, glint's limit",
                instance.node,
                if unique > placed_parts {
                    "triangles"
                } else {
                    "primitives"
                }
            ));
        }
    }
    Ok(plans)
}

/// The parts the nodes place, each primitive decoded once however often it is placed.
fn place_parts(
    root: &json::Root,
    buffers: &Buffers,
    instances: &[Instance],
    plans: &HashMap<usize, Vec<PrimitivePlan>>,
) -> Result<Vec<MeshPart>, String> {
    let mut decoder = Decoder::new(root, buffers);
    let mut geometries: HashMap<(usize, usize), Rc<Geometry>> = HashMap::new();
    let mut parts = Vec::new();
    for instance in instances {
        let placements = match &instance.gpu_instances {
            Some(attributes) => instancing::transforms(attributes, instance.node, &mut decoder)?
                .into_iter()
                .map(|m| instance.transform * m)
                .collect(),
            None => vec![instance.transform],
        };
        for (transform, (p, plan)) in placements.iter().flat_map(|t| {
            plans[&instance.mesh]
                .iter()
                .enumerate()
                .map(move |plan| (t, plan))
        }) {
            let key = (instance.mesh, p);
            let geometry = match geometries.get(&key) {
                Some(g) => g.clone(),
                None => {
                    let g = Rc::new(decoder.geometry(plan)?);
                    geometries.insert(key, g.clone());
                    g
                }
            };
            parts.push(MeshPart {
                geometry,
                transform: *transform,
                material: plan.material,
                name: format!("meshes[{}].primitives[{p}]", instance.mesh),
            });
        }
    }
    Ok(parts)
}

/// A mesh placed by a node.
struct Instance {
    node: usize,
    mesh: usize,
    transform: Mat4,
    /// The node's EXT_mesh_gpu_instancing instances, each placing the mesh again.
    gpu_instances: Option<Attributes>,
}

/// The meshes the scene's nodes place, with each node's world transform
/// (`nodes.rs` walks the hierarchy).
fn instances(root: &json::Root) -> Result<Vec<Instance>, String> {
    for (i, node) in root.nodes.iter().enumerate() {
        if let Some(m) = node.mesh {
            exists(m.value(), root.meshes.len(), "mesh")
                .map_err(|e| format!("nodes[{i}].mesh: {e}"))?;
        }
    }
    let mut out = Vec::new();
    for placed in placed_nodes(root)? {
        if let Some(mesh) = root.nodes[placed.node].mesh {
            out.push(Instance {
                node: placed.node,
                mesh: mesh.value(),
                transform: placed.transform,
                gpu_instances: instancing::attributes(root, placed.node)?,
            });
        }
    }
    Ok(out)
}
