//! Texture lookups (`shaders/textures/`): image and checker textures, normal maps and vertex
//! colours.

pub mod normal_map;
pub mod texture;
pub mod vertex_color;
