//! The kernel variants (src/kernel/variant.rs): uniform and storage scene bindings render bit-identical
//! images, and so do kernels with features compiled out and the kernel with all of them; a
//! 700-quad scene goes through storage buffers and traces the CPU's paths; a kernel lacking a
//! feature the scene needs is refused.

use crate::common;
use common::{gpu, render_cpu, shipped_scene, shipped_scene_text, sized};
use glint::gpu::GpuRenderer;
use glint::image::output::Image;
use glint::kernel::bvh::kernel_stack_size;
use glint::kernel::bvh::layout::BvhLayout;
use glint::kernel::bvh::wide;
use glint::kernel::variant::{
    bvh_uniform_nodes, bvh_wide_uniform_nodes, KernelFeatures, KernelVariant, SceneBinding,
    SceneCounts, MAX_UNIFORM_SCENE_BYTES,
};
use glint::kernel::KernelScene;
use glint::render::render_image;

fn render_with(scene: &KernelScene, binding: SceneBinding, spp: u32) -> Image {
    let ctx = gpu().unwrap();
    let mut renderer = GpuRenderer::with_scene_binding(ctx, scene, binding).unwrap();
    assert_eq!(renderer.scene_binding(), binding);
    render_image(&mut renderer, spp, spp).unwrap()
}

fn materials_scene(size: u32, seed: u32) -> KernelScene {
    sized(shipped_scene("cornell-materials.toml"), size, seed)
}

/// How many pixels of `a` and `b` are not bit-identical.
fn differing_pixels(a: &Image, b: &Image) -> usize {
    assert_eq!(a.pixels.len(), b.pixels.len());
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(x, y)| x != y)
        .count()
}

/// The same kernel code reads the same numbers from either binding, so every path is the same.
#[test]
fn uniform_and_storage_bindings_render_the_same_image() {
    if gpu().is_none() {
        return;
    }
    let scene = materials_scene(48, 7);
    let uniform = render_with(&scene, SceneBinding::Uniform(SceneCounts::of(&scene)), 2);
    let storage = render_with(&scene, SceneBinding::Storage, 2);
    let differing = differing_pixels(&uniform, &storage);
    eprintln!("{differing} of {} pixels differ", uniform.pixels.len());
    assert_eq!(differing, 0);
}

/// The Cornell box with a grid of `tiles` small green quads in front of the back wall.
fn tiled_cornell(tiles: u32, size: u32, seed: u32) -> KernelScene {
    let mut toml = shipped_scene_text("cornell.toml");
    for i in 0..tiles {
        let (x, y) = (10 + 19 * (i % 28), 10 + 19 * (i / 28));
        toml += &format!(
            "\n[[quads]]\ncorner = [{x}.0, {y}.0, 554.0]\nu = [12.0, 0.0, 0.0]\nv = [0.0, 12.0, 0.0]\nmaterial = \"green\"\n"
        );
    }
    sized(common::scene(&toml), size, seed)
}

/// The linear scan (the scene without its BVH, as in scenes of at most 64 spheres and quads):
/// uniform buffers while the largest array fits both the device's limit and 64 KiB, storage
/// buffers beyond.
fn without_bvh(mut scene: KernelScene) -> KernelScene {
    scene.bvh_nodes.clear();
    scene.bvh_primitives.clear();
    scene
}

#[test]
fn scenes_too_large_for_uniform_buffers_use_storage_buffers() {
    let tiled_cornell = |tiles, size, seed| without_bvh(tiled_cornell(tiles, size, seed));
    let cornell = common::cornell_at(16, 0);
    assert_eq!(
        SceneBinding::for_scene(&cornell, 65536),
        SceneBinding::Uniform(SceneCounts::of(&cornell))
    );
    // 682 quads of 96 bytes fit in 64 KiB (65472 bytes); 683 do not.
    let fitting_tiles = 682 - cornell.quads.len() as u32;
    assert!(matches!(
        SceneBinding::for_scene(&tiled_cornell(fitting_tiles, 16, 0), 65536),
        SceneBinding::Uniform(_)
    ));
    assert_eq!(
        SceneBinding::for_scene(&tiled_cornell(fitting_tiles + 1, 16, 0), 65536),
        SceneBinding::Storage
    );
    // A device with a larger limit still gets at most 64 KiB; one with a smaller limit, its own.
    assert_eq!(MAX_UNIFORM_SCENE_BYTES, 65536);
    assert_eq!(
        SceneBinding::for_scene(&tiled_cornell(fitting_tiles + 1, 16, 0), 1 << 30),
        SceneBinding::Storage
    );
    assert_eq!(
        SceneBinding::for_scene(&cornell, cornell.quads.len() as u64 * 96 - 1),
        SceneBinding::Storage
    );
}

