//! The GPU renderer: scene upload, sample batches, readback of the running sums.

use super::acceleration::AccelerationStructure;
use super::binding::{bind_group, compute_layout_entries};
use super::context::GpuContext;
use super::inline_uniforms::params_binding_for;
use super::limits::{check_buffers, BufferBinding, BufferNeed};
use super::loop_budget::{
    device_loop_limit, hardware_loop_iterations_per_sample, loop_iterations_per_sample,
    max_samples_per_dispatch, LAVAPIPE_LOOP_LIMIT,
};
use super::tiles::{next_tile, TilePlanner};
use super::traversal::Traversal;
use crate::image::output::Image;
use crate::kernel::texels::{TexelBinding, EXTRA_WINDOW_BINDINGS};
use crate::kernel::types::{BvhNode, BvhWideNode, Params};
use crate::kernel::variant::{
    render_kernel_source_with_texels, KernelFeatures, KernelVariant, ParamsBinding, SceneBinding,
    RENDER_ENTRY_POINT, WORKGROUP_SIZE,
};
use crate::kernel::KernelScene;
use crate::render::accumulation::Accumulation;
use crate::render::aov::Aovs;
use crate::render::{check_size, variance_of_mean, Renderer};
use anyhow::{anyhow, Result};
use bytemuck::Pod;
use wgpu::util::DeviceExt;

pub struct GpuRenderer<'a> {
    ctx: &'a GpuContext,
    variant: KernelVariant,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    params: Params,
    params_buffer: wgpu::Buffer,
    /// Per pixel vec4: running mean radiance (xyz).
    mean_buffer: wgpu::Buffer,
    /// Per pixel vec4: M2, the sum of squared deviations from the mean (xyz).
    m2_buffer: wgpu::Buffer,
    /// Per pixel vec4s of the denoiser's AOVs (shaders/integrator/aov.wgsl): albedo and depth, normal.
    /// One vec4 each when the kernel has AOVs compiled out.
    aov_buffers: [wgpu::Buffer; 2],
    readback_buffer: wgpu::Buffer,
    samples: u32,
    first_sample: u32,
    /// The kernel's segment counter (one u32).
    counter_buffer: wgpu::Buffer,
    /// Benchmark instrumentation, off unless asked for: it reads back after every batch.
    instruments: Option<Instruments>,
    /// The origin of the tile a dispatch covers (`shaders/integrator/tiles.wgsl`).
    tile_buffer: wgpu::Buffer,
    tiles: TilePlanner,
    /// The kernel's count of dropped samples (one u32), read and cleared after every batch.
    nonfinite_buffer: wgpu::Buffer,
    nonfinite_readback: wgpu::Buffer,
    nonfinite: u64,
    /// The device's loop limit (lavapipe: src/gpu/loop_budget.rs).
    loop_limit: Option<u64>,
    /// The scene's worst case of loop iterations per sample (src/gpu/loop_budget.rs).
    loop_iterations: u64,
    /// The hardware traversal's acceleration structure, bound with the kernel (kept alive).
    _acceleration: Option<AccelerationStructure>,
    /// Where the kernel reads texels from (src/kernel/texels.rs).
    texel_binding: TexelBinding,
}

/// Wanted duration of one GPU submission: a batch longer than this is split into tiles.
/// Desktop drivers kill submissions after about 2 s; lavapipe has no watchdog.
pub const SUBMISSION_TARGET: std::time::Duration = std::time::Duration::from_millis(250);

/// Timestamp queries and the segment count, read after each batch.
struct Instruments {
    /// Two timestamps around the render pass, where the device supports them.
    timestamps: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    /// Counter and timestamps land here for readback: [segments: u32, pad: u32, t0: u64, t1: u64].
    readback: wgpu::Buffer,
    segments: u64,
    last_kernel_time: Option<std::time::Duration>,
}

/// A read-only storage buffer holding `items`; bindings cannot be empty, so an empty list
/// uploads one zeroed element (the kernel reads the real count from `Params`).
pub fn storage_buffer<T: Pod + Default>(
    ctx: &GpuContext,
    label: &str,
    items: &[T],
) -> wgpu::Buffer {
    scene_buffer(ctx, label, items, wgpu::BufferUsages::STORAGE)
}

