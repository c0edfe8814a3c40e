//! The basics every part of the CPU reference uses (`shaders/core/`): rays, the random stream, local
//! shading frames and the camera's primary rays.

pub mod camera;
pub mod frame;
pub mod ray;
pub mod rng;
