//! Which WGSL kernel a scene compiles: where it binds the scene (`SceneBinding`) and which
//! features it compiles in (`KernelFeatures`); `kernel::source` assembles the kernel's text.

use crate::kernel::bvh::layout::BvhLayout;
use crate::kernel::types::{
    BvhNode, BvhWideNode, Emitter, Material, Quad, Sphere, ALPHA_OPAQUE, INTEGRATOR_BDPT,
    LIGHT_SUN, MATERIAL_DIELECTRIC, MATERIAL_METAL, MATERIAL_PBR, NO_TEXTURE, PRIMITIVE_LIGHT,
    PRIMITIVE_QUAD, PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE,
};
use crate::kernel::KernelScene;

/// Where the kernel reads the scene's spheres, quads, materials and emitters from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneBinding {
    /// Storage buffers: any scene, one kernel for all (`shaders/core/scene_storage.wgsl`).
    Storage,
    /// Uniform buffers sized for one scene, with the counts compiled in
    /// (`shaders/core/scene_uniform.wgsl`): 1.2–2.3× faster on lavapipe, for scenes that fit.
    Uniform(SceneCounts),
    /// Storage buffers traversed through the scene's BVH (`shaders/traverse/bvh.wgsl`): scenes with
    /// meshes or many objects, which [`KernelScene::bvh_nodes`] then holds. The first
    /// `uniform_nodes` nodes (the top levels: the tree is laid out breadth first) are also in
    /// a uniform buffer, which lavapipe reads far faster ([`bvh_uniform_nodes`]). The
    /// traversal stack holds `stack_size` entries: enough for the tree
    /// ([`crate::kernel::bvh::kernel_stack_size`]).
    Bvh { uniform_nodes: u32, stack_size: u32 },
    /// The same, traversing the 4-wide tree ([`KernelScene::bvh_wide_nodes`],
    /// `shaders/traverse/wide.wgsl`) where the GPU's layout is wide
    /// ([`crate::kernel::bvh::layout`]): `uniform_nodes` of its top in a uniform buffer, a stack of
    /// `stack_size` entries ([`crate::kernel::bvh::wide::kernel_stack_size`]).
    WideBvh { uniform_nodes: u32, stack_size: u32 },
    /// Storage buffers traced with the device's ray queries
    /// (`shaders/traverse/hardware.wgsl`) against an acceleration structure the host builds
    /// (`src/gpu/acceleration.rs`): only on devices with `wgpu::Features::EXPERIMENTAL_RAY_QUERY`,
    /// where a kernel with ray queries compiles. Chosen by `--traversal` (`src/gpu/traversal.rs`),
    /// never by [`SceneBinding::for_scene`].
    Hardware,
}

/// How many of the BVH's top nodes the kernel reads from a uniform buffer on a device whose
/// uniform bindings hold `max_uniform_binding` bytes: as many as fit in it and in
/// [`MAX_UNIFORM_SCENE_BYTES`] (2048 on lavapipe and NVIDIA: the top 11 levels).
/// Why: llvmpipe turns a storage-buffer load whose address differs between lanes into a loop
/// over the lanes with a branch per lane, a uniform-buffer load into one gather, and a
/// traversal reads mostly nodes (BENCHMARKS.md, "Why lavapipe's BVH kernel is slow": +45% at
/// 10³ triangles, whose whole tree fits).
pub fn bvh_uniform_nodes(max_uniform_binding: u64) -> u32 {
    let bytes = max_uniform_binding.min(MAX_UNIFORM_SCENE_BYTES);
    (bytes / size_of::<BvhNode>() as u64).max(1) as u32
}

/// [`bvh_uniform_nodes`] for the wide tree's nodes (512 on lavapipe and NVIDIA: the top 4½
/// levels).
pub fn bvh_wide_uniform_nodes(max_uniform_binding: u64) -> u32 {
    let bytes = max_uniform_binding.min(MAX_UNIFORM_SCENE_BYTES);
    (bytes / size_of::<BvhWideNode>() as u64).max(1) as u32
}

/// How many of each object a scene has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneCounts {
    pub spheres: u32,
    pub quads: u32,
    pub materials: u32,
    pub emitters: u32,
}

impl SceneCounts {
    pub fn of(scene: &KernelScene) -> SceneCounts {
        SceneCounts {
            spheres: scene.spheres.len() as u32,
            quads: scene.quads.len() as u32,
            materials: scene.materials.len() as u32,
            emitters: scene.emitters.len() as u32,
        }
    }

