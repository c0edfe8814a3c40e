// Triangles (mirror: src/cpu/geometry/triangle.rs): watertight intersection and area sampling.
//
// Intersection is Woop, Benthin and Wald's "Watertight Ray/Triangle Intersection" (JCGT 2013):
// the ray is made the +z axis of a sheared frame, and each edge's 2D edge function is computed
// from the same two vertices, in the same order, by whichever triangle shares the edge. A ray
// through a shared edge or vertex therefore sees it inside (or on the edge of) at least one of
// the triangles, never outside both.

// A ray prepared once for all the triangles it is tested against.
struct TriangleRay {
    origin: vec3<f32>,
    // The axis the direction is largest along (z of the sheared frame), and the other two, in
    // the order that keeps the frame's winding.
    kx: u32,
    ky: u32,
    kz: u32,
    // The shear that maps the direction to (0, 0, 1): (dx/dz, dy/dz, 1/dz).
    shear: vec3<f32>,
}

fn triangle_ray(ray: Ray) -> TriangleRay {
    let a = abs(ray.dir);
    var kz = 2u;
    if a.x > a.y && a.x > a.z {
        kz = 0u;
    } else if a.y > a.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if ray.dir[kz] < 0.0 {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let dz = ray.dir[kz];
    return TriangleRay(ray.origin, kx, ky, kz, vec3<f32>(ray.dir[kx] / dz, ray.dir[ky] / dz, 1.0 / dz));
}

// The scaled edge functions (u, v, w: the weights of v0, v1, v2, not yet divided by their sum)
// and the scaled distance, of a ray against a triangle.
struct TriangleEdges {
    u: f32,
    v: f32,
    w: f32,
    t_scaled: f32,
}

fn triangle_edges(tri: Triangle, r: TriangleRay) -> TriangleEdges {
    let a = tri.v0 - r.origin;
    let b = tri.v1 - r.origin;
    let c = tri.v2 - r.origin;
    let ax = a[r.kx] - r.shear.x * a[r.kz];
    let ay = a[r.ky] - r.shear.y * a[r.kz];
    let bx = b[r.kx] - r.shear.x * b[r.kz];
    let by = b[r.ky] - r.shear.y * b[r.kz];
    let cx = c[r.kx] - r.shear.x * c[r.kz];
    let cy = c[r.ky] - r.shear.y * c[r.kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let t_scaled = u * (r.shear.z * a[r.kz]) + v * (r.shear.z * b[r.kz]) + w * (r.shear.z * c[r.kz]);
    return TriangleEdges(u, v, w, t_scaled);
}

// t > 0 of a hit from either side, or NO_HIT. Points on an edge count as inside.
fn hit_triangle(tri: Triangle, r: TriangleRay) -> f32 {
    let e = triangle_edges(tri, r);
    if (e.u < 0.0 || e.v < 0.0 || e.w < 0.0) && (e.u > 0.0 || e.v > 0.0 || e.w > 0.0) {
        return NO_HIT;
    }
    let det = e.u + e.v + e.w;
    if det == 0.0 {
        return NO_HIT;
    }
    let t = e.t_scaled / det;
    if !(t > 0.0) {
        return NO_HIT;
    }
    return t;
}

// Barycentric weights of v0, v1, v2 where the ray meets the triangle (it must hit it).
fn triangle_barycentrics(tri: Triangle, r: TriangleRay) -> vec3<f32> {
    let e = triangle_edges(tri, r);
    return vec3<f32>(e.u, e.v, e.w) / (e.u + e.v + e.w);
}

// The point with barycentric weights b (of v0, v1, v2), on the triangle's plane, with its
// rounding error (surface.wgsl): v0 + b.y e1 + b.z e2, with the same edges as triangle_normal.
// The watertight test shears the axes into one another, so its rounding along any axis
// depends on every coordinate: the bound is the largest of the three, in every axis (else a
// wall in the plane x = 0 would get no offset along x at all, and its rays would hit it again).
fn triangle_surface_point(tri: Triangle, b: vec3<f32>) -> SurfacePoint {
    let point = parametric_point(tri.v0, tri.v1 - tri.v0, tri.v2 - tri.v0, b.y, b.z);
    let e = point.error;
    return SurfacePoint(point.position, vec3<f32>(max(e.x, max(e.y, e.z))));
}

fn triangle_normal(tri: Triangle) -> vec3<f32> {
    return normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
}

// The barycentrics (of v0, v1, v2) of a point uniform on a triangle's area, from two uniform
// numbers (the square-root warp).
fn triangle_sample_barycentrics(u: vec2<f32>) -> vec3<f32> {
    let su = sqrt(u.x);
    let b0 = 1.0 - su;
    let b1 = u.y * su;
    return vec3<f32>(b0, b1, 1.0 - b0 - b1);
}

// The point of the triangle at barycentrics b.
fn triangle_point(tri: Triangle, b: vec3<f32>) -> vec3<f32> {
    return b.x * tri.v0 + b.y * tri.v1 + b.z * tri.v2;
}

// Distance along a unit direction from p to the triangle's plane (negative or NaN: none ahead).
fn triangle_plane_distance(tri: Triangle, normal: vec3<f32>, p: vec3<f32>, dir: vec3<f32>) -> f32 {
    return dot(normal, tri.v0 - p) / dot(normal, dir);
}
