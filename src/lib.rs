//! glint: a physically based path tracer on the GPU (wgpu, Vulkan, WGSL compute shaders), with a
//! CPU reference that mirrors the kernel operation for operation.
//!
//! Data flows one way: scene file → [`scene::Scene`] (validated) → [`scene::KernelScene`]
//! (the kernel's structs) → a [`render::Renderer`] (GPU or CPU) → [`output::Image`].

// Everything printed goes through `outln!`/`errln!` (src/stdio.rs): `println!` panics on a
// closed pipe.
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub mod accumulation;
pub mod aov;
pub mod atomic_write;
pub mod bench;
pub mod clearcoat_energy;
pub mod cli;
pub mod compare;
pub mod cpu;
pub mod denoise;
pub mod dielectric_energy;
pub mod error;
pub mod exr_header;
pub mod ggx_energy;
pub mod gpu;
pub mod input_file;
pub mod interrupt;
pub mod merge;
pub mod output;
pub mod output_check;
pub mod partial;
pub mod render;
pub mod scene;
pub mod shader;
pub mod shader_types;
pub mod sheen_energy;
pub mod stdio;
pub mod table_threads;
pub mod texel_windows;
pub mod tonemap;
pub mod viewer;
