//! The WGSL kernel, assembled from one file per concept in `shaders/` (WGSL has no includes):
//! the parts in dependency order, with the variant's constants and the scene's bindings
//! ([`KernelVariant`]) spliced in after the types.

use crate::kernel::texels::TexelBinding;
use crate::kernel::variant::{KernelFeatures, KernelVariant, SceneBinding};

/// The kernel's parts in dependency order, with their file names, for error messages and tests.
/// The scene's bindings come between `types.wgsl` and the rest: see [`SceneBinding`].
pub const SHADER_PARTS: [(&str, &str); 48] = [
    (
        "core/types.wgsl",
        include_str!("../../shaders/core/types.wgsl"),
    ),
    ("core/rng.wgsl", include_str!("../../shaders/core/rng.wgsl")),
    (
        "core/camera.wgsl",
        include_str!("../../shaders/core/camera.wgsl"),
    ),
    (
        "geometry/hit.wgsl",
        include_str!("../../shaders/geometry/hit.wgsl"),
    ),
    (
        "geometry/surface.wgsl",
        include_str!("../../shaders/geometry/surface.wgsl"),
    ),
    (
        "geometry/shading_normal.wgsl",
        include_str!("../../shaders/geometry/shading_normal.wgsl"),
    ),
    (
        "geometry/triangle.wgsl",
        include_str!("../../shaders/geometry/triangle.wgsl"),
    ),
    (
        "geometry/intersect.wgsl",
        include_str!("../../shaders/geometry/intersect.wgsl"),
    ),
    (
        "traverse/bvh_ray.wgsl",
        include_str!("../../shaders/traverse/bvh_ray.wgsl"),
    ),
    (
        "traverse/binary_walk.wgsl",
        include_str!("../../shaders/traverse/binary_walk.wgsl"),
    ),
    (
        "traverse/bvh.wgsl",
        include_str!("../../shaders/traverse/bvh.wgsl"),
    ),
    (
        "geometry/instance.wgsl",
        include_str!("../../shaders/geometry/instance.wgsl"),
    ),
    (
        "traverse/blas.wgsl",
        include_str!("../../shaders/traverse/blas.wgsl"),
    ),
    (
        "core/frame.wgsl",
        include_str!("../../shaders/core/frame.wgsl"),
    ),
    (
        "materials/bsdf.wgsl",
        include_str!("../../shaders/materials/bsdf.wgsl"),
    ),
    (
        "materials/microfacet.wgsl",
        include_str!("../../shaders/materials/microfacet.wgsl"),
    ),
    (
        "materials/diffuse.wgsl",
        include_str!("../../shaders/materials/diffuse.wgsl"),
    ),
    (
        "materials/conductor.wgsl",
        include_str!("../../shaders/materials/conductor.wgsl"),
    ),
    (
        "materials/dielectric.wgsl",
        include_str!("../../shaders/materials/dielectric.wgsl"),
    ),
    (
        "materials/ggx_energy.wgsl",
        include_str!("../../shaders/materials/ggx_energy.wgsl"),
    ),
    (
        "materials/dielectric_energy.wgsl",
        include_str!("../../shaders/materials/dielectric_energy.wgsl"),
    ),
    (
        "materials/rough_dielectric_single.wgsl",
        include_str!("../../shaders/materials/rough_dielectric_single.wgsl"),
    ),
    (
        "materials/rough_dielectric.wgsl",
        include_str!("../../shaders/materials/rough_dielectric.wgsl"),
    ),
    (
        "materials/sheen_energy.wgsl",
        include_str!("../../shaders/materials/sheen_energy.wgsl"),
    ),
    (
        "materials/clearcoat_energy.wgsl",
        include_str!("../../shaders/materials/clearcoat_energy.wgsl"),
    ),
    (
        "materials/clearcoat.wgsl",
        include_str!("../../shaders/materials/clearcoat.wgsl"),
    ),
    (
        "materials/sheen.wgsl",
        include_str!("../../shaders/materials/sheen.wgsl"),
    ),
    (
        "materials/pbr.wgsl",
        include_str!("../../shaders/materials/pbr.wgsl"),
    ),
    (
        "materials/material.wgsl",
        include_str!("../../shaders/materials/material.wgsl"),
    ),
    (
        "textures/texture.wgsl",
        include_str!("../../shaders/textures/texture.wgsl"),
    ),
    (
        "textures/vertex_color.wgsl",
        include_str!("../../shaders/textures/vertex_color.wgsl"),
    ),
    (
        "geometry/alpha.wgsl",
        include_str!("../../shaders/geometry/alpha.wgsl"),
    ),
    (
        "textures/normal_map.wgsl",
        include_str!("../../shaders/textures/normal_map.wgsl"),
    ),
    (
        "lights/environment.wgsl",
        include_str!("../../shaders/lights/environment.wgsl"),
    ),
    (
        "integrator/volume.wgsl",
        include_str!("../../shaders/integrator/volume.wgsl"),
    ),
    (
        "lights/light_sample.wgsl",
        include_str!("../../shaders/lights/light_sample.wgsl"),
    ),
    (
        "lights/light_tree.wgsl",
        include_str!("../../shaders/lights/light_tree.wgsl"),
    ),
    (
        "lights/sampling.wgsl",
        include_str!("../../shaders/lights/sampling.wgsl"),
    ),
    (
        "lights/punctual.wgsl",
        include_str!("../../shaders/lights/punctual.wgsl"),
    ),
    (
        "media/phase.wgsl",
        include_str!("../../shaders/media/phase.wgsl"),
    ),
    (
        "media/grid.wgsl",
        include_str!("../../shaders/media/grid.wgsl"),
    ),
    (
        "media/medium.wgsl",
        include_str!("../../shaders/media/medium.wgsl"),
    ),
    (
        "integrator/aov.wgsl",
        include_str!("../../shaders/integrator/aov.wgsl"),
    ),
    (
        "integrator/accumulate.wgsl",
        include_str!("../../shaders/integrator/accumulate.wgsl"),
    ),
    (
        "integrator/pixel.wgsl",
        include_str!("../../shaders/integrator/pixel.wgsl"),
    ),
    (
        "integrator/tiles.wgsl",
        include_str!("../../shaders/integrator/tiles.wgsl"),
    ),
    (
        "integrator/path.wgsl",
        include_str!("../../shaders/integrator/path.wgsl"),
    ),
    (
        "integrator/path_media.wgsl",
        include_str!("../../shaders/integrator/path_media.wgsl"),
    ),
];

