// Light sampling for next-event estimation (mirror: src/cpu/lights/sampling.rs). An emitter is chosen
// in proportion to its power, or by the light tree where the scene has one (light_tree.wgsl),
// then a direction towards it: quads and triangles by area, spheres by the cone
// of directions they subtend from outside, and by area from inside (where there is no cone), the
// environment map by luminance (environment.wgsl), point, spot and directional lights in
// punctual.wgsl.
// All pdfs are per unit solid angle at the shading point and include the selection probability.

// The emitter light sampling chose: which primitive, and the probability of choosing it.
struct EmitterChoice {
    primitive: u32,
    index: u32,
    probability: f32,
}

// Selection in proportion to power, in O(1) by the alias table (src/kernel/scene/emitter_table.rs): u picks
// the slot, u_alias its emitter or the alias. The slot is floor(u * n) in f32 on both devices
// (a correctly rounded product, then truncation), so both pick the same emitter.
fn pick_emitter(u: f32, u_alias: f32) -> EmitterChoice {
    let n = emitter_count();
    let slot = emitters[min(u32(u * f32(n)), n - 1u)];
    if u_alias < slot.alias_threshold {
        return EmitterChoice(slot.primitive, slot.index, slot.probability);
    }
    return EmitterChoice(slot.alias_primitive, slot.alias_index, slot.alias_probability);
}

// The light tree's choice in place of the alias table's `e` (picked with u_slot): where every
// emitter is finite, the tree picks with u_slot itself; otherwise the alias table's choice
// between the infinite lights (kept as it is) and the finite ones stands, and the tree picks
// among those with one more number. Probability 0 where no finite emitter can light p.
fn tree_choice(p: vec3<f32>, u_slot: f32, e: EmitterChoice, rng: ptr<function, Rng>) -> EmitterChoice {
    var u = u_slot;
    if params.light_tree_probability < 1.0 {
        var infinite = emitter_is_environment(e.primitive);
        if emitter_is_light(e.primitive) {
            infinite = lights[e.index].kind == LIGHT_SUN;
        }
        if infinite {
            return e;
        }
        u = rng_next(rng);
    }
    let c = light_tree_pick(p, u);
    return EmitterChoice(c.primitive, c.index, params.light_tree_probability * c.probability);
}

// The probability that next-event estimation at p picks the emitting sphere, quad or triangle
// (primitive, index), whose probability by power is by_power.
fn selection_probability(p: vec3<f32>, primitive: u32, index: u32, by_power: f32) -> f32 {
    if light_tree_active() {
        return light_tree_selection_probability(p, primitive, index);
    }
    return by_power;
}

// Whether an emitter is a point, spot or directional light (punctual.wgsl); checked first.
fn emitter_is_light(primitive: u32) -> bool {
    return HAS_LIGHTS && primitive == PRIMITIVE_LIGHT;
}

// Whether an emitter is the environment map; checked before the others, whose tests assume
// a primitive.
fn emitter_is_environment(primitive: u32) -> bool {
    return HAS_ENVIRONMENT && primitive == PRIMITIVE_ENVIRONMENT;
}

// Whether an emitter is a triangle; known at compile time when the scene has no triangle
// emitters, or only those.
fn emitter_is_triangle(primitive: u32) -> bool {
    if !HAS_TRIANGLE_EMITTERS {
        return false;
    }
    if !HAS_SPHERE_EMITTERS && !HAS_QUAD_EMITTERS {
        return true;
    }
    return primitive == PRIMITIVE_TRIANGLE;
}

// Whether an emitter that is not a triangle is a quad; known at compile time when the scene's emitters are all quads
// or all spheres, and then the other kind's code is compiled out (see src/kernel/variant.rs).
fn emitter_is_quad(primitive: u32) -> bool {
    if !HAS_SPHERE_EMITTERS {
        return true;
    }
    if !HAS_QUAD_EMITTERS {
        return false;
    }
    return primitive == PRIMITIVE_QUAD;
}

