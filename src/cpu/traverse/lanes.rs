//! The wide walk's two tests on several lanes at once, for the CPU only (the kernel's are in
//! `shaders/traverse/wide.wgsl` and `shaders/geometry/triangle.wgsl`): a wide node's four
//! boxes, and up to four of a leaf's triangles. Each lane does the IEEE operations of the
//! scalar test it stands for, in the same order (`hit_box` in `bvh_ray.rs`, `hit_triangle`
//! in `src/cpu/geometry/triangle.rs`): no fused multiply-add (Rust never contracts), min and
//! max on operands that are never NaN, and a correctly rounded division per lane, so every
//! lane's result is the scalar test's, bit for bit.
//!
//! [`Portable`] does it with `glam` (SSE2 or NEON under it, where the target has them);
//! [`Sse`] with `std::arch`'s SSE2, which every x86-64 CPU has, so no run-time check is needed
//! (AVX2 measured no faster: `WideTests::Sse2` in `wide.rs`).

use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::geometry::triangle::hit_triangle;
use crate::cpu::traverse::bvh_ray::{widened, BvhRay, BOX_SLACK};
use crate::kernel::types::{BvhWideNode, Triangle, WIDE_EMPTY_CHILD};
use glam::{BVec4A, Vec4};

/// The tests a wide walk runs on several lanes.
pub trait WideLanes {
    /// Where the ray enters each of `node`'s four child boxes, and a mask with bit `s` set
    /// where slot `s` holds a child whose box the ray enters no later than `limit` (the bound,
    /// already widened): `hit_box`'s arithmetic and decision per slot. Lanes not in the mask
    /// hold anything.
    fn boxes(&self, node: &BvhWideNode, limit: f32) -> ([f32; 4], u32);

    /// `hit_triangle` on four triangles: each one's t, and a mask with bit `k` set where
    /// triangle `k` is hit (its t is then not `NO_HIT`). Lanes not in the mask hold anything.
    fn triangles(&self, tris: [&Triangle; 4]) -> ([f32; 4], u32);
}

/// Where the ray enters each of the node's four child boxes (0 when it starts inside), or
/// `NO_HIT` where it misses the box, enters it beyond `t_max`, or the slot holds no child.
/// Each child's is `hit_box`'s arithmetic (`bvh_ray.rs`), on four boxes at once: the same
/// IEEE operations, and no NaN can arise (inv_dir is finite and non-zero).
pub fn hit_wide_boxes(node: &BvhWideNode, r: &BvhRay, t_max: f32) -> Vec4 {
    let (near, hit) = wide_boxes(node, r, widened(t_max));
    Vec4::select(hit, near, Vec4::splat(NO_HIT))
}

fn wide_boxes(node: &BvhWideNode, r: &BvhRay, limit: f32) -> (Vec4, BVec4A) {
    let slab = |min: [f32; 4], max: [f32; 4], origin: f32, inv: f32| {
        let t0 = (Vec4::from(min) - origin) * inv;
        let t1 = (Vec4::from(max) - origin) * inv;
        (t0.min(t1), t0.max(t1))
    };
    let (near_x, far_x) = slab(node.min_x, node.max_x, r.origin.x, r.inv_dir.x);
    let (near_y, far_y) = slab(node.min_y, node.max_y, r.origin.y, r.inv_dir.y);
    let (near_z, far_z) = slab(node.min_z, node.max_z, r.origin.z, r.inv_dir.z);
    let near = near_x.max(near_y).max(near_z.max(Vec4::ZERO));
    let far = far_x.min(far_y).min(far_z) * BOX_SLACK;
    let present = BVec4A::from_array(node.count.map(|c| c != WIDE_EMPTY_CHILD));
    (near, near.cmple(far.min(Vec4::splat(limit))) & present)
}

/// The tests through `glam` and the scalar triangle test: what any target runs.
pub struct Portable<'a>(pub &'a BvhRay);

