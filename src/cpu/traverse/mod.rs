//! Traversal structures beyond the top-level BVH (WGSL side: `shaders/traverse/`).

pub mod blas;
