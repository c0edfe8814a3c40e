//! The light tree (`src/kernel/scene/light_tree.rs`, `src/cpu/lights/light_tree.rs`,
//! `shaders/lights/light_tree.wgsl`): its pick probabilities sum to 1 at any shading point,
//! the probability MIS reads for an emitter (`light_pdf`) is the one the pick had, the picks'
//! frequencies follow those probabilities (χ²), and renders with the tree estimate the image
//! renders by power do (per-pixel Z-tests), on the CPU and on the GPU, which traces the CPU's
//! paths.

use crate::common;
use common::chi2::{assert_fits, pearson};
use common::{gpu, render_with_variance, PathAgreement};
use glam::Vec3;
use glint::cpu::core::rng::{Rng, SAMPLER_INDEPENDENT};
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::cpu::lights::light_tree::{node_importance, tree_pick, tree_pmf};
use glint::cpu::lights::sampling::{light_pdf, sample_light};
use glint::cpu::scene_refs::SceneRefs;
use glint::gpu::GpuRenderer;
use glint::image::compare::compare;
use glint::kernel::types::{LightTreeNode, PRIMITIVE_LIGHT};
use glint::kernel::KernelScene;

/// A floor and two walls, open above, lit by a grid of `n`² small emissive spheres of four
/// strengths, a row of small quads, a point light, a spot and a sun (so the tree shares the
/// choice with an infinite light): a small many-lights scene.
fn many_lights_toml(n: usize, size: u32, light_sampler: &str) -> String {
    let mut toml = format!(
        r#"
[camera]
eye = [0.0, 2.2, -3.4]
target = [0.0, 0.4, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 50.0

[render]
width = {size}
height = {size}
spp = 1
max_bounces = 2
light_sampler = "{light_sampler}"

[materials.white]
type = "diffuse"
color = [0.7, 0.7, 0.7]

[[quads]]
corner = [-2.0, 0.0, -2.0]
u = [0.0, 0.0, 4.0]
v = [4.0, 0.0, 0.0]
material = "white"

[[quads]]
corner = [-2.0, 0.0, 2.0]
u = [4.0, 0.0, 0.0]
v = [0.0, 2.0, 0.0]
material = "white"

[[quads]]
corner = [-2.0, 0.0, -2.0]
u = [0.0, 2.0, 0.0]
v = [0.0, 0.0, 4.0]
material = "white"

[[lights]]
type = "point"
position = [1.2, 1.0, 0.5]
intensity = 0.6

[[lights]]
type = "spot"
position = [-1.0, 1.6, 0.0]
direction = [0.3, -1.0, 0.2]
intensity = 3.0
inner_angle = 15.0
outer_angle = 30.0

[[lights]]
type = "directional"
direction = [0.3, -1.0, 0.6]
intensity = 0.3
"#
    );
    for level in 0..4 {
        toml += &format!(
            "\n[materials.lamp{level}]\ntype = \"diffuse\"\ncolor = [0.0, 0.0, 0.0]\n\
             emission = [1.0, 0.8, 0.6]\nstrength = {}\n",
            [2.0, 6.0, 18.0, 54.0][level]
        );
    }
    for i in 0..n {
        for j in 0..n {
            let (x, z) = (
                -1.7 + 3.4 * i as f32 / (n - 1) as f32,
                -1.7 + 3.4 * j as f32 / (n - 1) as f32,
            );
            let y = 0.15 + 0.9 * ((i * 7 + j * 3) % 5) as f32 / 4.0;
            toml += &format!(
                "\n[[spheres]]\ncenter = [{x}, {y}, {z}]\nradius = 0.03\nmaterial = \"lamp{}\"\n",
                (i + 2 * j) % 4
            );
        }
    }
    for k in 0..6 {
        let x = -1.5 + 0.5 * k as f32;
        toml += &format!(
            "\n[[quads]]\ncorner = [{x}, 1.9, 1.99]\nu = [0.1, 0.0, 0.0]\nv = [0.0, -0.1, 0.0]\n\
             material = \"lamp{}\"\n",
            k % 4
        );
    }
    toml
}

fn many_lights(n: usize, size: u32, seed: u32, light_sampler: &str) -> KernelScene {
    let mut scene = common::kernel_scene(&many_lights_toml(n, size, light_sampler));
    scene.params.seed = seed;
    scene.params.sampler = SAMPLER_INDEPENDENT;
    scene
}

/// Each leaf's probability at `p`, enumerated down every branch with the importances alone
/// (not the samplers' code): (primitive, index, probability).
fn leaf_probabilities(nodes: &[LightTreeNode], p: Vec3) -> Vec<(u32, u32, f64)> {
    let mut out = Vec::new();
    let mut stack = vec![(0usize, 1.0f64)];
    while let Some((i, pmf)) = stack.pop() {
        let n = &nodes[i];
        if n.child == 0 {
            out.push((n.primitive, n.index, pmf));
            continue;
        }
        let c0 = node_importance(&nodes[i + 1], p) as f64;
        let c1 = node_importance(&nodes[n.child as usize], p) as f64;
        if c0 + c1 > 0.0 {
            stack.push((i + 1, pmf * c0 / (c0 + c1)));
            stack.push((n.child as usize, pmf * c1 / (c0 + c1)));
        }
    }
    out
}

const SHADING_POINTS: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [-1.9, 0.5, 1.2], [1.0, 1.95, 1.9]];

