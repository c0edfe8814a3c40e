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

use super::gltf_instancing::{self, Attributes};
use super::gltf_material::material;
use super::gltf_nodes::placed_nodes;
use super::{
    one_line, read_mesh_bytes, FileTextures, Geometry, ImageSource, MeshFile, MeshPart,
    MAX_TRIANGLES,
};
use crate::input_file::{format_size, read_regular_file, MESH_FILE_LIMIT};
use crate::scene::texture::Sampling;
use base64::Engine as _;
use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::json;
use json::accessor::{ComponentType, Type};
use json::mesh::{Mode, Semantic};
use json::validation::Checked;
use std::collections::hash_map::{Entry, HashMap};
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// How much of a glTF extension glint reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExtensionSupport {
    /// Everything in it that a path tracer can use.
    Fully,
    /// In part: what is not read, as the docs say it (a file that uses it gets a warning).
    InPart(&'static str),
}

/// Every glTF extension glint reads, and how fully: the one list that decides which
/// extensions a file may require (`extensionsRequired`: any of these) and which ones the
/// file uses get a warning (`extensionsUsed`: those read in part, and those not listed).
/// The docs' table of extensions (docs/src/reference/meshes.md) is checked against it.
pub const GLTF_EXTENSIONS: &[(&str, ExtensionSupport)] = &[
    ("EXT_mesh_gpu_instancing", ExtensionSupport::Fully),
    ("KHR_lights_punctual", ExtensionSupport::Fully),
    ("KHR_materials_clearcoat", ExtensionSupport::Fully),
    ("KHR_materials_emissive_strength", ExtensionSupport::Fully),
    (
        "KHR_materials_ior",
        ExtensionSupport::InPart(
            "`ior` 0 (a Fresnel of 1 at every angle) is read as the default 1.5",
        ),
    ),
    ("KHR_materials_sheen", ExtensionSupport::Fully),
    (
        "KHR_materials_specular",
        ExtensionSupport::InPart("`specularTexture` and `specularColorTexture` are ignored"),
    ),
    ("KHR_materials_transmission", ExtensionSupport::Fully),
    ("KHR_materials_unlit", ExtensionSupport::Fully),
    // thicknessFactor and thicknessTexture are for rasterisers, which cannot trace the ray
    // through the mesh: glint does, so it has read all it needs.
    ("KHR_materials_volume", ExtensionSupport::Fully),
    ("KHR_mesh_quantization", ExtensionSupport::Fully),
    ("KHR_texture_transform", ExtensionSupport::Fully),
];

fn extension_support(name: &str) -> Option<ExtensionSupport> {
    GLTF_EXTENSIONS
        .iter()
        .find(|(known, _)| *known == name)
        .map(|&(_, support)| support)
}

/// Decoded vertex data may reach this many bytes per byte of the file's buffers (plus
/// [`DECODE_SLACK`]): a byte index becomes a u32, a byte normal component an f32. It bounds
/// memory when accessors overlap or a sparse accessor has no buffer view.
const DECODE_RATIO: u64 = 4;
const DECODE_SLACK: u64 = 1 << 20;

/// The file's JSON, parsed but not checked, and a `.glb`'s binary chunk.
pub(super) fn read_document(path: &Path) -> Result<(json::Root, Option<Vec<u8>>), String> {
    let bytes = read_mesh_bytes(path)?;
    // The gltf crate subtracts the header's 12 bytes from a .glb's declared length unchecked.
    if bytes.starts_with(b"glTF")
        && bytes
            .get(8..12)
            .is_none_or(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]) < 12)
    {
        return Err(
            "malformed glTF: the .glb header is cut short or declares under 12 bytes".into(),
        );
    }
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| format!("malformed glTF: {}", one_line(&e.to_string())))?;
    drop(bytes);
    let gltf::Gltf { document, blob } = gltf;
    Ok((document.into_json(), blob))
}

