// Picking a finite emitter with the light tree (mirror: src/cpu/lights/light_tree.rs; the host
// builds it in src/kernel/scene/light_tree.rs): from the root, each child in proportion to
// pbrt-v4's bound on what its emitters send to the shading point, to a leaf; the product of
// those choices is the emitter's probability. light_tree_pmf follows an emitter's stored trail
// down the same nodes with the same arithmetic, so MIS reads the very probability the pick had.
// Only in kernels of scenes with a tree (HAS_LIGHT_TREE); lights/no_light_tree.wgsl stands in
// elsewhere.

@group(0) @binding(48) var<storage, read> light_tree_nodes: array<LightTreeNode>;
// Each emitting sphere's, quad's and triangle's path to its leaf (bit k: the second child at
// depth k), low and high 32 bits.
@group(0) @binding(49) var<storage, read> light_tree_trails: array<vec2<u32>>;

const ONE_MINUS_EPSILON: f32 = 0.99999994;

// Whether next-event estimation picks finite emitters with the tree (bidirectional path
// tracing keeps the choice by power).
fn light_tree_active() -> bool {
    return params.light_tree_nodes > 0u && params.integrator == INTEGRATOR_PATH;
}

// pbrt-v4's LightBounds::Importance without the normal's factor (see light_tree.rs).
fn node_importance(n: LightTreeNode, p: vec3<f32>) -> f32 {
    let center = 0.5 * (n.lo + n.hi);
    let diagonal = n.hi - n.lo;
    let radius2 = 0.25 * dot(diagonal, diagonal);
    let to_p = p - center;
    let d2 = dot(to_p, to_p);
    let clamped = max(max(d2, radius2), 1e-12);
    if d2 <= radius2 {
        // Inside the box's bounding sphere: every direction may reach an emitter.
        return min(n.phi / clamped, 3.4028235e38);
    }
    let wi = to_p / sqrt(d2);
    var cos_w = dot(n.axis, wi);
    if n.two_sided != 0u {
        cos_w = abs(cos_w);
    }
    let sin_w = sqrt(max(1.0 - cos_w * cos_w, 0.0));
    let sin2_b = radius2 / d2;
    let cos_b = sqrt(max(1.0 - sin2_b, 0.0));
    let sin_b = sqrt(sin2_b);
    let cos_o = n.cos_theta_o;
    let sin_o = sqrt(max(1.0 - cos_o * cos_o, 0.0));
    // theta_x = max(0, theta_w - theta_o), then theta' = max(0, theta_x - theta_b).
    var cos_x = 1.0;
    var sin_x = 0.0;
    if !(cos_w > cos_o) {
        cos_x = cos_w * cos_o + sin_w * sin_o;
        sin_x = sin_w * cos_o - cos_w * sin_o;
    }
    var cos_p = 1.0;
    if !(cos_x > cos_b) {
        cos_p = cos_x * cos_b + sin_x * sin_b;
    }
    if cos_p <= n.cos_theta_e {
        return 0.0;
    }
    return clamp(n.phi * cos_p / clamped, 0.0, 3.4028235e38);
}

// A finite emitter picked at p with u: primitive, index and probability in the choice
// (probability 0: no emitter can light p).
fn light_tree_pick(p: vec3<f32>, u_in: f32) -> EmitterChoice {
    var u = u_in;
    var i = 0u;
    var pmf = 1.0;
    for (var depth = 0u; depth < 64u; depth++) {
        let n = light_tree_nodes[i];
        if n.child == 0u {
            return EmitterChoice(n.primitive, n.index, pmf);
        }
        let c0 = node_importance(light_tree_nodes[i + 1u], p);
        let c1 = node_importance(light_tree_nodes[n.child], p);
        let sum = c0 + c1;
        if !(sum > 0.0) {
            break;
        }
        let p0 = c0 / sum;
        if u < p0 {
            u = min(u / p0, ONE_MINUS_EPSILON);
            pmf *= p0;
            i += 1u;
        } else {
            u = min((u - p0) / (1.0 - p0), ONE_MINUS_EPSILON);
            pmf *= c1 / sum;
            i = n.child;
        }
    }
    return EmitterChoice(0u, 0u, 0.0);
}

// The slot of an emitting sphere's, quad's or triangle's trail.
fn light_trail_slot(primitive: u32, index: u32) -> u32 {
    if primitive == PRIMITIVE_SPHERE {
        return index;
    }
    if primitive == PRIMITIVE_QUAD {
        return params.sphere_count + index;
    }
    return params.sphere_count + params.quad_count + index;
}

// The probability that light_tree_pick at p picks (primitive, index), times the probability
// of picking a finite emitter at all.
fn light_tree_selection_probability(p: vec3<f32>, primitive: u32, index: u32) -> f32 {
    let slot = light_trail_slot(primitive, index);
    if slot >= arrayLength(&light_tree_trails) {
        return 0.0;
    }
    let trail = light_tree_trails[slot];
    var i = 0u;
    var pmf = 1.0;
    for (var depth = 0u; depth < 64u; depth++) {
        let n = light_tree_nodes[i];
        if n.child == 0u {
            if n.primitive == primitive && n.index == index {
                return params.light_tree_probability * pmf;
            }
            return 0.0;
        }
        let c0 = node_importance(light_tree_nodes[i + 1u], p);
        let c1 = node_importance(light_tree_nodes[n.child], p);
        let sum = c0 + c1;
        if !(sum > 0.0) {
            return 0.0;
        }
        var bit = 0u;
        if depth < 32u {
            bit = (trail.x >> depth) & 1u;
        } else {
            bit = (trail.y >> (depth - 32u)) & 1u;
        }
        if bit == 0u {
            pmf *= c0 / sum;
            i += 1u;
        } else {
            pmf *= c1 / sum;
            i = n.child;
        }
    }
    return 0.0;
}
