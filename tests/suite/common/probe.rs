//! Runs the WGSL sampling routines on the GPU through tests/suite/shaders/probe.wgsl.

use bytemuck::{Pod, Zeroable};
use glint::gpu::binding::{bind_group, compute_layout_entries};
use glint::gpu::upload::storage_buffer;
use glint::gpu::GpuContext;
use glint::kernel::source::{render_kernel_source, render_kernel_source_for};
use glint::kernel::variant::{KernelFeatures, KernelVariant, SceneBinding};
use glint::kernel::KernelScene;
use wgpu::util::DeviceExt;

/// The probe kernel's parameters (tests/suite/shaders/probe.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Default, Pod, Zeroable)]
pub struct ProbeParams {
    pub normal: [f32; 3],
    pub count: u32,
    pub wo: [f32; 3],
    pub seed: u32,
    pub position: [f32; 3],
    pub alpha: f32,
    pub side_probe: [f32; 3],
    pub ior: f32,
    pub front_face: u32,
    /// The pbr material's transmission, coat (weight, α) and white sheen (its colour's value,
    /// roughness) (probe_pbr).
    pub transmission: f32,
    pub clearcoat: f32,
    pub clearcoat_alpha: f32,
    pub sheen: f32,
    pub sheen_roughness: f32,
    pub _pad: [u32; 2],
    /// The coat's own shading normal (probe_pbr); zero: the base's, `normal`.
    pub coat_normal: [f32; 3],
    pub _pad2: u32,
}