pub(super) fn read_gltf(path: &Path) -> Result<MeshFile, String> {
    let (root, blob) = read_document(path)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut warnings = Vec::new();
    check_extensions(&root, &mut warnings)?;
    check_references(&root)?;
    let buffers = read_buffers(&root, blob, dir)?;
    check_buffer_views(&root, &buffers)?;
    let instances = instances(&root)?;

    let mut materials = Vec::new();
    let mut textures = Vec::new();
    let mut has_other_textures = false;
    // Each image read once, however many materials use it.
    let mut images: Vec<Option<Rc<ImageSource>>> = vec![None; root.images.len()];
    for (i, m) in root.materials.iter().enumerate() {
        let (material, maps, other_textures) = material(&root, m, i, &mut warnings)?;
        let mut source = |image: Option<(usize, Sampling)>| -> Result<_, String> {
            let Some((i, sampling)) = image else {
                return Ok(None);
            };
            if images[i].is_none() {
                images[i] = Some(Rc::new(image_source(&root, &buffers, i, dir)?));
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

    // Every primitive the scene places is checked before any is read, and counted: each mesh's
    // triangles once (what is stored once, src/scene/mesh/reuse.rs, costs no more), and the
    // parts made, one per primitive placed, within glint's triangle limit. What is copied per
    // placement is bounded where the materials are known (`load_placed`, MAX_PLACED_TRIANGLES),
    // before any copy is made.
    let mut plans: HashMap<usize, Vec<PrimitivePlan>> = HashMap::new();
    let (mut unique, mut placed_parts) = (0u64, 0u64);
    for instance in &instances {
        let plan = match plans.entry(instance.mesh) {
            Entry::Occupied(plan) => plan.into_mut(),
            Entry::Vacant(slot) => {
                let plan = slot.insert(mesh_plan(&root, &buffers, instance.mesh)?);
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

    let mut decoder = Decoder {
        root: &root,
        buffers: &buffers,
        budget: DECODE_RATIO * buffers.total + DECODE_SLACK,
    };
    let mut geometries: HashMap<(usize, usize), Rc<Geometry>> = HashMap::new();
    let mut parts = Vec::new();
    for instance in &instances {
        let placements = match &instance.gpu_instances {
            Some(attributes) => {
                gltf_instancing::transforms(attributes, instance.node, &mut decoder)?
                    .into_iter()
                    .map(|m| instance.transform * m)
                    .collect()
            }
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
    Ok(MeshFile {
        parts,
        materials,
        textures,
        has_other_textures,
        warnings,
    })
}

/// A required extension glint does not read is an error; extensions used get one warning.
fn check_extensions(root: &json::Root, warnings: &mut Vec<String>) -> Result<(), String> {
    for (i, name) in root.extensions_required.iter().enumerate() {
        if extension_support(name).is_none() {
            let read: Vec<&str> = GLTF_EXTENSIONS.iter().map(|&(e, _)| e).collect();
            return Err(format!(
                "extensionsRequired[{i}]: the file requires {name}, which glint does not support \
                 (it reads {})",
                read.join(", ")
            ));
        }
    }
    let mut partly: Vec<&str> = root
        .extensions_used
        .iter()
        .map(String::as_str)
        .filter(|e| extension_support(e) != Some(ExtensionSupport::Fully))
        .collect();
    partly.sort_unstable();
    partly.dedup();
    if !partly.is_empty() {
        warnings.push(format!(
            "uses glTF extensions that glint reads in part or not at all: {}",
            partly.join(", ")
        ));
    }
    Ok(())
}

/// "accessor 99 does not exist (the file has 4)", when `index` is out of range.
pub(super) fn exists(index: usize, len: usize, kind: &str) -> Result<usize, String> {
    if index < len {
        Ok(index)
    } else {
        let plural = match (len, kind) {
            (1, _) => "",
            (_, "mesh") => "es",
            _ => "s",
        };
        Err(format!(
            "{kind} {index} does not exist (the file has {len} {kind}{plural})"
        ))
    }
}

/// The references between buffers, views, accessors and images, checked once so that the
/// rest can index freely.
fn check_references(root: &json::Root) -> Result<(), String> {
    let views = root.buffer_views.len();
    for (i, view) in root.buffer_views.iter().enumerate() {
        exists(view.buffer.value(), root.buffers.len(), "buffer")
            .map_err(|e| format!("bufferViews[{i}].buffer: {e}"))?;
    }
    for (i, a) in root.accessors.iter().enumerate() {
        if let Some(v) = a.buffer_view {
            exists(v.value(), views, "buffer view")
                .map_err(|e| format!("accessors[{i}].bufferView: {e}"))?;
        }
        if let Some(s) = &a.sparse {
            exists(s.indices.buffer_view.value(), views, "buffer view")
                .map_err(|e| format!("accessors[{i}].sparse.indices.bufferView: {e}"))?;
            exists(s.values.buffer_view.value(), views, "buffer view")
                .map_err(|e| format!("accessors[{i}].sparse.values.bufferView: {e}"))?;
        }
    }
    for (i, image) in root.images.iter().enumerate() {
        if let Some(v) = image.buffer_view {
            exists(v.value(), views, "buffer view")
                .map_err(|e| format!("images[{i}].bufferView: {e}"))?;
        }
    }
    for (i, texture) in root.textures.iter().enumerate() {
        exists(texture.source.value(), root.images.len(), "image")
            .map_err(|e| format!("textures[{i}].source: {e}"))?;
    }
    Ok(())
}

/// Every buffer's bytes, each read once and cut to its `byteLength` (which must not exceed
/// what was read). External files go through the same checks as the mesh file, and all
/// buffers together stay within the mesh file limit.
fn read_buffers(
    root: &json::Root,
    mut blob: Option<Vec<u8>>,
    dir: &Path,
) -> Result<Buffers, String> {
    let declared = root
        .buffers
        .iter()
        .fold(0u64, |sum, b| sum.saturating_add(b.byte_length.0));
    if declared > MESH_FILE_LIMIT {
        return Err(format!(
            "buffers: their byteLengths add up to {declared} bytes, more than glint's limit of {} \
             for a mesh file",
            format_size(MESH_FILE_LIMIT)
        ));
    }
    let mut buffers = Vec::with_capacity(root.buffers.len());
    for (i, buffer) in root.buffers.iter().enumerate() {
        let mut data = match &buffer.uri {
            Some(uri) => read_uri(uri, dir, "buffer file").map_err(|e| format!("buffers[{i}]: {e}"))?,
            // Only the first buffer may be the .glb's binary chunk.
            None if i == 0 => blob.take().ok_or_else(|| {
                "buffers[0]: no uri, and the file has no binary chunk (a .glb's BIN) to stand for it"
                    .to_string()
            })?,
            None => {
                return Err(format!(
                    "buffers[{i}]: no uri; only buffers[0] may be a .glb's binary chunk"
                ))
            }
        };
        let length = buffer.byte_length.0;
        if (data.len() as u64) < length {
            return Err(format!(
                "buffers[{i}]: byteLength is {length}, but its data holds only {} bytes",
                data.len()
            ));
        }
        data.truncate(length as usize);
        data.shrink_to_fit();
        buffers.push(data);
    }
    Ok(Buffers {
        total: buffers.iter().map(|b| b.len() as u64).sum(),
        data: buffers,
    })
}

/// The file's buffers, each cut to its `byteLength`.
struct Buffers {
    data: Vec<Vec<u8>>,
    /// Their bytes together, which bound what may be decoded from them.
    total: u64,
}

/// The bytes a URI names: a base64 `data:` URI, a `file:` URI, or a path relative to the glTF
/// file's folder (percent-decoded, as URIs are). `what` names the file in messages.
fn read_uri(uri: &str, dir: &Path, what: &str) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, data)) = rest.split_once(";base64,") else {
            return Err("a data: URI that is not base64".to_string());
        };
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("malformed base64 in the data: URI: {e}"));
    }
    let path = resolve_uri(uri, dir)?;
    read_regular_file(&path, MESH_FILE_LIMIT, what).map_err(|e| format!("{}: {e}", path.display()))
}

/// The file a (non-`data:`) URI names.
fn resolve_uri(uri: &str, dir: &Path) -> Result<PathBuf, String> {
    let rest = match uri
        .strip_prefix("file://")
        .or_else(|| uri.strip_prefix("file:"))
    {
        Some(rest) => rest,
        None if uri.contains(':') => {
            return Err(format!(
                "URI {uri:?}: only relative paths, file: and data: URIs are read"
            ))
        }
        None => uri,
    };
    let decoded = urlencoding::decode(rest)
        .map_err(|_| format!("URI {uri:?}: its percent-encoding is not UTF-8"))?;
    Ok(dir.join(&*decoded))
}

fn check_buffer_views(root: &json::Root, buffers: &Buffers) -> Result<(), String> {
    for (i, view) in root.buffer_views.iter().enumerate() {
        let b = view.buffer.value();
        let offset = view.byte_offset.map_or(0, |o| o.0);
        let length = view.byte_length.0;
        let available = buffers.data[b].len() as u64;
        if offset.checked_add(length).is_none_or(|end| end > available) {
            return Err(format!(
                "bufferViews[{i}]: byteOffset {offset} + byteLength {length} run past the end of \
                 buffers[{b}] ({available} bytes)"
            ));
        }
        if let Some(stride) = view.byte_stride {
            if !(4..=252).contains(&stride.0) || stride.0 % 4 != 0 {
                return Err(format!(
                    "bufferViews[{i}]: byteStride {} must be a multiple of 4 in [4, 252]",
                    stride.0
                ));
            }
        }
    }
    Ok(())
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
/// (`gltf_nodes.rs` walks the hierarchy).
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
                gpu_instances: gltf_instancing::attributes(root, placed.node)?,
            });
        }
    }
    Ok(out)
}

