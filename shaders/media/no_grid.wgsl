// Grid media compiled out (HAS_GRID_MEDIA false): in kernels of scenes whose media are all
// homogeneous, this stands in for media/grid.wgsl with what media/medium.wgsl and
// integrator/path_media.wgsl name. They call these only behind HAS_GRID_MEDIA.

fn grid_free_flight(m: Medium, ray: Ray, t_max: f32, rng: ptr<function, Rng>) -> FreeFlight {
    return FreeFlight(t_max, vec3<f32>(1.0), false);
}

fn grid_transmittance(m: Medium, ray: Ray, t_end: f32, rng: ptr<function, Rng>) -> vec3<f32> {
    return vec3<f32>(1.0);
}
