//! The BSDFs (`shaders/materials/`): one file per lobe or material, and the CPU lookups of the
//! energy tables that `crate::tables` computes.

pub mod bsdf;
pub mod clearcoat;
pub mod clearcoat_energy;
pub mod conductor;
pub mod dielectric;
pub mod dielectric_energy;
pub mod diffuse;
pub mod ggx_energy;
pub mod material;
pub mod microfacet;
pub mod pbr;
pub mod rough_dielectric;
pub mod rough_dielectric_single;
pub mod sheen;
pub mod sheen_energy;