/// Where image `i` comes from: a file its URI names, or bytes in the glTF file (a buffer view
/// or a base64 `data:` URI), which must be a PNG or JPEG image as glTF requires.
fn image_source(
    root: &json::Root,
    buffers: &Buffers,
    i: usize,
    dir: &Path,
) -> Result<ImageSource, String> {
    let element = format!("images[{i}]");
    let image = &root.images[i];
    let bytes: Vec<u8> = match (&image.uri, image.buffer_view) {
        (Some(uri), _) if !uri.starts_with("data:") => {
            return Ok(ImageSource::File(
                resolve_uri(uri, dir).map_err(|e| format!("{element}: {e}"))?,
            ))
        }
        (Some(uri), _) => read_uri(uri, dir, "image").map_err(|e| format!("{element}: {e}"))?,
        (None, Some(v)) => {
            // Inside its buffer: check_buffer_views saw it fit.
            let view = &root.buffer_views[v.value()];
            let start = view.byte_offset.map_or(0, |o| o.0) as usize;
            buffers.data[view.buffer.value()][start..start + view.byte_length.0 as usize].to_vec()
        }
        (None, None) => return Err(format!("{element}: neither a uri nor a bufferView")),
    };
    match image::guess_format(&bytes) {
        Ok(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
        Ok(other) => {
            return Err(format!(
                "{element}: a {other:?} image; glTF images glint reads are PNG and JPEG"
            ))
        }
        Err(_) => return Err(format!("{element}: not a PNG or JPEG image")),
    }
    Ok(ImageSource::Embedded {
        element,
        bytes: bytes.into(),
    })
}

/// A primitive, checked, with the accessors to read.
struct PrimitivePlan {
    /// `meshes[m].primitives[p]`, for messages.
    name: String,
    positions: usize,
    normals: Option<usize>,
    uvs: Option<usize>,
    /// TEXCOORD_1.
    uvs1: Option<usize>,
    tangents: Option<usize>,
    /// COLOR_0, and whether it is a VEC4 (RGBA) rather than a VEC3 (RGB).
    colors: Option<(usize, bool)>,
    indices: Option<usize>,
    material: Option<usize>,
    triangles: u64,
}

/// Checks mesh `m`'s primitives and their accessors against the buffers, reading nothing.
fn mesh_plan(root: &json::Root, buffers: &Buffers, m: usize) -> Result<Vec<PrimitivePlan>, String> {
    let mut plans = Vec::new();
    for (p, primitive) in root.meshes[m].primitives.iter().enumerate() {
        let name = format!("meshes[{m}].primitives[{p}]");
        match primitive.mode {
            Checked::Valid(Mode::Triangles) => {}
            Checked::Valid(other) => {
                return Err(format!(
                    "{name}: mode {other:?} is not supported; only triangle lists are"
                ))
            }
            Checked::Invalid => return Err(format!("{name}.mode: not a glTF primitive mode")),
        }
        let attribute = |semantic: Semantic, label: &str, kind: Type| {
            primitive
                .attributes
                .get(&Checked::Valid(semantic))
                .map(|a| {
                    let field = format!("{name}.attributes.{label}");
                    let a = exists(a.value(), root.accessors.len(), "accessor")
                        .map_err(|e| format!("{field}: {e}"))?;
                    let layout = Layout::of(root, buffers, a, kind, false)?;
                    Ok::<_, String>((a, layout.count))
                })
                .transpose()
        };
        let (positions, vertices) = attribute(Semantic::Positions, "POSITION", Type::Vec3)?
            .ok_or_else(|| format!("{name}.attributes: no POSITION"))?;
        let normals = attribute(Semantic::Normals, "NORMAL", Type::Vec3)?;
        let uvs = attribute(Semantic::TexCoords(0), "TEXCOORD_0", Type::Vec2)?;
        let uvs1 = attribute(Semantic::TexCoords(1), "TEXCOORD_1", Type::Vec2)?;
        let tangents = attribute(Semantic::Tangents, "TANGENT", Type::Vec4)?;
        let colors = match primitive
            .attributes
            .get(&Checked::Valid(Semantic::Colors(0)))
        {
            Some(a) => {
                let field = format!("{name}.attributes.COLOR_0");
                let a = exists(a.value(), root.accessors.len(), "accessor")
                    .map_err(|e| format!("{field}: {e}"))?;
                let rgba = color_accessor(root, a).map_err(|e| format!("{field}: {e}"))?;
                let kind = if rgba { Type::Vec4 } else { Type::Vec3 };
                let layout = Layout::of(root, buffers, a, kind, false)?;
                Some(((a, rgba), layout.count))
            }
            None => None,
        };
        for (label, other) in [
            ("NORMAL", normals),
            ("TEXCOORD_0", uvs),
            ("TEXCOORD_1", uvs1),
            ("TANGENT", tangents),
            ("COLOR_0", colors.map(|((a, _), count)| (a, count))),
        ] {
            if let Some((a, count)) = other {
                if count != vertices {
                    return Err(format!(
                        "{name}.attributes.{label}: accessors[{a}] has {count} elements, but \
                         POSITION (accessors[{positions}]) has {vertices}"
                    ));
                }
            }
        }
        let indices = match primitive.indices {
            Some(i) => {
                let i = exists(i.value(), root.accessors.len(), "accessor")
                    .map_err(|e| format!("{name}.indices: {e}"))?;
                Some((i, Layout::of(root, buffers, i, Type::Scalar, true)?.count))
            }
            None => None,
        };
        let material = match primitive.material {
            Some(i) => Some(
                exists(i.value(), root.materials.len(), "material")
                    .map_err(|e| format!("{name}.material: {e}"))?,
            ),
            None => None,
        };
        plans.push(PrimitivePlan {
            name,
            positions,
            normals: normals.map(|(a, _)| a),
            uvs: uvs.map(|(a, _)| a),
            uvs1: uvs1.map(|(a, _)| a),
            tangents: tangents.map(|(a, _)| a),
            colors: colors.map(|(a, _)| a),
            indices: indices.map(|(a, _)| a),
            material,
            triangles: indices.map_or(vertices, |(_, count)| count) as u64 / 3,
        });
    }
    Ok(plans)
}

/// Whether COLOR_0's accessor `a` is RGBA (VEC4) rather than RGB (VEC3), after checking it is
/// one of the forms glTF allows: VEC3 or VEC4 of FLOAT, or of normalized UNSIGNED_BYTE or
/// UNSIGNED_SHORT.
fn color_accessor(root: &json::Root, a: usize) -> Result<bool, String> {
    let accessor = &root.accessors[a];
    let field = format!("accessors[{a}]");
    let rgba = match accessor.type_ {
        Checked::Valid(Type::Vec3) => false,
        Checked::Valid(Type::Vec4) => true,
        Checked::Valid(other) => {
            return Err(format!(
                "{field}: type {}, but COLOR_0 must be VEC3 or VEC4",
                type_name(other)
            ))
        }
        Checked::Invalid => return Err(format!("{field}.type: not a glTF accessor type")),
    };
    match accessor.component_type {
        Checked::Valid(json::accessor::GenericComponentType(ComponentType::F32)) => {}
        Checked::Valid(json::accessor::GenericComponentType(
            c @ (ComponentType::U8 | ComponentType::U16),
        )) => {
            if !accessor.normalized {
                return Err(format!(
                    "{field}: componentType {} without \"normalized\": true; COLOR_0 must be \
                     FLOAT or normalized UNSIGNED_BYTE or UNSIGNED_SHORT",
                    component_name(c)
                ));
            }
        }
        Checked::Valid(json::accessor::GenericComponentType(c)) => {
            return Err(format!(
                "{field}: componentType {}; COLOR_0 must be FLOAT or normalized UNSIGNED_BYTE or \
                 UNSIGNED_SHORT",
                component_name(c)
            ))
        }
        Checked::Invalid => {
            return Err(format!("{field}.componentType: not a glTF component type"))
        }
    }
    Ok(rgba)
}

/// Where an accessor's elements lie, checked against its buffer views.
pub(super) struct Layout<'a> {
    index: usize,
    count: usize,
    component: ComponentType,
    components: usize,
    normalized: bool,
    /// The bytes from the first element on, and the distance between elements; `None`: zeros.
    data: Option<(&'a [u8], usize)>,
    sparse: Option<Sparse<'a>>,
}

struct Sparse<'a> {
    count: usize,
    index_type: ComponentType,
    indices: &'a [u8],
    values: &'a [u8],
}

