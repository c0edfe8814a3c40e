// Path tracing kernel (mirror: src/cpu/trace.rs): one invocation per pixel adds
// params.sample_count samples, starting at global sample index params.sample_start.

fn trace_path(pixel: u32, px: u32, py: u32, sample: u32) -> vec3<f32> {
    var camera_rng = rng_init(pixel, sample, 0u, params.seed);
    let jitter = vec2<f32>(rng_next(&camera_rng), rng_next(&camera_rng));
    var ray = camera_ray(px, py, jitter);
    var throughput = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    // max_bounces counts scattering events; the loop bound also caps a corrupt value.
    for (var bounce = 0u; bounce <= params.max_bounces; bounce++) {
        let hit = intersect_scene(ray);
        if hit.t == NO_HIT {
            radiance += throughput * params.background;
            break;
        }
        let m = materials[hit.material];
        radiance += throughput * m.emission;
        if bounce == params.max_bounces {
            break;
        }
        var rng = rng_init(pixel, sample, bounce + 1u, params.seed);
        let s = scatter(m, ray.dir, hit.normal, &rng);
        throughput *= s.weight;
        if all(throughput == vec3<f32>(0.0)) {
            break;
        }
        let p = ray.origin + hit.t * ray.dir;
        // Leave on the side the new direction goes to.
        let side = select(-hit.normal, hit.normal, dot(s.dir, hit.normal) >= 0.0);
        ray = Ray(offset_ray_origin(p, side), s.dir);
    }
    return radiance;
}

@compute @workgroup_size(8, 8, 1)
fn render(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    // Welford over this batch's samples...
    var mean = vec3<f32>(0.0);
    var m2 = vec3<f32>(0.0);
    for (var i = 0u; i < params.sample_count; i++) {
        let x = trace_path(pixel, id.x, id.y, params.sample_start + i);
        let delta = x - mean;
        mean += delta / f32(i + 1u);
        m2 += delta * (x - mean);
    }
    // ...then merged into the totals (Chan, Golub and LeVeque's pairwise update).
    let n_old = f32(params.sample_start);
    let n_new = f32(params.sample_count);
    let n = n_old + n_new;
    let old_mean = accum_mean[pixel].xyz;
    let delta = mean - old_mean;
    accum_mean[pixel] = vec4<f32>(old_mean + delta * (n_new / n), 0.0);
    accum_m2[pixel] = vec4<f32>(accum_m2[pixel].xyz + m2 + delta * delta * (n_old * n_new / n), 0.0);
}