/// A scene over the uniform limit renders through storage buffers (and, having more than 64
/// objects, its BVH) and traces the same paths as the CPU reference (the criterion of
/// tests/suite/gpu_vs_cpu.rs); so does the same scene scanned linearly from storage buffers.
#[test]
fn large_scene_renders_through_storage_buffers_like_the_cpu() {
    let Some(ctx) = gpu() else { return };
    let mut agreement = common::PathAgreement::default();
    for seed in [1, 2] {
        let scene = tiled_cornell(700, 64, seed);
        let mut renderer = GpuRenderer::new(ctx, &scene).unwrap();
        assert!(matches!(
            renderer.scene_binding(),
            SceneBinding::Bvh { .. } | SceneBinding::WideBvh { .. }
        ));
        let gpu_image = render_image(&mut renderer, 1, 1).unwrap();
        agreement.add(&render_cpu(&scene, 1), &gpu_image);
        let scene = without_bvh(scene);
        let mut renderer = GpuRenderer::new(ctx, &scene).unwrap();
        assert_eq!(renderer.scene_binding(), SceneBinding::Storage);
        let gpu_image = render_image(&mut renderer, 1, 1).unwrap();
        agreement.add(&render_cpu(&scene, 1), &gpu_image);
    }
    agreement.check(0.99);
}

/// The BVH's top nodes: as many as 64 KiB (or the device's smaller limit) holds, whatever the
/// scene, so the kernel for a device does not change with the tree.
#[test]
fn bvh_top_nodes_fill_the_uniform_limit() {
    assert_eq!(bvh_uniform_nodes(65536), 2048);
    assert_eq!(bvh_uniform_nodes(1 << 30), 2048);
    assert_eq!(bvh_uniform_nodes(16384), 512);
    assert_eq!(bvh_wide_uniform_nodes(65536), 512);
    let bunny = sized(shipped_scene("bunny.toml"), 8, 0);
    let expected = match BvhLayout::for_gpu() {
        BvhLayout::Binary => SceneBinding::Bvh {
            uniform_nodes: 2048,
            stack_size: kernel_stack_size(&bunny.bvh_nodes),
        },
        BvhLayout::Wide => SceneBinding::WideBvh {
            uniform_nodes: 512,
            stack_size: wide::kernel_stack_size(&bunny.bvh_wide_nodes),
        },
    };
    assert_eq!(SceneBinding::for_scene(&bunny, 65536), expected);
}

