//! OBJ files and their `.mtl` materials, read by `tobj`.

use super::{
    check_emission, check_ior, check_reflectance, read_mesh_bytes, FileTextures, Geometry,
    ImageSource, MeshFile, MeshPart,
};
use crate::input_file::{read_regular_file, MESH_FILE_LIMIT};
use crate::scene::{Material, MaterialKind};
use glam::{Vec2, Vec3};
use std::io::{BufRead, Read};
use std::path::Path;
use std::rc::Rc;

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

/// OBJ `.mtl`: Kd → diffuse colour, Ke → emission, d < 1 → dielectric with Ni (default 1.5),
/// illum 3 or 5 → mirror with Ks (else Kd).
fn obj_material(m: &tobj::Material) -> Result<(Material, bool), String> {
    // map_Kd is used (see read_obj); the other maps are not.
    let name = &m.name;
    let kd = Vec3::from(m.diffuse.unwrap_or([0.8; 3]));
    let emission = check_emission(name, "Ke", Vec3::from(m.emissive.unwrap_or([0.0; 3])))?;
    let kind = if m.dissolve.is_some_and(|d| d < 1.0) {
        let ior = m.optical_density.filter(|&n| n > 0.0).unwrap_or(1.5);
        MaterialKind::Dielectric {
            ior: check_ior(name, "Ni", ior)?,
        }
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
            emission_texture: None,
            normal_texture: None,
            alpha: crate::scene::Alpha::OPAQUE,
        },
        textures,
    ))
}

pub(super) fn read_obj(path: &Path) -> Result<MeshFile, String> {
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
    let mut file_textures = Vec::new();
    for m in &materials {
        let (mut material, textures) = obj_material(m)?;
        // map_Kd is the diffuse colour: mirrors (Ks) and glass (clear) do not use it. Relative
        // to the OBJ's folder, as tobj reads the .mtl from there.
        let map_kd = m.diffuse_texture.as_ref().map(|t| dir.join(t.trim()));
        let diffuse = material.kind == MaterialKind::Diffuse;
        has_other_textures |= textures || (map_kd.is_some() && !diffuse);
        let map_kd = map_kd.filter(|_| diffuse);
        if map_kd.is_some() {
            // map_Kd replaces Kd (the kernel multiplies the colour by the texture).
            material.color = Vec3::ONE;
        }
        file_textures.push(FileTextures {
            color: map_kd.map(|path| (Rc::new(ImageSource::File(path)), Default::default())),
            ..Default::default()
        });
        converted.push(material);
    }
    let parts = models
        .into_iter()
        .map(|model| {
            let mesh = model.mesh;
            MeshPart::unplaced(
                Geometry {
                    positions: triples(&mesh.positions),
                    normals: triples(&mesh.normals),
                    uvs: mesh
                        .texcoords
                        .chunks_exact(2)
                        .map(Vec2::from_slice)
                        .collect(),
                    tangents: Vec::new(),
                    indices: mesh
                        .indices
                        .chunks_exact(3)
                        .map(|c| [c[0], c[1], c[2]])
                        .collect(),
                },
                mesh.material_id.filter(|&i| i < converted.len()),
                format!("object {:?}", model.name),
            )
        })
        .collect();
    Ok(MeshFile {
        parts,
        materials: converted,
        textures: file_textures,
        has_other_textures,
        warnings: Vec::new(),
    })
}

fn triples(flat: &[f32]) -> Vec<Vec3> {
    flat.chunks_exact(3).map(Vec3::from_slice).collect()
}
