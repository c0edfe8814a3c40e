//! What a mesh file's reader yields (`obj.rs`, `ply.rs`, `gltf/`): its parts and their
//! geometry in the file's own coordinates, its materials, and the images their texture maps
//! come from.

use crate::scene::texture::Sampling;
use crate::scene::Material;
use glam::{Mat4, Vec2, Vec3, Vec4};
use std::path::PathBuf;
use std::rc::Rc;

/// Triangles with one material, in the file's own coordinates: positions, optional vertex
/// normals (as many as positions), and triangles as indices into them.
pub(in crate::scene) struct Geometry {
    pub(super) positions: Vec<Vec3>,
    pub(super) normals: Vec<Vec3>,
    /// Texture coordinates (v up), as many as positions, or none.
    pub(super) uvs: Vec<Vec2>,
    /// glTF's TEXCOORD_1 (v up), as many as positions, or none.
    pub(super) uvs1: Vec<Vec2>,
    /// glTF's TANGENT (xyz along increasing u, w the bitangent's sign), as many as positions,
    /// or none.
    pub(super) tangents: Vec<Vec4>,
    /// Vertex colours (linear RGBA in [0, 1], glTF's COLOR_0), as many as positions, or none.
    pub(super) colors: Vec<Vec4>,
    pub(super) indices: Vec<[u32; 3]>,
}

/// A part of a mesh file: its geometry, placed in the file's space. A glTF mesh used by several
/// nodes is one geometry shared by several parts, read once.
pub(in crate::scene) struct MeshPart {
    pub(super) geometry: Rc<Geometry>,
    /// The file's own placement (a glTF node's world transform), before the scene's.
    pub(super) transform: Mat4,
    /// Index into the file's materials, if the file gives one.
    pub(super) material: Option<usize>,
    /// Where the part came from, for messages (an OBJ object, a glTF node and mesh).
    pub(super) name: String,
}

impl MeshPart {
    /// A part the file places as it is (OBJ, PLY).
    pub(super) fn unplaced(geometry: Geometry, material: Option<usize>, name: String) -> Self {
        MeshPart {
            geometry: Rc::new(geometry),
            transform: Mat4::IDENTITY,
            material,
            name,
        }
    }
}

/// What a mesh file holds.
pub(in crate::scene) struct MeshFile {
    pub(super) parts: Vec<MeshPart>,
    pub(super) materials: Vec<Material>,
    /// Per material: the images of its texture maps.
    pub(super) textures: Vec<FileTextures>,
    /// Whether any material refers to a texture glint does not use (normal maps, ...).
    pub(super) has_other_textures: bool,
    /// Anything else worth a warning line, each a sentence without the file's name.
    pub(super) warnings: Vec<String>,
}

/// Where a texture's image comes from.
pub(in crate::scene) enum ImageSource {
    File(PathBuf),
    /// An image file's bytes inside the mesh file (a glTF buffer view or `data:` URI), and the
    /// element that holds them (`images[2]`), for messages.
    Embedded {
        element: String,
        bytes: Rc<[u8]>,
    },
}

/// A material's texture maps, as images (shared between the materials that use them).
#[derive(Default)]
pub(in crate::scene) struct FileTextures {
    /// Multiplies the material's colour (OBJ `map_Kd`, whose colour is then 1; glTF
    /// `baseColorTexture`).
    pub(super) color: Option<(Rc<ImageSource>, Sampling)>,
    /// glTF's `metallicRoughnessTexture`: green multiplies the roughness, blue the metallic
    /// factor.
    pub(super) metallic_roughness: Option<(Rc<ImageSource>, Sampling)>,
    /// glTF's `emissiveTexture` (sRGB), multiplying the emission.
    pub(super) emission: Option<(Rc<ImageSource>, Sampling)>,
    /// KHR_materials_transmission's `transmissionTexture` (linear): red multiplies the
    /// transmission factor.
    pub(super) transmission: Option<(Rc<ImageSource>, Sampling)>,
    /// glTF's `normalTexture` (linear), and its scale.
    pub(super) normal: Option<((Rc<ImageSource>, Sampling), f32)>,
    /// KHR_materials_clearcoat's `clearcoatNormalTexture` (linear), and its scale.
    pub(super) clearcoat_normal: Option<((Rc<ImageSource>, Sampling), f32)>,
    /// OBJ's separate roughness (`map_Pr`) and metallic (`map_Pm`) images, merged on load.
    pub(super) roughness_and_metallic: Option<(Option<PathBuf>, Option<PathBuf>)>,
    /// KHR_materials_clearcoat's clearcoatTexture (red) and clearcoatRoughnessTexture (green).
    pub(super) clearcoat: Option<(Rc<ImageSource>, Sampling)>,
    pub(super) clearcoat_roughness: Option<(Rc<ImageSource>, Sampling)>,
    /// KHR_materials_sheen's sheenColorTexture (sRGB) and sheenRoughnessTexture (alpha).
    pub(super) sheen_color: Option<(Rc<ImageSource>, Sampling)>,
    pub(super) sheen_roughness: Option<(Rc<ImageSource>, Sampling)>,
    /// OBJ's colour (`map_Kd`, if any) and opacity (`map_d`) images, merged on load into the
    /// colour texture (the opacity its alpha).
    pub(super) color_and_opacity: Option<(Option<PathBuf>, PathBuf)>,
}
