// Pinhole camera (mirror: src/cpu/camera.rs). Pixel row 0 is the top of the image;
// `jitter` in [0,1)^2 places the sample uniformly inside the pixel square.

fn camera_ray(px: u32, py: u32, jitter: vec2<f32>) -> Ray {
    let ndc_x = (f32(px) + jitter.x) / f32(params.width) * 2.0 - 1.0;
    let ndc_y = 1.0 - (f32(py) + jitter.y) / f32(params.height) * 2.0;
    let dir = normalize(params.forward + ndc_x * params.right + ndc_y * params.up);
    return Ray(params.eye, dir);
}
