// The path tracer's steps in participating media (mirror: src/cpu/integrator/path_media.rs):
// a segment's free flight, scattering at a medium vertex, crossing an interface.

// The path's ray travels through its medium towards a surface at t_hit (NO_HIT: none).
fn free_flight(path: ptr<function, PathState>, t_hit: f32, pixel: u32, sample: u32) -> FreeFlight {
    let slot = current_medium((*path).media);
    if slot == NO_MEDIUM {
        return FreeFlight(t_hit, vec3<f32>(1.0), false);
    }
    var rng = rng_stream(pixel, sample, stream_id((*path).bounce, PURPOSE_FREE_FLIGHT), params.seed, params.sampler);
    let flight = sample_flight(slot, (*path).ray, t_hit, &rng);
    (*path).throughput *= flight.weight;
    return flight;
}

// A scattering event at `position` in the path's medium: light sampling through the media
// weighted against phase sampling, then phase sampling and Russian roulette; true when the
// path ends here.
fn medium_vertex(path: ptr<function, PathState>, position: vec3<f32>, light_sampling: bool, pixel: u32, sample: u32) -> bool {
    let bounce = (*path).bounce;
    if scatterings(*path) >= params.max_bounces {
        return true;
    }
    let g = params.media[current_medium((*path).media)].g;
    let d = (*path).ray.dir;
    if light_sampling {
        var light_rng = rng_stream(pixel, sample, stream_id(bounce, PURPOSE_MEDIUM_LIGHT), params.seed, params.sampler);
        let light = sample_light(position, position, &light_rng);
        if light.pdf > 0.0 {
            let phase = hg_phase(g, dot(d, light.dir));
            segments += 1u;
            if HAS_ALPHA {
                alpha_key = alpha_segment_key(pixel, sample, bounce + 1u);
            }
            let through = shadow_transmittance(Ray(position, light.dir), light, (*path).media, pixel, sample, bounce);
            if any(through > vec3<f32>(0.0)) {
                let weight = nee_weight(light, phase);
                let contribution = (*path).throughput * through * light.radiance * (phase * weight / light.pdf);
                (*path).radiance += firefly_clamp(contribution, scatterings(*path) + 1u);
            }
        }
    }
    var phase_rng = rng_stream(pixel, sample, stream_id(bounce, PURPOSE_PHASE), params.seed, params.sampler);
    let u1 = rng_next(&phase_rng);
    let u2 = rng_next(&phase_rng);
    let dir = sample_hg(g, d, u1, u2);
    let pdf = hg_phase(g, dot(d, dir));
    var throughput = (*path).throughput;
    if scatterings(*path) >= params.roulette_start {
        var roulette_rng = rng_stream(pixel, sample, stream_id(bounce, PURPOSE_ROULETTE), params.seed, params.sampler);
        let q = min(max(throughput.x, max(throughput.y, throughput.z)), 0.95);
        if rng_next(&roulette_rng) >= q {
            return true;
        }
        throughput /= q;
    }
    (*path).throughput = throughput;
    (*path).came_from_delta = false;
    (*path).bsdf_pdf_of_ray = pdf;
    (*path).ray = Ray(position, dir);
    (*path).ray_start = position;
    (*path).bounce = bounce + 1u;
    return false;
}

// Straight through an interface: no scattering event, so the previous vertex's pdf, origin
// and delta flag stay for MIS; not counted against max_bounces, but the path ends at
// segment_limit segments.
fn cross_interface(path: ptr<function, PathState>, hit: Hit) -> bool {
    if (*path).bounce + 1u >= segment_limit(params.max_bounces + 2u) {
        return true;
    }
    (*path).media = medium_crossed((*path).media, hit.material, hit.front_face);
    (*path).ray = Ray(offset_ray_origin(hit.position, hit.error, -hit.normal), (*path).ray.dir);
    (*path).bounce += 1u;
    (*path).crossings += 1u;
    return false;
}
