//! Vertex colours (WGSL side: `shaders/textures/vertex_color.wgsl`): glTF's COLOR_0, interpolated at a
//! triangle hit, multiplies the material's base colour (albedo) and, for alpha-tested and
//! blended materials, its alpha (`alpha.rs`). An unlit material's base colour is its emission
//! (KHR_materials_unlit), so there the colour multiplies the emission, at hits and at light
//! samples alike.

use crate::cpu::geometry::hit::Hit;
use crate::kernel::types::{Material, TriangleColors, MATERIAL_UNLIT, PRIMITIVE_TRIANGLE};
use glam::{Vec3, Vec4};

/// The vertex colour (linear RGBA) at barycentrics `b` (`b.x` for `c0`) of triangle colours `c`.
pub fn vertex_color(c: &TriangleColors, b: Vec3) -> Vec4 {
    b.x * Vec4::from(c.c0) + b.y * Vec4::from(c.c1) + b.z * Vec4::from(c.c2)
}

/// Material `m` at hit `hit` with the vertex colour there multiplying its albedo; `colors` is
/// empty (the kernel's `HAS_VERTEX_COLORS` off) when no mesh has vertex colours.
pub fn vertex_colored(colors: &[TriangleColors], m: &Material, hit: &Hit) -> Material {
    let mut out = *m;
    if !colors.is_empty() && hit.primitive == PRIMITIVE_TRIANGLE {
        let c = vertex_color(&colors[hit.index as usize], hit.barycentrics);
        out.albedo = (Vec3::from(m.albedo) * c.truncate()).into();
        if m.kind == MATERIAL_UNLIT {
            out.emission = (Vec3::from(m.emission) * c.truncate()).into();
        }
    }
    out
}

/// What triangle `index` of material `m` emits at barycentrics `b`, given `emission` there
/// (its texture's): an unlit material's times the vertex colour; `colors` as for
/// [`vertex_colored`].
pub fn vertex_colored_emission(
    colors: &[TriangleColors],
    m: &Material,
    index: u32,
    b: Vec3,
    emission: Vec3,
) -> Vec3 {
    if !colors.is_empty() && m.kind == MATERIAL_UNLIT {
        return emission * vertex_color(&colors[index as usize], b).truncate();
    }
    emission
}
