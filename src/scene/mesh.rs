//! Triangle meshes from OBJ (`tobj`), glTF (`gltf`) and PLY (`ply-rs-bw`) files: read, checked,
//! transformed into the scene, and their own materials mapped to glint's (README.md has the
//! table). Everything is checked here, before rendering: unreadable or malformed files, vertices
//! that are not finite, indices out of range, meshes left with no triangles.

use super::texture::{TextureSet, TextureUse};
use super::{Material, MaterialKind, Triangle};
use crate::input_file::{read_regular_file, MESH_FILE_LIMIT};
use glam::{Mat3, Mat4, Vec2, Vec3};
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

/// The most triangles one scene may hold: every BVH reference must fit 30 bits, and far fewer
/// fit any GPU's storage binding anyway.
pub const MAX_TRIANGLES: usize = 1 << 28;

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

/// A part of a mesh file with one material: positions, optional vertex normals (as many as
/// positions), and triangles as indices into them.
pub(super) struct MeshPart {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    /// Texture coordinates (v up), as many as positions, or none.
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
    /// Index into the file's materials, if the file gives one.
    material: Option<usize>,
    /// Where the part came from, for messages (an OBJ object, a glTF mesh).
    name: String,
}

/// What a mesh file holds.
pub(super) struct MeshFile {
    parts: Vec<MeshPart>,
    materials: Vec<Material>,
    /// Per material: its colour texture's file (OBJ `map_Kd`, glTF `baseColorTexture` by URI).
    color_textures: Vec<Option<PathBuf>>,
    /// Whether any material refers to a texture glint does not use (normal maps, ...).
    has_other_textures: bool,
}

/// The triangles of one `[[meshes]]` entry, ready for the scene.
pub(super) struct LoadedMesh {
    pub triangles: Vec<Triangle>,
    /// One line each, for stderr.
    pub warnings: Vec<String>,
}

