// Ray-scene intersection (mirror: src/cpu/geometry/intersect.rs). Ray directions are unit length.

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

// The structure is the host's choice, compiled in: ray queries (USE_RAY_QUERY,
// shaders/traverse/hardware.wgsl), the BVH (USE_BVH, shaders/traverse/bvh.wgsl), or the scan.
fn closest_primitive(ray: Ray) -> ClosestPrimitive {
    if USE_RAY_QUERY {
        return hardware_closest_primitive(ray);
    }
    if USE_BVH {
        return bvh_closest_primitive(ray);
    }
    return scan_closest_primitive(ray);
}

// The closest primitive by testing every one (every instance's every triangle too, after the
// triangles placed as they are: triangle_count() counts those): the structure without a BVH,
// and what every other traversal must agree with. It visits primitives in the closest-hit rule's order
// (hit_comes_first) and keeps only strictly nearer hits, so among equal t the first, the lowest
// reference, wins.
fn scan_closest_primitive(ray: Ray) -> ClosestPrimitive {
    var best = ClosestPrimitive(NO_HIT, PRIMITIVE_QUAD, 0u, NO_INSTANCE);
    for (var i = 0u; i < sphere_count(); i++) {
        let t = hit_sphere(spheres[i], ray);
        if t < best.t {
            best = ClosestPrimitive(t, PRIMITIVE_SPHERE, i, NO_INSTANCE);
        }
    }
    for (var i = 0u; i < quad_count(); i++) {
        let t = hit_quad(quads[i], ray);
        if t < best.t {
            best = ClosestPrimitive(t, PRIMITIVE_QUAD, i, NO_INSTANCE);
        }
    }
    if HAS_TRIANGLES && triangle_count() > 0u {
        let r = triangle_ray(ray);
        for (var i = 0u; i < triangle_count(); i++) {
            let t = hit_scene_triangle(i, r);
            if t < best.t {
                best = ClosestPrimitive(t, PRIMITIVE_TRIANGLE, i, NO_INSTANCE);
            }
        }
    }
    if HAS_INSTANCES {
        best = scan_instances(ray, best);
    }
    return best;
}

// Whether the first thing `ray` meets is the primitive (primitive, index).
fn first_hit_is(ray: Ray, primitive: u32, index: u32) -> bool {
    if HAS_ENVIRONMENT && primitive == PRIMITIVE_ENVIRONMENT {
        return escapes(ray);
    }
    if USE_RAY_QUERY {
        return hardware_first_hit_is(ray, primitive, index);
    }
    if USE_BVH {
        return bvh_first_hit_is(ray, primitive, index);
    }
    let closest = closest_primitive(ray);
    // A target is placed as it is: a light never goes through an instance.
    return closest.t != NO_HIT && closest.primitive == primitive && closest.index == index && closest.instance == NO_INSTANCE;
}

// Whether ray leaves the scene without hitting anything (it then sees the environment).
fn escapes(ray: Ray) -> bool {
    if USE_RAY_QUERY {
        return hardware_escapes(ray);
    }
    if USE_BVH {
        return bvh_escapes(ray);
    }
    return closest_primitive(ray).t == NO_HIT;
}

fn intersect_scene(ray: Ray) -> Hit {
    let closest = closest_primitive(ray);
    var hit: Hit;
    hit.t = closest.t;
    if closest.t == NO_HIT {
        return hit;
    }
    hit.primitive = closest.primitive;
    hit.index = closest.index;
    var outward: vec3<f32>;
    // Zero: shade with the geometric normal.
    var shading = vec3<f32>(0.0);
    if closest.primitive == PRIMITIVE_SPHERE {
        let s = spheres[closest.index];
        // Normalised, not divided by the radius: a normal a little too long would make
        // reflected directions too long, and the error would grow with every bounce.
        outward = normalize(ray.origin + closest.t * ray.dir - s.center);
        let surface = sphere_point(s.center, s.radius, outward);
        hit.position = surface.position;
        hit.error = surface.error;
        hit.material = s.material;
        if HAS_TEXTURES {
            hit.uv = both_sets(sphere_uv(outward));
        }
    } else if HAS_TRIANGLES && closest.primitive == PRIMITIVE_TRIANGLE {
        let tri = scene_triangle(closest.instance, closest.index);
        let b = triangle_barycentrics(tri, triangle_ray(ray));
        hit.barycentrics = b;
        outward = triangle_normal(tri);
        // On the triangle's plane: v0 + b1 e1 + b2 e2, from the edges the normal is made of.
        let surface = triangle_surface_point(tri, b);
        hit.position = surface.position;
        hit.error = surface.error;
        hit.material = tri.material;
        if HAS_TEXTURES {
            hit.uv = triangle_uv(closest.index, b);
        }
        let n = scene_triangle_normals(closest.instance, closest.index);
        if n.smooth_shading != 0u {
            shading = normalize(b.x * n.n0 + b.y * n.n1 + b.z * n.n2);
        }
    } else {
        let q = quads[closest.index];
        outward = q.normal;
        // On the plane through corner, edge_u and edge_v: the hit test's a and b, clamped.
        let w = ray.origin + closest.t * ray.dir - q.corner;
        let a = clamp(dot(q.u_dual, w), 0.0, 1.0);
        let b = clamp(dot(q.v_dual, w), 0.0, 1.0);
        let surface = parametric_point(q.corner, q.edge_u, q.edge_v, a, b);
        hit.position = surface.position;
        hit.error = surface.error;
        hit.material = q.material;
        if HAS_TEXTURES {
            hit.uv = both_sets(vec2<f32>(a, b));
        }
    }
    hit.front_face = dot(outward, ray.dir) < 0.0;
    hit.normal = select(-outward, outward, hit.front_face);
    hit.shading_normal = hit.normal;
    if HAS_TRIANGLES && any(shading != vec3<f32>(0.0)) {
        let facing = select(-shading, shading, dot(shading, hit.normal) >= 0.0);
        hit.shading_normal = valid_shading_normal(hit.normal, -ray.dir, facing);
    }
    return hit;
}

// Whether `dir` is on one side of the surface by the shading normal and on the other by the
// geometric normal: following it would leak light through a smooth-shaded surface, so such
// directions carry nothing. Never true where the shading normal is the geometric one.
fn crosses_shading_side(dir: vec3<f32>, hit: Hit) -> bool {
    return HAS_TRIANGLES && dot(dir, hit.normal) * dot(dir, hit.shading_normal) < 0.0;
}
