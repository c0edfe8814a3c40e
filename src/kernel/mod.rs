//! The validated scene as the kernel reads it: the `#[repr(C)]` structs both devices trace
//! from (`types`, mirrored byte for byte by `shaders/core/types.wgsl`), the scene laid out in
//! them (`scene`: `KernelScene`), its BVHs (`bvh`), the emitters' powers for light sampling
//! (`emitters`), the accumulation's block schedule (`schedule`), how the texels are bound
//! (`texels`) and which WGSL kernel a scene compiles (`variant`).

pub mod bvh;
mod emitters;
pub mod scene;
pub mod schedule;
pub mod source;
pub mod texels;
pub mod types;
pub mod variant;

pub use scene::{place_camera, KernelScene};