/// Reads, checks, transforms and materials one mesh file. `scene_materials` receives the file's
/// own materials when `material` is `None`, named `<file name>/<material name>`.
pub(super) fn load(
    path: &Path,
    shown: &str,
    transform: &MeshTransform,
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
        "obj" => read_obj(path),
        "ply" => read_ply(path),
        _ => read_gltf(path),
    }
    .map_err(|e| format!("{shown}: {e}"))?;
    let mut warnings = Vec::new();
    if file.has_other_textures {
        warnings.push(format!(
            "{shown}: texture maps other than the base colour (normal, roughness, emission, ...) are ignored"
        ));
    }
    // The file's materials become scene materials, but only when they are used.
    let mut material_for_file: Vec<Option<u32>> = vec![None; file.materials.len()];
    let stem = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let matrix = transform.matrix();
    // Normals go through the inverse transpose of the linear part.
    let normal_matrix = Mat3::from_mat4(matrix).inverse().transpose();
    let mut triangles = Vec::new();
    let mut degenerate = 0usize;
    for part in &file.parts {
        for (i, p) in part.positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(format!(
                    "{shown}: {}vertex {i} is not finite: {p}",
                    part_prefix(&part.name)
                ));
            }
        }
        let use_normals = smooth && !part.normals.is_empty();
        if use_normals {
            if let Some(i) = part.normals.iter().position(|n| !n.is_finite()) {
                return Err(format!(
                    "{shown}: {}vertex normal {i} is not finite: {}",
                    part_prefix(&part.name),
                    part.normals[i]
                ));
            }
        }
        let material = match material {
            Some(m) => m,
            None => {
                let Some(index) = part.material else {
                    return Err(format!(
                        "{shown}: {}the file gives no material for these triangles; set `material` in [[meshes]]",
                        part_prefix(&part.name)
                    ));
                };
                match material_for_file[index] {
                    Some(m) => m,
                    None => {
                        let mut m = file.materials[index].clone();
                        if let Some(texture) = &file.color_textures[index] {
                            let index =
                                textures.image(texture, TextureUse::Color).map_err(|e| {
                                    format!(
                                        "material {:?}: texture {}: {e}",
                                        m.name,
                                        texture.display()
                                    )
                                })?;
                            m.color_texture = Some(index);
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
        let count = part.positions.len();
        for (f, idx) in part.indices.iter().enumerate() {
            if let Some(&bad) = idx.iter().find(|&&i| i as usize >= count) {
                return Err(format!(
                    "{shown}: {}face {f} refers to vertex {bad}, but there are only {count} vertices",
                    part_prefix(&part.name)
                ));
            }
            let v = idx.map(|i| matrix.transform_point3(part.positions[i as usize]));
            let cross = (v[1] - v[0]).cross(v[2] - v[0]);
            let area2 = cross.length();
            if area2.is_nan() || area2 <= 0.0 || !area2.is_finite() {
                if !v.iter().all(|p| p.is_finite()) {
                    return Err(format!(
                        "{shown}: {}face {f} is not finite after the transform",
                        part_prefix(&part.name)
                    ));
                }
                degenerate += 1;
                continue;
            }
            let normals = use_normals
                .then(|| {
                    idx.map(|i| (normal_matrix * part.normals[i as usize]).normalize_or_zero())
                })
                // A zero vertex normal cannot shade: the triangle is shaded flat.
                .filter(|n| n.iter().all(|n| *n != Vec3::ZERO));
            let uvs = (part.uvs.len() == count).then(|| idx.map(|i| part.uvs[i as usize]));
            triangles.push(Triangle {
                vertices: v,
                normals,
                material,
                uvs,
            });
            if triangles.len() > MAX_TRIANGLES {
                return Err(format!(
                    "{shown}: more than {MAX_TRIANGLES} triangles; glint holds at most that many"
                ));
            }
        }
    }
    if degenerate > 0 {
        warnings.push(format!(
            "{shown}: skipped {degenerate} degenerate (zero-area) triangle{}",
            if degenerate == 1 { "" } else { "s" }
        ));
    }
    if triangles.is_empty() {
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
        warnings,
    })
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

fn triples(flat: &[f32]) -> Vec<Vec3> {
    flat.chunks_exact(3).map(Vec3::from_slice).collect()
}

/// A reader that counts the lines consumed, so an OBJ error can name the line tobj stopped at
/// (tobj's errors carry none).
struct LineCounter<R> {
    inner: R,
    lines: usize,
}

impl<R: BufRead> Read for LineCounter<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.lines += buf[..n].iter().filter(|&&b| b == b'\n').count();
        Ok(n)
    }
}

impl<R: BufRead> BufRead for LineCounter<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }
    fn consume(&mut self, amount: usize) {
        if let Ok(buf) = self.inner.fill_buf() {
            self.lines += buf[..amount.min(buf.len())]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
        }
        self.inner.consume(amount);
    }
}

fn check_reflectance(name: &str, what: &str, c: Vec3) -> Result<Vec3, String> {
    if !c.is_finite() || c.min_element() < 0.0 || c.max_element() > 1.0 {
        return Err(format!(
            "material {name:?}: {what} must be in [0, 1], got {c}"
        ));
    }
    Ok(c)
}

fn check_emission(name: &str, what: &str, e: Vec3) -> Result<Vec3, String> {
    if !e.is_finite() || e.min_element() < 0.0 {
        return Err(format!("material {name:?}: {what} must be ≥ 0, got {e}"));
    }
    Ok(e)
}

