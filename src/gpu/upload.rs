//! The scene's arrays and the energy tables uploaded into the buffers the render kernel binds,
//! after checking that the device can hold every one of them: one place that knows which
//! array goes to which binding, in which kind of buffer, for each kernel variant.

use super::context::GpuContext;
use super::limits::{check_buffers, BufferBinding, BufferNeed};
use crate::kernel::texels::{TexelBinding, EXTRA_WINDOW_BINDINGS};
use crate::kernel::types::{BvhNode, BvhWideNode};
use crate::kernel::variant::{KernelVariant, SceneBinding};
use crate::kernel::KernelScene;
use anyhow::Result;
use bytemuck::Pod;
use wgpu::util::DeviceExt;

/// A buffer binding as the kernel's layout declares it: binding number, type, buffer.
pub type Binding<'b> = (u32, wgpu::BufferBindingType, &'b wgpu::Buffer);

const READ_ONLY: wgpu::BufferBindingType = wgpu::BufferBindingType::Storage { read_only: true };
const UNIFORM: wgpu::BufferBindingType = wgpu::BufferBindingType::Uniform;

/// A read-only storage buffer holding `items`; bindings cannot be empty, so an empty list
/// uploads one zeroed element (the kernel reads the real count from `Params`).
pub fn storage_buffer<T: Pod + Default>(
    ctx: &GpuContext,
    label: &str,
    items: &[T],
) -> wgpu::Buffer {
    scene_buffer(ctx, label, items, wgpu::BufferUsages::STORAGE)
}

/// Bytes of the buffer [`scene_buffer`] makes for `items` (at least one element).
pub fn array_bytes<T>(items: &[T]) -> u64 {
    items.len().max(1) as u64 * size_of::<T>() as u64
}

/// A buffer of the scene's objects for a storage or uniform binding, holding at least one
/// (zeroed) element, as the kernel's arrays do.
fn scene_buffer<T: Pod + Default>(
    ctx: &GpuContext,
    label: &str,
    items: &[T],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let placeholder = [T::default()];
    let items = if items.is_empty() {
        &placeholder[..]
    } else {
        items
    };
    ctx.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(items),
            usage,
        })
}

/// Checks that the kernel's storage bindings, `buffers`' and the extra texel windows among them,
/// are within the device's `max_storage_buffers_per_shader_stage`: bad input naming both
/// counts otherwise.
pub fn check_storage_binding_count(
    limits: &wgpu::Limits,
    buffers: &[Binding],
) -> Result<(), crate::error::InputError> {
    let storage = buffers
        .iter()
        .filter(|(_, ty, _)| matches!(ty, wgpu::BufferBindingType::Storage { .. }))
        .count() as u32;
    if storage > limits.max_storage_buffers_per_shader_stage {
        return Err(crate::error::InputError(format!(
            "the scene is too large for this GPU: its texture texels need {} more storage \
             bindings, {storage} in all, but the device's max_storage_buffers_per_shader_stage \
             is {}",
            EXTRA_WINDOW_BINDINGS.len(),
            limits.max_storage_buffers_per_shader_stage
        )));
    }
    Ok(())
}

const WINDOW_LABELS: [&str; 4] = [
    "texture texels",
    "texture texels window 2",
    "texture texels window 3",
    "texture texels window 4",
];

/// Sizes of the buffers the renderer makes beside the scene's (accumulators and AOVs), so that
/// one check covers every buffer before anything is uploaded.
pub struct ImageSizes {
    pub accumulation: u64,
    pub aov: u64,
    /// The splat film's bytes, in kernels that have one (bidirectional path tracing).
    pub splats: Option<u64>,
}

/// The scene's arrays and the energy tables in GPU buffers, bound as the kernel `variant`
/// declares them.
pub struct SceneBuffers {
    /// Storage, or uniform for [`SceneBinding::Uniform`]: the binding of spheres, quads,
    /// materials and emitters.
    scene_type: wgpu::BufferBindingType,
    spheres: wgpu::Buffer,
    quads: wgpu::Buffer,
    materials: wgpu::Buffer,
    emitters: wgpu::Buffer,
    triangles: wgpu::Buffer,
    triangle_normals: wgpu::Buffer,
    bvh_nodes: wgpu::Buffer,
    bvh_top_nodes: wgpu::Buffer,
    bvh_primitives: wgpu::Buffer,
    instances: wgpu::Buffer,
    textures: wgpu::Buffer,
    /// One buffer per texel window (src/kernel/texels.rs).
    texels: Vec<wgpu::Buffer>,
    triangle_uvs: wgpu::Buffer,
    triangle_uvs1: wgpu::Buffer,
    triangle_tangents: wgpu::Buffer,
    triangle_colors: wgpu::Buffer,
    environment_texels: wgpu::Buffer,
    environment_alias: wgpu::Buffer,
    lights: wgpu::Buffer,
    light_tree_nodes: wgpu::Buffer,
    light_tree_trails: wgpu::Buffer,
    ggx_energy: wgpu::Buffer,
    dielectric_energy: wgpu::Buffer,
    sheen_energy: wgpu::Buffer,
    clearcoat_energy: wgpu::Buffer,
    /// The wide tree's nodes and its uniform top, in the wide variant only.
    wide: Option<(wgpu::Buffer, wgpu::Buffer)>,
    /// Grid media's descriptors and numbers (bindings 46 and 47), in kernels with grid media
    /// only.
    grids: Option<(wgpu::Buffer, wgpu::Buffer)>,
    pub texel_binding: TexelBinding,
    /// Whether the kernel declares the light tree's bindings (48 and 49).
    light_tree: bool,
}

