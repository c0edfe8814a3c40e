//! Participating media (`[media.NAME]`): homogeneous absorption and scattering with a
//! Henyey–Greenstein phase function, filling the inside of closed objects, the whole scene
//! (`[render] medium`) or the camera's surroundings (`[camera] medium`). The kernel's side is
//! `shaders/media/` (mirror: `src/cpu/media/`); docs/src/reference/media.md is the user's.

use super::grid::DensityGrid;
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// The most medium slots the kernel holds (`Params::media`): one per object material that
/// bounds a medium, one for the global medium, one for the camera's where no object bounds it.
pub const MAX_MEDIUM_SLOTS: usize = 8;

/// Largest absorption or scattering coefficient (per unit length): the inverse of the
/// shortest length glint supports, so σ·t never overflows f32 inside the coordinate range.
pub const MAX_COEFFICIENT: f32 = 1e8;

/// One medium: coefficients per unit length, per RGB channel (per unit length and unit
/// density for a grid medium).
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    pub name: String,
    pub sigma_a: Vec3,
    pub sigma_s: Vec3,
    /// Henyey–Greenstein's mean cosine, in (−1, 1): > 0 scatters forwards.
    pub g: f32,
    /// A heterogeneous medium's density grid (`[media.NAME] grid`), and once a `[[volumes]]`
    /// entry places it, where: `None` for a homogeneous medium.
    pub grid: Option<GridMedium>,
}

/// A density grid, and the transform from the grid's own space to the scene's (identity
/// until a volume places it).
#[derive(Clone, Debug, PartialEq)]
pub struct GridMedium {
    pub grid: Arc<DensityGrid>,
    pub placement: Mat4,
}

/// The scene's media and where they are.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Media {
    pub list: Vec<Medium>,
    /// The medium filling the space outside every object (`[render] medium`).
    pub global: Option<u32>,
    /// The medium the camera is in (`[camera] medium`), when it is not the global one.
    pub camera: Option<u32>,
    /// (material, medium): objects of that material (each a clone made for its medium) bound
    /// the medium, which fills their inside.
    pub boundaries: Vec<(u32, u32)>,
}

impl Media {
    pub fn is_empty(&self) -> bool {
        self.global.is_none() && self.camera.is_none() && self.boundaries.is_empty()
    }
}