/// OBJ `.mtl`: Kd → diffuse colour, Ke → emission, d < 1 → dielectric with Ni (default 1.5),
/// illum 3 or 5 → mirror with Ks (else Kd).
fn obj_material(m: &tobj::Material) -> Result<(Material, bool), String> {
    // map_Kd is used (see read_obj); the other maps are not.
    let name = &m.name;
    let kd = Vec3::from(m.diffuse.unwrap_or([0.8; 3]));
    let emission = check_emission(name, "Ke", Vec3::from(m.emissive.unwrap_or([0.0; 3])))?;
    let kind = if m.dissolve.is_some_and(|d| d < 1.0) {
        let ior = m.optical_density.filter(|&n| n > 0.0).unwrap_or(1.5);
        MaterialKind::Dielectric { ior }
    } else if matches!(m.illumination_model, Some(3) | Some(5)) {
        MaterialKind::Specular
    } else {
        MaterialKind::Diffuse
    };
    let color = match kind {
        MaterialKind::Specular => {
            check_reflectance(name, "Ks", Vec3::from(m.specular.unwrap_or(kd.to_array())))?
        }
        MaterialKind::Dielectric { .. } => Vec3::ONE,
        _ => check_reflectance(name, "Kd", kd)?,
    };
    let textures = [
        &m.ambient_texture,
        &m.specular_texture,
        &m.normal_texture,
        &m.shininess_texture,
        &m.dissolve_texture,
    ]
    .iter()
    .any(|t| t.is_some())
        || m.unknown_param
            .keys()
            .any(|k| k.starts_with("map_") || k == "bump" || k == "disp");
    Ok((
        Material {
            name: name.clone(),
            kind,
            color,
            emitted_radiance: emission,
            color_texture: None,
            roughness_texture: None,
        },
        textures,
    ))
}

/// The bytes of a mesh file, if it is a regular file within [`MESH_FILE_LIMIT`].
fn read_mesh_bytes(path: &Path) -> Result<Vec<u8>, String> {
    read_regular_file(path, MESH_FILE_LIMIT, "mesh file")
}

fn read_obj(path: &Path) -> Result<MeshFile, String> {
    let bytes = read_mesh_bytes(path)?;
    let mut reader = LineCounter {
        inner: &bytes[..],
        lines: 0,
    };
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let dir = path.parent().unwrap_or(Path::new(".")).to_owned();
    let (models, materials) = tobj::load_obj_buf(&mut reader, &options, |mtl| {
        // The same checks as the mesh file itself (a FIFO or a huge file is not read).
        let mtl = read_regular_file(&dir.join(mtl), MESH_FILE_LIMIT, "material file")
            .map_err(|_| tobj::LoadError::OpenFileFailed)?;
        tobj::load_mtl_buf(&mut &mtl[..])
    })
    .map_err(|e| format!("line {}: malformed OBJ: {e}", reader.lines.max(1)))?;
    // A missing or broken .mtl leaves the faces without materials; a face that needs one says so.
    let materials = materials.unwrap_or_default();
    let mut has_other_textures = false;
    let mut converted = Vec::new();
    let mut color_textures = Vec::new();
    for m in &materials {
        let (material, textures) = obj_material(m)?;
        // map_Kd is the diffuse colour: mirrors (Ks) and glass (clear) do not use it. Relative
        // to the OBJ's folder, as tobj reads the .mtl from there.
        let map_kd = m.diffuse_texture.as_ref().map(|t| dir.join(t.trim()));
        let diffuse = material.kind == MaterialKind::Diffuse;
        has_other_textures |= textures || (map_kd.is_some() && !diffuse);
        color_textures.push(map_kd.filter(|_| diffuse));
        converted.push(material);
    }
    let parts = models
        .into_iter()
        .map(|model| {
            let mesh = model.mesh;
            MeshPart {
                positions: triples(&mesh.positions),
                normals: triples(&mesh.normals),
                uvs: mesh
                    .texcoords
                    .chunks_exact(2)
                    .map(Vec2::from_slice)
                    .collect(),
                indices: mesh
                    .indices
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2]])
                    .collect(),
                material: mesh.material_id.filter(|&i| i < converted.len()),
                name: format!("object {:?}", model.name),
            }
        })
        .collect();
    Ok(MeshFile {
        parts,
        materials: converted,
        color_textures,
        has_other_textures,
    })
}