/// Bidirectional path tracing's parts, in dependency order after [`SHADER_PARTS`]: only in
/// kernels with [`KernelFeatures::bdpt`], so that path tracing kernels neither hold nor
/// compile them. Their entry point is [`BDPT_ENTRY_POINT`].
pub const BDPT_PARTS: [(&str, &str); 6] = [
    (
        "lights/emission.wgsl",
        include_str!("../../shaders/lights/emission.wgsl"),
    ),
    (
        "integrator/splat.wgsl",
        include_str!("../../shaders/integrator/splat.wgsl"),
    ),
    (
        "integrator/bdpt/vertex.wgsl",
        include_str!("../../shaders/integrator/bdpt/vertex.wgsl"),
    ),
    (
        "integrator/bdpt/walk.wgsl",
        include_str!("../../shaders/integrator/bdpt/walk.wgsl"),
    ),
    (
        "integrator/bdpt/connect.wgsl",
        include_str!("../../shaders/integrator/bdpt/connect.wgsl"),
    ),
    (
        "integrator/bdpt/mod.wgsl",
        include_str!("../../shaders/integrator/bdpt/mod.wgsl"),
    ),
];

const SCENE_STORAGE: &str = include_str!("../../shaders/core/scene_storage.wgsl");
/// The hardware traversal (ray queries), in the hardware variant only.
const TRAVERSE_HARDWARE: &str = include_str!("../../shaders/traverse/hardware.wgsl");
/// Its entry points as stubs, in every other variant.
const TRAVERSE_SOFTWARE_ONLY: &str = include_str!("../../shaders/traverse/software_only.wgsl");
/// The 4-wide BVH's traversal, in the wide variant only.
const TRAVERSE_WIDE: &str = include_str!("../../shaders/traverse/wide.wgsl");
/// Its entry point as a stub, in every other variant.
const TRAVERSE_BINARY_ONLY: &str = include_str!("../../shaders/traverse/binary_only.wgsl");
const SCENE_UNIFORM: &str = include_str!("../../shaders/core/scene_uniform.wgsl");
/// The parts that only scenes with media need (`KernelFeatures::media`): behind a constant
/// false, lavapipe still translated and inlined them for every kernel it built (about 0.2 s
/// of CPU time and 45 MiB each)...
const MEDIA_PARTS: [&str; 4] = [
    "media/phase.wgsl",
    "media/grid.wgsl",
    "media/medium.wgsl",
    "integrator/path_media.wgsl",
];
/// ...and what stands in for them in every other variant: stubs of what path.wgsl calls.
const NO_MEDIA: (&str, &str) = (
    "media/no_media.wgsl",
    include_str!("../../shaders/media/no_media.wgsl"),
);

