//! The display pass: shows a renderer's running mean (with bidirectional path tracing's splat
//! film added where there is one), or the denoised image, on a surface,
//! through the tone curve (`shaders/viewer/display.wgsl`, `shaders/viewer/tonemap.wgsl`). It reads the mean
//! buffer where the kernel wrote it, so showing a frame costs no readback.

use crate::gpu::binding::buffer_layout_entry;
use crate::image::tonemap::{DisplayTransform, Tonemap};
use bytemuck::{Pod, Zeroable};

/// The tone curves (src/image/tonemap.rs's GPU mirror), then the pass that uses them.
pub const DISPLAY_SHADER: &str = concat!(
    include_str!("../../shaders/viewer/tonemap.wgsl"),
    include_str!("../../shaders/viewer/display.wgsl")
);
pub const VERTEX_ENTRY_POINT: &str = "vs_main";
pub const FRAGMENT_ENTRY_POINT: &str = "fs_main";

/// The shader's `Display` uniform, byte for byte (`tests/suite/viewer_display.rs` checks the layout).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DisplayUniform {
    pub image_size: [u32; 2],
    pub target_size: [u32; 2],
    pub scale: f32,
    pub encode_srgb: u32,
    /// [`tonemap_code`] of the curve.
    pub tonemap: u32,
    /// 1 / (splat scale × samples per pixel): what a unit of the splat film's sums adds to the
    /// mean; 0 where nothing splats.
    pub splat_weight: f32,
}

/// The shader's code for `tonemap` (`TONEMAP_*` in shaders/viewer/tonemap.wgsl).
pub fn tonemap_code(tonemap: Tonemap) -> u32 {
    match tonemap {
        Tonemap::Clamp => 0,
        Tonemap::Aces => 1,
        Tonemap::Agx => 2,
    }
}

pub struct DisplayPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    bind_group: Option<wgpu::BindGroup>,
    encode_srgb: bool,
}

impl DisplayPass {
    /// A pass that draws into textures of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> DisplayPass {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("glint display"),
            source: wgpu::ShaderSource::Wgsl(DISPLAY_SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display"),
            entries: &[
                buffer_layout_entry(
                    0,
                    wgpu::BufferBindingType::Storage { read_only: true },
                    wgpu::ShaderStages::FRAGMENT,
                ),
                buffer_layout_entry(
                    1,
                    wgpu::BufferBindingType::Storage { read_only: true },
                    wgpu::ShaderStages::FRAGMENT,
                ),
                buffer_layout_entry(
                    2,
                    wgpu::BufferBindingType::Storage { read_only: true },
                    wgpu::ShaderStages::FRAGMENT,
                ),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("display"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(VERTEX_ENTRY_POINT),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(FRAGMENT_ENTRY_POINT),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display uniform"),
            size: size_of::<DisplayUniform>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        DisplayPass {
            pipeline,
            layout,
            uniform,
            bind_group: None,
            // An *Srgb target encodes on store; any other gets the shader's encoding.
            encode_srgb: !format.is_srgb(),
        }
    }

    /// Shows `mean` (per pixel vec4s of linear radiance), plus `splats` (a splat film) where
    /// given, from now on: call it whenever the renderer (and so its buffers) changes, or to
    /// switch between the raw and denoised images. Without a film the mean is bound in its
    /// place, unread ([`DisplayPass::draw`]'s `splat_weight` is then 0).
    pub fn bind(
        &mut self,
        device: &wgpu::Device,
        mean: &wgpu::Buffer,
        splats: Option<&wgpu::Buffer>,
    ) {
        self.bind_group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: mean.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: splats.unwrap_or(mean).as_entire_binding(),
                },
            ],
        }));
    }

    /// Records the pass: the bound image of `image_size`, its splat sums weighted by
    /// `splat_weight` (see [`DisplayUniform::splat_weight`]), shown through `transform` (as a
    /// PNG would hold it), drawn over all of `target` (of `target_size`).
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        image_size: (u32, u32),
        target_size: (u32, u32),
        transform: &DisplayTransform,
        splat_weight: f32,
    ) {
        let Some(bind_group) = &self.bind_group else {
            return;
        };
        let uniform = DisplayUniform {
            image_size: [image_size.0, image_size.1],
            target_size: [target_size.0.max(1), target_size.1.max(1)],
            scale: transform.exposure.exp2(),
            encode_srgb: self.encode_srgb as u32,
            tonemap: tonemap_code(transform.tonemap),
            splat_weight,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    // The triangle covers every pixel; clearing rather than loading spares a read.
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
