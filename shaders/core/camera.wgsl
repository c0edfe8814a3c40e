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

// The film's area: on the plane at unit distance (perspective) or in world units
// (orthographic). `right` and `up` span half of it each.
fn film_area() -> f32 {
    return 4.0 * length(params.right) * length(params.up);
}

// The solid-angle density with which a camera ray, through a point of the film uniform over
// the whole image, leaves a point of a perspective camera's lens along `dir`: 1 / (A cos^3),
// A the film's area at unit distance, the angle to `forward`; 0 behind the camera.
// Bidirectional path tracing compares its strategies with it (and weights light tracing's
// splats by it).
fn camera_direction_pdf(dir: vec3<f32>) -> f32 {
    let cos_theta = dot(dir, params.forward);
    if cos_theta <= 0.0 {
        return 0.0;
    }
    return 1.0 / (film_area() * cos_theta * cos_theta * cos_theta);
}

// A point seen through the camera: the lens point it is seen from, the unit direction to it
// from there, the pixel it lands in, and the density of that direction
// (camera_direction_pdf). `visible` is false when the point is behind the camera or outside
// the image.
struct CameraView {
    lens_point: vec3<f32>,
    dir: vec3<f32>,
    distance: f32,
    pixel_x: u32,
    pixel_y: u32,
    pdf_direction: f32,
    visible: bool,
}

// Where a perspective camera sees `point` from the lens point at `lens` (uniform numbers, as
// camera_ray takes them): the inverse of camera_ray. The ray from the lens point through the
// point meets the focus plane where the pinhole ray of the same film position does.
fn camera_view(point: vec3<f32>, lens: vec2<f32>) -> CameraView {
    let disk = sample_unit_disk(lens);
    let offset = disk.x * params.lens_right + disk.y * params.lens_up;
    let lens_point = params.eye + offset;
    let to_point = point - lens_point;
    let distance = length(to_point);
    var view = CameraView(lens_point, vec3<f32>(0.0, 0.0, 1.0), distance, 0u, 0u, 0.0, false);
    if distance <= 0.0 {
        return view;
    }
    view.dir = to_point / distance;
    let cos_theta = dot(view.dir, params.forward);
    if cos_theta <= 0.0 {
        return view;
    }
    // The film position: (focus-plane point - eye) / focus distance = forward + x right + y up.
    let through = (offset + view.dir * (params.focus_distance / cos_theta)) / params.focus_distance;
    let ndc_x = dot(through, params.right) / dot(params.right, params.right);
    let ndc_y = dot(through, params.up) / dot(params.up, params.up);
    let fx = (ndc_x + 1.0) * 0.5 * f32(params.width);
    let fy = (1.0 - ndc_y) * 0.5 * f32(params.height);
    if !(fx >= 0.0 && fx < f32(params.width) && fy >= 0.0 && fy < f32(params.height)) {
        return view;
    }
    view.pixel_x = min(u32(fx), params.width - 1u);
    view.pixel_y = min(u32(fy), params.height - 1u);
    view.pdf_direction = camera_direction_pdf(view.dir);
    view.visible = true;
    return view;
}
