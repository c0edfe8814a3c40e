//! Bind groups of whole buffers, described once as (binding, type, buffer) so the layout and
//! the bind group cannot disagree, and the compute pipelines that use them.

/// The layout entry of a whole-buffer binding.
pub fn buffer_layout_entry(
    binding: u32,
    ty: wgpu::BufferBindingType,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// The layout entries of a compute bind group of whole `buffers` (and a TLAS at
/// `tlas_binding`, the hardware traversal's: shaders/traverse/hardware.wgsl). Explicit, not
/// taken from the pipeline: an automatic layout drops the bindings a shader does not use, and
/// kernels with features compiled out (or probe entry points) use fewer. They are part of
/// what `GpuContext::compute_pipeline` looks a cached pipeline up by.
pub fn compute_layout_entries(
    buffers: &[(u32, wgpu::BufferBindingType, &wgpu::Buffer)],
    tlas_binding: Option<u32>,
) -> Vec<wgpu::BindGroupLayoutEntry> {
    let mut entries: Vec<_> = buffers
        .iter()
        .map(|&(binding, ty, _)| buffer_layout_entry(binding, ty, wgpu::ShaderStages::COMPUTE))
        .collect();
    if let Some(binding) = tlas_binding {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::AccelerationStructure {
                vertex_return: false,
            },
            count: None,
        });
    }
    entries
}

/// The bind group binding `buffers` (and the TLAS, where given) to `layout`.
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[(u32, wgpu::BufferBindingType, &wgpu::Buffer)],
    tlas: Option<(u32, &wgpu::Tlas)>,
) -> wgpu::BindGroup {
    let mut entries: Vec<_> = buffers
        .iter()
        .map(|&(binding, _, buffer)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    if let Some((binding, tlas)) = tlas {
        entries.push(wgpu::BindGroupEntry {
            binding,
            resource: tlas.as_binding(),
        });
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A compute pipeline running `entry_point` of `module` with `layout` as its one bind group.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    module: &wgpu::ShaderModule,
    entry_point: &str,
) -> wgpu::ComputePipeline {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module,
        entry_point: Some(entry_point),
        compilation_options: Default::default(),
        cache: None,
    })
}