fn component_size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn component_name(c: ComponentType) -> &'static str {
    match c {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

fn type_name(t: Type) -> &'static str {
    match t {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

/// The bytes of buffer view `v` from `offset`, which must hold `needed` bytes.
fn view_bytes<'a>(
    root: &json::Root,
    buffers: &'a Buffers,
    v: usize,
    offset: u64,
    needed: u64,
    what: &dyn Fn() -> String,
) -> Result<&'a [u8], String> {
    let view = &root.buffer_views[v];
    let length = view.byte_length.0;
    if offset.checked_add(needed).is_none_or(|end| end > length) {
        return Err(format!(
            "{}: needs {needed} bytes from byteOffset {offset}, but bufferViews[{v}] holds {length}",
            what()
        ));
    }
    // Inside the buffer: check_buffer_views saw the view fit.
    let start = view.byte_offset.map_or(0, |o| o.0) + offset;
    Ok(&buffers.data[view.buffer.value()][start as usize..(start + needed) as usize])
}

impl<'a> Layout<'a> {
    /// Accessor `a`, of type `kind`: indices (`is_index`: unsigned integers) or a vertex
    /// attribute (any component type but UNSIGNED_INT; integers are KHR_mesh_quantization's).
    fn of(
        root: &json::Root,
        buffers: &'a Buffers,
        a: usize,
        kind: Type,
        is_index: bool,
    ) -> Result<Layout<'a>, String> {
        let accessor = &root.accessors[a];
        let field = format!("accessors[{a}]");
        let Checked::Valid(t) = accessor.type_ else {
            return Err(format!("{field}.type: not a glTF accessor type"));
        };
        let Checked::Valid(json::accessor::GenericComponentType(component)) =
            accessor.component_type
        else {
            return Err(format!("{field}.componentType: not a glTF component type"));
        };
        if t != kind {
            return Err(format!(
                "{field}: type {}, but this use needs {}",
                type_name(t),
                type_name(kind)
            ));
        }
        let allowed = if is_index {
            matches!(
                component,
                ComponentType::U8 | ComponentType::U16 | ComponentType::U32
            )
        } else {
            component != ComponentType::U32
        };
        if !allowed {
            return Err(format!(
                "{field}: componentType {} is not allowed for {}",
                component_name(component),
                if is_index {
                    "indices"
                } else {
                    "this attribute"
                }
            ));
        }
        let components = match kind {
            Type::Scalar => 1,
            Type::Vec2 => 2,
            Type::Vec3 => 3,
            _ => 4,
        };
        let element = (components * component_size(component)) as u64;
        let count = accessor.count.0;
        let data = match accessor.buffer_view {
            Some(v) => {
                let v = v.value();
                let stride = root.buffer_views[v]
                    .byte_stride
                    .map_or(element, |s| s.0 as u64);
                if stride < element {
                    return Err(format!(
                        "{field}: bufferViews[{v}]'s byteStride {stride} is less than one element \
                         ({} of {}, {element} bytes)",
                        type_name(kind),
                        component_name(component)
                    ));
                }
                let offset = accessor.byte_offset.map_or(0, |o| o.0);
                // The last element ends `element` bytes after its start.
                let needed = match count {
                    0 => 0,
                    c => (c - 1)
                        .checked_mul(stride)
                        .and_then(|n| n.checked_add(element))
                        .unwrap_or(u64::MAX),
                };
                let what = || format!("{field}: {count} elements with stride {stride}");
                Some((
                    view_bytes(root, buffers, v, offset, needed, &what)?,
                    stride as usize,
                ))
            }
            None => {
                // Zeros, but for the sparse values: nothing bounds the count but the file's
                // size, so the elements must not outnumber what its buffers could hold.
                if count.saturating_mul(element) > buffers.total {
                    return Err(format!(
                        "{field}: {count} elements of {element} bytes without a bufferView, more \
                         than the file's {} bytes of buffers could hold",
                        buffers.total
                    ));
                }
                None
            }
        };
        let sparse = match &accessor.sparse {
            None => None,
            Some(s) => {
                let sparse_count = s.count.0;
                if sparse_count > count {
                    return Err(format!(
                        "{field}.sparse.count: {sparse_count}, more than the accessor's {count} \
                         elements"
                    ));
                }
                let Checked::Valid(json::accessor::IndexComponentType(index_type)) =
                    s.indices.component_type
                else {
                    return Err(format!(
                        "{field}.sparse.indices.componentType: not a glTF component type"
                    ));
                };
                if !matches!(
                    index_type,
                    ComponentType::U8 | ComponentType::U16 | ComponentType::U32
                ) {
                    return Err(format!(
                        "{field}.sparse.indices.componentType: {} is not an index type",
                        component_name(index_type)
                    ));
                }
                let index_bytes = sparse_count.saturating_mul(component_size(index_type) as u64);
                let what = || format!("{field}.sparse.indices: {sparse_count} indices");
                let indices = view_bytes(
                    root,
                    buffers,
                    s.indices.buffer_view.value(),
                    s.indices.byte_offset.0,
                    index_bytes,
                    &what,
                )?;
                let what = || format!("{field}.sparse.values: {sparse_count} values");
                let values = view_bytes(
                    root,
                    buffers,
                    s.values.buffer_view.value(),
                    s.values.byte_offset.0,
                    sparse_count.saturating_mul(element),
                    &what,
                )?;
                Some(Sparse {
                    count: sparse_count as usize,
                    index_type,
                    indices,
                    values,
                })
            }
        };
        Ok(Layout {
            index: a,
            count: count as usize,
            component,
            components,
            normalized: accessor.normalized,
            data,
            sparse,
        })
    }

    fn element_size(&self) -> usize {
        self.components * component_size(self.component)
    }

    /// Element `i`'s bytes in the dense data (`None`: zeros).
    fn element(&self, i: usize) -> Option<&'a [u8]> {
        self.data.map(|(bytes, stride)| &bytes[i * stride..])
    }

    /// Each sparse entry: the element it replaces and the new value's bytes.
    fn sparse_entries(&self) -> Result<Vec<(usize, &'a [u8])>, String> {
        let Some(s) = &self.sparse else {
            return Ok(Vec::new());
        };
        let size = component_size(s.index_type);
        (0..s.count)
            .map(|k| {
                let target = unsigned(&s.indices[k * size..], s.index_type) as usize;
                if target >= self.count {
                    return Err(format!(
                        "accessors[{}].sparse.indices[{k}]: {target}, but the accessor has only {} \
                         elements",
                        self.index, self.count
                    ));
                }
                Ok((target, &s.values[k * self.element_size()..]))
            })
            .collect()
    }

    /// Every element's components as f32, normalized integers mapped to [0, 1] or [-1, 1].
    pub(super) fn floats<const N: usize>(&self) -> Result<Vec<[f32; N]>, String> {
        debug_assert_eq!(N, self.components);
        let component = |bytes: &[u8], c: usize| -> f32 {
            let size = component_size(self.component);
            float(&bytes[c * size..], self.component, self.normalized)
        };
        let mut out: Vec<[f32; N]> = (0..self.count)
            .map(|i| match self.element(i) {
                Some(e) => std::array::from_fn(|c| component(e, c)),
                None => [0.0; N],
            })
            .collect();
        for (target, bytes) in self.sparse_entries()? {
            out[target] = std::array::from_fn(|c| component(bytes, c));
        }
        Ok(out)
    }

    fn indices(&self) -> Result<Vec<u32>, String> {
        let mut out: Vec<u32> = (0..self.count)
            .map(|i| self.element(i).map_or(0, |e| unsigned(e, self.component)))
            .collect();
        for (target, bytes) in self.sparse_entries()? {
            out[target] = unsigned(bytes, self.component);
        }
        Ok(out)
    }
}