/// At three shading points (on the floor, near a wall, beside the quads): the leaves'
/// probabilities sum to 1; the probability the trail gives each sphere and quad is the
/// enumeration's; and what `light_pdf` reads for a direction `sample_light` drew is the pdf
/// the sample came with (the same selection probability times the same solid-angle pdf).
#[test]
fn tree_probabilities_sum_to_one_and_light_pdf_reads_the_picks() {
    let scene = many_lights(8, 8, 1, "tree");
    assert!(
        scene.params.light_tree_nodes > 100,
        "a tree over 64 + 8 emitters"
    );
    assert!(
        scene.params.light_tree_probability < 1.0,
        "the sun keeps a share"
    );
    let refs = SceneRefs::of(&scene, &scene.params);
    let nodes = &scene.light_tree_nodes;
    for p in SHADING_POINTS.map(Vec3::from) {
        let leaves = leaf_probabilities(nodes, p);
        let sum: f64 = leaves.iter().map(|l| l.2).sum();
        assert!((sum - 1.0).abs() < 1e-5, "at {p}: the leaves sum to {sum}");
        for &(primitive, index, expected) in &leaves {
            if primitive == PRIMITIVE_LIGHT {
                continue;
            }
            let trail = tree_pmf(
                nodes,
                &scene.light_tree_trails,
                &scene.params,
                p,
                primitive,
                index,
            ) as f64;
            assert!(
                (trail - expected).abs() <= 1e-5 * expected,
                "at {p}: emitter ({primitive}, {index}) has {trail} by its trail, {expected} enumerated"
            );
        }
        let mut rng = Rng::new(5, 0, 3, 11);
        let mut checked = 0;
        for _ in 0..2000 {
            let s = sample_light(&refs, p, p + Vec3::Y * 1e-3, &mut rng);
            if s.pdf <= 0.0 || s.is_delta {
                continue;
            }
            let read = light_pdf(&refs, p, p + Vec3::Y * 1e-3, s.dir, s.primitive, s.index);
            assert!(
                (read - s.pdf).abs() <= 1e-3 * s.pdf,
                "at {p}: sampled ({}, {}) with pdf {}, light_pdf reads {read}",
                s.primitive,
                s.index,
                s.pdf
            );
            checked += 1;
        }
        assert!(checked > 1000, "{checked} area samples checked");
    }
}

/// The picks' frequencies over 2·10⁵ numbers at each shading point against the enumerated
/// probabilities (χ²), and each pick's returned probability is exactly its trail's.
#[test]
fn tree_picks_follow_their_probabilities() {
    let scene = many_lights(8, 8, 1, "tree");
    let nodes = &scene.light_tree_nodes;
    for p in SHADING_POINTS.map(Vec3::from) {
        let leaves = leaf_probabilities(nodes, p);
        let slot = |primitive: u32, index: u32| {
            leaves
                .iter()
                .position(|l| l.0 == primitive && l.1 == index)
                .expect("a leaf")
        };
        let draws = 200_000u64;
        let mut observed = vec![0u64; leaves.len()];
        let mut rng = Rng::new(9, 0, 1, 17);
        for _ in 0..draws {
            let (primitive, index, pmf) = tree_pick(nodes, p, rng.next_f32()).expect("a pick");
            observed[slot(primitive, index)] += 1;
            if primitive != PRIMITIVE_LIGHT {
                let trail = tree_pmf(
                    nodes,
                    &scene.light_tree_trails,
                    &scene.params,
                    p,
                    primitive,
                    index,
                );
                assert_eq!(
                    pmf.to_bits(),
                    trail.to_bits(),
                    "at {p}: ({primitive}, {index})"
                );
            }
        }
        let expected: Vec<f64> = leaves.iter().map(|l| l.2 * draws as f64).collect();
        assert_fits(
            &format!("light tree picks at {p}"),
            &Ok(pearson(&observed, &expected)),
        );
    }
}

