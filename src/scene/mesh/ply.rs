//! PLY files (ASCII and binary), read by `ply-rs-bw`: vertices, optional normals and vertex
//! colours, and faces (polygons split into fans). PLY carries no materials.

use super::{one_line, read_mesh_bytes, Geometry, MeshFile, MeshPart};
use crate::scene::image::srgb_to_linear;
use glam::{Vec3, Vec4};
use std::path::Path;

pub(super) fn read_ply(path: &Path) -> Result<MeshFile, String> {
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
    // Vertex colours as scanners and MeshLab write them: `red green blue` (and `alpha`) uchar,
    // display colours (sRGB-decoded here), alpha linear.
    let has_colors = vertices
        .first()
        .is_some_and(|v| matches!(v.get("red"), Some(Property::UChar(_))));
    let mut colors = Vec::new();
    for (i, v) in vertices.iter().enumerate() {
        let get = |k: &str| {
            scalar(v, k).ok_or_else(|| format!("malformed PLY: vertex {i} has no numeric {k:?}"))
        };
        positions.push(Vec3::new(get("x")?, get("y")?, get("z")?));
        if has_normals {
            normals.push(Vec3::new(get("nx")?, get("ny")?, get("nz")?));
        }
        if has_colors {
            let channel = |k: &str| match v.get(k) {
                Some(Property::UChar(c)) => Ok(*c as f32 / 255.0),
                _ => Err(format!("malformed PLY: vertex {i} has no uchar {k:?}")),
            };
            let alpha = match v.get("alpha") {
                Some(Property::UChar(a)) => *a as f32 / 255.0,
                _ => 1.0,
            };
            colors.push(Vec4::new(
                srgb_to_linear(channel("red")?),
                srgb_to_linear(channel("green")?),
                srgb_to_linear(channel("blue")?),
                alpha,
            ));
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
        parts: vec![MeshPart::unplaced(
            Geometry {
                positions,
                normals,
                uvs: Vec::new(),
                uvs1: Vec::new(),
                tangents: Vec::new(),
                colors,
                indices,
            },
            None,
            String::new(),
        )],
        materials: Vec::new(),
        textures: Vec::new(),
        has_other_textures: false,
        warnings: Vec::new(),
    })
}