fn sphere_contains(s: Sphere, p: vec3<f32>) -> bool {
    let d = p - s.center;
    return dot(d, d) < s.radius * s.radius;
}

// 1 - cos(theta_max) of the cone a sphere subtends from outside, without cancellation for
// small, distant spheres: sin^2 / (1 + cos).
fn cone_one_minus_cos(s: Sphere, p: vec3<f32>) -> f32 {
    let d = s.center - p;
    let sin2 = min(s.radius * s.radius / dot(d, d), 1.0);
    return sin2 / (1.0 + sqrt(1.0 - sin2));
}

// Leaving a point p inside (or on) a sphere along a unit direction: the distance t to the
// sphere and the cosine there, from the chord's geometry. With h = dir . (center - p), the
// exit is at t = h + sqrt(h^2 + r^2 - |center - p|^2) and the cosine is that square root / r.
// Keeping r^2 - |center - p|^2 apart (clamped at 0, for p on the surface) stays accurate for
// nearly tangent directions, where h is tiny.
struct Chord {
    t: f32,
    cos_exit: f32,
}

fn sphere_chord(s: Sphere, p: vec3<f32>, dir: vec3<f32>) -> Chord {
    let oc = s.center - p;
    let h = dot(dir, oc);
    let root = sqrt(h * h + max(0.0, s.radius * s.radius - dot(oc, oc)));
    return Chord(h + root, root / s.radius);
}

// Solid-angle pdf of area sampling: distance^2 / (|cos| at the light * area).
fn area_to_solid_angle(t: f32, cos_light: f32, area: f32) -> f32 {
    return t * t / (max(abs(cos_light), 1e-12) * area);
}

// Every pdf here is evaluated at the shading point `p` itself, the same way for a light sample
// and for a BSDF-sampled ray, so the two strategies' MIS weights match. `probe` is `p` moved
// off the surface to the side light arrives from: it decides whether p is inside a sphere
// (a point on the sphere itself is ambiguous) and starts the shadow ray.
fn sample_light(p: vec3<f32>, probe: vec3<f32>, rng: ptr<function, Rng>) -> LightSample {
    var out: LightSample;
    out.pdf = 0.0;
    if emitter_count() == 0u {
        return out;
    }
    let u_slot = rng_next(rng);
    let u_alias = rng_next(rng);
    var e = pick_emitter(u_slot, u_alias);
    let u = vec2<f32>(rng_next(rng), rng_next(rng));
    if light_tree_active() {
        e = tree_choice(p, u_slot, e, rng);
        if !(e.probability > 0.0) {
            return out;
        }
    }
    out.primitive = e.primitive;
    out.index = e.index;
    out.is_delta = false;
    if emitter_is_light(e.primitive) {
        return sample_punctual(e.index, e.probability, p, u);
    }
    if emitter_is_environment(e.primitive) {
        let s = sample_environment(u, rng);
        out.dir = s.dir;
        out.pdf = e.probability * s.pdf;
        out.radiance = s.radiance;
        return out;
    }
    if emitter_is_triangle(e.primitive) {
        // Uniform on the triangle's area.
        let tri = triangles[e.index];
        let b = triangle_sample_barycentrics(u);
        let to_light = triangle_point(tri, b) - p;
        let t = length(to_light);
        if t <= 0.0 {
            return out;
        }
        out.dir = to_light / t;
        out.pdf = e.probability * area_to_solid_angle(t, dot(triangle_normal(tri), out.dir), tri.area);
        // The emission where the sample lies (glTF's emissive texture).
        let m = materials[tri.material];
        out.radiance = m.emission;
        if HAS_TEXTURES && m.emission_texture != NO_TEXTURE {
            out.radiance = emission_at(m, triangle_uv(e.index, b));
        }
        out.radiance = vertex_colored_emission(m, e.index, b, out.radiance);
        return out;
    }
    if emitter_is_quad(e.primitive) {
        let q = quads[e.index];
        let to_light = q.corner + u.x * q.edge_u + u.y * q.edge_v - p;
        let t = length(to_light);
        if t <= 0.0 {
            return out;
        }
        out.dir = to_light / t;
        out.pdf = e.probability * area_to_solid_angle(t, dot(q.normal, out.dir), q.area);
        out.radiance = materials[q.material].emission;
        return out;
    }
    let s = spheres[e.index];
    out.radiance = materials[s.material].emission;
    if sphere_contains(s, probe) {
        // Uniform on the sphere's area; from inside, every direction meets it exactly once.
        let z = 1.0 - 2.0 * u.x;
        let r = sqrt(max(0.0, 1.0 - z * z));
        let phi = 2.0 * PI * u.y;
        let normal = vec3<f32>(r * cos(phi), r * sin(phi), z);
        let to_light = s.center + s.radius * normal - p;
        let distance = length(to_light);
        if distance <= 0.0 {
            return out;
        }
        out.dir = to_light / distance;
        // The same formula as light_pdf, so both strategies agree on this direction's pdf.
        let chord = sphere_chord(s, p, out.dir);
        out.pdf = e.probability * area_to_solid_angle(chord.t, chord.cos_exit, 4.0 * PI * s.radius * s.radius);
        return out;
    }
    // Uniform in the cone of directions towards the sphere.
    let axis = normalize(s.center - p);
    let one_minus_cos_max = cone_one_minus_cos(s, p);
    let one_minus_cos = u.x * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    let sin_theta = sqrt(max(0.0, one_minus_cos * (2.0 - one_minus_cos)));
    let phi = 2.0 * PI * u.y;
    out.dir = normalize(sin_theta * cos(phi) * basis_tangent(axis) + sin_theta * sin(phi) * basis_bitangent(axis) + cos_theta * axis);
    out.pdf = e.probability / (2.0 * PI * one_minus_cos_max);
    return out;
}