    /// Bytes of the largest of the four uniform buffers (each holds at least one element).
    pub fn largest_uniform_buffer(&self) -> u64 {
        let bytes = |count: u32, size: usize| count.max(1) as u64 * size as u64;
        [
            bytes(self.spheres, size_of::<Sphere>()),
            bytes(self.quads, size_of::<Quad>()),
            bytes(self.materials, size_of::<Material>()),
            bytes(self.emitters, size_of::<Emitter>()),
        ]
        .into_iter()
        .max()
        .unwrap_or(0)
    }
}

/// The most bytes a uniform array may hold, whatever the device allows: 64 KiB (682 quads), the
/// limit of lavapipe and NVIDIA. Larger scenes are better served by storage buffers anyway, as
/// their loops over all objects are too long to unroll.
pub const MAX_UNIFORM_SCENE_BYTES: u64 = 64 << 10;

impl SceneBinding {
    /// The fast uniform binding when every array fits in `max_uniform_binding` bytes (the
    /// device's limit) and in [`MAX_UNIFORM_SCENE_BYTES`], storage buffers otherwise.
    pub fn for_scene(scene: &KernelScene, max_uniform_binding: u64) -> SceneBinding {
        // A scene without the binary tree is scanned, as on the CPU, whatever else it holds.
        if !scene.bvh_nodes.is_empty()
            && !scene.bvh_wide_nodes.is_empty()
            && BvhLayout::for_gpu() == BvhLayout::Wide
        {
            return SceneBinding::WideBvh {
                uniform_nodes: bvh_wide_uniform_nodes(max_uniform_binding),
                stack_size: crate::kernel::bvh::wide::kernel_stack_size(&scene.bvh_wide_nodes),
            };
        }
        if !scene.bvh_nodes.is_empty() {
            return SceneBinding::Bvh {
                uniform_nodes: bvh_uniform_nodes(max_uniform_binding),
                stack_size: crate::kernel::bvh::kernel_stack_size(&scene.bvh_nodes),
            };
        }
        let counts = SceneCounts::of(scene);
        if counts.largest_uniform_buffer() <= max_uniform_binding.min(MAX_UNIFORM_SCENE_BYTES) {
            SceneBinding::Uniform(counts)
        } else {
            SceneBinding::Storage
        }
    }

    /// How many nodes the kernel's uniform copy of the BVH's top holds (`BVH_UNIFORM_NODES`):
    /// one, unused, in the layouts without a BVH.
    pub fn uniform_node_count(&self) -> u32 {
        match self {
            SceneBinding::Bvh { uniform_nodes, .. } => *uniform_nodes,
            SceneBinding::Storage
            | SceneBinding::Uniform(_)
            | SceneBinding::Hardware
            | SceneBinding::WideBvh { .. } => 1,
        }
    }

    /// The kernel's traversal stack length (`BVH_STACK_SIZE`): one, unused, in the layouts
    /// without a BVH.
    pub fn stack_size(&self) -> u32 {
        match self {
            SceneBinding::Bvh { stack_size, .. } => *stack_size,
            SceneBinding::Storage
            | SceneBinding::Uniform(_)
            | SceneBinding::Hardware
            | SceneBinding::WideBvh { .. } => 1,
        }
    }

    /// The wide traversal's uniform node count and stack length (`BVH_WIDE_UNIFORM_NODES`,
    /// `BVH_WIDE_STACK_SIZE`): one each, unused, in the other layouts.
    pub fn wide_sizes(&self) -> (u32, u32) {
        match self {
            SceneBinding::WideBvh {
                uniform_nodes,
                stack_size,
            } => (*uniform_nodes, *stack_size),
            _ => (1, 1),
        }
    }

    /// Short name for benchmarks and logs.
    pub fn name(&self) -> &'static str {
        match self {
            SceneBinding::Storage => "storage",
            SceneBinding::Uniform(_) => "uniform",
            SceneBinding::Bvh { .. } => "bvh",
            SceneBinding::WideBvh { .. } => "bvh-wide",
            SceneBinding::Hardware => "hardware",
        }
    }

    /// Whether the kernel traces with ray queries: it then needs the device feature.
    pub fn uses_ray_queries(&self) -> bool {
        matches!(self, SceneBinding::Hardware)
    }
}