/// The tree each variant binds: the wide one where the variant traverses it, the binary one
/// otherwise (the other a placeholder).
fn trees<'s>(
    scene: &'s KernelScene,
    variant: &KernelVariant,
) -> (&'s [BvhNode], &'s [BvhWideNode]) {
    let wide_nodes: &[BvhWideNode] = if matches!(variant.binding, SceneBinding::WideBvh { .. }) {
        &scene.bvh_wide_nodes
    } else {
        &[]
    };
    let binary_nodes: &[BvhNode] = if wide_nodes.is_empty() {
        &scene.bvh_nodes
    } else {
        &[]
    };
    (binary_nodes, wide_nodes)
}

/// The energy table `table()` where the kernel reads it, a placeholder elsewhere.
fn energy_table(
    ctx: &GpuContext,
    label: &str,
    used: bool,
    table: fn() -> &'static [f32],
) -> wgpu::Buffer {
    let values: &[f32] = if used { table() } else { &[] };
    storage_buffer(ctx, label, values)
}

impl SceneBuffers {
    /// Checks every buffer a renderer of `scene` needs against the device's limits (bad input
    /// if one does not fit), then uploads the scene's. Texels are split into windows of at
    /// most `window_bytes` where they exceed one binding.
    pub fn upload(
        ctx: &GpuContext,
        scene: &KernelScene,
        variant: &KernelVariant,
        window_bytes: u64,
        images: &ImageSizes,
    ) -> Result<SceneBuffers> {
        let (usage, scene_type) = match variant.binding {
            SceneBinding::Storage
            | SceneBinding::Bvh { .. }
            | SceneBinding::WideBvh { .. }
            | SceneBinding::Hardware => (wgpu::BufferUsages::STORAGE, READ_ONLY),
            SceneBinding::Uniform(_) => (wgpu::BufferUsages::UNIFORM, UNIFORM),
        };
        let limits = ctx.device.limits();
        let window_bytes = window_bytes
            .min(limits.max_storage_buffer_binding_size)
            .min(limits.max_buffer_size);
        let texel_binding = TexelBinding::plan(scene.texels.len() as u64, window_bytes)?;
        Self::check(scene, variant, scene_type, texel_binding, images, &limits)?;
        let (binary_nodes, wide_nodes) = trees(scene, variant);
        let uniform_nodes = variant.binding.uniform_node_count();
        let mut top_nodes = binary_nodes[..binary_nodes.len().min(uniform_nodes as usize)].to_vec();
        top_nodes.resize(uniform_nodes as usize, BvhNode::default());
        let (wide_uniform_nodes, _) = variant.binding.wide_sizes();
        let wide = (!wide_nodes.is_empty()).then(|| {
            let mut top = wide_nodes[..wide_nodes.len().min(wide_uniform_nodes as usize)].to_vec();
            top.resize(wide_uniform_nodes as usize, BvhWideNode::default());
            (
                storage_buffer(ctx, "wide BVH nodes", wide_nodes),
                scene_buffer(ctx, "wide BVH top nodes", &top, wgpu::BufferUsages::UNIFORM),
            )
        });
        let features = &variant.features;
        let grids = (features.media && features.grid_media).then(|| {
            (
                storage_buffer(ctx, "grid media", &scene.grids),
                storage_buffer(ctx, "grid media voxels", &scene.grid_voxels),
            )
        });
        Ok(SceneBuffers {
            scene_type,
            spheres: scene_buffer(ctx, "spheres", &scene.spheres, usage),
            quads: scene_buffer(ctx, "quads", &scene.quads, usage),
            materials: scene_buffer(ctx, "materials", &scene.materials, usage),
            emitters: scene_buffer(ctx, "emitters", &scene.emitters, usage),
            // Meshes and the BVH are always in storage buffers (placeholders when unused).
            triangles: storage_buffer(ctx, "triangles", &scene.triangles),
            triangle_normals: storage_buffer(ctx, "triangle normals", &scene.triangle_normals),
            bvh_nodes: storage_buffer(ctx, "BVH nodes", binary_nodes),
            bvh_top_nodes: scene_buffer(
                ctx,
                "BVH top nodes",
                &top_nodes,
                wgpu::BufferUsages::UNIFORM,
            ),
            bvh_primitives: storage_buffer(ctx, "BVH primitives", &scene.bvh_primitives),
            instances: storage_buffer(ctx, "instances", &scene.instances),
            // Textures are storage buffers in every layout (shaders/textures/texture.wgsl says
            // why).
            textures: storage_buffer(ctx, "textures", &scene.textures),
            texels: texel_binding
                .windows(scene.texels.len())
                .iter()
                .zip(WINDOW_LABELS)
                .map(|(range, label)| storage_buffer(ctx, label, &scene.texels[range.clone()]))
                .collect(),
            triangle_uvs: storage_buffer(ctx, "triangle texture coordinates", &scene.triangle_uvs),
            triangle_uvs1: storage_buffer(
                ctx,
                "triangle texture coordinates (set 1)",
                &scene.triangle_uvs1,
            ),
            triangle_tangents: storage_buffer(ctx, "triangle tangents", &scene.triangle_tangents),
            triangle_colors: storage_buffer(ctx, "triangle vertex colours", &scene.triangle_colors),
            environment_texels: storage_buffer(ctx, "environment map", &scene.environment_texels),
            environment_alias: storage_buffer(
                ctx,
                "environment alias table",
                &scene.environment_alias,
            ),
            lights: storage_buffer(ctx, "lights", &scene.lights),
            light_tree_nodes: storage_buffer(ctx, "light tree", &scene.light_tree_nodes),
            light_tree_trails: storage_buffer(ctx, "light tree trails", &scene.light_tree_trails),
            // The PBR material's energy tables (src/tables/), placeholders where the kernel
            // does not read them.
            ggx_energy: energy_table(
                ctx,
                "GGX energy tables",
                features.pbr,
                crate::tables::ggx::ggx_energy_table,
            ),
            dielectric_energy: energy_table(
                ctx,
                "dielectric energy tables",
                features.pbr && features.transmission,
                crate::tables::dielectric::dielectric_energy_table,
            ),
            sheen_energy: energy_table(
                ctx,
                "sheen energy table",
                features.pbr && features.sheen,
                crate::tables::sheen::sheen_energy_table,
            ),
            clearcoat_energy: energy_table(
                ctx,
                "clear coat energy table",
                features.pbr && features.clearcoat,
                crate::tables::clearcoat::clearcoat_energy_table,
            ),
            wide,
            grids,
            texel_binding,
            light_tree: features.light_tree,
        })
    }

