//! Light sampling (`shaders/lights/`): emitters chosen by power or by the light tree,
//! punctual lights and the environment map, with the MIS weights they share.

pub mod emission;
pub mod environment;
pub mod light_sample;
pub mod light_tree;
pub mod punctual;
pub mod sampling;
