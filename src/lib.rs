//! glint: a physically based path tracer on the GPU (wgpu, Vulkan, WGSL compute shaders), with a
//! CPU reference that mirrors the kernel operation for operation.
//!
//! Data flows one way: scene file → [`scene::Scene`] (validated) → [`scene::KernelScene`]
//! (the kernel's structs) → a [`render::Renderer`] (GPU or CPU) → [`output::Image`].

pub mod aov;
pub mod bench;
pub mod cli;
pub mod compare;
pub mod cpu;
pub mod denoise;
pub mod error;
pub mod gpu;
pub mod output;
pub mod render;
pub mod scene;
pub mod shader;
pub mod shader_types;
pub mod tonemap;
pub mod viewer;