fn read_ply(path: &Path) -> Result<MeshFile, String> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let bytes = read_mesh_bytes(path)?;
    let mut reader = &bytes[..];
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut reader)
        // The reader's messages span several lines; errors here are one line.
        .map_err(|e| format!("malformed PLY: {}", one_line(&e.to_string())))?;
    let scalar = |e: &DefaultElement, key: &str| -> Option<f32> {
        match e.get(key)? {
            Property::Float(v) => Some(*v),
            Property::Double(v) => Some(*v as f32),
            Property::Char(v) => Some(*v as f32),
            Property::UChar(v) => Some(*v as f32),
            Property::Short(v) => Some(*v as f32),
            Property::UShort(v) => Some(*v as f32),
            Property::Int(v) => Some(*v as f32),
            Property::UInt(v) => Some(*v as f32),
            _ => None,
        }
    };
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or("malformed PLY: no \"vertex\" element")?;
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::new();
    let has_normals = vertices.first().is_some_and(|v| v.contains_key("nx"));
    for (i, v) in vertices.iter().enumerate() {
        let get = |k: &str| {
            scalar(v, k).ok_or_else(|| format!("malformed PLY: vertex {i} has no numeric {k:?}"))
        };
        positions.push(Vec3::new(get("x")?, get("y")?, get("z")?));
        if has_normals {
            normals.push(Vec3::new(get("nx")?, get("ny")?, get("nz")?));
        }
    }
    let faces = ply
        .payload
        .get("face")
        .ok_or("malformed PLY: no \"face\" element")?;
    let mut indices = Vec::with_capacity(faces.len());
    for (f, face) in faces.iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .ok_or_else(|| format!("malformed PLY: face {f} has no vertex_indices list"))?;
        let list: Vec<i64> = match list {
            Property::ListChar(l) => l.iter().map(|&x| x as i64).collect(),
            Property::ListUChar(l) => l.iter().map(|&x| x as i64).collect(),
            Property::ListShort(l) => l.iter().map(|&x| x as i64).collect(),
            Property::ListUShort(l) => l.iter().map(|&x| x as i64).collect(),
            Property::ListInt(l) => l.iter().map(|&x| x as i64).collect(),
            Property::ListUInt(l) => l.iter().map(|&x| x as i64).collect(),
            _ => {
                return Err(format!(
                    "malformed PLY: face {f}: vertex_indices is not an integer list"
                ))
            }
        };
        if list.len() < 3 {
            return Err(format!(
                "malformed PLY: face {f} has {} vertices; a face needs at least 3",
                list.len()
            ));
        }
        if let Some(&bad) = list
            .iter()
            .find(|&&i| i < 0 || i as usize >= positions.len())
        {
            return Err(format!(
                "face {f} refers to vertex {bad}, but there are only {} vertices",
                positions.len()
            ));
        }
        // Polygons as fans.
        for k in 1..list.len() - 1 {
            indices.push([list[0] as u32, list[k] as u32, list[k + 1] as u32]);
        }
    }
    Ok(MeshFile {
        parts: vec![MeshPart {
            positions,
            normals,
            uvs: Vec::new(),
            indices,
            material: None,
            name: String::new(),
        }],
        materials: Vec::new(),
        color_textures: Vec::new(),
        has_other_textures: false,
    })
}

