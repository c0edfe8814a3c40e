//! The GPU path: wgpu on Vulkan, running the WGSL kernel in `shaders/`.

pub mod acceleration;
pub mod binding;
pub mod context;
pub mod image_buffers;
pub mod inline_uniforms;
pub mod instruments;
pub mod limits;
pub mod loop_budget;
pub mod renderer;
pub mod tiles;
pub mod traversal;
pub mod upload;

pub use context::{GpuContext, GpuUnavailable};
pub use renderer::GpuRenderer;
pub use traversal::{Traversal, TraversalChoice};