/// What stands in for media/grid.wgsl in kernels with media but no grid media: the tracking
/// functions medium.wgsl calls, never reached (no medium has a grid).
const NO_GRID_MEDIA: (&str, &str) = (
    "media/no_grid.wgsl",
    include_str!("../../shaders/media/no_grid.wgsl"),
);

/// What stands in for lights/light_tree.wgsl in kernels without a light tree: what
/// lights/sampling.wgsl names, never reached (`light_tree_active` is false).
const NO_LIGHT_TREE: (&str, &str) = (
    "lights/no_light_tree.wgsl",
    include_str!("../../shaders/lights/no_light_tree.wgsl"),
);

/// Name of the compute entry point in `shaders/integrator/path.wgsl`.
pub const RENDER_ENTRY_POINT: &str = "render";

/// Name of bidirectional path tracing's entry point, in `shaders/integrator/bdpt/mod.wgsl`
/// (kernels with [`KernelFeatures::bdpt`] only).
pub const BDPT_ENTRY_POINT: &str = "render_bdpt";

/// The entry point that renders with `integrator` (`Params::integrator`).
pub fn entry_point_for(integrator: u32) -> &'static str {
    if integrator == crate::kernel::types::INTEGRATOR_BDPT {
        BDPT_ENTRY_POINT
    } else {
        RENDER_ENTRY_POINT
    }
}

/// Workgroup size of the render kernel, as declared in `shaders/integrator/path.wgsl`.
pub const WORKGROUP_SIZE: (u32, u32) = (8, 8);

/// The WGSL declaring the scene's bindings, as a named part.
fn scene_binding_part(binding: &SceneBinding) -> (&'static str, String) {
    // Triangles exist only in the storage layouts; the uniform one compiles their code out.
    // The BVH's constants are declared in every layout, since bvh.wgsl is always compiled.
    let (wide_nodes, wide_stack) = binding.wide_sizes();
    let wide = matches!(binding, SceneBinding::WideBvh { .. });
    let bvh = format!(
        "const BVH_UNIFORM_NODES: u32 = {}u;\nconst BVH_STACK_SIZE: u32 = {}u;\n\
         const BVH_WIDE: bool = {wide};\nconst BVH_WIDE_UNIFORM_NODES: u32 = {wide_nodes}u;\n\
         const BVH_WIDE_STACK_SIZE: u32 = {wide_stack}u;\n{}",
        binding.uniform_node_count(),
        binding.stack_size(),
        if wide {
            TRAVERSE_WIDE
        } else {
            TRAVERSE_BINARY_ONLY
        }
    );
    // The traversal's entry points: ray queries in the hardware variant, stubs elsewhere.
    let hardware = binding.uses_ray_queries();
    let traverse = format!(
        "const USE_RAY_QUERY: bool = {hardware};\n{}",
        if hardware {
            TRAVERSE_HARDWARE
        } else {
            TRAVERSE_SOFTWARE_ONLY
        }
    );
    let storage = |use_bvh: bool| {
        format!(
            "const USE_BVH: bool = {use_bvh};\nconst HAS_TRIANGLES: bool = true;\n\
             {bvh}{SCENE_STORAGE}{traverse}"
        )
    };
    match binding {
        SceneBinding::Storage => ("core/scene_storage.wgsl", storage(false)),
        SceneBinding::Bvh { .. } | SceneBinding::WideBvh { .. } => {
            ("core/scene_storage.wgsl", storage(true))
        }
        SceneBinding::Hardware => ("core/scene_storage.wgsl", storage(false)),
        SceneBinding::Uniform(c) => (
            "core/scene_uniform.wgsl",
            format!(
                "const SPHERE_COUNT: u32 = {}u;\nconst QUAD_COUNT: u32 = {}u;\n\
                 const MATERIAL_COUNT: u32 = {}u;\nconst EMITTER_COUNT: u32 = {}u;\n\
                 const USE_BVH: bool = false;\nconst HAS_TRIANGLES: bool = false;\n{bvh}{}{traverse}",
                c.spheres, c.quads, c.materials, c.emitters, SCENE_UNIFORM
            ),
        ),
    }
}