/// Tree and power estimate the same image: per-pixel Z-tests of `tree` against `power`, whose
/// variances are each render's variance of its pixel means (independent seeds, so the
/// difference's variance is their sum). The thresholds are statistics.rs's (see there): 97%
/// of the pixel channels within |z| ≤ 2.576, and |z| < 4 for the difference of the image
/// means, which catches a bias common to all pixels (a wrong factor in a pdf).
fn assert_same_expectation(
    what: &str,
    tree: &(glint::image::output::Image, glint::image::output::Image),
    power: &(glint::image::output::Image, glint::image::output::Image),
) {
    let z = compare(&tree.0, &power.0, Some((&tree.1, &power.1)))
        .unwrap()
        .z_test
        .unwrap();
    eprintln!(
        "{what}: Z-test pass rate {:.2}% of {}, z of means {:.2}",
        100.0 * z.pass_rate,
        z.tested,
        z.z_of_means
    );
    assert!(z.pass_rate >= 0.97, "{what}: pass rate {}", z.pass_rate);
    assert!(
        z.z_of_means.abs() < 4.0,
        "{what}: z of means {}",
        z.z_of_means
    );
}

/// On the CPU: 24², 256 samples each, different seeds.
#[test]
fn tree_and_power_render_the_same_image_on_the_cpu() {
    let tree = render_with_variance(&mut CpuRenderer::new(&many_lights(6, 24, 3, "tree")), 256);
    let power = render_with_variance(&mut CpuRenderer::new(&many_lights(6, 24, 4, "power")), 256);
    assert_same_expectation("cpu tree against cpu power", &tree, &power);
}

/// On the GPU, whose tree render is tested against the CPU's render by power (one kernel, the
/// tree's), then traces the CPU's paths with the tree: one path per pixel, four seeds, at
/// gpu_vs_cpu.rs's bound (99% agree to 1e-3; the picks compare importances the two devices
/// round alike but for the last ulp of a sqrt).
#[test]
fn gpu_tree_renders_the_cpu_image_and_traces_its_paths() {
    let Some(ctx) = gpu() else { return };
    let tree = render_with_variance(
        &mut GpuRenderer::new(ctx, &many_lights(6, 24, 5, "tree")).unwrap(),
        256,
    );
    let power = render_with_variance(&mut CpuRenderer::new(&many_lights(6, 24, 6, "power")), 256);
    assert_same_expectation("gpu tree against cpu power", &tree, &power);
    let mut agreement = PathAgreement::default();
    for seed in [3, 4, 5, 6] {
        let scene = many_lights(6, 32, seed, "tree");
        agreement.add(
            &common::render_cpu(&scene, 1),
            &common::render_gpu(ctx, &scene, 1),
        );
    }
    agreement.check(0.99);
}

/// A scene with one finite emitter builds no tree (picking it costs nothing), nor does
/// bidirectional path tracing, which keeps the choice by power; the tree is part of the
/// settings a partial render's hash covers.
#[test]
fn no_tree_for_one_emitter_nor_for_bdpt() {
    let one = common::kernel_scene(
        &common::shipped_scene_text("cornell.toml")
            .replace("seed = 0", "seed = 0\nlight_sampler = \"tree\""),
    );
    assert_eq!(one.params.light_tree_nodes, 0);
    assert!(one.light_tree_nodes.is_empty());
    let bdpt = common::kernel_scene(
        &many_lights_toml(4, 8, "tree")
            .replace("max_bounces = 2", "max_bounces = 2\nintegrator = \"bdpt\""),
    );
    assert_eq!(bdpt.params.light_tree_nodes, 0);
    // A render with the tree does not resume or merge with one by power.
    use glint::render::partial::settings_hash;
    assert_ne!(
        settings_hash(&many_lights(4, 8, 0, "tree")),
        settings_hash(&many_lights(4, 8, 0, "power"))
    );
}

/// `--light-sampler` overrides `[render] light_sampler` and shows in `--json`; an unknown
/// name in the scene file is refused with the known ones.
#[test]
fn light_sampler_switch_on_the_command_line_and_in_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.toml"), many_lights_toml(3, 4, "power")).unwrap();
    let out = common::glint_ok(
        dir.path(),
        &[
            "render",
            "--cpu",
            "m.toml",
            "-o",
            "m.exr",
            "--json",
            "--light-sampler",
            "tree",
        ],
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["light_sampler"], "tree");
    let bad = many_lights_toml(3, 4, "bvh");
    let err = glint::scene::Scene::parse(&bad, std::path::Path::new("bad.toml")).unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("render.light_sampler") && message.contains("\"tree\", \"power\""),
        "{message}"
    );
}