fn unsigned(bytes: &[u8], c: ComponentType) -> u32 {
    match c {
        ComponentType::U8 | ComponentType::I8 => bytes[0] as u32,
        ComponentType::U16 | ComponentType::I16 => u16::from_le_bytes([bytes[0], bytes[1]]) as u32,
        ComponentType::U32 | ComponentType::F32 => {
            u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
        }
    }
}

/// One component as glTF defines it: floats as they are, normalized integers mapped to
/// [0, 1] (unsigned) or [-1, 1] (signed), other integers as their value.
fn float(bytes: &[u8], c: ComponentType, normalized: bool) -> f32 {
    let (value, max) = match c {
        ComponentType::F32 => {
            return f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        }
        ComponentType::I8 => (bytes[0] as i8 as f32, 127.0),
        ComponentType::U8 => (bytes[0] as f32, 255.0),
        ComponentType::I16 => (i16::from_le_bytes([bytes[0], bytes[1]]) as f32, 32767.0),
        ComponentType::U16 => (u16::from_le_bytes([bytes[0], bytes[1]]) as f32, 65535.0),
        ComponentType::U32 => (unsigned(bytes, c) as f32, u32::MAX as f32),
    };
    if normalized {
        (value / max).max(-1.0)
    } else {
        value
    }
}

