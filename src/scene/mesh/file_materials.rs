//! A mesh file's own materials made scene materials (for a `[[meshes]]` entry without
//! `material`): each with its texture maps loaded, named `<file name>/<material name>`, and
//! added to the scene only when a part first uses it.

use super::{ImageSource, MeshFile};
use crate::scene::texture::{Sampling, TextureSet, TextureUse};
use crate::scene::{Material, MaterialKind};
use std::path::Path;
use std::rc::Rc;

/// The file's materials and which of them are scene materials yet.
pub(super) struct FileMaterials<'a> {
    file: &'a MeshFile,
    path: &'a Path,
    /// The mesh file as messages show it.
    shown: &'a str,
    /// The file's name, which prefixes its materials' names in the scene.
    stem: String,
    /// Per file material: its scene material, once a part has used it.
    scene_ids: Vec<Option<u32>>,
}

impl<'a> FileMaterials<'a> {
    pub(super) fn new(file: &'a MeshFile, path: &'a Path, shown: &'a str) -> Self {
        let stem = path
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        FileMaterials {
            file,
            path,
            shown,
            stem,
            scene_ids: vec![None; file.materials.len()],
        }
    }

    /// The scene material of the file's material `index`, added to `scene_materials` (its
    /// textures to `textures`) the first time it is asked for.
    pub(super) fn scene_material(
        &mut self,
        index: usize,
        scene_materials: &mut Vec<Material>,
        textures: &mut TextureSet,
    ) -> Result<u32, String> {
        if let Some(id) = self.scene_ids[index] {
            return Ok(id);
        }
        let mut m = self.with_textures(index, textures)?;
        m.name = format!("{}/{}", self.stem, m.name);
        let id = scene_materials.len() as u32;
        scene_materials.push(m);
        self.scene_ids[index] = Some(id);
        Ok(id)
    }

    /// The file's material `index` with its texture maps loaded into `textures`.
    fn with_textures(&self, index: usize, textures: &mut TextureSet) -> Result<Material, String> {
        let mut m = self.file.materials[index].clone();
        let maps = &self.file.textures[index];
        let name = m.name.clone();
        let (path, shown) = (self.path, self.shown);
        let mut load = |map: &Option<(Rc<ImageSource>, Sampling)>, usage| {
            map.as_ref()
                .map(|(source, sampling)| {
                    let image = texture(source, usage, path, shown, &name, textures)?;
                    Ok::<_, String>(textures.sampled(image, sampling))
                })
                .transpose()
        };
        m.color_texture = load(&maps.color, TextureUse::Color)?;
        m.roughness_texture = load(&maps.metallic_roughness, TextureUse::MetallicRoughness)?;
        m.emission_texture = load(&maps.emission, TextureUse::Color)?;
        if let MaterialKind::Pbr {
            transmission_texture,
            layers,
            ..
        } = &mut m.kind
        {
            *transmission_texture = load(&maps.transmission, TextureUse::Transmission)?;
            layers.clearcoat_texture = load(&maps.clearcoat, TextureUse::Transmission)?;
            layers.clearcoat_roughness_texture =
                load(&maps.clearcoat_roughness, TextureUse::MetallicRoughness)?;
            layers.sheen_color_texture = load(&maps.sheen_color, TextureUse::Color)?;
            layers.sheen_roughness_texture =
                load(&maps.sheen_roughness, TextureUse::SheenRoughness)?;
            if let Some((map, scale)) = &maps.clearcoat_normal {
                layers.clearcoat_normal_texture =
                    load(&Some(map.clone()), TextureUse::Normal)?.map(|t| (t, *scale));
            }
        }
        if let Some((map, scale)) = &maps.normal {
            m.normal_texture = load(&Some(map.clone()), TextureUse::Normal)?.map(|t| (t, *scale));
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
                    .roughness_and_metallic(roughness.as_deref(), metallic.as_deref())
                    .map_err(|e| format!("material {name:?}: {e}"))?,
            );
        }
        Ok(m)
    }
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
