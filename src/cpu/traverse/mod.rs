//! Traversal structures other than the scene's binary BVH (`super::bvh`), one file each,
//! mirroring `shaders/traverse/`: the instances' own trees (`blas`) and the 4-wide tree
//! (`wide`). Which tree a device runs is chosen once, in `scene::bvh_layout`.

pub mod blas;
pub mod wide;