/// Reads primitives' accessors, keeping the decoded bytes within a budget set by the size of
/// the file's buffers.
pub(super) struct Decoder<'a> {
    root: &'a json::Root,
    buffers: &'a Buffers,
    budget: u64,
}

impl Decoder<'_> {
    pub(super) fn layout(
        &mut self,
        a: usize,
        kind: Type,
        is_index: bool,
    ) -> Result<Layout<'_>, String> {
        let layout = Layout::of(self.root, self.buffers, a, kind, is_index)?;
        let bytes = layout.count as u64 * layout.components as u64 * 4;
        if bytes > self.budget {
            return Err(format!(
                "accessors[{a}]: decoding it would bring the file's vertex data to more than \
                 {DECODE_RATIO} bytes per byte of its {} bytes of buffers (do its accessors \
                 overlap?)",
                self.buffers.total
            ));
        }
        self.budget -= bytes;
        Ok(layout)
    }

    fn geometry(&mut self, plan: &PrimitivePlan) -> Result<Geometry, String> {
        let positions = self
            .layout(plan.positions, Type::Vec3, false)?
            .floats::<3>()?
            .into_iter()
            .map(Vec3::from)
            .collect::<Vec<_>>();
        let normals = match plan.normals {
            Some(a) => self
                .layout(a, Type::Vec3, false)?
                .floats::<3>()?
                .into_iter()
                .map(Vec3::from)
                .collect(),
            None => Vec::new(),
        };
        // glTF's texture coordinates have v down (the image's top row at v = 0).
        let mut uvs = |accessor: Option<usize>| -> Result<Vec<Vec2>, String> {
            Ok(match accessor {
                Some(a) => self
                    .layout(a, Type::Vec2, false)?
                    .floats::<2>()?
                    .into_iter()
                    .map(|[u, v]| Vec2::new(u, 1.0 - v))
                    .collect(),
                None => Vec::new(),
            })
        };
        let (uvs, uvs1) = (uvs(plan.uvs)?, uvs(plan.uvs1)?);
        // glTF's tangents point along increasing u, and their w (±1) makes the bitangent
        // w · normal × tangent point along increasing v of glTF's v-up normal-map convention,
        // which is glint's v: both are kept as they are.
        let tangents = match plan.tangents {
            Some(a) => self
                .layout(a, Type::Vec4, false)?
                .floats::<4>()?
                .into_iter()
                .map(Vec4::from)
                .collect(),
            None => Vec::new(),
        };
        // Linear RGB(A) multiplying the base colour: a VEC3's alpha is 1. Floats outside
        // [0, 1] (or not finite) would make a surface reflect more light than reaches it.
        let colors = match plan.colors {
            Some((a, rgba)) => {
                let colors: Vec<Vec4> = if rgba {
                    self.layout(a, Type::Vec4, false)?
                        .floats::<4>()?
                        .into_iter()
                        .map(Vec4::from)
                        .collect()
                } else {
                    self.layout(a, Type::Vec3, false)?
                        .floats::<3>()?
                        .into_iter()
                        .map(|c| Vec3::from(c).extend(1.0))
                        .collect()
                };
                if let Some((i, c)) = colors
                    .iter()
                    .enumerate()
                    .find(|(_, c)| !(c.cmpge(Vec4::ZERO).all() && c.cmple(Vec4::ONE).all()))
                {
                    return Err(format!(
                        "{}.attributes.COLOR_0: accessors[{a}] element {i} is {c}, outside [0, 1]",
                        plan.name
                    ));
                }
                colors
            }
            None => Vec::new(),
        };
        let flat: Vec<u32> = match plan.indices {
            Some(a) => self.layout(a, Type::Scalar, true)?.indices()?,
            None => (0..positions.len() as u32).collect(),
        };
        Ok(Geometry {
            positions,
            normals,
            uvs,
            uvs1,
            tangents,
            colors,
            indices: flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        })
    }
}
