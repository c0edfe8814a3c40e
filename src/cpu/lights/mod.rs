//! Light sampling (`shaders/lights/`): emitters chosen by power, punctual lights and the
//! environment map, with the MIS weights they share.

pub mod emission;
pub mod environment;
pub mod light_sample;
pub mod punctual;
pub mod sampling;
