// The light tree compiled out (HAS_LIGHT_TREE false): in kernels of scenes whose emitters
// are picked by power alone, this stands in for lights/light_tree.wgsl with what
// lights/sampling.wgsl names, never reached.

fn light_tree_active() -> bool {
    return false;
}

fn light_tree_pick(p: vec3<f32>, u_in: f32) -> EmitterChoice {
    return EmitterChoice(0u, 0u, 0.0);
}

fn light_tree_selection_probability(p: vec3<f32>, primitive: u32, index: u32) -> f32 {
    return 0.0;
}
