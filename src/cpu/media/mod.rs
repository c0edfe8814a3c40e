//! Participating media (`shaders/media/`): the Henyey–Greenstein phase function, and
//! homogeneous media: which one a path is in, free-flight sampling and transmittance along
//! shadow rays; heterogeneous media from density grids (`grid.rs`). The path tracer's medium
//! vertices are in `integrator/path_media.rs`.

pub mod grid;
pub mod medium;
pub mod phase;