/// Reading the BVH's top nodes from the uniform copy, for all of a small tree or the top of a
/// large one, gives the same image bit for bit as reading every node from the storage buffer
/// (one node in the copy). The bunny's tree has 1633 nodes: 2048 holds all of it, and 64 or
/// 512 put the boundary mid-tree, so traversals cross from one buffer to the other.
#[test]
fn bvh_top_nodes_in_a_uniform_buffer_do_not_change_the_image() {
    if gpu().is_none() {
        return;
    }
    let bunny = sized(shipped_scene("bunny.toml"), 32, 3);
    assert!(bunny.bvh_nodes.len() > 512, "{}", bunny.bvh_nodes.len());
    let small = sized(shipped_scene("cornell-mesh.toml"), 32, 4);
    for (name, scene) in [("bunny", bunny), ("cornell-mesh", small)] {
        let stack_size = kernel_stack_size(&scene.bvh_nodes);
        let storage_only = render_with(
            &scene,
            SceneBinding::Bvh {
                uniform_nodes: 1,
                stack_size,
            },
            2,
        );
        assert!(
            storage_only.pixels.iter().any(|p| p[0] > 0.0),
            "{name} is black"
        );
        for uniform_nodes in [64, 512, 2048] {
            let binding = SceneBinding::Bvh {
                uniform_nodes,
                stack_size,
            };
            let image = render_with(&scene, binding, 2);
            let differing = differing_pixels(&storage_only, &image);
            assert_eq!(differing, 0, "{name} with {uniform_nodes} uniform nodes");
        }
        // The same for the wide tree (whose 512 uniform nodes hold all of the bunny's).
        let wide_stack = wide::kernel_stack_size(&scene.bvh_wide_nodes);
        let wide_storage_only = render_with(
            &scene,
            SceneBinding::WideBvh {
                uniform_nodes: 1,
                stack_size: wide_stack,
            },
            2,
        );
        for uniform_nodes in [16, 64, 512] {
            let binding = SceneBinding::WideBvh {
                uniform_nodes,
                stack_size: wide_stack,
            };
            let image = render_with(&scene, binding, 2);
            let differing = differing_pixels(&wide_storage_only, &image);
            assert_eq!(
                differing, 0,
                "{name}, wide, with {uniform_nodes} uniform nodes"
            );
        }
    }
}

/// Kernels with unused features compiled out render exactly what the kernel with everything
/// renders: the flags only remove code a scene cannot reach. The scenes cover each flag both
/// ways: light sampling on and off; quad emitters only, sphere emitters only, and both; metal
/// and glass present and absent; transmission, volumes, clearcoat and sheen (the pbr grid)
/// present and absent.
#[test]
fn compiled_out_features_do_not_change_the_image() {
    let Some(ctx) = gpu() else { return };
    let mut lit_by_both = shipped_scene_text("cornell-materials.toml");
    lit_by_both +=
        "\n[[spheres]]\ncenter = [100.0, 450.0, 300.0]\nradius = 40.0\nmaterial = \"light\"\n";
    let lit_by_both = sized(common::scene(&lit_by_both), 32, 5);
    let mut cornell_off = common::cornell_at(32, 6);
    cornell_off.params.light_sampling = 0;
    let scenes = [
        ("cornell, light sampling on", common::cornell_at(32, 6)),
        ("cornell, light sampling off", cornell_off),
        ("materials", materials_scene(32, 5)),
        ("quad and sphere emitters", lit_by_both),
        ("sphere emitter only", common::floor_under_lamp(32, 2, 3)),
        (
            "textured",
            sized(shipped_scene("cornell-textured.toml"), 32, 4),
        ),
        (
            "point, spot and sun lights",
            sized(shipped_scene("lights.toml"), 32, 7),
        ),
        (
            "pbr grid with glass and a volume",
            sized(shipped_scene("materials.toml"), 32, 8),
        ),
    ];
    // Every scene through the storage binding, so the kernel with everything is one shader,
    // compiled once: the uniform binding compiles each scene's counts in, which made this test
    // compile the largest kernel once per scene (11 min on lavapipe). That the two bindings
    // render alike is uniform_and_storage_bindings_render_the_same_image's test.
    let mut variants_seen = Vec::new();
    for (name, scene) in scenes {
        // What GpuRenderer::new compiles out for the scene.
        let features = KernelFeatures::of(&scene);
        variants_seen.push(features);
        let fast = KernelVariant {
            binding: SceneBinding::Storage,
            features,
        };
        let general = KernelVariant {
            binding: SceneBinding::Storage,
            features: KernelFeatures::ALL,
        };
        let a = render_image(
            &mut GpuRenderer::with_variant(ctx, &scene, fast).unwrap(),
            2,
            2,
        )
        .unwrap();
        let b = render_image(
            &mut GpuRenderer::with_variant(ctx, &scene, general).unwrap(),
            2,
            2,
        )
        .unwrap();
        let differing = differing_pixels(&a, &b);
        eprintln!("{name}: {:?}: {differing} pixels differ", features);
        // Not one pixel may differ: the coat's normal is its own value in every variant
        // (shaders/integrator/path.wgsl), so none merges the coat's arithmetic with the base's, which
        // the kernel with every feature cannot, and rounds it otherwise (one pixel in 1024
        // parted in the coated pbr scene before).
        assert!(differing == 0, "{name}: {differing} pixels differ");
        assert!(a.pixels.iter().any(|p| p[0] > 0.0), "{name} is black");
    }
    // Each flag was off for some scene and on for another.
    let flags = |f: &KernelFeatures| {
        [
            f.light_sampling,
            f.sphere_emitters,
            f.quad_emitters,
            f.metal,
            f.dielectric,
            f.textures,
            f.lights,
            f.sun_disks,
            f.transmission,
            f.volume,
            f.clearcoat,
            f.sheen,
        ]
    };
    for i in 0..12 {
        assert!(
            variants_seen.iter().any(|f| flags(f)[i]),
            "flag {i} never on"
        );
        assert!(
            variants_seen.iter().any(|f| !flags(f)[i]),
            "flag {i} never off"
        );
    }
}

