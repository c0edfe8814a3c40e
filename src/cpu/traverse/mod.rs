//! Traversal structures other than the binary BVH (`super::bvh`), one file each, mirroring
//! `shaders/traverse/`. Which one a device runs is chosen once, in `scene::bvh_layout`.

pub mod wide;
