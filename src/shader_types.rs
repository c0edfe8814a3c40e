//! The structs the kernel reads, byte for byte (WGSL side: `shaders/types.wgsl`).
//! The CPU reference traces from these same structs, so both devices see identical numbers.
//! `tests/layout.rs` checks every offset and size against the WGSL with naga's layouter.

use bytemuck::{Pod, Zeroable};

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub eye: [f32; 3],
    pub width: u32,
    /// Unit vector from the eye towards the target.
    pub forward: [f32; 3],
    pub height: u32,
    /// Image-right and image-up, scaled to half the viewport at unit distance.
    pub right: [f32; 3],
    pub sample_start: u32,
    pub up: [f32; 3],
    pub sample_count: u32,
    pub background: [f32; 3],
    pub max_bounces: u32,
    pub seed: u32,
    pub sphere_count: u32,
    pub quad_count: u32,
    pub material_count: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Sphere {
    pub center: [f32; 3],
    pub radius: f32,
    pub material: u32,
    pub _pad: [u32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Quad {
    pub corner: [f32; 3],
    pub material: u32,
    pub edge_u: [f32; 3],
    pub area: f32,
    pub edge_v: [f32; 3],
    /// The plane is `dot(normal, p) == plane_offset`.
    pub plane_offset: f32,
    pub normal: [f32; 3],
    pub pad0: f32,
    /// `edge_u / dot(edge_u, edge_u)`.
    pub u_dual: [f32; 3],
    pub pad1: f32,
    /// `edge_v / dot(edge_v, edge_v)`.
    pub v_dual: [f32; 3],
    pub pad2: f32,
}

pub const MATERIAL_DIFFUSE: u32 = 0;
pub const MATERIAL_SPECULAR: u32 = 1;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Material {
    pub albedo: [f32; 3],
    pub kind: u32,
    /// `emission * strength`.
    pub emission: [f32; 3],
    pub pad0: f32,
}
