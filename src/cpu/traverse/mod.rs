//! Finding the closest hit along a ray (`shaders/traverse/`): the scene's binary BVH (`bvh`),
//! the instances' own trees (`blas`), both by one walk (`binary_walk`), and the 4-wide tree
//! (`wide`), whose box and triangle tests run in SIMD lanes (`lanes`, the CPU's only: the
//! kernel tests one lane's worth per invocation). Which tree a device runs is chosen once, in
//! `kernel::bvh::layout`.

pub mod binary_walk;
pub mod blas;
pub mod bvh;
pub mod bvh_ray;
pub mod lanes;
pub mod wide;