/// The WGSL constants that turn the features on and off.
fn features_part(features: &KernelFeatures) -> String {
    format!(
        "const LIGHT_SAMPLING: bool = {};\nconst HAS_SPHERE_EMITTERS: bool = {};\n\
         const HAS_QUAD_EMITTERS: bool = {};\nconst HAS_TRIANGLE_EMITTERS: bool = {};\n\
         const HAS_METAL: bool = {};\nconst HAS_DIELECTRIC: bool = {};\nconst HAS_PBR: bool = {};\n\
         const HAS_TRANSMISSION: bool = {};\nconst HAS_CLEARCOAT: bool = {};\n\
         const HAS_SHEEN: bool = {};\nconst HAS_VOLUME: bool = {};\n\
         const AOVS: bool = {};\n\
         const HAS_TEXTURES: bool = {};\nconst HAS_ENVIRONMENT: bool = {};\n\
         const HAS_LIGHTS: bool = {};\nconst HAS_SUN_DISKS: bool = {};\n\
         const HAS_ALPHA: bool = {};\nconst HAS_VERTEX_COLORS: bool = {};\n\
         const HAS_TEXCOORD_1: bool = {};\nconst HAS_INSTANCES: bool = {};\n\
         const HAS_MEDIA: bool = {};\nconst HAS_GRID_MEDIA: bool = {};\n\
         const HAS_LIGHT_TREE: bool = {};\n",
        features.light_sampling,
        features.sphere_emitters,
        features.quad_emitters,
        features.triangle_emitters,
        features.metal,
        features.dielectric,
        features.pbr,
        features.pbr && features.transmission,
        features.pbr && features.clearcoat,
        features.pbr && features.sheen,
        features.volume,
        features.aovs,
        features.textures,
        features.environment,
        features.lights,
        features.sun_disks,
        features.alpha,
        features.vertex_colors,
        features.textures && features.texcoord1,
        features.instances,
        features.media,
        features.media && features.grid_media,
        features.light_tree
    )
}

/// The whole kernel as one WGSL module, for any scene ([`KernelVariant::GENERAL`]).
pub fn render_kernel_source() -> String {
    render_kernel_source_for(KernelVariant::GENERAL)
}

/// Where the kernel reads its `Params` from (src/gpu/inline_uniforms.rs chooses per device).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamsBinding {
    Uniform,
    /// A read-only storage buffer, whose values drivers never compile into the kernel.
    Storage,
}

impl ParamsBinding {
    /// The WGSL address space of the declaration.
    pub fn address_space(&self) -> &'static str {
        match self {
            ParamsBinding::Uniform => "uniform",
            ParamsBinding::Storage => "storage, read",
        }
    }
}

/// The whole kernel as one WGSL module, in the given variant, with `Params` in a uniform buffer.
pub fn render_kernel_source_for(variant: KernelVariant) -> String {
    render_kernel_source_with(variant, ParamsBinding::Uniform)
}

/// The whole kernel as one WGSL module, in the given variant, with `Params` bound as `params`
/// and the texels in one binding.
pub fn render_kernel_source_with(variant: KernelVariant, params: ParamsBinding) -> String {
    render_kernel_source_with_texels(variant, params, TexelBinding::One)
}

/// [`render_kernel_source_with`], reading texels as `texels` says (src/kernel/texels.rs).
pub fn render_kernel_source_with_texels(
    variant: KernelVariant,
    params: ParamsBinding,
    texels: TexelBinding,
) -> String {
    let (scene_name, scene_text) = scene_binding_part(&variant.binding);
    let (texels_name, texels_text) = texels.part();
    let mut source = String::new();
    // An extension must be enabled before any declaration.
    if variant.binding.uses_ray_queries() {
        source += "enable wgpu_ray_query;\n";
    }
    let bdpt_parts: &[(&str, &str)] = if variant.features.bdpt {
        &BDPT_PARTS
    } else {
        &[]
    };
    for (i, &(name, text)) in SHADER_PARTS.iter().chain(bdpt_parts).enumerate() {
        // Without media, the stubs take the media's parts' place (medium.wgsl's).
        let (name, text) = if name == "lights/light_tree.wgsl" {
            if variant.features.light_tree {
                (name, text)
            } else {
                NO_LIGHT_TREE
            }
        } else if name == "media/grid.wgsl" {
            if !variant.features.media {
                continue;
            }
            if variant.features.grid_media {
                (name, text)
            } else {
                NO_GRID_MEDIA
            }
        } else if variant.features.media || !MEDIA_PARTS.contains(&name) {
            (name, text)
        } else if name == "media/medium.wgsl" {
            NO_MEDIA
        } else {
            continue;
        };
        source += &format!("// ---- {name}\n{text}\n");
        if i == 0 {
            source += &format!(
                "// ---- params\n@group(0) @binding(0) var<{}> params: Params;\n",
                params.address_space()
            );
            source += &format!("// ---- features\n{}\n", features_part(&variant.features));
            source += &format!("// ---- {scene_name}\n{scene_text}\n");
            source += &format!("// ---- {texels_name}\n{texels_text}\n");
        }
    }
    source
}
