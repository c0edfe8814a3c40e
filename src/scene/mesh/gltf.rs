//! glTF 2.0 files (`.gltf` with external or embedded buffers, binary `.glb`), read by the
//! `gltf` crate: the default scene's node hierarchy, triangle-list primitives and their
//! materials.

use super::{check_emission, check_reflectance, one_line, read_mesh_bytes, MeshFile, MeshPart};
use crate::scene::{Material, MaterialKind};
use glam::{Mat3, Mat4, Vec2, Vec3};
use std::path::Path;

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

pub(super) fn read_gltf(path: &Path) -> Result<MeshFile, String> {
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
