// 4-wide BVH traversal (mirror: src/cpu/traverse/wide.rs), compiled only into the wide kernel
// variant (SceneBinding::WideBvh in src/kernel/variant.rs), over the tree src/kernel/bvh/wide.rs
// collapses from the binary one. The meaning and the arguments are bvh_traverse's
// (shaders/traverse/bvh.wgsl), and so are the leaves' tests and bookkeeping (hit_primitive,
// hit_comes_first, the leaf-entry pruning): only the inner nodes differ. A node's four boxes
// are tested at once, and its children pushed farthest first, so the nearest is visited next.
// Why wide on lavapipe: it loads each storage-buffer value with a loop over the lanes, and a
// wide node's 32 words replace about three binary nodes' 72, with fewer stack operations.

@group(0) @binding(44) var<storage, read> bvh_wide_nodes: array<BvhWideNode>;
// The first BVH_WIDE_UNIFORM_NODES of bvh_wide_nodes again, in a uniform buffer: the top of
// the tree (laid out breadth first), as bvh_top_nodes is for the binary tree.
@group(0) @binding(45) var<uniform> bvh_wide_top_nodes: array<BvhWideNode, BVH_WIDE_UNIFORM_NODES>;

fn bvh_wide_node(i: u32) -> BvhWideNode {
    if i < BVH_WIDE_UNIFORM_NODES {
        return bvh_wide_top_nodes[i];
    }
    return bvh_wide_nodes[i];
}

// A leaf's first primitive and count, read from its parent's slot.
fn bvh_wide_leaf(parent: u32, slot: u32) -> vec2<u32> {
    if parent < BVH_WIDE_UNIFORM_NODES {
        return vec2<u32>(bvh_wide_top_nodes[parent].first[slot], bvh_wide_top_nodes[parent].count[slot]);
    }
    return vec2<u32>(bvh_wide_nodes[parent].first[slot], bvh_wide_nodes[parent].count[slot]);
}

// Where the ray enters each of the node's four child boxes (0 when it starts inside), or
// NO_HIT where it misses the box, enters it beyond t_max, or the slot holds no child: each
// child's is hit_box's arithmetic (shaders/traverse/bvh.wgsl), on four boxes at once.
fn hit_wide_boxes(node: BvhWideNode, r: BvhRay, t_max: f32) -> vec4<f32> {
    let o = r.ray.origin;
    let tx0 = (node.min_x - o.x) * r.inv_dir.x;
    let tx1 = (node.max_x - o.x) * r.inv_dir.x;
    let ty0 = (node.min_y - o.y) * r.inv_dir.y;
    let ty1 = (node.max_y - o.y) * r.inv_dir.y;
    let tz0 = (node.min_z - o.z) * r.inv_dir.z;
    let tz1 = (node.max_z - o.z) * r.inv_dir.z;
    let near = max(max(min(tx0, tx1), min(ty0, ty1)), max(min(tz0, tz1), vec4<f32>(0.0)));
    let far = min(min(max(tx0, tx1), max(ty0, ty1)), max(tz0, tz1)) * BOX_SLACK;
    let hit = (near <= min(far, vec4<f32>(widened(t_max)))) & (node.count != vec4<u32>(WIDE_EMPTY_CHILD));
    return select(vec4<f32>(NO_HIT), near, hit);
}

// The four slots ordered by their entry distance t, farthest first (misses, at NO_HIT, before
// all): a sorting network over keys holding t's bits with the slot in the low two, which
// t >= 0 orders as floats. Only the visit order rests on it, never a decision.
fn farthest_first(t: vec4<f32>) -> vec4<u32> {
    let key = (bitcast<vec4<u32>>(t) & vec4<u32>(~3u)) | vec4<u32>(0u, 1u, 2u, 3u);
    let a = max(key.x, key.y);
    let b = min(key.x, key.y);
    let c = max(key.z, key.w);
    let d = min(key.z, key.w);
    let a2 = max(a, c);
    let c2 = min(a, c);
    let b2 = max(b, d);
    let d2 = min(b, d);
    return vec4<u32>(a2, max(b2, c2), min(b2, c2), d2) & vec4<u32>(3u);
}

// A stack entry for a leaf: its parent's index times four plus its slot, with this bit set
// (src/kernel/bvh/wide.rs bounds the node count below 2^29).
const WIDE_LEAF: u32 = 0x80000000u;

fn wide_traverse(r: BvhRay, t_max: f32, t_prune: f32, max_reference: u32, shadow_target: u32) -> ClosestPrimitive {
    var best = ClosestPrimitive(t_max, PRIMITIVE_QUAD, 0u, NO_INSTANCE);
    var best_reference = max_reference;
    var prune = t_prune;
    var found = false;
    // Children left for later, and where the ray enters their box. The root is entered from
    // 0: its children's boxes are tested instead.
    var stack: array<u32, BVH_WIDE_STACK_SIZE>;
    var stack_entry: array<f32, BVH_WIDE_STACK_SIZE>;
    stack[0] = 0u;
    stack_entry[0] = 0.0;
    var top = 1u;
    while top > 0u {
        top -= 1u;
        let node_entry = stack_entry[top];
        if node_entry > widened(prune) {
            continue;
        }
        let item = stack[top];
        if (item & WIDE_LEAF) == 0u {
            let node = bvh_wide_node(item);
            let t = hit_wide_boxes(node, r, prune);
            let order = farthest_first(t);
            for (var k = 0u; k < 4u; k++) {
                let slot = order[k];
                if t[slot] != NO_HIT {
                    stack[top] = select((item << 2u) | slot | WIDE_LEAF, node.first[slot], node.count[slot] == 0u);
                    stack_entry[top] = t[slot];
                    top += 1u;
                }
            }
            continue;
        }
        let leaf = bvh_wide_leaf((item & ~WIDE_LEAF) >> 2u, item & 3u);
        for (var i = leaf.x; i < leaf.x + leaf.y; i++) {
            let reference = bvh_primitives[i];
            let t = hit_primitive(reference, r);
            // The target is excluded by name too, as in bvh_traverse.
            if hit_comes_first(t, reference, best.t, best_reference) && reference != shadow_target {
                best = ClosestPrimitive(t, reference >> PRIMITIVE_KIND_SHIFT, reference & PRIMITIVE_INDEX_MASK, NO_INSTANCE);
                best_reference = reference;
                prune = max(t, node_entry);
                found = true;
                if shadow_target != NO_PRIMITIVE {
                    return best;
                }
            }
        }
    }
    if !found {
        best.t = NO_HIT;
    }
    return best;
}
