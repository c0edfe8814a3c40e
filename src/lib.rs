//! glint: a physically based path tracer on the GPU (wgpu, Vulkan, WGSL compute shaders), with a
//! CPU reference that mirrors the kernel operation for operation.
//!
//! Data flows one way: scene file → [`scene::Scene`] (validated) → [`scene::KernelScene`]
//! (the kernel's structs) → a [`render::Renderer`] (GPU or CPU) → [`output::Image`].

// Everything printed goes through `outln!`/`errln!` (src/stdio.rs): `println!` panics on a
// closed pipe.
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub mod cli;
pub mod cpu;
pub mod error;
pub mod exr_header;
pub mod gpu;
pub mod image;
pub mod input_file;
pub mod kernel;
pub mod render;
pub mod scene;
pub mod stdio;
pub mod tables;
pub mod viewer;
