//! OBJ files and their `.mtl` materials, read by `tobj`.

use super::{
    check_emission, check_ior, check_normal_scale, check_reflectance, read_mesh_bytes,
    FileTextures, Geometry, ImageSource, MeshFile, MeshPart,
};
use crate::input_file::{read_regular_file, MESH_FILE_LIMIT};
use crate::scene::{Alpha, AlphaMode, Material, MaterialKind};
use glam::{Vec2, Vec3};
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};
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

/// OBJ `.mtl` statements of the PBR extension (as Blender writes them) that make a material
/// glint's `pbr`.
const PBR_STATEMENTS: &[&str] = &["Pr", "Pm", "map_Pr", "map_Pm"];

/// PBR-extension statements glint does not read: each gets a warning.
const UNREAD_PBR_STATEMENTS: &[&str] = &[
    "Ps",
    "Pc",
    "Pcr",
    "aniso",
    "anisor",
    "map_Ps",
    "map_Pc",
    "map_Pcr",
    "map_aniso",
];

/// One `.mtl` material as glint's, its texture maps, and warning lines (without the file):
/// - `Pr`/`Pm`/`map_Pr`/`map_Pm` present → `pbr` with Kd, roughness `Pr` (else from `Ns` as
///   Blender's importer derives it, 1 − √(Ns/1000)), metallic `Pm` and ior `Ni`;
/// - else illum 3 or 5 → mirror with Ks (else Kd); else diffuse Kd;
/// - `d` (or `Tr`, 1 − d) < 1 → alpha `blend` with opacity d (stochastic transparency);
/// - Ke → emission, with `map_Ke` multiplying it (Ke 1 when only the map is given);
/// - `map_Kd` multiplies a diffuse or pbr colour; `norm`, `map_Bump` or `bump` is a
///   tangent-space normal map, its `-bm` option the scale (Blender's importer reads these as
///   normal maps too).
fn obj_material(
    m: &tobj::Material,
    dir: &Path,
) -> Result<(Material, FileTextures, bool, Vec<String>), String> {
    let name = &m.name;
    let mtl = MtlStatements { m, dir };
    let kd = Vec3::from(m.diffuse.unwrap_or([0.8; 3]));
    let map_ke = mtl.map(mtl.param("map_Ke"), "map_Ke")?;
    let ke = m.emissive.map(Vec3::from).unwrap_or(if map_ke.is_some() {
        Vec3::ONE
    } else {
        Vec3::ZERO
    });
    let emission = check_emission(name, "Ke", ke)?;
    let opacity = mtl.opacity()?;
    let kind = mtl.kind()?;
    let warnings = mtl.unread_pbr_warning().into_iter().collect();
    let color = match kind {
        MaterialKind::Specular => {
            check_reflectance(name, "Ks", Vec3::from(m.specular.unwrap_or(kd.to_array())))?
        }
        _ => check_reflectance(name, "Kd", kd)?,
    };
    let alpha = if opacity < 1.0 {
        Alpha {
            mode: AlphaMode::Blend,
            opacity,
        }
    } else {
        Alpha::OPAQUE
    };
    let mut material = Material::untextured(name.clone(), kind, color, emission, alpha);
    let (maps, other_textures) = mtl.texture_maps(&mut material, map_ke)?;
    let other_textures = other_textures | mtl.has_unread_textures();
    Ok((material, maps, other_textures, warnings))
}

/// A map statement's image file (relative to the OBJ's folder) and its `-bm`.
type MapFile = (PathBuf, Option<f32>);

/// One `.mtl` material's statements, read and checked; errors name the material.
struct MtlStatements<'a> {
    m: &'a tobj::Material,
    /// The folder the map statements' files are relative to.
    dir: &'a Path,
}

