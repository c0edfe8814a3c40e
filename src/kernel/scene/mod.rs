//! The validated scene laid out as the kernel's `#[repr(C)]` structs (`KernelScene`), one
//! step per concept: the emitter table that light sampling draws from (`emitter_table`), the
//! `Params` and camera (`params`), the materials (`materials`), the primitives and their
//! per-triangle attributes (`geometry`), and the BVH with its instances (`acceleration`).

mod acceleration;
mod emitter_table;
mod geometry;
mod grids;
mod light_tree;
mod materials;
mod params;

pub use light_tree::MAX_TREE_EMITTERS;
pub use params::place_camera;

use crate::error::InputError;
use crate::kernel::types::{
    self, BvhNode, BvhWideNode, Emitter, EnvironmentAlias, EnvironmentTexel, Params, Texture,
    TriangleColors, TriangleNormals, TriangleTangents, TriangleUvs,
};
use crate::scene::{MaterialKind, Scene};
use emitter_table::EmitterTable;
use glam::Vec3;

/// The scene as the kernel reads it; the CPU reference traces from the same structs.
#[derive(Clone, Debug)]
pub struct KernelScene {
    pub params: Params,
    pub spheres: Vec<types::Sphere>,
    pub quads: Vec<types::Quad>,
    pub materials: Vec<types::Material>,
    pub emitters: Vec<Emitter>,
    pub triangles: Vec<types::Triangle>,
    /// One per triangle.
    pub triangle_normals: Vec<TriangleNormals>,
    /// The BVH over all primitives; empty for scenes small enough to test every primitive
    /// (see [`bvh::wants_bvh`](crate::kernel::bvh::wants_bvh)).
    pub bvh_nodes: Vec<BvhNode>,
    pub bvh_primitives: Vec<u32>,
    /// The same tree collapsed 4 wide (`bvh_wide.rs`), over the same `bvh_primitives`; empty
    /// with no BVH. Each device traverses one of the two (`kernel::bvh::layout`).
    pub bvh_wide_nodes: Vec<BvhWideNode>,
    pub bvh_build_seconds: f64,
    /// Texture descriptors and all images' texels (`scene::texture`); empty without textures.
    pub textures: Vec<Texture>,
    pub texels: Vec<[f32; 4]>,
    /// One per triangle when the scene has textures, else empty.
    pub triangle_uvs: Vec<TriangleUvs>,
    /// The second set (glTF's TEXCOORD_1), one per triangle when a texture reads it, else
    /// empty.
    pub triangle_uvs1: Vec<TriangleUvs>,
    /// One per triangle when a material has a normal map, else empty.
    pub triangle_tangents: Vec<TriangleTangents>,
    /// One per triangle when a mesh has vertex colours, else empty.
    pub triangle_colors: Vec<TriangleColors>,
    /// The environment map's texels and alias table (`environment.rs`); empty without one.
    pub environment_texels: Vec<EnvironmentTexel>,
    pub environment_alias: Vec<EnvironmentAlias>,
    /// Point, spot and directional lights (`scene::light`); point lights with a radius are
    /// spheres instead.
    pub lights: Vec<types::Light>,
    /// The placements of instanced meshes (`Scene::instanced`), whose triangles follow the
    /// scene's own in `triangles` and whose bottom-level BVHs follow the top level in
    /// `bvh_nodes`; empty without instances.
    pub instances: Vec<types::Instance>,
    /// Grid media's descriptors (`Medium::grid` indexes them) and, in one array, each grid's
    /// densities and block majorants (`grids.rs`); empty without grid media.
    pub grids: Vec<types::GridMedium>,
    pub grid_voxels: Vec<f32>,
    /// The light tree path tracing's next-event estimation picks finite emitters with
    /// (`light_tree.rs`), `Params::light_tree_nodes` of them, and each emitting sphere's,
    /// quad's and triangle's path to its leaf, in that order, 64 bits as two words; both
    /// empty where the alias table picks every emitter.
    pub light_tree_nodes: Vec<types::LightTreeNode>,
    pub light_tree_trails: Vec<[u32; 2]>,
}

impl KernelScene {
    /// Bytes of the scene's arrays on the device (all but the image's accumulators).
    pub fn scene_bytes(&self) -> u64 {
        fn bytes<T>(items: &[T]) -> u64 {
            std::mem::size_of_val(items) as u64
        }
        bytes(&self.spheres)
            + bytes(&self.quads)
            + bytes(&self.materials)
            + bytes(&self.emitters)
            + bytes(&self.triangles)
            + bytes(&self.triangle_normals)
            + bytes(&self.bvh_nodes)
            + bytes(&self.bvh_primitives)
            + bytes(&self.bvh_wide_nodes)
            + bytes(&self.textures)
            + bytes(&self.texels)
            + bytes(&self.triangle_uvs)
            + bytes(&self.triangle_uvs1)
            + bytes(&self.triangle_tangents)
            + bytes(&self.triangle_colors)
            + bytes(&self.environment_texels)
            + bytes(&self.environment_alias)
            + bytes(&self.lights)
            + bytes(&self.instances)
            + bytes(&self.grids)
            + bytes(&self.grid_voxels)
            + bytes(&self.light_tree_nodes)
            + bytes(&self.light_tree_trails)
    }
}