// The pdf with which sample_light(p, probe) would have produced `dir`, a direction that meets
// the emitting primitive (primitive, index).
fn light_pdf(p: vec3<f32>, probe: vec3<f32>, dir: vec3<f32>, primitive: u32, index: u32) -> f32 {
    if emitter_is_environment(primitive) {
        return params.environment_light_probability * environment_pdf(dir);
    }
    if emitter_is_triangle(primitive) {
        let tri = triangles[index];
        let normal = triangle_normal(tri);
        let t = triangle_plane_distance(tri, normal, p, dir);
        if !(t > 0.0) {
            return 0.0;
        }
        let chosen = selection_probability(p, primitive, index, tri.light_probability);
        return chosen * area_to_solid_angle(t, dot(normal, dir), tri.area);
    }
    if emitter_is_quad(primitive) {
        let q = quads[index];
        let cos_light = dot(q.normal, dir);
        let t = (q.plane_offset - dot(q.normal, p)) / cos_light;
        if !(t > 0.0) {
            return 0.0;
        }
        let chosen = selection_probability(p, primitive, index, q.light_probability);
        return chosen * area_to_solid_angle(t, cos_light, q.area);
    }
    let s = spheres[index];
    let chosen = selection_probability(p, primitive, index, s.light_probability);
    if sphere_contains(s, probe) {
        let chord = sphere_chord(s, p, dir);
        if !(chord.t > 0.0) {
            return 0.0;
        }
        return chosen * area_to_solid_angle(chord.t, chord.cos_exit, 4.0 * PI * s.radius * s.radius);
    }
    return chosen / (2.0 * PI * cone_one_minus_cos(s, p));
}

// Whether a shadow ray along a light sample reaches the light it sampled.
fn light_visible(shadow: Ray, light: LightSample) -> bool {
    if emitter_is_light(light.primitive) {
        return punctual_visible(shadow, light);
    }
    return first_hit_is(shadow, light.primitive, light.index);
}