/// Checks that the kernel's storage bindings, `buffers`' and the extra texel windows among them,
/// are within the device's `max_storage_buffers_per_shader_stage`: bad input naming both
/// counts otherwise.
fn check_storage_binding_count(
    limits: &wgpu::Limits,
    buffers: &[(u32, wgpu::BufferBindingType, &wgpu::Buffer)],
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

/// Bytes of the buffer [`scene_buffer`] makes for `items` (at least one element).
fn array_bytes<T>(items: &[T]) -> u64 {
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

impl<'a> GpuRenderer<'a> {
    /// A renderer for `scene` with the fastest kernel for it: its objects in uniform buffers
    /// when they fit the device's limit (storage buffers otherwise), and only the features it
    /// uses compiled in; or a kernel shared by scenes where `GLINT_KERNEL_VARIANT=shared`
    /// ([`KernelVariant::default_for`]).
    pub fn new(ctx: &'a GpuContext, scene: &KernelScene) -> Result<GpuRenderer<'a>> {
        let max_uniform = ctx.device.limits().max_uniform_buffer_binding_size;
        Self::with_variant(ctx, scene, KernelVariant::default_for(scene, max_uniform))
    }

    /// A renderer with [`KernelVariant::for_scene`]'s kernel whatever `GLINT_KERNEL_VARIANT`
    /// says: for tests of that choice.
    pub fn with_fastest_kernel(
        ctx: &'a GpuContext,
        scene: &KernelScene,
    ) -> Result<GpuRenderer<'a>> {
        let max_uniform = ctx.device.limits().max_uniform_buffer_binding_size;
        Self::with_variant(ctx, scene, KernelVariant::for_scene(scene, max_uniform))
    }

    /// A renderer tracing rays with `traversal`: [`GpuRenderer::new`]'s kernel for the
    /// software one, the hardware variant ([`SceneBinding::Hardware`]) for ray queries.
    pub fn with_traversal(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        traversal: Traversal,
    ) -> Result<GpuRenderer<'a>> {
        match traversal {
            Traversal::Software => Self::new(ctx, scene),
            Traversal::Hardware => Self::with_scene_binding(ctx, scene, SceneBinding::Hardware),
        }
    }

    /// A renderer with the scene bound as `scene_binding` says and the scene's features (tests
    /// and benchmarks compare the bindings).
    pub fn with_scene_binding(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        scene_binding: SceneBinding,
    ) -> Result<GpuRenderer<'a>> {
        let features = KernelFeatures::of(scene);
        Self::with_variant(
            ctx,
            scene,
            KernelVariant {
                binding: scene_binding,
                features,
            },
        )
    }

    /// A renderer running the kernel `variant`, which must cover what `scene` uses.
    pub fn with_variant(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        variant: KernelVariant,
    ) -> Result<GpuRenderer<'a>> {
        Self::with_variant_and_texel_window(ctx, scene, variant, u64::MAX)
    }

    /// [`GpuRenderer::new`]'s kernel with texel bindings of at most `window_bytes` (or the
    /// device's limit, if smaller): tests split small textures over several bindings with it
    /// (src/kernel/texels.rs).
    pub fn with_texel_window(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        window_bytes: u64,
    ) -> Result<GpuRenderer<'a>> {
        let max_uniform = ctx.device.limits().max_uniform_buffer_binding_size;
        let variant = KernelVariant::default_for(scene, max_uniform);
        Self::with_variant_and_texel_window(ctx, scene, variant, window_bytes)
    }

    fn with_variant_and_texel_window(
        ctx: &'a GpuContext,
        scene: &KernelScene,
        variant: KernelVariant,
        window_bytes: u64,
    ) -> Result<GpuRenderer<'a>> {
        if !variant.features.covers(&KernelFeatures::of(scene)) {
            return Err(anyhow!(
                "the kernel variant {variant:?} lacks features the scene uses"
            ));
        }
        let device = &ctx.device;
        let params = scene.params;
        let pixel_count = params.width as u64 * params.height as u64;
        let accum_size = pixel_count * 16;
        let aov_size = if variant.features.aovs {
            accum_size
        } else {
            16
        };
        let uniform_nodes = variant.binding.uniform_node_count();
        // The wide tree, bound at 44 and 45 in the wide variant only.
        let (wide_uniform_nodes, _) = variant.binding.wide_sizes();
        let wide_nodes: &[BvhWideNode] = if matches!(variant.binding, SceneBinding::WideBvh { .. })
        {
            &scene.bvh_wide_nodes
        } else {
            &[]
        };
        // The binary tree, a placeholder where the wide one serves instead.
        let binary_nodes: &[BvhNode] = if wide_nodes.is_empty() {
            &scene.bvh_nodes
        } else {
            &[]
        };
        let (usage, scene_type) = match variant.binding {
            SceneBinding::Storage
            | SceneBinding::Bvh { .. }
            | SceneBinding::WideBvh { .. }
            | SceneBinding::Hardware => (
                wgpu::BufferUsages::STORAGE,
                wgpu::BufferBindingType::Storage { read_only: true },
            ),
            SceneBinding::Uniform(_) => (
                wgpu::BufferUsages::UNIFORM,
                wgpu::BufferBindingType::Uniform,
            ),
        };
        let read_only = wgpu::BufferBindingType::Storage { read_only: true };
        // Texels beyond one binding are split over several (src/kernel/texels.rs).
        let limits = device.limits();
        let window_bytes = window_bytes
            .min(limits.max_storage_buffer_binding_size)
            .min(limits.max_buffer_size);
        let texel_binding = TexelBinding::plan(scene.texels.len() as u64, window_bytes)?;
        let texel_windows = texel_binding.windows(scene.texels.len());
        let window_labels = [
            "texture texels",
            "texture texels window 2",
            "texture texels window 3",
            "texture texels window 4",
        ];
        let texel_needs = texel_windows
            .iter()
            .zip(window_labels)
            .map(|(range, label)| {
                BufferNeed::new(label, array_bytes(&scene.texels[range.clone()]), read_only)
            });
        // Before any upload: a scene the device cannot hold is bad input, not a wgpu error.
        check_buffers(
            &limits,
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
                    wgpu::BufferBindingType::Uniform,
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
                BufferNeed::new("accumulation", accum_size, BufferBinding::Storage),
                BufferNeed::new("readback", accum_size, BufferBinding::Unbound),
                BufferNeed::new("aov_albedo_depth", aov_size, BufferBinding::Storage),
                BufferNeed::new("aov_normal", aov_size, BufferBinding::Storage),
            ]
            .into_iter()
            .chain(texel_needs)
            .collect::<Vec<_>>(),
        )?;
        let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM
                | wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST,
        });
        let spheres = scene_buffer(ctx, "spheres", &scene.spheres, usage);
        let quads = scene_buffer(ctx, "quads", &scene.quads, usage);
        let materials = scene_buffer(ctx, "materials", &scene.materials, usage);
        let emitters = scene_buffer(ctx, "emitters", &scene.emitters, usage);
        // Meshes and the BVH are always in storage buffers (placeholders when unused).
        let triangles = storage_buffer(ctx, "triangles", &scene.triangles);
        let triangle_normals = storage_buffer(ctx, "triangle normals", &scene.triangle_normals);
        let bvh_nodes = storage_buffer(ctx, "BVH nodes", binary_nodes);
        let mut top_nodes = binary_nodes[..binary_nodes.len().min(uniform_nodes as usize)].to_vec();
        top_nodes.resize(uniform_nodes as usize, BvhNode::default());
        let bvh_top_nodes = scene_buffer(
            ctx,
            "BVH top nodes",
            &top_nodes,
            wgpu::BufferUsages::UNIFORM,
        );
        let bvh_primitives = storage_buffer(ctx, "BVH primitives", &scene.bvh_primitives);
        let instances = storage_buffer(ctx, "instances", &scene.instances);
        // Textures are storage buffers in every layout (shaders/textures/texture.wgsl says why).
        let textures = storage_buffer(ctx, "textures", &scene.textures);
        let texels: Vec<_> = texel_windows
            .iter()
            .zip(window_labels)
            .map(|(range, label)| storage_buffer(ctx, label, &scene.texels[range.clone()]))
            .collect();
        // Windows 2 to 4 are bound only where the kernel declares them.
        let extra_windows: Vec<_> = if texel_binding.is_split() {
            EXTRA_WINDOW_BINDINGS
                .iter()
                .zip(&texels[1..])
                .map(|(&binding, buffer)| (binding, read_only, buffer))
                .collect()
        } else {
            Vec::new()
        };
        let triangle_uvs = storage_buffer(ctx, "triangle texture coordinates", &scene.triangle_uvs);
        let triangle_uvs1 = storage_buffer(
            ctx,
            "triangle texture coordinates (set 1)",
            &scene.triangle_uvs1,
        );
        let triangle_tangents = storage_buffer(ctx, "triangle tangents", &scene.triangle_tangents);
        let triangle_colors =
            storage_buffer(ctx, "triangle vertex colours", &scene.triangle_colors);
        let environment_texels = storage_buffer(ctx, "environment map", &scene.environment_texels);
        let environment_alias =
            storage_buffer(ctx, "environment alias table", &scene.environment_alias);
        let lights = storage_buffer(ctx, "lights", &scene.lights);
        // The PBR material's energy tables (src/tables/ggx.rs), a placeholder without one.
        let ggx_energy: &[f32] = if variant.features.pbr {
            crate::tables::ggx::ggx_energy_table()
        } else {
            &[]
        };
        let ggx_energy = storage_buffer(ctx, "GGX energy tables", ggx_energy);
        // The rough dielectric's compensation tables (src/tables/dielectric.rs), a placeholder
        // where no material transmits.
        let dielectric_energy: &[f32] = if variant.features.pbr && variant.features.transmission {
            crate::tables::dielectric::dielectric_energy_table()
        } else {
            &[]
        };
        let dielectric_energy = storage_buffer(ctx, "dielectric energy tables", dielectric_energy);
        // The sheen's albedo table (src/tables/sheen.rs), a placeholder without a sheen.
        let sheen_energy: &[f32] = if variant.features.pbr && variant.features.sheen {
            crate::tables::sheen::sheen_energy_table()
        } else {
            &[]
        };
        let sheen_energy = storage_buffer(ctx, "sheen energy table", sheen_energy);
        // The coat's scaling of the specular lobes below it (src/tables/clearcoat.rs), a
        // placeholder without a coat.
        let clearcoat_energy: &[f32] = if variant.features.pbr && variant.features.clearcoat {
            crate::tables::clearcoat::clearcoat_energy_table()
        } else {
            &[]
        };
        let clearcoat_energy = storage_buffer(ctx, "clear coat energy table", clearcoat_energy);
        // Buffers the kernel writes and the host clears and reads back.
        let read_write_buffer = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let counter_buffer = read_write_buffer("segments_traced", 8);
        let tile_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tile_origin"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let nonfinite_buffer = read_write_buffer("nonfinite_samples", 8);
        let nonfinite_readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("nonfinite readback"),
            size: 8,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mean_buffer = read_write_buffer("accum_mean", accum_size);
        let m2_buffer = read_write_buffer("accum_m2", accum_size);
        let aov_buffers =
            ["aov_albedo_depth", "aov_normal"].map(|label| read_write_buffer(label, aov_size));
        let readback_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: accum_size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let read_write = wgpu::BufferBindingType::Storage { read_only: false };
        let params_binding = params_binding_for(&ctx.adapter_info);
        let params_type = match params_binding {
            ParamsBinding::Uniform => wgpu::BufferBindingType::Uniform,
            ParamsBinding::Storage => read_only,
        };
        // The hardware traversal's structure: references at 27, the TLAS at 26.
        let acceleration = if variant.binding.uses_ray_queries() {
            Some(super::acceleration::build(ctx, scene)?)
        } else {
            None
        };
        let wide_buffers = (!wide_nodes.is_empty()).then(|| {
            let mut top = wide_nodes[..wide_nodes.len().min(wide_uniform_nodes as usize)].to_vec();
            top.resize(wide_uniform_nodes as usize, BvhWideNode::default());
            (
                storage_buffer(ctx, "wide BVH nodes", wide_nodes),
                scene_buffer(ctx, "wide BVH top nodes", &top, wgpu::BufferUsages::UNIFORM),
            )
        });
        let wide_bindings: Vec<_> = wide_buffers
            .iter()
            .flat_map(|(nodes, top)| {
                [
                    (44, read_only, nodes),
                    (45, wgpu::BufferBindingType::Uniform, top),
                ]
            })
            .collect();
        let hardware_buffers: Vec<_> = acceleration
            .iter()
            .map(|a| (27, read_only, &a.references))
            .collect();
        let buffers: Vec<_> = [
            (0, params_type, &params_buffer),
            (1, scene_type, &spheres),
            (2, scene_type, &quads),
            (3, scene_type, &materials),
            (4, read_write, &mean_buffer),
            (5, read_write, &m2_buffer),
            (6, scene_type, &emitters),
            (7, read_write, &counter_buffer),
            (8, read_only, &triangles),
            (9, read_only, &triangle_normals),
            (12, read_only, &bvh_nodes),
            (23, wgpu::BufferBindingType::Uniform, &bvh_top_nodes),
            (13, read_only, &bvh_primitives),
            (40, read_only, &instances),
            (10, read_write, &aov_buffers[0]),
            (11, read_write, &aov_buffers[1]),
            (16, read_write, &nonfinite_buffer),
            (17, wgpu::BufferBindingType::Uniform, &tile_buffer),
            (20, read_only, &textures),
            (21, read_only, &texels[0]),
            (22, read_only, &triangle_uvs),
            (28, read_only, &triangle_tangents),
            (34, read_only, &triangle_colors),
            (35, read_only, &triangle_uvs1),
            (18, read_only, &environment_texels),
            (19, read_only, &environment_alias),
            (24, read_only, &lights),
            (25, read_only, &ggx_energy),
            (33, read_only, &dielectric_energy),
            (32, read_only, &sheen_energy),
            (36, read_only, &clearcoat_energy),
        ]
        .into_iter()
        .chain(hardware_buffers)
        .chain(wide_bindings)
        .chain(extra_windows)
        .collect();
        if texel_binding.is_split() {
            check_storage_binding_count(&limits, &buffers)?;
        }
        let tlas = acceleration.as_ref().map(|a| (26, &a.tlas));
        let (bind_group_layout, pipeline) = ctx.compute_pipeline(
            "glint render kernel",
            &render_kernel_source_with_texels(variant, params_binding, texel_binding),
            RENDER_ENTRY_POINT,
            &compute_layout_entries(&buffers, tlas.map(|(binding, _)| binding)),
        );
        let bind_group = bind_group(device, "scene", &bind_group_layout, &buffers, tlas);
        ctx.wait_idle()?;
        let renderer = GpuRenderer {
            ctx,
            variant,
            pipeline,
            bind_group,
            params,
            params_buffer,
            mean_buffer,
            m2_buffer,
            aov_buffers,
            readback_buffer,
            samples: 0,
            first_sample: 0,
            counter_buffer,
            instruments: None,
            tile_buffer,
            tiles: TilePlanner::new(SUBMISSION_TARGET),
            nonfinite_buffer,
            nonfinite_readback,
            nonfinite: 0,
            loop_limit: device_loop_limit(&ctx.adapter_info),
            loop_iterations: if variant.binding.uses_ray_queries() {
                hardware_loop_iterations_per_sample(scene)
            } else {
                loop_iterations_per_sample(scene)
            },
            _acceleration: acceleration,
            texel_binding,
        };
        renderer.warm_up()?;
        Ok(renderer)
    }

    /// Runs the kernel once, on one workgroup and with no samples (it returns at once, leaving
    /// the image untouched), so the driver finishes compiling it now: lavapipe compiles at the
    /// first dispatch (about 1 s with a cold Mesa cache), which would otherwise count as
    /// render time.
    fn warm_up(&self) -> Result<()> {
        let params = Params {
            sample_count: 0,
            ..self.params
        };
        let queue = &self.ctx.queue;
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        queue.submit([encoder.finish()]);
        self.ctx.wait_idle()
    }

    /// Turns on benchmark instrumentation: after every batch, the renderer reads back the
    /// number of ray segments traced and, where the device has timestamp queries, the
    /// kernel's device time. This adds a small readback per batch, so renders leave it off.
    pub fn instrument(&mut self) {
        let device = &self.ctx.device;
        let timestamps = self
            .ctx
            .features
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("kernel time"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                });
                let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("kernel time resolve"),
                    size: 16,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                (set, resolve)
            });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("instrument readback"),
            size: 24,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.instruments = Some(Instruments {
            timestamps,
            readback,
            segments: 0,
            last_kernel_time: None,
        });
    }

    /// Reads the counter and timestamps of the submission just made, and clears the counter;
    /// returns the kernel's device time (zero where it is not measured).
    fn read_instruments(&mut self) -> Result<std::time::Duration> {
        let Some(instruments) = &mut self.instruments else {
            return Ok(std::time::Duration::ZERO);
        };
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.counter_buffer, 0, &instruments.readback, 0, 8);
        if let Some((_, resolve)) = &instruments.timestamps {
            encoder.copy_buffer_to_buffer(resolve, 0, &instruments.readback, 8, 16);
        }
        encoder.clear_buffer(&self.counter_buffer, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        let (segments, t0, t1) = self.ctx.read_mapped(&instruments.readback, |bytes| {
            let words: &[u32] = bytemuck::cast_slice(&bytes[..8]);
            let stamps: &[u64] = bytemuck::cast_slice(&bytes[8..24]);
            (words[0], stamps[0], stamps[1])
        })?;
        instruments.segments += segments as u64;
        if instruments.timestamps.is_some() && t1 > t0 {
            let ns = (t1 - t0) as f64 * self.ctx.queue.get_timestamp_period() as f64;
            return Ok(std::time::Duration::from_nanos(ns as u64));
        }
        Ok(std::time::Duration::ZERO)
    }

    /// Sets the wanted duration of one GPU submission (default [`SUBMISSION_TARGET`]); batches
    /// that would take longer are split into tiles of pixels. Zero gives the smallest tiles
    /// (one workgroup each), which tests use to check that tiling never changes the image.
    pub fn set_submission_target(&mut self, target: std::time::Duration) {
        self.tiles = TilePlanner::new(target);
    }

    /// The per-pixel mean radiance (vec4 per pixel, xyz used), for display passes that read it
    /// on the GPU without a readback.
    pub fn mean_buffer(&self) -> &wgpu::Buffer {
        &self.mean_buffer
    }

    /// Where the kernel reads the scene from.
    pub fn scene_binding(&self) -> SceneBinding {
        self.variant.binding
    }

    /// The traversal the kernel runs.
    pub fn traversal(&self) -> Traversal {
        if self.variant.binding.uses_ray_queries() {
            Traversal::Hardware
        } else {
            Traversal::Software
        }
    }

    /// The kernel variant this renderer runs.
    pub fn variant(&self) -> KernelVariant {
        self.variant
    }

    /// Where the kernel reads texels from: one binding, or windows over several.
    pub fn texel_binding(&self) -> TexelBinding {
        self.texel_binding
    }

    /// The kernel parameters in use (camera, size, counts).
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Replaces the camera and render parameters (not the image size or the scene's objects)
    /// and restarts accumulation.
    pub fn set_params(&mut self, params: Params) -> Result<()> {
        let size = (self.params.width, self.params.height);
        if (params.width, params.height) != size {
            return Err(anyhow!(
                "set_params cannot change the image size; make a new renderer"
            ));
        }
        if params.aovs != 0 && !self.variant.features.aovs {
            return Err(anyhow!(
                "set_params cannot turn on AOVs compiled out of the kernel; make a new renderer"
            ));
        }
        if params.light_sampling != 0 && !self.variant.features.light_sampling {
            return Err(anyhow!(
                "set_params cannot turn on light sampling compiled out of the kernel; make a new renderer"
            ));
        }
        self.params = params;
        self.reset()
    }

    /// Each vec4 of `buffer`, which is at most as large as the readback buffer.
    fn read_vec4s(&self, buffer: &wgpu::Buffer) -> Result<Vec<[f32; 4]>> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &self.readback_buffer, 0, buffer.size());
        self.ctx.queue.submit([encoder.finish()]);
        let size = buffer.size() as usize;
        self.ctx.read_mapped(&self.readback_buffer, |bytes| {
            bytemuck::cast_slice::<u8, [f32; 4]>(&bytes[..size]).to_vec()
        })
    }

    /// One submission: the batch in `self.params` over the pixels of `tile`, waited for.
    fn submit_tile(&mut self, tile: super::tiles::Tile) -> Result<()> {
        let origin = [tile.x, tile.y, 0, 0];
        self.ctx
            .queue
            .write_buffer(&self.tile_buffer, 0, bytemuck::bytes_of(&origin));
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        let timestamps = self
            .instruments
            .as_ref()
            .and_then(|i| i.timestamps.as_ref());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("render"),
                timestamp_writes: timestamps.map(|(set, _)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(
                tile.width.div_ceil(WORKGROUP_SIZE.0),
                tile.height.div_ceil(WORKGROUP_SIZE.1),
                1,
            );
        }
        if let Some((set, resolve)) = timestamps {
            encoder.resolve_query_set(set, 0..2, resolve, 0);
        }
        self.ctx.queue.submit([encoder.finish()]);
        self.ctx.wait_idle()
    }

    /// Reads and clears the kernel's counters: dropped samples and invocations cut short.
    fn take_counters(&self) -> Result<[u32; 2]> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.nonfinite_buffer, 0, &self.nonfinite_readback, 0, 8);
        encoder.clear_buffer(&self.nonfinite_buffer, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        self.ctx.read_mapped(&self.nonfinite_readback, |bytes| {
            let words = bytemuck::cast_slice::<u8, u32>(bytes);
            [words[0], words[1]]
        })
    }

    /// Samples `first..first + count` for every pixel, in tiles.
    fn dispatch_samples(&mut self, first: u32, count: u32) -> Result<()> {
        self.params.sample_start = first;
        self.params.accumulated_samples = first - self.first_sample;
        self.params.sample_count = count;
        self.ctx
            .queue
            .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        // Tiles sized so each submission lasts about SUBMISSION_TARGET (src/gpu/tiles.rs).
        let (width, height) = (self.params.width, self.params.height);
        let (mut x, mut y) = (0, 0);
        let mut last_pixels = None;
        let mut kernel_time = std::time::Duration::ZERO;
        while y < height {
            let budget = self.tiles.pixel_budget(count, last_pixels);
            let tile = next_tile(width, height, x, y, budget);
            let started = std::time::Instant::now();
            self.submit_tile(tile)?;
            let took = started.elapsed();
            let pixels = tile.width as u64 * tile.height as u64;
            self.tiles.record(pixels, count, took);
            last_pixels = Some(pixels);
            kernel_time += self.read_instruments()?;
            x += tile.width;
            if x >= width {
                x = 0;
                y += tile.height;
            }
        }
        if let Some(instruments) = &mut self.instruments {
            if instruments.timestamps.is_some() {
                instruments.last_kernel_time = Some(kernel_time);
            }
        }
        Ok(())
    }

    /// The first three floats of each vec4 of `buffer`.
    fn read_vec3s(&self, buffer: &wgpu::Buffer) -> Result<Vec<[f32; 3]>> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &self.readback_buffer, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        self.ctx.read_mapped(&self.readback_buffer, |bytes| {
            bytemuck::cast_slice::<u8, [f32; 4]>(bytes)
                .iter()
                .map(|p| [p[0], p[1], p[2]])
                .collect()
        })
    }

    fn image(&self, pixels: Vec<[f32; 3]>) -> Image {
        Image {
            width: self.params.width,
            height: self.params.height,
            pixels,
        }
    }
}

