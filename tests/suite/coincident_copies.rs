//! Coincident copies, as CAD exports and kitbashed scenes hold by the thousand: the Cornell box
//! with its white sphere copied 2000 times and a block (6 quads) 1000 times in place renders the
//! plain box's image, on both devices and through the hardware traversal, bit for bit the
//! software traversal's. By the closest-hit rule the first copy hides the others from every ray
//! (tests/suite/closest_hit.rs); the BVH leaves the copies out, and its depth is bounded either way.

use crate::common;
use common::{gpu, gpu_with_ray_queries, render_cpu, render_gpu, shipped_scene_text, sized};
use glint::gpu::{GpuRenderer, Traversal};
use glint::kernel::bvh;
use glint::kernel::KernelScene;
use glint::render::render_image;
use glint::scene::Scene;
use std::path::Path;

/// A block on the floor, clear of both spheres: its 6 faces.
const BLOCK: &str = r#"
[[quads]]
corner = [60.0, 0.0, 340.0]
u = [120.0, 0.0, 0.0]
v = [0.0, 200.0, 0.0]
material = "white"

[[quads]]
corner = [60.0, 0.0, 480.0]
u = [120.0, 0.0, 0.0]
v = [0.0, 200.0, 0.0]
material = "white"

[[quads]]
corner = [60.0, 0.0, 340.0]
u = [0.0, 0.0, 140.0]
v = [0.0, 200.0, 0.0]
material = "white"

[[quads]]
corner = [180.0, 0.0, 340.0]
u = [0.0, 0.0, 140.0]
v = [0.0, 200.0, 0.0]
material = "white"

[[quads]]
corner = [60.0, 200.0, 340.0]
u = [120.0, 0.0, 0.0]
v = [0.0, 0.0, 140.0]
material = "white"

[[quads]]
corner = [60.0, 0.0, 340.0]
u = [120.0, 0.0, 0.0]
v = [0.0, 0.0, 140.0]
material = "white"
"#;

/// The shipped sphere's copy, in the mirror's material: a later copy that were ever hit would
/// show.
const SPHERE_COPY: &str = r#"
[[spheres]]
center = [190.0, 90.0, 190.0]
radius = 90.0
material = "mirror"
"#;

/// The Cornell box with the block, and with `copies` the copies after the originals.
fn cornell_with_block(copies: bool, size: u32, seed: u32) -> KernelScene {
    let mut text = shipped_scene_text("cornell.toml") + BLOCK;
    if copies {
        text += &SPHERE_COPY.repeat(2000);
        text += &BLOCK.replace("white", "red").repeat(1000);
    }
    let scene = Scene::parse(&text, Path::new("cornell.toml")).unwrap_or_else(|e| panic!("{e}"));
    let scene = sized(scene, size, seed);
    if copies {
        assert_eq!(
            (scene.spheres.len(), scene.quads.len()),
            (2002, 6 + 6 * 1001)
        );
    }
    scene
}

/// `scene` with its BVH over every primitive, copies too.
fn with_copies_in_the_tree(scene: &KernelScene) -> KernelScene {
    let tree = bvh::build_with_copies(&scene.spheres, &scene.quads, &scene.triangles).unwrap();
    assert!(
        tree.depth <= glint::kernel::bvh::BVH_STACK_SIZE,
        "{}",
        tree.depth
    );
    KernelScene {
        bvh_wide_nodes: tree.wide_nodes(),
        bvh_nodes: tree.nodes,
        bvh_primitives: tree.primitives,
        ..scene.clone()
    }
}

/// On the CPU the paths are the plain box's to the bit, through the BVH without the copies and
/// through the one with every copy.
#[test]
fn cpu_renders_the_plain_box_bit_for_bit() {
    let plain = cornell_with_block(false, 32, 1);
    let copies = cornell_with_block(true, 32, 1);
    assert!(plain.bvh_nodes.is_empty() && !copies.bvh_nodes.is_empty());
    // Only the 14 distinct primitives are in the tree.
    assert_eq!(copies.bvh_primitives.len(), 14);
    let expected = render_cpu(&plain, 4);
    assert_eq!(render_cpu(&copies, 4).pixels, expected.pixels);
    assert_eq!(
        render_cpu(&with_copies_in_the_tree(&copies), 4).pixels,
        expected.pixels
    );
}

/// On the GPU too, bit for bit. With every copy in the tree the kernel tests leaves of nearly
/// 2000 spheres and of 1001 quads one by one: lavapipe's loop budget
/// (src/gpu/loop_budget.rs) then allows one sample per dispatch, and it renders. The paths
/// are compared at 1 spp (one path per pixel): at 4 spp the means differ in the last bit,
/// from the merging of one-sample dispatches, not from the paths.
#[test]
fn gpu_renders_the_plain_box() {
    let Some(ctx) = gpu() else { return };
    let plain = cornell_with_block(false, 32, 1);
    let copies = cornell_with_block(true, 32, 1);
    assert_eq!(
        render_gpu(ctx, &copies, 4).pixels,
        render_gpu(ctx, &plain, 4).pixels
    );
    let full = with_copies_in_the_tree(&copies);
    assert_eq!(
        render_gpu(ctx, &full, 1).pixels,
        render_gpu(ctx, &plain, 1).pixels
    );
}

/// With the hardware traversal too: the copies stay invisible, over the tree's primitives (the
/// copies left out, as for the BVH) and with every copy in the acceleration structure, where
/// the hardware proposes 2000 coincident spheres and 1001 coincident blocks in its own order
/// and only the closest-hit rule picks the first. The images are the software traversal's,
/// bit for bit.
#[test]
fn gpu_hardware_traversal_renders_the_plain_box() {
    let Some(ctx) = gpu_with_ray_queries() else {
        return;
    };
    let render = |scene: &KernelScene, traversal, spp| {
        let mut renderer = GpuRenderer::with_traversal(ctx, scene, traversal).unwrap();
        assert_eq!(renderer.traversal(), traversal);
        render_image(&mut renderer, spp, spp).unwrap().pixels
    };
    let plain = cornell_with_block(false, 32, 1);
    let copies = cornell_with_block(true, 32, 1);
    let expected = render(&plain, Traversal::Software, 1);
    assert_eq!(render(&plain, Traversal::Hardware, 1), expected);
    assert_eq!(render(&copies, Traversal::Hardware, 1), expected);
    let full = with_copies_in_the_tree(&copies);
    assert_eq!(render(&full, Traversal::Hardware, 1), expected);
}