/// glTF `pbrMetallicRoughness`: baseColorFactor; metallicFactor ≥ 0.5 → metal with
/// roughnessFactor, else diffuse; KHR_materials_transmission > 0.5 → dielectric with
/// KHR_materials_ior (default 1.5); emissiveFactor × KHR_materials_emissive_strength → emission.
fn gltf_material(m: &gltf::Material, index: usize) -> Result<(Material, bool), String> {
    // By index: the `names` feature of gltf would keep every name in memory for this alone.
    let name = format!("material{index}");
    let pbr = m.pbr_metallic_roughness();
    let base = Vec3::from_slice(&pbr.base_color_factor()[..3]);
    let kind = if m
        .transmission()
        .is_some_and(|t| t.transmission_factor() > 0.5)
    {
        MaterialKind::Dielectric {
            ior: m.ior().filter(|&n| n > 0.0).unwrap_or(1.5),
        }
    } else if pbr.metallic_factor() >= 0.5 {
        MaterialKind::Metal {
            roughness: pbr.roughness_factor().clamp(0.0, 1.0),
        }
    } else {
        MaterialKind::Diffuse
    };
    let color = check_reflectance(&name, "baseColorFactor", base)?;
    let emission = check_emission(
        &name,
        "emissiveFactor × emissive strength",
        Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
    )?;
    let textures = pbr.metallic_roughness_texture().is_some()
        || m.normal_texture().is_some()
        || m.occlusion_texture().is_some()
        || m.emissive_texture().is_some();
    Ok((
        Material {
            name,
            kind,
            color,
            emitted_radiance: emission,
            color_texture: None,
            roughness_texture: None,
        },
        textures,
    ))
}

fn read_gltf(path: &Path) -> Result<MeshFile, String> {
    let bytes = read_mesh_bytes(path)?;
    let gltf = gltf::Gltf::from_slice(&bytes)
        .map_err(|e| format!("malformed glTF: {}", one_line(&e.to_string())))?;
    let buffers = gltf::import_buffers(&gltf.document, path.parent(), gltf.blob.clone())
        .map_err(|e| format!("glTF buffers: {e}"))?;
    let mut materials = Vec::new();
    let mut color_textures = Vec::new();
    let mut has_other_textures = false;
    for (i, m) in gltf.document.materials().enumerate() {
        let base = m.pbr_metallic_roughness().base_color_texture();
        // Images referred to by URI, relative to the glTF file, on texture coordinate set 0;
        // embedded images (buffer views, data URIs) and other sets are not read.
        let file = base
            .as_ref()
            .and_then(|info| match info.texture().source().source() {
                gltf::image::Source::Uri { uri, .. }
                    if info.tex_coord() == 0 && !uri.starts_with("data:") =>
                {
                    Some(path.parent().unwrap_or(Path::new("")).join(uri))
                }
                _ => None,
            });
        has_other_textures |= base.is_some() && file.is_none();
        color_textures.push(file);
        let (m, textures) = gltf_material(&m, i)?;
        has_other_textures |= textures;
        materials.push(m);
    }
    let mut parts = Vec::new();
    let scene = gltf
        .document
        .default_scene()
        .or_else(|| gltf.document.scenes().next())
        .ok_or("malformed glTF: no scene")?;
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        for child in node.children() {
            stack.push((child, world));
        }
        let Some(mesh) = node.mesh() else { continue };
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        for (p, primitive) in mesh.primitives().enumerate() {
            let name = format!("mesh {} primitive {p}", mesh.index());
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                return Err(format!(
                    "{name}: mode {:?} is not supported; only triangle lists are",
                    primitive.mode()
                ));
            }
            let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| format!("{name}: no POSITION attribute"))?
                .map(|p| world.transform_point3(Vec3::from(p)))
                .collect();
            let normals: Vec<Vec3> = reader
                .read_normals()
                .map(|n| n.map(|n| normal_matrix * Vec3::from(n)).collect())
                .unwrap_or_default();
            // glTF's texture coordinates have v down (the image's top row at v = 0).
            let uvs: Vec<Vec2> = reader
                .read_tex_coords(0)
                .map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect())
                .unwrap_or_default();
            let flat: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            parts.push(MeshPart {
                positions,
                normals,
                uvs,
                indices: flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
                material: primitive.material().index(),
                name,
            });
        }
    }
    Ok(MeshFile {
        parts,
        materials,
        color_textures,
        has_other_textures,
    })
}
