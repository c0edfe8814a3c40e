//! What intersection reads of the scene: the CPU's view of the kernel's geometry bindings
//! (`shaders/core/scene_storage.wgsl`), which the traversals and `intersect.rs` take as one
//! argument where the kernel reads globals.

use crate::cpu::geometry::alpha::AlphaTest;
use crate::kernel::types::{
    BvhNode, BvhWideNode, Instance, Quad, Sphere, Triangle, TriangleNormals, TriangleUvs,
};

/// The scene's surfaces as the kernel's intersection code reads them. With `bvh_nodes` empty,
/// every ray tests every primitive (the kernel's `USE_BVH = false`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Geometry<'a> {
    pub spheres: &'a [Sphere],
    pub quads: &'a [Quad],
    pub triangles: &'a [Triangle],
    pub triangle_normals: &'a [TriangleNormals],
    pub bvh_nodes: &'a [BvhNode],
    pub bvh_primitives: &'a [u32],
    /// Instanced meshes' placements (`instance.rs`); empty without any.
    pub instances: &'a [Instance],
    /// The same tree 4 wide, traversed instead of `bvh_nodes` when not empty (the CPU's
    /// layout: src/kernel/bvh/layout.rs).
    pub bvh_wide_nodes: &'a [BvhWideNode],
    /// One per triangle when `textured`.
    pub triangle_uvs: &'a [TriangleUvs],
    /// The second set, where a texture reads it (else empty).
    pub triangle_uvs1: &'a [TriangleUvs],
    /// Whether hits need texture coordinates (the kernel's `HAS_TEXTURES`).
    pub textured: bool,
    /// Alpha-tested and blended triangles (`alpha.rs`); off by default.
    pub alpha: AlphaTest<'a>,
}

impl<'a> Geometry<'a> {
    /// Spheres and quads only, tested one by one.
    pub fn new(spheres: &'a [Sphere], quads: &'a [Quad]) -> Geometry<'a> {
        Geometry {
            spheres,
            quads,
            ..Default::default()
        }
    }
}
