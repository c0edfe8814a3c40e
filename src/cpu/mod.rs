//! The CPU reference: the kernel's algorithm in Rust, one file per WGSL file, with the same
//! names, the same random stream and the same f32 operations. It is the oracle for the GPU
//! and the fallback where there is no Vulkan device.

pub mod accumulate;
pub mod alpha;
pub mod aov;
pub mod bsdf;
pub mod bvh;
pub mod camera;
pub mod clearcoat;
pub mod clearcoat_energy;
pub mod conductor;
pub mod dielectric;
pub mod dielectric_energy;
pub mod diffuse;
pub mod environment;
pub mod frame;
pub mod ggx_energy;
pub mod instance;
pub mod intersect;
pub mod lights;
pub mod material;
pub mod microfacet;
pub mod normal_map;
pub mod pbr;
pub mod punctual;
pub mod renderer;
pub mod rng;
pub mod rough_dielectric;
pub mod shading_normal;
pub mod sheen;
pub mod sheen_energy;
pub mod surface;
pub mod texture;
pub mod trace;
pub mod traverse;
pub mod triangle;
pub mod vertex_color;
pub mod volume;

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}