    /// Before any upload: a scene the device cannot hold is bad input, not a wgpu error.
    fn check(
        scene: &KernelScene,
        variant: &KernelVariant,
        scene_type: wgpu::BufferBindingType,
        texel_binding: TexelBinding,
        images: &ImageSizes,
        limits: &wgpu::Limits,
    ) -> Result<()> {
        let (binary_nodes, wide_nodes) = trees(scene, variant);
        let uniform_nodes = variant.binding.uniform_node_count();
        let texel_needs = texel_binding
            .windows(scene.texels.len())
            .into_iter()
            .zip(WINDOW_LABELS)
            .map(|(range, label)| {
                BufferNeed::new(label, array_bytes(&scene.texels[range]), READ_ONLY)
            });
        let read_only = READ_ONLY;
        check_buffers(
            limits,
            &[
                BufferNeed::new("spheres", array_bytes(&scene.spheres), scene_type),
                BufferNeed::new("quads", array_bytes(&scene.quads), scene_type),
                BufferNeed::new("materials", array_bytes(&scene.materials), scene_type),
                BufferNeed::new("emitters", array_bytes(&scene.emitters), scene_type),
                BufferNeed::new("triangles", array_bytes(&scene.triangles), read_only),
                BufferNeed::new(
                    "triangle normals",
                    array_bytes(&scene.triangle_normals),
                    read_only,
                ),
                BufferNeed::new("BVH nodes", array_bytes(binary_nodes), read_only),
                BufferNeed::new(
                    "BVH top nodes",
                    uniform_nodes as u64 * size_of::<BvhNode>() as u64,
                    UNIFORM,
                ),
                BufferNeed::new(
                    "BVH primitives",
                    array_bytes(&scene.bvh_primitives),
                    read_only,
                ),
                BufferNeed::new("instances", array_bytes(&scene.instances), read_only),
                BufferNeed::new("wide BVH nodes", array_bytes(wide_nodes), read_only),
                BufferNeed::new("textures", array_bytes(&scene.textures), read_only),
                BufferNeed::new(
                    "triangle texture coordinates",
                    array_bytes(&scene.triangle_uvs),
                    read_only,
                ),
                BufferNeed::new(
                    "triangle tangents",
                    array_bytes(&scene.triangle_tangents),
                    read_only,
                ),
                BufferNeed::new(
                    "triangle texture coordinates (set 1)",
                    array_bytes(&scene.triangle_uvs1),
                    read_only,
                ),
                BufferNeed::new(
                    "triangle vertex colours",
                    array_bytes(&scene.triangle_colors),
                    read_only,
                ),
                BufferNeed::new(
                    "environment map",
                    array_bytes(&scene.environment_texels),
                    read_only,
                ),
                BufferNeed::new(
                    "environment alias table",
                    array_bytes(&scene.environment_alias),
                    read_only,
                ),
                BufferNeed::new("lights", array_bytes(&scene.lights), read_only),
                BufferNeed::new(
                    "light tree",
                    array_bytes(&scene.light_tree_nodes),
                    read_only,
                ),
                BufferNeed::new(
                    "light tree trails",
                    array_bytes(&scene.light_tree_trails),
                    read_only,
                ),
                BufferNeed::new("grid media", array_bytes(&scene.grids), read_only),
                BufferNeed::new(
                    "grid media voxels",
                    array_bytes(&scene.grid_voxels),
                    read_only,
                ),
                BufferNeed::new("accumulation", images.accumulation, BufferBinding::Storage),
                BufferNeed::new("readback", images.accumulation, BufferBinding::Unbound),
                BufferNeed::new("aov_albedo_depth", images.aov, BufferBinding::Storage),
                BufferNeed::new("aov_normal", images.aov, BufferBinding::Storage),
            ]
            .into_iter()
            .chain(images.splats.into_iter().flat_map(|bytes| {
                [
                    BufferNeed::new("splats", bytes, BufferBinding::Storage),
                    BufferNeed::new("splat readback", bytes, BufferBinding::Unbound),
                ]
            }))
            .chain(texel_needs)
            .collect::<Vec<_>>(),
        )?;
        Ok(())
    }

