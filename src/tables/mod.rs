//! The energy tables: directional albedos and scalings computed at first use by numerical
//! integration, which the materials read on both devices (the CPU lookups live beside the
//! materials in `src/cpu/materials/`, the WGSL ones in `shaders/materials/`).

pub mod clearcoat;
pub mod dielectric;
pub mod ggx;
pub mod sheen;
pub mod threads;
