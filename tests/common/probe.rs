//! Runs the WGSL sampling routines on the GPU through tests/shaders/probe.wgsl.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use glint::gpu::GpuContext;
use glint::shader::render_kernel_source;
use wgpu::util::DeviceExt;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ProbeParams {
    normal: [f32; 3],
    count: u32,
    seed: u32,
    _pad: [u32; 3],
}

pub const PROBE_SOURCE: &str = include_str!("../shaders/probe.wgsl");

pub fn probe_module_source() -> String {
    render_kernel_source() + PROBE_SOURCE
}

/// Runs the probe entry point `entry` for `count` samples and returns what it wrote.
pub fn run_probe(
    ctx: &GpuContext,
    entry: &str,
    normal: Vec3,
    count: u32,
    seed: u32,
) -> Vec<[f32; 4]> {
    let device = &ctx.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("probe"),
        source: wgpu::ShaderSource::Wgsl(probe_module_source().into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    let params = ProbeParams {
        normal: normal.into(),
        count,
        seed,
        _pad: [0; 3],
    };
    let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe params"),
        contents: bytemuck::bytes_of(&params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let size = count as u64 * 16;
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
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 10,
                resource: params_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 11,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(count.div_ceil(256), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&out, 0, &readback, 0, None);
    ctx.queue.submit([encoder.finish()]);
    readback
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    ctx.wait_idle().unwrap();
    let values =
        bytemuck::cast_slice::<u8, [f32; 4]>(&readback.slice(..).get_mapped_range().unwrap())
            .to_vec();
    readback.unmap();
    values
}
