// Vertex colours (mirror: src/cpu/textures/vertex_color.rs): glTF's COLOR_0, interpolated at a triangle
// hit, multiplies the material's base colour (albedo) and, for alpha-tested and blended
// materials, its alpha (alpha.wgsl). An unlit material's base colour is its emission, so there
// the colour multiplies the emission, at hits and at light samples alike. Compiled in only when a mesh has vertex colours
// (HAS_VERTEX_COLORS, src/kernel/variant.rs).

// One per triangle when a mesh has vertex colours (a placeholder otherwise).
@group(0) @binding(34) var<storage, read> triangle_colors: array<TriangleColors>;

// The vertex colour (linear RGBA) at barycentrics b (b.x for c0) of triangle `index`.
fn vertex_color(index: u32, b: vec3<f32>) -> vec4<f32> {
    let c = triangle_colors[index];
    return b.x * c.c0 + b.y * c.c1 + b.z * c.c2;
}

// Material m at triangle hit `hit` with the vertex colour there multiplying its albedo.
fn vertex_colored(m: Material, hit: Hit) -> Material {
    var out = m;
    if HAS_VERTEX_COLORS && hit.primitive == PRIMITIVE_TRIANGLE {
        let c = vertex_color(hit.index, hit.barycentrics).xyz;
        out.albedo = m.albedo * c;
        if m.kind == MATERIAL_UNLIT {
            out.emission = m.emission * c;
        }
    }
    return out;
}

// What triangle `index` of material m emits at barycentrics b, given `emission` there (its
// texture's): an unlit material's times the vertex colour.
fn vertex_colored_emission(m: Material, index: u32, b: vec3<f32>, emission: vec3<f32>) -> vec3<f32> {
    if HAS_VERTEX_COLORS && m.kind == MATERIAL_UNLIT {
        return emission * vertex_color(index, b).xyz;
    }
    return emission;
}