    /// The scene's bindings, by the kernel's binding numbers (the wide tree's at 44 and 45,
    /// texel windows 2 to 4 only where the kernel declares them).
    pub fn bindings(&self) -> Vec<Binding<'_>> {
        let scene_type = self.scene_type;
        let mut bindings = vec![
            (1, scene_type, &self.spheres),
            (2, scene_type, &self.quads),
            (3, scene_type, &self.materials),
            (6, scene_type, &self.emitters),
            (8, READ_ONLY, &self.triangles),
            (9, READ_ONLY, &self.triangle_normals),
            (12, READ_ONLY, &self.bvh_nodes),
            (23, UNIFORM, &self.bvh_top_nodes),
            (13, READ_ONLY, &self.bvh_primitives),
            (40, READ_ONLY, &self.instances),
            (20, READ_ONLY, &self.textures),
            (21, READ_ONLY, &self.texels[0]),
            (22, READ_ONLY, &self.triangle_uvs),
            (28, READ_ONLY, &self.triangle_tangents),
            (34, READ_ONLY, &self.triangle_colors),
            (35, READ_ONLY, &self.triangle_uvs1),
            (18, READ_ONLY, &self.environment_texels),
            (19, READ_ONLY, &self.environment_alias),
            (24, READ_ONLY, &self.lights),
            (25, READ_ONLY, &self.ggx_energy),
            (33, READ_ONLY, &self.dielectric_energy),
            (32, READ_ONLY, &self.sheen_energy),
            (36, READ_ONLY, &self.clearcoat_energy),
        ];
        if let Some((nodes, top)) = &self.wide {
            bindings.push((44, READ_ONLY, nodes));
            bindings.push((45, UNIFORM, top));
        }
        if self.light_tree {
            bindings.push((48, READ_ONLY, &self.light_tree_nodes));
            bindings.push((49, READ_ONLY, &self.light_tree_trails));
        }
        if let Some((grids, voxels)) = &self.grids {
            bindings.push((46, READ_ONLY, grids));
            bindings.push((47, READ_ONLY, voxels));
        }
        if self.texel_binding.is_split() {
            bindings.extend(
                EXTRA_WINDOW_BINDINGS
                    .iter()
                    .zip(&self.texels[1..])
                    .map(|(&binding, buffer)| (binding, READ_ONLY, buffer)),
            );
        }
        bindings
    }
}