/// The parts of the kernel a scene needs, compiled in as constants; the rest is compiled out.
/// Why: lavapipe runs every branch of the path loop for all lanes, under a mask, whether or not
/// a lane takes it, so code a scene cannot reach still costs time on every segment (compiling
/// out light sampling halves the time of a render without it). On real GPUs it saves
/// registers. Each flag only removes code that cannot run for the scene, so images do not
/// change (tests/suite/scene_binding.rs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KernelFeatures {
    /// Next-event estimation with MIS (`Params::light_sampling`, with at least one emitter).
    pub light_sampling: bool,
    pub sphere_emitters: bool,
    pub quad_emitters: bool,
    pub triangle_emitters: bool,
    pub metal: bool,
    pub dielectric: bool,
    /// glTF's metallic-roughness material (shaders/materials/pbr.wgsl) and its energy tables.
    pub pbr: bool,
    /// pbr's transmission lobe (shaders/materials/rough_dielectric.wgsl), for pbr materials with
    /// transmission.
    pub transmission: bool,
    /// pbr's KHR_materials_clearcoat layer (shaders/materials/clearcoat.wgsl), for pbr materials with a
    /// coat.
    pub clearcoat: bool,
    /// pbr's KHR_materials_sheen layer (shaders/materials/sheen.wgsl) and its albedo table, for pbr
    /// materials with a sheen.
    pub sheen: bool,
    /// Beer–Lambert attenuation inside meshes (shaders/integrator/volume.wgsl), for materials with an
    /// attenuation distance.
    pub volume: bool,
    /// The denoiser's albedo, normal and depth outputs (`Params::aovs`, shaders/integrator/aov.wgsl).
    pub aovs: bool,
    /// Textured materials: texture coordinates at hits and lookups (shaders/textures/texture.wgsl).
    pub textures: bool,
    /// An environment map (`[environment]`, shaders/lights/environment.wgsl) in place of the
    /// constant background, and light sampling of it when that is on.
    pub environment: bool,
    /// Point, spot and directional lights, sampled by light sampling (shaders/lights/punctual.wgsl).
    pub lights: bool,
    /// Sun disks, which rays that escape can see (with or without light sampling).
    pub sun_disks: bool,
    /// Alpha-tested or blended materials (shaders/geometry/alpha.wgsl): without them every triangle hit
    /// is accepted as before, at the same cost.
    pub alpha: bool,
    /// Meshes with vertex colours (glTF's COLOR_0, shaders/textures/vertex_color.wgsl).
    pub vertex_colors: bool,
    /// Instanced meshes (shaders/geometry/instance.wgsl, shaders/traverse/blas.wgsl): without them no
    /// top-level leaf is an instance and every triangle is read as it is stored.
    pub instances: bool,
    /// Textures on the second texture coordinate set (glTF's TEXCOORD_1, shaders/textures/texture.wgsl).
    pub texcoord1: bool,
    /// Participating media (shaders/media/, shaders/integrator/path_media.wgsl): free flights,
    /// medium vertices, interfaces and shadow rays through them.
    pub media: bool,
    /// Heterogeneous media's density grids (shaders/media/grid.wgsl): delta and ratio tracking
    /// against a majorant grid. Without them (and in kernels without media) a stub stands in,
    /// and homogeneous media keep their closed forms alone.
    pub grid_media: bool,
    /// Bidirectional path tracing (shaders/integrator/bdpt/, shaders/lights/emission.wgsl,
    /// shaders/integrator/splat.wgsl) and its entry point, for scenes rendered with
    /// `Params::integrator` = `INTEGRATOR_BDPT`; compiled out of path tracing's kernels. Its
    /// next-event estimation and light paths reach every emitter, light sampling or not, so
    /// [`KernelFeatures::of`] compiles the lights in wherever the scene has them.
    pub bdpt: bool,
    /// The light tree (shaders/lights/light_tree.wgsl), for scenes whose next-event
    /// estimation picks emitters with one (`Params::light_tree_nodes`); a stub stands in
    /// elsewhere, so scenes picking by power compile what they did before.
    pub light_tree: bool,
}

