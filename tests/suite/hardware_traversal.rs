//! The hardware traversal (ray queries: shaders/traverse/hardware.wgsl, src/gpu/acceleration.rs)
//! on whole meshes: its leaks at a closed mesh's shared edges and vertices (10⁶ rays each on meshes
//! of 120 and 3968 triangles: 0 on lavapipe, Mesa 25.0.7), its paths against the CPU reference's
//! through the bunny, and a Z-test of its bunny against the CPU's. Closest hits are checked in
//! tests/suite/closest_hit.rs, coincident copies in tests/suite/coincident_copies.rs. Every test skips, saying
//! why, on a device without ray queries, unless GLINT_REQUIRE_RAY_QUERIES=1 (set by scripts/test).

use crate::common;
use common::probe::{run_probe_hardware, ProbeParams};
use common::{gpu_with_ray_queries, render_cpu, PathAgreement, MESH_SCENE_HEADER};
use glint::cpu::geometry::hit::NO_HIT;
use glint::gpu::{GpuRenderer, Traversal};
use glint::render::{render_image, Renderer};
use glint::scene::stress::StressMesh;
use glint::scene::Scene;

/// Issue 11's watertightness rays through the hardware traversal: 10⁶ rays from points inside
/// a closed tessellated sphere aimed exactly at its vertices, edge midpoints and points on its
/// edges (probe_watertight in tests/suite/shaders/probe.wgsl). The hardware proposes the candidates
/// and glint's watertight test decides them, so a ray leaks only where the hardware proposes
/// none of the triangles glint's test would hit. The count is reported; on lavapipe (Mesa
/// 25.0.7) it measured 0, and any leak fails the test, so a driver whose triangle test is
/// not watertight is noticed here.
#[test]
fn hardware_closed_mesh_leaks_at_edges_and_vertices() {
    let Some(ctx) = gpu_with_ray_queries() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut leaks_by_mesh = Vec::new();
    // The 120-triangle sphere of tests/suite/mesh.rs's GPU check, and a finer one.
    for (segments, rings, scale) in [(12, 6, 3.0), (64, 32, 3.0)] {
        StressMesh::displaced(segments, rings, 0.0)
            .write_ply(&dir.path().join("mesh.ply"))
            .unwrap();
        let path = dir.path().join("scene.toml");
        std::fs::write(
            &path,
            format!(
                "{MESH_SCENE_HEADER}[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\nscale = {scale}\n"
            ),
        )
        .unwrap();
        let scene = Scene::load(&path).unwrap().kernel_scene();
        let params = ProbeParams {
            count: 1_000_000,
            seed: 17,
            position: [0.1, -0.2, 0.05],
            // Origins within ±1 of the centre, well inside the facets.
            alpha: 2.0,
            ..Default::default()
        };
        let out = run_probe_hardware(ctx, "probe_watertight", params, &scene);
        let leaks = out.iter().filter(|v| v[0] == NO_HIT).count();
        eprintln!(
            "hardware traversal on {}: {leaks} of 10⁶ edge and vertex rays leaked through a closed \
             mesh of {} triangles",
            ctx.device_name(),
            scene.triangles.len()
        );
        leaks_by_mesh.push(leaks);
    }
    assert_eq!(
        leaks_by_mesh,
        [0, 0],
        "rays that slipped through the closed meshes"
    );
}

/// The hardware traversal traces the CPU reference's paths through the bunny (1 spp per pixel,
/// so pixels are paths; the 99% bound is tests/suite/gpu_vs_cpu.rs's, for the same reasons).
#[test]
fn hardware_and_cpu_trace_the_same_paths_through_the_bunny() {
    let Some(ctx) = gpu_with_ray_queries() else {
        return;
    };
    let mut agreement = PathAgreement::default();
    for seed in [3, 4] {
        let scene = common::sized(common::shipped_scene("bunny.toml"), 48, seed);
        let mut renderer = GpuRenderer::with_traversal(ctx, &scene, Traversal::Hardware).unwrap();
        let gpu = render_image(&mut renderer, 1, 1).unwrap();
        agreement.add(&render_cpu(&scene, 1), &gpu);
    }
    agreement.check(0.99);
}

/// GPU (hardware traversal) ≡ CPU on the bunny by the per-pixel Z-test of tests/suite/statistics.rs,
/// with its thresholds and reasons (97% of pixel channels within |z| ≤ 2.576, and |z| < 4 for
/// the difference of the image means), at 48² and 128 spp with different seeds: independent
/// estimates of the same image.
#[test]
fn hardware_renders_the_cpu_bunny() {
    let Some(ctx) = gpu_with_ray_queries() else {
        return;
    };
    use glint::image::compare::compare;
    let render = |renderer: &mut dyn Renderer| {
        while renderer.samples() < 128 {
            renderer.add_samples(32).unwrap();
        }
        (
            renderer.read_mean().unwrap(),
            renderer.read_variance().unwrap(),
        )
    };
    let scene = |seed| common::sized(common::shipped_scene("bunny.toml"), 48, seed);
    let a = render(&mut GpuRenderer::with_traversal(ctx, &scene(1), Traversal::Hardware).unwrap());
    let b = render(&mut glint::cpu::integrator::renderer::CpuRenderer::new(
        &scene(2),
    ));
    let z = compare(&a.0, &b.0, Some((&a.1, &b.1)))
        .unwrap()
        .z_test
        .unwrap();
    eprintln!(
        "bunny, hardware GPU vs CPU: pass rate {:.2}%, z of means {:.2}",
        100.0 * z.pass_rate,
        z.z_of_means
    );
    assert!(z.pass_rate >= 0.97, "{z:?}");
    assert!(z.z_of_means.abs() < 4.0, "{z:?}");
}