impl<'a> MtlStatements<'a> {
    /// Statement `key`'s value, trimmed, among those tobj does not read itself.
    fn param(&self, key: &str) -> Option<&'a str> {
        self.m.unknown_param.get(key).map(|v| v.trim())
    }

    /// Statement `key`'s value as a finite number.
    fn number(&self, key: &str) -> Result<Option<f32>, String> {
        let name = &self.m.name;
        self.param(key)
            .map(|v| {
                v.parse::<f32>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("material {name:?}: {key}: not a number: {v:?}"))
            })
            .transpose()
    }

    /// `v`, statement `key`'s, checked to lie in [0, 1].
    fn unit(&self, key: &str, v: f32) -> Result<f32, String> {
        let name = &self.m.name;
        if (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(format!(
                "material {name:?}: {key} must be in [0, 1], got {v}"
            ))
        }
    }

    /// Map statement `key` of value `value` (`None`: not given): its file and `-bm`.
    fn map(&self, value: Option<&str>, key: &str) -> Result<Option<MapFile>, String> {
        let name = &self.m.name;
        value
            .map(|v| {
                map_statement(v)
                    .map(|(file, scale)| (self.dir.join(file), scale))
                    .ok_or_else(|| format!("material {name:?}: {key}: no image file named"))
            })
            .transpose()
    }

    /// The opacity, checked to lie in [0, 1].
    fn opacity(&self) -> Result<f32, String> {
        // `d` (dissolve) is the opacity; `Tr` (transparency), which some exporters write in its
        // place, is 1 − d. Blender writes `d 1.000000` on every opaque material: only d < 1
        // makes a material blended, so those stay opaque, at no alpha cost.
        Ok(match (self.m.dissolve, self.number("Tr")?) {
            (Some(d), _) => self.unit("d", d)?,
            (None, Some(tr)) => 1.0 - self.unit("Tr", tr)?,
            (None, None) => 1.0,
        })
    }

    /// `pbr` where a PBR-extension statement is given, else a mirror under illum 3 or 5, else
    /// diffuse; the ior `Ni` is checked whatever the kind.
    fn kind(&self) -> Result<MaterialKind, String> {
        let m = self.m;
        let is_pbr = PBR_STATEMENTS.iter().any(|k| self.param(k).is_some());
        // Checked whatever the material's kind, as a scene file's `ior` is. Exporters write
        // `Ni 0` (Blender for some materials, 3ds Max) where they mean no index: that is the
        // default.
        let ior = match m.optical_density {
            None | Some(0.0) => 1.5,
            Some(n) => check_ior(&m.name, "Ni", n)?,
        };
        Ok(if is_pbr {
            self.pbr_kind(ior)?
        } else if matches!(m.illumination_model, Some(3) | Some(5)) {
            MaterialKind::Specular
        } else {
            MaterialKind::Diffuse
        })
    }

    /// The `pbr` kind: roughness `Pr` (else from `Ns`), metallic `Pm`, ior `ior`.
    fn pbr_kind(&self, ior: f32) -> Result<MaterialKind, String> {
        let roughness = match self.number("Pr")? {
            Some(r) => self.unit("Pr", r)?,
            None => self
                .m
                .shininess
                .map_or(0.5, |ns| 1.0 - (ns.clamp(0.0, 1000.0) / 1000.0).sqrt()),
        };
        Ok(MaterialKind::Pbr {
            roughness,
            metallic: self.unit("Pm", self.number("Pm")?.unwrap_or(0.0))?,
            ior,
            specular: 1.0,
            specular_color: Vec3::ONE,
            transmission: 0.0,
            transmission_texture: None,
            attenuation_color: Vec3::ONE,
            attenuation_distance: None,
            layers: Default::default(),
        })
    }

    /// The warning for the PBR-extension statements given that glint does not read.
    fn unread_pbr_warning(&self) -> Option<String> {
        let unread: Vec<&str> = UNREAD_PBR_STATEMENTS
            .iter()
            .copied()
            .filter(|k| self.param(k).is_some())
            .collect();
        (!unread.is_empty()).then(|| {
            format!(
                "material {:?}: {} (sheen, clearcoat, anisotropy) not read; ignored",
                self.m.name,
                unread.join(", ")
            )
        })
    }

    /// The texture maps, and whether a map glint does not read is given (map_Kd on a mirror);
    /// map_Kd makes `material`'s colour white, map_d its alpha blended. `map_ke` is map_Ke's,
    /// read with the emission.
    fn texture_maps(
        &self,
        material: &mut Material,
        map_ke: Option<MapFile>,
    ) -> Result<(FileTextures, bool), String> {
        let m = self.m;
        let mut maps = FileTextures::default();
        let mut other_textures = false;
        // map_Kd is the diffuse or base colour: mirrors (Ks) do not use it.
        if let Some((file, _)) = self.map(m.diffuse_texture.as_deref(), "map_Kd")? {
            if matches!(
                material.kind,
                MaterialKind::Diffuse | MaterialKind::Pbr { .. }
            ) {
                // map_Kd replaces Kd (the kernel multiplies the colour by the texture).
                material.color = Vec3::ONE;
                maps.color = Some((Rc::new(ImageSource::File(file)), Default::default()));
            } else {
                other_textures = true;
            }
        }
        // map_d's first channel is the opacity: it becomes the colour texture's alpha, merged
        // on load with map_Kd where the material reads that (white otherwise, so the colour is
        // the constant's).
        if let Some((file, _)) = self.map(m.dissolve_texture.as_deref(), "map_d")? {
            let color = maps
                .color
                .take()
                .and(self.map(m.diffuse_texture.as_deref(), "map_Kd")?)
                .map(|(f, _)| f);
            maps.color_and_opacity = Some((color, file));
            material.alpha.mode = AlphaMode::Blend;
        }
        let map_pr = self.map(self.param("map_Pr"), "map_Pr")?.map(|(f, _)| f);
        let map_pm = self.map(self.param("map_Pm"), "map_Pm")?.map(|(f, _)| f);
        if map_pr.is_some() || map_pm.is_some() {
            maps.roughness_and_metallic = Some((map_pr, map_pm));
        }
        if let Some((file, _)) = map_ke {
            maps.emission = Some((Rc::new(ImageSource::File(file)), Default::default()));
        }
        if let Some((file, scale)) = self.normal_map()? {
            maps.normal = Some((
                (Rc::new(ImageSource::File(file)), Default::default()),
                scale,
            ));
        }
        Ok((maps, other_textures))
    }

    /// The normal map (`norm`, `map_Bump` or `bump`): its file and scale (`-bm`, checked).
    fn normal_map(&self) -> Result<Option<(PathBuf, f32)>, String> {
        // tobj files `map_Bump` and `bump` as its normal texture; `norm` is the PBR extension's.
        let (normal_key, normal) = match self.param("norm") {
            Some(v) => ("norm", Some(v)),
            None => ("map_Bump", self.m.normal_texture.as_deref()),
        };
        let Some((file, scale)) = self.map(normal, normal_key)? else {
            return Ok(None);
        };
        let scale = check_normal_scale(
            &self.m.name,
            &format!("{normal_key}'s -bm"),
            scale.unwrap_or(1.0),
        )?;
        Ok(Some((file, scale)))
    }

    /// Whether a map statement glint does not read is given (map_Ka, map_Ks, map_Ns, disp,
    /// refl, ...; the unread PBR ones have their own warning).
    fn has_unread_textures(&self) -> bool {
        let m = self.m;
        [
            &m.ambient_texture,
            &m.specular_texture,
            &m.shininess_texture,
        ]
        .iter()
        .any(|t| t.is_some())
            || m.unknown_param.keys().any(|k| {
                (k.starts_with("map_") || k == "disp" || k == "refl")
                    && !matches!(k.as_str(), "map_Pr" | "map_Pm" | "map_Ke")
                    && !UNREAD_PBR_STATEMENTS.contains(&k.as_str())
            })
    }
}

