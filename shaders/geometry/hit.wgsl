// What a ray meets (mirror: src/cpu/geometry/hit.rs): a hit and the nearest primitive, the
// closest-hit rule every traversal keeps, and the sphere and quad tests. Ray directions are unit
// length.

const NO_HIT: f32 = 3.402823e38;

struct Hit {
    t: f32,
    // The hit point, put back on the surface (surface.wgsl), so errors cannot build up over
    // many bounces, and a bound on its rounding error per coordinate.
    position: vec3<f32>,
    error: vec3<f32>,
    // Geometric normal, unit length, facing against the incoming ray. It alone decides which
    // side of the surface a ray is on (offsets, entering or leaving glass).
    normal: vec3<f32>,
    // The normal to shade with, on the geometric normal's side: interpolated vertex normals on
    // smooth triangles, the geometric normal elsewhere.
    shading_normal: vec3<f32>,
    material: u32,
    // True when the ray hit the side the surface's outward normal points to.
    front_face: bool,
    // Which primitive: PRIMITIVE_SPHERE, PRIMITIVE_QUAD or PRIMITIVE_TRIANGLE, and its index.
    primitive: u32,
    index: u32,
    // Texture coordinates, set 0 in xy and set 1 in zw (texture.wgsl's both_sets); computed
    // only when HAS_TEXTURES.
    uv: vec4<f32>,
    // A triangle hit's barycentrics (of v0, v1, v2), for its vertex tangents (normal_map.wgsl);
    // zero on other primitives.
    barycentrics: vec3<f32>,
}

// Nearest t > 0 of a sphere hit, or NO_HIT. The discriminant is r^2 - |oc - h d|^2 rather than
// h^2 - c, which cancels catastrophically for small spheres far from the ray origin.
fn hit_sphere(s: Sphere, ray: Ray) -> f32 {
    let oc = s.center - ray.origin;
    let h = dot(ray.dir, oc);
    let perp = oc - h * ray.dir;
    let r2 = s.radius * s.radius;
    let disc = r2 - dot(perp, perp);
    if disc < 0.0 {
        return NO_HIT;
    }
    let c = dot(oc, oc) - r2;
    // Roots of t^2 - 2 h t + c = 0 in the cancellation-free form: q and c / q.
    let q = h + select(-1.0, 1.0, h >= 0.0) * sqrt(disc);
    let t0 = min(q, c / q);
    let t1 = max(q, c / q);
    if t0 > 0.0 {
        return t0;
    }
    if t1 > 0.0 {
        return t1;
    }
    return NO_HIT;
}

// t of a quad hit, or NO_HIT: the plane, then 0 <= (u.w)/(u.u) <= 1 and 0 <= (v.w)/(v.v) <= 1
// for the offset w of the hit point from the corner.
fn hit_quad(q: Quad, ray: Ray) -> f32 {
    let denom = dot(q.normal, ray.dir);
    if abs(denom) < 1e-12 {
        return NO_HIT;
    }
    let t = (q.plane_offset - dot(q.normal, ray.origin)) / denom;
    if !(t > 0.0) {
        return NO_HIT;
    }
    let w = ray.origin + t * ray.dir - q.corner;
    let a = dot(q.u_dual, w);
    let b = dot(q.v_dual, w);
    if a < 0.0 || a > 1.0 || b < 0.0 || b > 1.0 {
        return NO_HIT;
    }
    return t;
}

// The nearest primitive a ray meets, without the hit's point, normal and material: all a
// shadow ray needs. (On lavapipe all code in the path loop costs time, taken or not.)
struct ClosestPrimitive {
    // NO_HIT when the ray meets nothing.
    t: f32,
    // PRIMITIVE_SPHERE, PRIMITIVE_QUAD or PRIMITIVE_TRIANGLE, and its index.
    primitive: u32,
    index: u32,
    // The instance a triangle was hit through (shaders/geometry/instance.wgsl), or NO_INSTANCE: index
    // is then the triangle's in the arrays, which hold it in the instance's coordinates.
    instance: u32,
}

// The closest-hit rule, the same for every traversal on every device so that any structure
// finds the same hit: the smallest t, and among equal t the lowest primitive reference,
// (kind << PRIMITIVE_KIND_SHIFT) | index, that is spheres first, then quads, then triangles,
// then instances, each by index; among an instance's own triangles at equal t, the lowest
// triangle index (shaders/traverse/blas.wgsl). Whether a hit at t on `reference` comes before the best so far.
fn hit_comes_first(t: f32, reference: u32, best_t: f32, best_reference: u32) -> bool {
    return t < best_t || (t == best_t && reference < best_reference);
}