impl Renderer for GpuRenderer<'_> {
    fn add_samples(&mut self, count: u32) -> Result<()> {
        // Dispatches of at most this many samples stay within lavapipe's loop limit. They end
        // at multiples of a power of two of samples, fixed by the scene and the device, so
        // where the kernel merges (shaders/integrator/accumulate.wgsl) never depends on the batching;
        // from 64 on those multiples are block ends anyway.
        let per_dispatch = max_samples_per_dispatch(self.loop_iterations, self.loop_limit);
        let step = 1u32 << (31 - per_dispatch.leading_zeros());
        // Global sample indices: a partial render's dispatches end where a single render's do.
        let end = self.first_sample + self.samples + count;
        let mut first = self.first_sample + self.samples;
        while first < end {
            let next = (first / step + 1).saturating_mul(step).min(end);
            self.dispatch_samples(first, next - first)?;
            first = next;
        }
        self.samples = end - self.first_sample;
        let [nonfinite, cut_short] = self.take_counters()?;
        self.nonfinite += nonfinite as u64;
        if cut_short > 0 {
            return Err(anyhow!(
                "the GPU driver ended the kernel early in {cut_short} pixel groups: lavapipe ends \
                 a shader's loops after {LAVAPIPE_LOOP_LIMIT} iterations in all, and one sample of \
                 this scene ({} spheres and quads, {} triangles, {} bounces) can need {} \
                 (render with --cpu)",
                self.params.sphere_count + self.params.quad_count,
                self.params.triangle_count,
                self.params.max_bounces,
                self.loop_iterations
            ));
        }
        Ok(())
    }

    fn samples(&self) -> u32 {
        self.samples
    }

    fn first_sample(&self) -> u32 {
        self.first_sample
    }

    fn read_accumulation(&mut self) -> Result<Accumulation> {
        Ok(Accumulation {
            width: self.params.width,
            height: self.params.height,
            count: self.samples,
            mean: self.read_vec3s(&self.mean_buffer)?,
            m2: self.read_vec3s(&self.m2_buffer)?,
        })
    }

    fn load_accumulation(&mut self, first_sample: u32, state: Option<&Accumulation>) -> Result<()> {
        self.reset()?;
        if let Some(state) = state {
            check_size(&self.params, state)?;
            let vec4s = |v: &[[f32; 3]]| -> Vec<[f32; 4]> {
                v.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect()
            };
            let queue = &self.ctx.queue;
            queue.write_buffer(
                &self.mean_buffer,
                0,
                bytemuck::cast_slice(&vec4s(&state.mean)),
            );
            queue.write_buffer(&self.m2_buffer, 0, bytemuck::cast_slice(&vec4s(&state.m2)));
            self.samples = state.count;
        }
        self.first_sample = first_sample;
        self.ctx.wait_idle()
    }

    fn nonfinite_samples(&self) -> u64 {
        self.nonfinite
    }

    fn read_mean(&mut self) -> Result<Image> {
        Ok(self.image(self.read_vec3s(&self.mean_buffer)?))
    }

    fn read_variance(&mut self) -> Result<Image> {
        let n = self.samples;
        let m2 = self.read_vec3s(&self.m2_buffer)?;
        Ok(self.image(m2.into_iter().map(|v| variance_of_mean(v, n)).collect()))
    }

    fn read_aovs(&mut self) -> Result<Aovs> {
        if self.params.aovs == 0 {
            return Err(anyhow!(
                "this render does not accumulate AOVs (Params::aovs is 0)"
            ));
        }
        let albedo_depth = self.read_vec4s(&self.aov_buffers[0])?;
        let normal = self.read_vec4s(&self.aov_buffers[1])?;
        let (width, height) = (self.params.width, self.params.height);
        Ok(Aovs::from_vec4s(width, height, &albedo_depth, &normal))
    }

    fn reset(&mut self) -> Result<()> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        for buffer in &self.aov_buffers {
            encoder.clear_buffer(buffer, 0, None);
        }
        encoder.clear_buffer(&self.mean_buffer, 0, None);
        encoder.clear_buffer(&self.m2_buffer, 0, None);
        encoder.clear_buffer(&self.counter_buffer, 0, None);
        encoder.clear_buffer(&self.nonfinite_buffer, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        self.samples = 0;
        self.nonfinite = 0;
        if let Some(instruments) = &mut self.instruments {
            instruments.segments = 0;
        }
        self.ctx.wait_idle()
    }

    fn segments_traced(&self) -> Option<u64> {
        self.instruments.as_ref().map(|i| i.segments)
    }

    fn last_kernel_time(&self) -> Option<std::time::Duration> {
        self.instruments.as_ref().and_then(|i| i.last_kernel_time)
    }

    fn device_name(&self) -> String {
        self.ctx.device_name()
    }

    fn backend_name(&self) -> String {
        self.ctx.backend_name()
    }
}
