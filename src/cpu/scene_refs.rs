//! The scene as the kernel binds it (WGSL side: the global bindings of
//! `shaders/core/scene_storage.wgsl` or `scene_uniform.wgsl`): every array the CPU reference
//! reads, borrowed from a `KernelScene`, and the views of it that intersection and texture
//! lookups take. Lights and the integrator read the scene through it.

use crate::cpu::geometry::alpha::AlphaTest;
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::media::grid::Grids;
use crate::cpu::textures::texture::Textures;
use crate::kernel::bvh::layout::BvhLayout;
use crate::kernel::types::{
    Emitter, EnvironmentAlias, EnvironmentTexel, Light, LightTreeNode, Material, Params, Texture,
    TriangleColors, TriangleTangents,
};
use crate::kernel::variant::has_alpha;
use crate::kernel::KernelScene;

/// The scene as the kernel sees it.
#[derive(Clone, Copy)]
pub struct SceneRefs<'a> {
    pub params: &'a Params,
    pub materials: &'a [Material],
    pub emitters: &'a [Emitter],
    /// Texture descriptors and texels (`texture.rs`); empty without textures.
    pub textures: &'a [Texture],
    pub texels: &'a [[f32; 4]],
    /// One per triangle when a material has a normal map, else empty.
    pub triangle_tangents: &'a [TriangleTangents],
    /// One per triangle when a mesh has vertex colours, else empty.
    pub triangle_colors: &'a [TriangleColors],
    /// Empty without an environment map.
    pub environment_texels: &'a [EnvironmentTexel],
    pub environment_alias: &'a [EnvironmentAlias],
    /// Point, spot and directional lights (`punctual.rs`).
    pub lights: &'a [Light],
    /// Grid media's grids (`src/cpu/media/grid.rs`); empty without them.
    pub grids: Grids<'a>,
    /// The light tree and its trails (`src/cpu/lights/light_tree.rs`); empty without one.
    pub light_tree_nodes: &'a [LightTreeNode],
    pub light_tree_trails: &'a [[u32; 2]],
    /// The surfaces, as intersection reads them: spheres, quads, triangles with their normals
    /// and texture coordinates, the BVHs and instances, and the key of the ray segment being
    /// traced (the kernel's private `alpha_key`), which `path_step` sets when `has_alpha`.
    /// Built once here, not per ray: building it for every ray and shadow ray was 3% of a CPU
    /// render.
    pub geometry: Geometry<'a>,
}

impl<'a> SceneRefs<'a> {
    /// `scene`'s arrays with `params` in place of its own.
    pub fn of(scene: &'a KernelScene, params: &'a Params) -> SceneRefs<'a> {
        let textures = Textures {
            descriptors: &scene.textures,
            texels: &scene.texels,
        };
        SceneRefs {
            params,
            materials: &scene.materials,
            emitters: &scene.emitters,
            environment_texels: &scene.environment_texels,
            environment_alias: &scene.environment_alias,
            textures: &scene.textures,
            texels: &scene.texels,
            triangle_tangents: &scene.triangle_tangents,
            triangle_colors: &scene.triangle_colors,
            lights: &scene.lights,
            grids: Grids {
                grids: &scene.grids,
                voxels: &scene.grid_voxels,
            },
            light_tree_nodes: &scene.light_tree_nodes,
            light_tree_trails: &scene.light_tree_trails,
            geometry: Geometry {
                spheres: &scene.spheres,
                quads: &scene.quads,
                triangles: &scene.triangles,
                triangle_normals: &scene.triangle_normals,
                bvh_nodes: &scene.bvh_nodes,
                bvh_primitives: &scene.bvh_primitives,
                instances: &scene.instances,
                bvh_wide_nodes: match BvhLayout::for_cpu() {
                    BvhLayout::Wide => &scene.bvh_wide_nodes,
                    BvhLayout::Binary => &[],
                },
                triangle_uvs: &scene.triangle_uvs,
                triangle_uvs1: &scene.triangle_uvs1,
                textured: !scene.textures.is_empty(),
                alpha: AlphaTest {
                    enabled: has_alpha(&scene.materials),
                    materials: &scene.materials,
                    textures,
                    triangle_uvs: &scene.triangle_uvs,
                    triangle_uvs1: &scene.triangle_uvs1,
                    triangle_colors: &scene.triangle_colors,
                    key: 0,
                },
            },
        }
    }

    /// Whether a material is alpha-tested or blended (the kernel's `HAS_ALPHA`, alpha.rs).
    pub fn has_alpha(&self) -> bool {
        self.geometry.alpha.enabled
    }

    /// What texture lookups read.
    pub fn textures(&self) -> Textures<'a> {
        Textures {
            descriptors: self.textures,
            texels: self.texels,
        }
    }

    /// The same scene tracing the ray segment whose alpha key is `key`.
    pub fn with_alpha_key(&self, key: u32) -> SceneRefs<'a> {
        let mut keyed = *self;
        keyed.geometry.alpha.key = key;
        keyed
    }

    /// What intersection reads.
    pub fn geometry(&self) -> Geometry<'a> {
        self.geometry
    }
}