impl WideLanes for Portable<'_> {
    #[inline(always)]
    fn boxes(&self, node: &BvhWideNode, limit: f32) -> ([f32; 4], u32) {
        let (near, hit) = wide_boxes(node, self.0, limit);
        (near.to_array(), hit.bitmask())
    }

    #[inline(always)]
    fn triangles(&self, tris: [&Triangle; 4]) -> ([f32; 4], u32) {
        let t = tris.map(|tri| hit_triangle(tri, &self.0.tri));
        let mask = (0..4)
            .filter(|&k| t[k] != NO_HIT)
            .fold(0, |m, k| m | 1 << k);
        (t, mask)
    }
}

#[cfg(target_arch = "x86_64")]
pub use sse::Sse;

#[cfg(target_arch = "x86_64")]
mod sse {
    use super::WideLanes;
    use crate::cpu::geometry::hit::NO_HIT;
    use crate::cpu::traverse::bvh_ray::{BvhRay, BOX_SLACK};
    use crate::kernel::types::{BvhWideNode, Triangle};
    use std::arch::x86_64::*;

    /// The ray's values the tests share, each in all four lanes.
    #[derive(Clone, Copy)]
    pub struct Sse {
        origin: [__m128; 3],
        inv_dir: [__m128; 3],
        /// The triangle test's: its frame's axes (kx, ky, kz), the origin in that order, and
        /// the shear.
        axes: [usize; 3],
        tri_origin: [__m128; 3],
        shear: [__m128; 3],
    }

    impl Sse {
        #[inline(always)]
        pub fn new(r: &BvhRay) -> Sse {
            // SAFETY: SSE2 is part of x86-64.
            unsafe {
                let t = &r.tri;
                Sse {
                    origin: [r.origin.x, r.origin.y, r.origin.z].map(|v| _mm_set1_ps(v)),
                    inv_dir: [r.inv_dir.x, r.inv_dir.y, r.inv_dir.z].map(|v| _mm_set1_ps(v)),
                    axes: [t.kx, t.ky, t.kz],
                    tri_origin: [t.origin.x, t.origin.y, t.origin.z].map(|v| _mm_set1_ps(v)),
                    shear: [t.shear.x, t.shear.y, t.shear.z].map(|v| _mm_set1_ps(v)),
                }
            }
        }
    }

    /// Lanes 0..3 of four registers' x, y and z: the three rows of their transpose.
    #[inline(always)]
    unsafe fn transpose3(r0: __m128, r1: __m128, r2: __m128, r3: __m128) -> [__m128; 3] {
        let xy01 = _mm_unpacklo_ps(r0, r1);
        let xy23 = _mm_unpacklo_ps(r2, r3);
        let zw01 = _mm_unpackhi_ps(r0, r1);
        let zw23 = _mm_unpackhi_ps(r2, r3);
        [
            _mm_movelh_ps(xy01, xy23),
            _mm_movehl_ps(xy23, xy01),
            _mm_movelh_ps(zw01, zw23),
        ]
    }

