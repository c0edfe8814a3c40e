//! Ray–primitive intersection and the surface at a hit (`shaders/geometry/`): spheres, quads,
//! triangles (with alpha testing), instances, and the shading normal.

pub mod alpha;
pub mod hit;
pub mod instance;
pub mod intersect;
pub mod scene_geometry;
pub mod shading_normal;
pub mod surface;
pub mod triangle;