impl KernelFeatures {
    /// Everything compiled in: a kernel for any scene and any `Params`.
    pub const ALL: KernelFeatures = KernelFeatures {
        light_sampling: true,
        sphere_emitters: true,
        quad_emitters: true,
        triangle_emitters: true,
        metal: true,
        dielectric: true,
        pbr: true,
        transmission: true,
        clearcoat: true,
        sheen: true,
        volume: true,
        aovs: true,
        textures: true,
        environment: true,
        lights: true,
        sun_disks: true,
        alpha: true,
        vertex_colors: true,
        instances: true,
        texcoord1: true,
        media: true,
        grid_media: true,
        bdpt: true,
        light_tree: true,
    };

    /// What `scene`, rendered with its own `Params`, can reach.
    pub fn of(scene: &KernelScene) -> KernelFeatures {
        let emits = |primitive| scene.emitters.iter().any(|e| e.primitive == primitive);
        let has_kind = |kind| scene.materials.iter().any(|m| m.kind == kind);
        let light_sampling = scene.params.light_sampling != 0 && !scene.emitters.is_empty();
        let bdpt = scene.params.integrator == INTEGRATOR_BDPT;
        KernelFeatures {
            light_sampling,
            sphere_emitters: emits(PRIMITIVE_SPHERE),
            quad_emitters: emits(PRIMITIVE_QUAD),
            triangle_emitters: emits(PRIMITIVE_TRIANGLE),
            metal: has_kind(MATERIAL_METAL),
            dielectric: has_kind(MATERIAL_DIELECTRIC),
            pbr: has_kind(MATERIAL_PBR),
            transmission: scene.materials.iter().any(|m| {
                m.kind == MATERIAL_PBR
                    && (m.transmission > 0.0 || m.transmission_texture != NO_TEXTURE)
            }),
            clearcoat: scene
                .materials
                .iter()
                .any(|m| m.kind == MATERIAL_PBR && m.clearcoat > 0.0),
            sheen: scene
                .materials
                .iter()
                .any(|m| m.kind == MATERIAL_PBR && m.sheen_color.iter().any(|&c| c > 0.0)),
            volume: scene.materials.iter().any(|m| m.attenuation_distance > 0.0),
            aovs: scene.params.aovs != 0,
            textures: !scene.textures.is_empty(),
            environment: scene.params.environment_width > 0,
            lights: (light_sampling || bdpt) && emits(PRIMITIVE_LIGHT),
            sun_disks: scene
                .lights
                .iter()
                .any(|l| l.kind == LIGHT_SUN && l.sun_one_minus_cos > 0.0),
            alpha: has_alpha(&scene.materials),
            vertex_colors: !scene.triangle_colors.is_empty(),
            instances: !scene.instances.is_empty(),
            texcoord1: !scene.triangle_uvs1.is_empty(),
            media: scene.params.medium_count > 0,
            grid_media: scene.params.medium_count > 0 && !scene.grids.is_empty(),
            bdpt,
            light_tree: light_sampling && scene.params.light_tree_nodes > 0 && !bdpt,
        }
    }

    /// The features of both: a kernel for every scene either serves (tests share one kernel
    /// between scenes so).
    pub fn union(&self, other: &KernelFeatures) -> KernelFeatures {
        KernelFeatures {
            light_sampling: self.light_sampling || other.light_sampling,
            sphere_emitters: self.sphere_emitters || other.sphere_emitters,
            quad_emitters: self.quad_emitters || other.quad_emitters,
            triangle_emitters: self.triangle_emitters || other.triangle_emitters,
            metal: self.metal || other.metal,
            dielectric: self.dielectric || other.dielectric,
            pbr: self.pbr || other.pbr,
            transmission: self.transmission || other.transmission,
            clearcoat: self.clearcoat || other.clearcoat,
            sheen: self.sheen || other.sheen,
            volume: self.volume || other.volume,
            aovs: self.aovs || other.aovs,
            textures: self.textures || other.textures,
            environment: self.environment || other.environment,
            lights: self.lights || other.lights,
            sun_disks: self.sun_disks || other.sun_disks,
            alpha: self.alpha || other.alpha,
            vertex_colors: self.vertex_colors || other.vertex_colors,
            instances: self.instances || other.instances,
            texcoord1: self.texcoord1 || other.texcoord1,
            media: self.media || other.media,
            grid_media: self.grid_media || other.grid_media,
            bdpt: self.bdpt || other.bdpt,
            light_tree: self.light_tree || other.light_tree,
        }
    }