    #[inline(always)]
    unsafe fn select(mask: __m128, a: __m128, b: __m128) -> __m128 {
        _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b))
    }

    impl WideLanes for Sse {
        #[inline(always)]
        fn boxes(&self, node: &BvhWideNode, limit: f32) -> ([f32; 4], u32) {
            // SAFETY: SSE2 is part of x86-64, and the loads read the node's own arrays.
            unsafe {
                let slab = |min: &[f32; 4], max: &[f32; 4], k: usize| {
                    let t0 = _mm_mul_ps(
                        _mm_sub_ps(_mm_loadu_ps(min.as_ptr()), self.origin[k]),
                        self.inv_dir[k],
                    );
                    let t1 = _mm_mul_ps(
                        _mm_sub_ps(_mm_loadu_ps(max.as_ptr()), self.origin[k]),
                        self.inv_dir[k],
                    );
                    (_mm_min_ps(t0, t1), _mm_max_ps(t0, t1))
                };
                let (near_x, far_x) = slab(&node.min_x, &node.max_x, 0);
                let (near_y, far_y) = slab(&node.min_y, &node.max_y, 1);
                let (near_z, far_z) = slab(&node.min_z, &node.max_z, 2);
                // The operand order of glam's `a.max(b)` (`_mm_max_ps(a, b)`) in `hit_box`.
                let near = _mm_max_ps(
                    _mm_max_ps(near_x, near_y),
                    _mm_max_ps(near_z, _mm_setzero_ps()),
                );
                let far = _mm_mul_ps(
                    _mm_min_ps(_mm_min_ps(far_x, far_y), far_z),
                    _mm_set1_ps(BOX_SLACK),
                );
                let hit = _mm_cmple_ps(near, _mm_min_ps(far, _mm_set1_ps(limit)));
                let empty = _mm_cmpeq_epi32(
                    _mm_loadu_si128(node.count.as_ptr().cast()),
                    _mm_set1_epi32(-1),
                );
                let mask = _mm_movemask_ps(_mm_andnot_ps(_mm_castsi128_ps(empty), hit));
                let mut t = [0f32; 4];
                _mm_storeu_ps(t.as_mut_ptr(), near);
                (t, mask as u32)
            }
        }

        #[inline(always)]
        fn triangles(&self, tris: [&Triangle; 4]) -> ([f32; 4], u32) {
            // SAFETY: SSE2 is part of x86-64; each load reads a vertex and the word after it
            // (`Triangle` is repr(C): v0, material, v1, light_probability, v2, area).
            unsafe {
                let vertex = |offset: usize| {
                    let load = |t: &Triangle| {
                        _mm_loadu_ps((t as *const Triangle).cast::<f32>().add(offset))
                    };
                    transpose3(load(tris[0]), load(tris[1]), load(tris[2]), load(tris[3]))
                };
                let [kx, ky, kz] = self.axes;
                let o = &self.tri_origin;
                // `triangle_edges`: the vertex less the origin, per axis, then sheared.
                let sheared = |v: [__m128; 3]| {
                    let d = [
                        _mm_sub_ps(v[0], o[0]),
                        _mm_sub_ps(v[1], o[1]),
                        _mm_sub_ps(v[2], o[2]),
                    ];
                    let (x, y, z) = (d[kx], d[ky], d[kz]);
                    (
                        _mm_sub_ps(x, _mm_mul_ps(self.shear[0], z)),
                        _mm_sub_ps(y, _mm_mul_ps(self.shear[1], z)),
                        z,
                    )
                };
                let (ax, ay, az) = sheared(vertex(0));
                let (bx, by, bz) = sheared(vertex(4));
                let (cx, cy, cz) = sheared(vertex(8));
                let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
                let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
                let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
                let sz = self.shear[2];
                let t_scaled = _mm_add_ps(
                    _mm_add_ps(
                        _mm_mul_ps(u, _mm_mul_ps(sz, az)),
                        _mm_mul_ps(v, _mm_mul_ps(sz, bz)),
                    ),
                    _mm_mul_ps(w, _mm_mul_ps(sz, cz)),
                );
                // `hit_triangle`: outside where the edge functions have both signs, no hit
                // where their sum is 0, and t must be > 0 (false for NaN).
                let zero = _mm_setzero_ps();
                let negative = _mm_or_ps(
                    _mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)),
                    _mm_cmplt_ps(w, zero),
                );
                let positive = _mm_or_ps(
                    _mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)),
                    _mm_cmpgt_ps(w, zero),
                );
                let det = _mm_add_ps(_mm_add_ps(u, v), w);
                let t = _mm_div_ps(t_scaled, det);
                let missed = _mm_or_ps(_mm_and_ps(negative, positive), _mm_cmpeq_ps(det, zero));
                let hit = _mm_andnot_ps(missed, _mm_cmpgt_ps(t, zero));
                let mut out = [0f32; 4];
                _mm_storeu_ps(out.as_mut_ptr(), select(hit, t, _mm_set1_ps(NO_HIT)));
                (out, _mm_movemask_ps(hit) as u32)
            }
        }
    }
}
