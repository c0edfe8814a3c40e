// Points on surfaces, with a bound on their rounding error, and where the rays leaving them
// start (mirror: src/cpu/geometry/surface.rs).
//
// A hit point computed as origin + t * dir carries an error proportional to |origin| and t,
// which can be far larger than the point's own coordinates (a floor at y = 0 seen from 5000
// units away). So hit points are put back on their surface, from the surface's own
// description: spheres as center + radius * normal, quads (and triangles) as
// corner + a * u + b * v. Their error then depends on the surface's numbers only, and a new ray
// starts beyond it along the normal (after pbrt-v4's OffsetRayOrigin: Pharr, Jakob and
// Humphreys, Physically Based Rendering, 4th edition, section 6.8.6).

struct SurfacePoint {
    position: vec3<f32>,
    // Bound on the rounding error of `position`, per coordinate.
    error: vec3<f32>,
}

// Error bound per unit of the magnitudes summed to make a point: 2^-18, 32 ulps. A few ulps
// is the error of the point itself; the rest covers the next intersection test's own rounding
// (the plane's offset, the sphere's centre minus the ray origin), so that a ray leaving from
// the offset origin never finds the surface it leaves.
const SURFACE_ERROR_SCALE: f32 = 3.81469727e-6;

// The point corner + a * u + b * v of a quad (a, b in [0, 1]) or a triangle (u and v its
// edges from the corner, a and b barycentrics): on the plane, whatever the error of a and b.
fn parametric_point(corner: vec3<f32>, u: vec3<f32>, v: vec3<f32>, a: f32, b: f32) -> SurfacePoint {
    let au = a * u;
    let bv = b * v;
    let error = SURFACE_ERROR_SCALE * (abs(corner) + abs(au) + abs(bv));
    return SurfacePoint(corner + au + bv, error);
}

// The point of a sphere in the unit direction `outward` from its centre.
fn sphere_point(center: vec3<f32>, radius: f32, outward: vec3<f32>) -> SurfacePoint {
    let error = SURFACE_ERROR_SCALE * (abs(center) + vec3<f32>(radius));
    return SurfacePoint(center + radius * outward, error);
}

// Moves a surface point off its surface along the unit vector n (to the side a new ray
// leaves by) beyond its rounding error, so the next ray cannot hit the surface it leaves.
fn offset_ray_origin(p: vec3<f32>, error: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return p + dot(abs(n), error) * n;
}
