// Instances (mirror: src/cpu/geometry/instance.rs). A mesh placed many times keeps its triangles once,
// in its own coordinates, and each placement keeps its transforms (src/kernel/scene/acceleration.rs), so
// memory grows with unique geometry. A hit through an instance carries (instance, triangle);
// what shading reads of the triangle is put in the scene's coordinates here, so the code after
// intersection is the same for every triangle. Triangles placed as they are (NO_INSTANCE) are
// read unchanged, and HAS_INSTANCES compiles all of this out of scenes without instances.

// One per instance; one unused placeholder when the scene has none.
@group(0) @binding(40) var<storage, read> instances: array<Instance>;

// rows · (p, 1): a point through a 3×4 transform.
fn transform_point(rows: array<vec4<f32>, 3>, p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        dot(rows[0].xyz, p) + rows[0].w,
        dot(rows[1].xyz, p) + rows[1].w,
        dot(rows[2].xyz, p) + rows[2].w,
    );
}

// rows · (v, 0): a direction through a 3×4 transform's linear part.
fn transform_vector(rows: array<vec4<f32>, 3>, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(rows[0].xyz, v), dot(rows[1].xyz, v), dot(rows[2].xyz, v));
}

// The ray in the instance's own coordinates. The direction is not renormalised, so t is the
// same parameter along both rays and hits compare across instances by t.
fn object_ray(inst: Instance, ray: Ray) -> Ray {
    return Ray(transform_point(inst.to_object, ray.origin), transform_vector(inst.to_object, ray.dir));
}

// A normal in the scene's coordinates: through the inverse transpose of the instance's linear
// part, which is the transpose of to_object's, so no third matrix is stored.
fn normal_to_world(inst: Instance, n: vec3<f32>) -> vec3<f32> {
    let m = inst.to_object;
    return normalize(n.x * m[0].xyz + n.y * m[1].xyz + n.z * m[2].xyz);
}

// Triangle `index`, hit through `instance`, in the scene's coordinates.
fn scene_triangle(instance: u32, index: u32) -> Triangle {
    var tri = triangles[index];
    if HAS_INSTANCES && instance != NO_INSTANCE {
        let m = instances[instance].to_world;
        tri.v0 = transform_point(m, tri.v0);
        tri.v1 = transform_point(m, tri.v1);
        tri.v2 = transform_point(m, tri.v2);
    }
    return tri;
}

// Triangle `index`'s vertex normals, hit through `instance`, in the scene's coordinates.
fn scene_triangle_normals(instance: u32, index: u32) -> TriangleNormals {
    var n = triangle_normals[index];
    if HAS_INSTANCES && instance != NO_INSTANCE && n.smooth_shading != 0u {
        let inst = instances[instance];
        n.n0 = normal_to_world(inst, n.n0);
        n.n1 = normal_to_world(inst, n.n1);
        n.n2 = normal_to_world(inst, n.n2);
    }
    return n;
}

// `best`, or the closest hit on an instance's triangle if it comes before it, testing every
// triangle of every instance in the closest-hit rule's order (instances, then their triangles,
// by index) and keeping only strictly nearer hits: the scan's part for instances
// (scan_closest_primitive), which the two-level traversal must agree with.
fn scan_instances(ray: Ray, best: ClosestPrimitive) -> ClosestPrimitive {
    var out = best;
    for (var k = 0u; k < arrayLength(&instances); k++) {
        let inst = instances[k];
        let r = triangle_ray(object_ray(inst, ray));
        for (var i = inst.first_triangle; i < inst.first_triangle + inst.triangle_count; i++) {
            let t = hit_scene_triangle(i, r);
            if t < out.t {
                out = ClosestPrimitive(t, PRIMITIVE_TRIANGLE, i, k);
            }
        }
    }
    return out;
}