/// A one-pixel scene for probes that read none of the scene, and the header of the small
/// scenes some probes build on it.
pub const PROBE_SCENE: &str = r#"
[camera]
eye = [0.0, 0.0, -5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
[render]
width = 1
height = 1
spp = 1
max_bounces = 1
"#;

pub const PROBE_SOURCE: &str = include_str!("../shaders/probe.wgsl");

pub fn probe_module_source() -> String {
    render_kernel_source() + PROBE_SOURCE
}

/// Runs the probe entry point `entry` for `params.count` samples, with `scene` bound as the
/// kernel's scene (light sampling reads it), and returns what it wrote.
pub fn run_probe(
    ctx: &GpuContext,
    entry: &str,
    params: ProbeParams,
    scene: &KernelScene,
) -> Vec<[f32; 4]> {
    run_probe_source(ctx, entry, params, scene, probe_module_source())
}

/// [`run_probe`] in the kernel variant that traverses `scene`'s BVH (which it must have), with
/// the BVH's root alone in the uniform copy of its top.
pub fn run_probe_bvh(
    ctx: &GpuContext,
    entry: &str,
    params: ProbeParams,
    scene: &KernelScene,
) -> Vec<[f32; 4]> {
    let source = probe_source_with(SceneBinding::Bvh {
        uniform_nodes: 1,
        stack_size: glint::kernel::bvh::kernel_stack_size(&scene.bvh_nodes),
    });
    run_probe_source(ctx, entry, params, scene, source)
}

/// [`run_probe_bvh`] through the 4-wide tree (shaders/traverse/wide.wgsl), its root alone in
/// the uniform copy of its top.
pub fn run_probe_bvh_wide(
    ctx: &GpuContext,
    entry: &str,
    params: ProbeParams,
    scene: &KernelScene,
) -> Vec<[f32; 4]> {
    let source = probe_source_with(SceneBinding::WideBvh {
        uniform_nodes: 1,
        stack_size: glint::kernel::bvh::wide::kernel_stack_size(&scene.bvh_wide_nodes),
    });
    run_probe_source(ctx, entry, params, scene, source)
}

/// [`run_probe`] in the kernel variant that traces with ray queries (the hardware traversal),
/// against `scene`'s acceleration structure; the device must have ray queries.
pub fn run_probe_hardware(
    ctx: &GpuContext,
    entry: &str,
    params: ProbeParams,
    scene: &KernelScene,
) -> Vec<[f32; 4]> {
    let source = probe_source_with(SceneBinding::Hardware);
    let acceleration = glint::gpu::acceleration::build(ctx, scene).unwrap();
    run_probe_with(ctx, entry, params, scene, source, Some(&acceleration))
}

/// The kernel with every feature, reading the scene through `binding`, and the probe's entry
/// points after it.
fn probe_source_with(binding: SceneBinding) -> String {
    render_kernel_source_for(KernelVariant {
        binding,
        features: KernelFeatures::ALL,
    }) + PROBE_SOURCE
}

fn run_probe_source(
    ctx: &GpuContext,
    entry: &str,
    params: ProbeParams,
    scene: &KernelScene,
    source: String,
) -> Vec<[f32; 4]> {
    run_probe_with(ctx, entry, params, scene, source, None)
}

fn run_probe_with(
    ctx: &GpuContext,
    entry: &str,
    params: ProbeParams,
    scene: &KernelScene,
    source: String,
    acceleration: Option<&glint::gpu::acceleration::AccelerationStructure>,
) -> Vec<[f32; 4]> {
    let device = &ctx.device;
    let uniform = |bytes: &[u8]| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytes,
            usage: wgpu::BufferUsages::UNIFORM,
        })
    };
    let scene_params = uniform(bytemuck::bytes_of(&scene.params));
    let probe_params = uniform(bytemuck::bytes_of(&params));
    // The general kernel keeps one node (the root) in its uniform copy of the BVH's top.
    let bvh_top_nodes = uniform(bytemuck::bytes_of(
        &scene.bvh_nodes.first().copied().unwrap_or_default(),
    ));
    let bvh_wide_top_nodes = uniform(bytemuck::bytes_of(
        &scene.bvh_wide_nodes.first().copied().unwrap_or_default(),
    ));
    let bvh_wide_nodes = storage_buffer(ctx, "wide BVH nodes", &scene.bvh_wide_nodes);
    let spheres = storage_buffer(ctx, "spheres", &scene.spheres);
    let quads = storage_buffer(ctx, "quads", &scene.quads);
    let materials = storage_buffer(ctx, "materials", &scene.materials);
    let emitters = storage_buffer(ctx, "emitters", &scene.emitters);
    let triangles = storage_buffer(ctx, "triangles", &scene.triangles);
    let triangle_normals = storage_buffer(ctx, "triangle normals", &scene.triangle_normals);
    let bvh_nodes = storage_buffer(ctx, "BVH nodes", &scene.bvh_nodes);
    let bvh_primitives = storage_buffer(ctx, "BVH primitives", &scene.bvh_primitives);
    let instances = storage_buffer(ctx, "instances", &scene.instances);
    let textures = storage_buffer(ctx, "textures", &scene.textures);
    let texels = storage_buffer(ctx, "texels", &scene.texels);
    let triangle_uvs = storage_buffer(ctx, "triangle uvs", &scene.triangle_uvs);
    let triangle_tangents = storage_buffer(ctx, "triangle tangents", &scene.triangle_tangents);
    let triangle_colors = storage_buffer(ctx, "triangle colours", &scene.triangle_colors);
    let triangle_uvs1 = storage_buffer(ctx, "triangle uvs 1", &scene.triangle_uvs1);
    let environment_texels = storage_buffer(ctx, "environment map", &scene.environment_texels);
    let environment_alias = storage_buffer(ctx, "environment alias", &scene.environment_alias);
    let lights = storage_buffer(ctx, "lights", &scene.lights);
    let light_tree_nodes = storage_buffer(ctx, "light tree nodes", &scene.light_tree_nodes);
    let light_tree_trails = storage_buffer(ctx, "light tree trails", &scene.light_tree_trails);
    let ggx_energy = storage_buffer(ctx, "GGX energy", glint::tables::ggx::ggx_energy_table());
    let dielectric_energy = storage_buffer(
        ctx,
        "dielectric energy",
        glint::tables::dielectric::dielectric_energy_table(),
    );
    let clearcoat_energy = storage_buffer(
        ctx,
        "clear coat energy",
        glint::tables::clearcoat::clearcoat_energy_table(),
    );
    let sheen_energy = storage_buffer(
        ctx,
        "sheen energy",
        glint::tables::sheen::sheen_energy_table(),
    );
    let size = params.count as u64 * 16;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe out"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    // Every scene binding, whichever the entry point uses.
    let read_only = wgpu::BufferBindingType::Storage { read_only: true };
    let read_write = wgpu::BufferBindingType::Storage { read_only: false };
    let hardware: Vec<_> = acceleration
        .iter()
        .map(|a| (27, read_only, &a.references))
        .collect();
    let buffers: Vec<_> = [
        (0, wgpu::BufferBindingType::Uniform, &scene_params),
        (1, read_only, &spheres),
        (2, read_only, &quads),
        (3, read_only, &materials),
        (6, read_only, &emitters),
        (8, read_only, &triangles),
        (9, read_only, &triangle_normals),
        (12, read_only, &bvh_nodes),
        (23, wgpu::BufferBindingType::Uniform, &bvh_top_nodes),
        (13, read_only, &bvh_primitives),
        (40, read_only, &instances),
        (44, read_only, &bvh_wide_nodes),
        (45, wgpu::BufferBindingType::Uniform, &bvh_wide_top_nodes),
        (10, wgpu::BufferBindingType::Uniform, &probe_params),
        (11, read_write, &out),
        (20, read_only, &textures),
        (21, read_only, &texels),
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
        (48, read_only, &light_tree_nodes),
        (49, read_only, &light_tree_trails),
    ]
    .into_iter()
    .chain(hardware)
    .collect();
    let tlas = acceleration.map(|a| (26, &a.tlas));
    // The context's cache: the chi² suites probe the same entry point over many scenes.
    let (layout, pipeline) = ctx.compute_pipeline(
        entry,
        &source,
        entry,
        &compute_layout_entries(&buffers, tlas.map(|(binding, _)| binding)),
    );
    let bind_group = bind_group(device, "probe", &layout, &buffers, tlas);
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(params.count.div_ceil(256), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&out, 0, &readback, 0, None);
    ctx.queue.submit([encoder.finish()]);
    ctx.read_mapped(&readback, |bytes| {
        bytemuck::cast_slice::<u8, [f32; 4]>(bytes).to_vec()
    })
    .unwrap()
}