impl Scene {
    /// [`Scene::try_kernel_scene`] for scenes known to fit the kernel (tests, the built-in
    /// benchmark scene); panics where that one returns an error.
    pub fn kernel_scene(&self) -> KernelScene {
        self.try_kernel_scene().unwrap_or_else(|e| panic!("{e}"))
    }

    /// Converts to the kernel's structs (camera basis precomputed, quads' duals, emission ×
    /// strength, the BVH). Fails (bad input) when there are more primitives than the BVH can
    /// reference.
    pub fn try_kernel_scene(&self) -> Result<KernelScene, InputError> {
        if self.lights.iter().any(|l| l.sphere().is_some()) {
            return self.with_sphere_lights().lay_out();
        }
        self.lay_out()
    }

    /// The scene with each point light that has a radius turned into an emitting sphere, with
    /// a material of its own (`lights[i]`), which the kernel traces like any other sphere.
    fn with_sphere_lights(&self) -> Scene {
        let mut scene = self.clone();
        scene.lights.clear();
        for (i, light) in self.lights.iter().enumerate() {
            let Some((center, radius, radiance)) = light.sphere() else {
                scene.lights.push(light.clone());
                continue;
            };
            scene.spheres.push(crate::scene::Sphere {
                center,
                radius,
                material: scene.materials.len() as u32,
            });
            scene.materials.push(crate::scene::Material::untextured(
                format!("lights[{i}]"),
                MaterialKind::Diffuse,
                Vec3::ZERO,
                radiance,
                crate::scene::Alpha::OPAQUE,
            ));
        }
        scene
    }

    /// The kernel's arrays, laid out one concept at a time (this module's files).
    fn lay_out(&self) -> Result<KernelScene, InputError> {
        // Every triangle the kernel holds: the scene's own, then each instanced mesh's once, in
        // its own coordinates. Per-triangle arrays are indexed alike; instanced meshes never
        // emit (validate/objects.rs), so light sampling reads only the first part.
        let stored: Vec<&crate::scene::Triangle> = self
            .triangles
            .iter()
            .chain(self.instanced.iter().flat_map(|m| &m.triangles))
            .collect();
        let environment = self.environment.as_ref().map(|e| (e, e.tables()));
        let EmitterTable {
            emitters,
            sphere_probability,
            quad_probability,
            triangle_probability,
            light_probability,
            finite,
            finite_probability,
        } = self.emitter_table(environment.as_ref().map(|(_, t)| t.radiance_integral));
        let params = self.kernel_params(&emitters, environment.as_ref().map(|(e, _)| *e));
        let (environment_texels, environment_alias) = match environment {
            Some((_, tables)) => (tables.texels, tables.alias),
            None => (Vec::new(), Vec::new()),
        };
        let (grids, grid_voxels) = grids::kernel_grids(&self.media);
        // Bidirectional path tracing keeps the choice by power, which its light subpaths
        // and their MIS weights assume.
        let tree = if self.render.light_sampler == crate::scene::LightSampler::Tree
            && self.render.integrator == crate::scene::Integrator::Path
        {
            self.light_tree(&finite)
        } else {
            light_tree::LightTree::default()
        };
        let mut scene = KernelScene {
            params,
            spheres: geometry::kernel_spheres(self, &sphere_probability),
            quads: geometry::kernel_quads(self, &quad_probability),
            materials: self
                .materials
                .iter()
                .map(materials::kernel_material)
                .collect(),
            emitters,
            triangles: geometry::kernel_triangles(&stored, &triangle_probability),
            triangle_normals: geometry::triangle_normals(&stored),
            bvh_nodes: Vec::new(),
            bvh_primitives: Vec::new(),
            bvh_wide_nodes: Vec::new(),
            bvh_build_seconds: 0.0,
            textures: self.textures.descriptors.clone(),
            texels: self.textures.texels.clone(),
            triangle_uvs: geometry::triangle_uvs(self, &stored),
            triangle_uvs1: geometry::triangle_uvs1(self, &stored),
            triangle_tangents: geometry::triangle_tangents(self, &stored),
            triangle_colors: geometry::triangle_colors(&stored),
            environment_texels,
            environment_alias,
            lights: self
                .lights
                .iter()
                .zip(light_probability)
                .map(|(l, p)| l.kernel_light(p))
                .collect(),
            instances: Vec::new(),
            grids,
            grid_voxels,
            light_tree_nodes: tree.nodes,
            light_tree_trails: tree.trails,
        };
        scene.params.light_tree_nodes = scene.light_tree_nodes.len() as u32;
        if !scene.light_tree_nodes.is_empty() {
            scene.params.light_tree_probability = finite_probability;
        }
        scene.params.splat_scale = params::splat_scale(&scene);
        self.lay_out_bvh(&mut scene)?;
        Ok(scene)
    }
}
