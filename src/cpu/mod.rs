//! The CPU reference: the kernel's algorithm in Rust, one file per WGSL file, with the same
//! names, the same random stream and the same f32 operations, in the same folders as
//! `shaders/`. It is the oracle for the GPU and the fallback where there is no Vulkan device.
//!
//! From the bottom up: `core` (rays, random numbers, frames, the camera), `geometry`
//! (intersections and surfaces), `traverse` (the BVHs), `textures`, `materials` (the BSDFs),
//! `scene_refs` (the scene as the kernel binds it), `lights` (light sampling), `integrator` (the path tracer and the renderer).

pub mod core;
pub mod geometry;
pub mod integrator;
pub mod lights;
pub mod materials;
pub mod media;
pub mod scene_refs;
pub mod textures;
pub mod traverse;
