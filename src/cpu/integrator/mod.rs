//! The path tracer itself (`shaders/integrator/`): the path loop, Beer–Lambert volumes, the
//! denoiser's AOVs, per-pixel accumulation, and the CPU renderer that runs it over tiles.

pub mod accumulate;
pub mod aov;
pub mod bdpt;
pub mod path;
pub mod path_media;
pub mod pixel;
pub mod renderer;
pub mod splat;
pub mod volume;