    /// Whether a kernel with these features renders everything `other` needs.
    pub fn covers(&self, other: &KernelFeatures) -> bool {
        let needs = |have: bool, need: bool| have || !need;
        needs(self.light_sampling, other.light_sampling)
            && needs(self.sphere_emitters, other.sphere_emitters)
            && needs(self.quad_emitters, other.quad_emitters)
            && needs(self.triangle_emitters, other.triangle_emitters)
            && needs(self.metal, other.metal)
            && needs(self.dielectric, other.dielectric)
            && needs(self.pbr, other.pbr)
            && needs(self.transmission, other.transmission)
            && needs(self.clearcoat, other.clearcoat)
            && needs(self.sheen, other.sheen)
            && needs(self.volume, other.volume)
            && needs(self.aovs, other.aovs)
            && needs(self.textures, other.textures)
            && needs(self.environment, other.environment)
            && needs(self.lights, other.lights)
            && needs(self.sun_disks, other.sun_disks)
            && needs(self.alpha, other.alpha)
            && needs(self.vertex_colors, other.vertex_colors)
            && needs(self.instances, other.instances)
            && needs(self.texcoord1, other.texcoord1)
            && needs(self.media, other.media)
            && needs(self.grid_media, other.grid_media)
            && needs(self.bdpt, other.bdpt)
            && needs(self.light_tree, other.light_tree)
    }
}

/// Whether a material is alpha-tested or blended (the kernel's `HAS_ALPHA`).
pub fn has_alpha(materials: &[Material]) -> bool {
    materials.iter().any(|m| m.alpha_mode != ALPHA_OPAQUE)
}

/// One compiled form of the kernel: where it reads the scene from, and what it compiles in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KernelVariant {
    pub binding: SceneBinding,
    pub features: KernelFeatures,
}

impl KernelVariant {
    /// The kernel for any scene: storage buffers, every feature.
    pub const GENERAL: KernelVariant = KernelVariant {
        binding: SceneBinding::Storage,
        features: KernelFeatures::ALL,
    };

    /// The fastest kernel for `scene` on a device whose uniform bindings hold
    /// `max_uniform_binding` bytes.
    pub fn for_scene(scene: &KernelScene, max_uniform_binding: u64) -> KernelVariant {
        KernelVariant {
            binding: SceneBinding::for_scene(scene, max_uniform_binding),
            features: KernelFeatures::of(scene),
        }
    }

    /// [`KernelVariant::for_scene`]'s kernel with storage buffers where that has uniform ones:
    /// the same features, but nothing of the scene's size compiled in, so that scenes using
    /// the same features share one kernel. It renders the same image
    /// (tests/suite/scene_binding.rs), a little more slowly. (A kernel with every feature
    /// would serve every scene, but lavapipe takes minutes to compile it.)
    pub fn shared_for(scene: &KernelScene, max_uniform_binding: u64) -> KernelVariant {
        let fastest = KernelVariant::for_scene(scene, max_uniform_binding);
        match fastest.binding {
            SceneBinding::Uniform(_) => KernelVariant {
                binding: SceneBinding::Storage,
                ..fastest
            },
            _ => fastest,
        }
    }

    /// The kernel a renderer takes unless told otherwise: [`KernelVariant::for_scene`]'s, or
    /// [`KernelVariant::shared_for`]'s where `GLINT_KERNEL_VARIANT=shared` says so. On
    /// lavapipe, compiling a kernel takes seconds and rendering a test's few pixels
    /// milliseconds, so the test suite (scripts/test) renders through shared kernels; the
    /// uniform variants themselves are tested by asking for them.
    pub fn default_for(scene: &KernelScene, max_uniform_binding: u64) -> KernelVariant {
        if shared_kernel_requested() {
            KernelVariant::shared_for(scene, max_uniform_binding)
        } else {
            KernelVariant::for_scene(scene, max_uniform_binding)
        }
    }
}

/// `GLINT_KERNEL_VARIANT`, read once: `shared` or `fastest` (the default); anything else is
/// ignored with a warning.
fn shared_kernel_requested() -> bool {
    static SHARED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *SHARED.get_or_init(|| match std::env::var("GLINT_KERNEL_VARIANT").as_deref() {
        Ok("shared") => true,
        Ok("fastest") | Err(_) => false,
        Ok(other) => {
            crate::errln!(
                "glint: GLINT_KERNEL_VARIANT={other} is neither shared nor fastest; ignored"
            );
            false
        }
    })
}
