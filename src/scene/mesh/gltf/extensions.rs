//! Which glTF extensions glint reads, and how fully: the one table that decides what a file
//! may require and which extensions it uses get a warning.

use gltf::json;

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

/// A required extension glint does not read is an error; extensions used get one warning.
pub(super) fn check_extensions(
    root: &json::Root,
    warnings: &mut Vec<String>,
) -> Result<(), String> {
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
