// Thin-lens camera (mirror: src/cpu/core/camera.rs); a pinhole when the lens radius is 0, or an
// orthographic camera (Params.projection).
// Pixel row 0 is the top of the image; `jitter` in [0,1)^2 places the sample uniformly inside
// the pixel square and `lens` in [0,1)^2 picks the point on the lens.

// Uniform point in the unit disk (polar mapping; r = sqrt(u) makes it uniform in area).
fn sample_unit_disk(u: vec2<f32>) -> vec2<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec2<f32>(r * cos(phi), r * sin(phi));
}

fn camera_ray(px: u32, py: u32, jitter: vec2<f32>, lens: vec2<f32>) -> Ray {
    let ndc_x = (f32(px) + jitter.x) / f32(params.width) * 2.0 - 1.0;
    let ndc_y = 1.0 - (f32(py) + jitter.y) / f32(params.height) * 2.0;
    if params.projection == PROJECTION_ORTHOGRAPHIC {
        // The jittered point on the image plane (through the eye, across the view; `right` and
        // `up` span half the view in world units), looking along the view direction. No lens:
        // `lens` goes unused.
        return Ray(params.eye + ndc_x * params.right + ndc_y * params.up, params.forward);
    }
    // `forward` is unit length, so this point lies on the focus plane.
    let through = params.forward + ndc_x * params.right + ndc_y * params.up;
    let disk = sample_unit_disk(lens);
    let offset = disk.x * params.lens_right + disk.y * params.lens_up;
    let dir = normalize(through * params.focus_distance - offset);
    return Ray(params.eye + offset, dir);
}