/// A kernel without a feature the scene uses is refused, not run with wrong results.
#[test]
fn a_kernel_lacking_a_needed_feature_is_refused() {
    let Some(ctx) = gpu() else { return };
    let scene = materials_scene(16, 1);
    let mut features = KernelFeatures::of(&scene);
    features.dielectric = false;
    let variant = KernelVariant {
        binding: SceneBinding::Storage,
        features,
    };
    assert!(GpuRenderer::with_variant(ctx, &scene, variant).is_err());
}

/// The longest root-to-leaf path below the root of a tree laid out as `bvh::build` does, by a
/// recursive walk (the function under test makes one breadth-first pass).
fn levels_below_root(nodes: &[glint::kernel::types::BvhNode], i: usize) -> u32 {
    let node = nodes[i];
    if node.count > 0 {
        return 0;
    }
    let first = node.first as usize;
    1 + levels_below_root(nodes, first).max(levels_below_root(nodes, first + 1))
}

/// The kernel's traversal stack is sized per scene: room for one entry per level below the
/// root (the most a traversal holds at once), in steps of 8.
#[test]
fn the_traversal_stack_fits_the_tree() {
    let mut trees: Vec<(String, KernelScene)> = ["bunny.toml", "cornell-mesh.toml"]
        .iter()
        .map(|name| (name.to_string(), sized(shipped_scene(name), 8, 0)))
        .collect();
    // Deeper trees: the benchmark's bumpy spheres (18 to 30 levels here).
    for case in glint::render::bench::mesh_cases(&[1000, 30000], true) {
        trees.push((
            format!("{case:?}"),
            glint::render::bench::case_scene(&case).unwrap(),
        ));
    }
    for (name, scene) in &trees {
        let levels = levels_below_root(&scene.bvh_nodes, 0);
        let stack = kernel_stack_size(&scene.bvh_nodes);
        assert!(
            stack >= levels,
            "{name}: {stack} entries for {levels} levels"
        );
        assert!(
            stack < levels.max(1) + 8,
            "{name}: {stack} entries for {levels} levels"
        );
        assert_eq!(stack % 8, 0, "{name}");
    }
}

/// The stack sized for the tree renders what the largest stack renders, bit for bit, while
/// one too small for the bunny's tree does not, so the comparison can tell. (Traversals rarely
/// hold many entries at once: at this size 8 entries for the bunny's 18 levels still gives the
/// same image, 2 do not.)
#[test]
fn a_stack_sized_for_the_tree_renders_the_full_stacks_image() {
    if gpu().is_none() {
        return;
    }
    let bunny = sized(shipped_scene("bunny.toml"), 32, 5);
    let with_stack = |stack_size| {
        render_with(
            &bunny,
            SceneBinding::Bvh {
                uniform_nodes: bvh_uniform_nodes(65536),
                stack_size,
            },
            2,
        )
    };
    let full = with_stack(64);
    let sized_for_tree = kernel_stack_size(&bunny.bvh_nodes);
    assert!(sized_for_tree < 64, "{sized_for_tree}");
    assert_eq!(differing_pixels(&full, &with_stack(sized_for_tree)), 0);
    assert!(differing_pixels(&full, &with_stack(2)) > 0);
}
