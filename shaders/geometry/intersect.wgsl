// Ray-scene intersection (mirror: src/cpu/geometry/intersect.rs): the closest primitive, shadow
// rays' tests and the full hit, through whichever structure the host compiled in, built on
// hit.wgsl's tests. Ray directions are unit length.

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

// Whether nothing lies along `ray` before distance t_max (a shadow ray to a point).
fn unoccluded_before(ray: Ray, t_max: f32) -> bool {
    if USE_BVH {
        // Any hit nearer than t_max ends the search (a target no primitive matches).
        return bvh_traverse(bvh_ray(ray), t_max, t_max, 0u, PRIMITIVE_ENVIRONMENT << PRIMITIVE_KIND_SHIFT).t == NO_HIT;
    }
    return closest_primitive(ray).t >= t_max;
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
