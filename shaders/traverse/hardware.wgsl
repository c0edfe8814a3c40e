// Hardware traversal with ray queries (wgpu's EXPERIMENTAL_RAY_QUERY), compiled only into the
// hardware kernel variant (SceneBinding::Hardware in src/kernel/variant.rs): a shader that uses ray
// queries does not compile on a device without them. The host builds the acceleration
// structure (src/gpu/acceleration.rs): a TLAS over the triangles placed as they are (triangle
// geometry), the spheres and quads (boxes), and one instance per placement of an instanced
// mesh, over that mesh's triangles in its own coordinates. The hardware only proposes
// candidates: every one, triangles included (RAY_FLAG_FORCE_NO_OPAQUE), is tested here with
// glint's own exact test (hit_primitive, shaders/traverse/bvh.wgsl; an instance's triangle in the
// instance's coordinates, as shaders/traverse/blas.wgsl tests it) and kept by the closest-hit
// rule (hit_comes_first, extended by triangle within an instance), so a hit's t, primitive and
// instance are the software traversal's. That test includes alpha
// (hit_scene_triangle, shaders/geometry/alpha.wgsl): a candidate in a hole, or that a blended triangle
// lets through, is rejected like a miss, so no geometry needs other flags for alpha. No CPU mirror: the CPU traces with
// the software BVH (src/cpu/traverse/bvh.rs), which this must agree with (tests/suite/closest_hit.rs).

@group(0) @binding(26) var scene_tlas: acceleration_structure;
// The reference ((kind << PRIMITIVE_KIND_SHIFT) | index) of every primitive in the TLAS: a
// candidate's is at its instance's custom data (where its BLAS's references start) plus its
// primitive index. An instanced mesh's triangles are those past the ones placed as they are
// (triangle_count()); the placements take the TLAS's first slots, so such a candidate is hit
// through the instance whose index is its TLAS instance index.
@group(0) @binding(27) var<storage, read> hardware_references: array<u32>;

// How much further than a hit the hardware is asked to look, relatively: 2^-12, far more than
// the few ulps by which its own triangle test's t can differ from hit_triangle's, so every
// primitive the rule puts before the hit is proposed; what is proposed beyond is rejected by
// the rule. NO_HIT stays NO_HIT.
fn hardware_bound(t: f32) -> f32 {
    return select(t * 1.0002441, t, t > 1e38);
}

// The hardware counterpart of bvh_traverse, with the same meaning: the closest primitive that
// comes before the bound (t_max, max_reference) by the closest-hit rule, or with
// `shadow_target` not NO_PRIMITIVE, the first other primitive before it (t = NO_HIT when none).
//
// The hardware stops looking beyond what is committed. A box's hit is committed at
// hardware_bound(t), so everything the rule may put before it is still proposed. A triangle's
// could only be committed at the hardware's own t, which rounding can put before a triangle
// the rule prefers (a neighbour hit at the same edge, an ulp nearer by hit_triangle): it is
// never committed; instead the query starts over, reaching only to hardware_bound(t).
fn hardware_traverse(ray: Ray, t_max: f32, max_reference: u32, shadow_target: u32) -> ClosestPrimitive {
    let r = bvh_ray(ray);
    var best = ClosestPrimitive(t_max, PRIMITIVE_QUAD, 0u, NO_INSTANCE);
    var best_reference = max_reference;
    var found = false;
    var reach = hardware_bound(t_max);
    var rq: ray_query;
    loop {
        rayQueryInitialize(&rq, scene_tlas, RayDesc(RAY_FLAG_FORCE_NO_OPAQUE, 0xffu, 0.0, reach, ray.origin, ray.dir));
        var committed = reach;
        var again = false;
        loop {
            let proceed = rayQueryProceed(&rq);
            if !proceed {
                break;
            }
            let candidate = rayQueryGetCandidateIntersection(&rq);
            var reference = hardware_references[candidate.instance_custom_data + candidate.primitive_index];
            var index = reference & PRIMITIVE_INDEX_MASK;
            var instance = NO_INSTANCE;
            var t: f32;
            var first: bool;
            if HAS_INSTANCES && (reference >> PRIMITIVE_KIND_SHIFT) == PRIMITIVE_TRIANGLE && index >= triangle_count() {
                // Tested as blas.wgsl tests it, and ordered as the software traversal orders
                // it: by the instance's reference, then among one instance's triangles by index.
                instance = candidate.instance_index;
                t = hit_scene_triangle(index, triangle_ray(object_ray(instances[instance], ray)));
                reference = (PRIMITIVE_INSTANCE << PRIMITIVE_KIND_SHIFT) | instance;
                first = hit_comes_first(t, reference, best.t, best_reference)
                    || (t == best.t && reference == best_reference && index < best.index);
            } else {
                t = hit_primitive(reference, r);
                // The target is excluded by name too (as in bvh_traverse); an instance's
                // triangle never is one (no light is hit through an instance).
                first = hit_comes_first(t, reference, best.t, best_reference) && reference != shadow_target;
            }
            if !first {
                continue;
            }
            best = ClosestPrimitive(t, select(reference >> PRIMITIVE_KIND_SHIFT, PRIMITIVE_TRIANGLE, instance != NO_INSTANCE), index, instance);
            best_reference = reference;
            found = true;
            if shadow_target != NO_PRIMITIVE {
                rayQueryTerminate(&rq);
                return best;
            }
            // Computed before the store: naga 30 does not emit the expressions of
            // rayQueryGenerateIntersection's argument itself, so they must be emitted first.
            let bound = min(hardware_bound(t), committed);
            committed = bound;
            if candidate.kind == RAY_QUERY_INTERSECTION_AABB {
                rayQueryGenerateIntersection(&rq, bound);
            } else if bound < reach {
                reach = bound;
                again = true;
                rayQueryTerminate(&rq);
                break;
            }
        }
        if !again {
            break;
        }
    }
    if !found {
        best.t = NO_HIT;
    }
    return best;
}

fn hardware_closest_primitive(ray: Ray) -> ClosestPrimitive {
    return hardware_traverse(ray, NO_HIT, 0u, NO_PRIMITIVE);
}

fn hardware_escapes(ray: Ray) -> bool {
    return hardware_traverse(ray, NO_HIT, 0u, PRIMITIVE_ENVIRONMENT << PRIMITIVE_KIND_SHIFT).t == NO_HIT;
}

fn hardware_first_hit_is(ray: Ray, primitive: u32, index: u32) -> bool {
    let target_ref = (primitive << PRIMITIVE_KIND_SHIFT) | index;
    let t_target = hit_primitive(target_ref, bvh_ray(ray));
    if t_target == NO_HIT {
        return false;
    }
    return hardware_traverse(ray, t_target, target_ref, target_ref).t == NO_HIT;
}