/// The image file of an `.mtl` map statement's value and its `-bm` (bump multiplier): the
/// options before the file name (`-s 1 1 1`, `-bm 0.5`, `-clamp on`, ...) are read past, each
/// with its arguments; what follows is the file name, spaces included. `None` when no file
/// name is left.
fn map_statement(value: &str) -> Option<(String, Option<f32>)> {
    let mut rest = value.trim();
    let mut bump_multiplier = None;
    let next_word = |s: &str| {
        let s = s.trim_start();
        let end = s.find(char::is_whitespace).unwrap_or(s.len());
        (s[..end].to_string(), s[end..].trim_start().to_string())
    };
    while rest.starts_with('-') {
        let (option, after) = next_word(rest);
        let mut after = after;
        // -o, -s and -t take one to three numbers; the others a fixed count.
        let (least, most) = match option.as_str() {
            "-o" | "-s" | "-t" => (1, 3),
            "-mm" => (2, 2),
            "-blendu" | "-blendv" | "-bm" | "-boost" | "-cc" | "-clamp" | "-imfchan"
            | "-texres" | "-type" => (1, 1),
            _ => (0, 0),
        };
        let mut arguments = Vec::new();
        while arguments.len() < most {
            let (word, later) = next_word(&after);
            let numeric = word.parse::<f32>().is_ok();
            if word.is_empty() || (arguments.len() >= least && !numeric) {
                break;
            }
            arguments.push(word);
            after = later;
        }
        if option == "-bm" {
            bump_multiplier = arguments.first().and_then(|a| a.parse::<f32>().ok());
        }
        rest = value[value.len() - after.len()..].trim();
    }
    (!rest.is_empty()).then(|| (rest.to_string(), bump_multiplier))
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
    let mut warnings = Vec::new();
    for m in &materials {
        // Relative to the OBJ's folder, as tobj reads the .mtl from there.
        let (material, maps, other_textures, material_warnings) = obj_material(m, &dir)?;
        has_other_textures |= other_textures;
        warnings.extend(material_warnings);
        file_textures.push(maps);
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
                    uvs1: Vec::new(),
                    tangents: Vec::new(),
                    colors: Vec::new(),
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
        warnings,
    })
}

fn triples(flat: &[f32]) -> Vec<Vec3> {
    flat.chunks_exact(3).map(Vec3::from_slice).collect()
}
