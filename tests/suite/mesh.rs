//! Meshes and the BVH: traversal against brute force on 10⁵ rays (random, through vertices,
//! along edges, grazing spheres); 10⁶ rays from inside a closed mesh at its vertices and edges
//! with zero leaks, on the CPU and the GPU; GPU and CPU tracing the same paths through the bunny;
//! white furnaces with diffuse and mirror meshes and inside a closed emitting mesh; a 65,024-
//! triangle sphere against the analytic one by a Z-test widened by the tessellation error derived
//! here; cornell-mesh.toml against cornell.toml. Triangle emitters' χ² is in tests/suite/chi2.rs.

use crate::common;
use common::{gpu, render_cpu, render_gpu, PathAgreement, MESH_SCENE_HEADER};
use glam::Vec3;
use glint::cpu::core::ray::Ray;
use glint::cpu::core::rng::Rng;
use glint::cpu::geometry::hit::NO_HIT;
use glint::cpu::geometry::intersect::{closest_primitive, first_hit_is};
use glint::cpu::geometry::scene_geometry::Geometry;
use glint::cpu::scene_refs::SceneRefs;
use glint::kernel::KernelScene;
use glint::scene::stress::StressMesh;
use glint::scene::Scene;

/// A scene file in a temporary folder next to the stress mesh `mesh.ply` (segments × rings).
fn scene_with_stress_mesh(
    dir: &std::path::Path,
    segments: usize,
    rings: usize,
    toml: &str,
) -> Scene {
    StressMesh::new(segments, rings)
        .write_ply(&dir.join("mesh.ply"))
        .unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A stress mesh, 40 random spheres and 40 random quads, all in one BVH.
fn mixed_scene(dir: &std::path::Path) -> KernelScene {
    let mut rng = Rng::new(1, 2, 3, 4);
    let mut u = || rng.next_f32();
    let mut toml = MESH_SCENE_HEADER.to_string();
    toml += "[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\nscale = 3.0\nrotate = [10.0, 20.0, 30.0]\n";
    for _ in 0..40 {
        toml += &format!(
            "[[spheres]]\ncenter = [{}, {}, {}]\nradius = {}\nmaterial = \"white\"\n",
            8.0 * u() - 4.0,
            8.0 * u() - 4.0,
            8.0 * u() - 4.0,
            0.1 + 0.8 * u()
        );
    }
    for _ in 0..40 {
        let e1 = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 3.0;
        let e2 = e1
            .cross(Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5))
            .normalize()
            * (0.2 + 2.0 * u());
        toml += &format!(
            "[[quads]]\ncorner = [{}, {}, {}]\nu = [{}, {}, {}]\nv = [{}, {}, {}]\nmaterial = \"white\"\n",
            8.0 * u() - 4.0,
            8.0 * u() - 4.0,
            8.0 * u() - 4.0,
            e1.x,
            e1.y,
            e1.z,
            e2.x,
            e2.y,
            e2.z
        );
    }
    scene_with_stress_mesh(dir, 40, 20, &toml).kernel_scene()
}

fn unit_vector(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// 10⁵ rays: random ones from inside and outside the scene, rays aimed exactly at triangle
/// vertices and at points on their edges, and rays grazing spheres (aimed at their silhouette).
/// The BVH must find the brute-force closest hit, t and primitive: at a tie (a shared vertex,
/// say) both take the lowest primitive by the closest-hit rule. Shadow queries agree too.
#[test]
fn bvh_finds_the_brute_force_closest_hit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = mixed_scene(dir.path());
    assert!(!scene.bvh_nodes.is_empty());
    let refs = SceneRefs::of(&scene, &scene.params);
    let with_bvh = refs.geometry();
    let brute = Geometry {
        bvh_nodes: &[],
        bvh_primitives: &[],
        ..with_bvh
    };
    let mut rng = Rng::new(7, 0, 0, 11);
    let mut hits = 0;
    for i in 0..100_000u32 {
        let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 6.0;
        let dir = match i % 4 {
            0 => unit_vector(&mut rng),
            1 => {
                let t = &scene.triangles[(rng.next_f32() * scene.triangles.len() as f32) as usize
                    % scene.triangles.len()];
                (Vec3::from(t.v1) - origin).normalize()
            }
            2 => {
                let t = &scene.triangles[(rng.next_f32() * scene.triangles.len() as f32) as usize
                    % scene.triangles.len()];
                let a = rng.next_f32();
                (Vec3::from(t.v0) * a + Vec3::from(t.v2) * (1.0 - a) - origin).normalize()
            }
            _ => {
                let s = &scene.spheres[i as usize % scene.spheres.len()];
                let to_center = Vec3::from(s.center) - origin;
                let side = to_center.cross(unit_vector(&mut rng)).normalize();
                (Vec3::from(s.center) + s.radius * side - origin).normalize()
            }
        };
        let ray = Ray { origin, dir };
        let expected = closest_primitive(&brute, &ray);
        let found = closest_primitive(&with_bvh, &ray);
        assert_eq!(found, expected, "ray {i}: {ray:?}");
        if found.t == NO_HIT {
            continue;
        }
        hits += 1;
        assert!(
            first_hit_is(&with_bvh, &ray, found.primitive, found.index),
            "ray {i}"
        );
        if i % 16 == 0 {
            // A primitive that is not the first hit is occluded, with and without the BVH.
            let other = (found.index + 1) % scene.spheres.len() as u32;
            assert_eq!(
                first_hit_is(&with_bvh, &ray, 0, other),
                first_hit_is(&brute, &ray, 0, other) && expected.t == found.t,
                "ray {i}"
            );
        }
    }
    eprintln!("{hits} hits");
    assert!(hits > 50_000, "{hits}");
}

/// 10⁶ rays from points inside a closed mesh aimed exactly at its vertices and at points on its
/// edges (where two or more triangles meet): every one must hit the mesh. A non-watertight test
/// (Möller–Trumbore with a tolerance, say) lets some through between the triangles.
#[test]
fn closed_mesh_has_no_leaks_at_edges_and_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let toml = format!(
        "{MESH_SCENE_HEADER}[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\nscale = 2.0\n"
    );
    let scene = scene_with_stress_mesh(dir.path(), 64, 32, &toml).kernel_scene();
    let refs = SceneRefs::of(&scene, &scene.params);
    let geometry = refs.geometry();
    let mut rng = Rng::new(5, 0, 0, 9);
    let mut leaks = 0;
    let n = scene.triangles.len() as f32;
    for i in 0..1_000_000u32 {
        // Inside: the displaced sphere's radius is at least 2 × 0.92.
        let origin = unit_vector(&mut rng) * (1.5 * rng.next_f32());
        let t = &scene.triangles[((rng.next_f32() * n) as usize).min(scene.triangles.len() - 1)];
        let (a, b) = (Vec3::from(t.v0), Vec3::from(t.v1));
        let target = match i % 3 {
            0 => a,
            1 => 0.5 * (a + b),
            _ => a.lerp(b, rng.next_f32()),
        };
        let ray = Ray {
            origin,
            dir: (target - origin).normalize(),
        };
        if closest_primitive(&geometry, &ray).t == NO_HIT {
            leaks += 1;
        }
    }
    assert_eq!(leaks, 0, "rays that slipped through the closed mesh");
}

/// The GPU's BVH traversal traces the CPU's paths (the bunny in the Cornell box, 1 spp per
/// pixel, so pixels are paths; the 99% bound is tests/suite/gpu_vs_cpu.rs's, for the same reasons).
#[test]
fn gpu_and_cpu_trace_the_same_paths_through_the_bvh() {
    let Some(ctx) = gpu() else { return };
    let mut agreement = PathAgreement::default();
    for seed in [3, 4] {
        let scene = common::sized(common::shipped_scene("bunny.toml"), 48, seed);
        assert!(!scene.bvh_nodes.is_empty());
        agreement.add(&render_cpu(&scene, 1), &render_gpu(ctx, &scene, 1));
    }
    agreement.check(0.99);
}

/// The white furnace with meshes: under a uniform white sky, a closed white diffuse mesh and
/// a white mirror mesh (a tessellated sphere, convex, flat shaded) vanish, every pixel 1 up
/// to f32 rounding. (Not glass: in a faceted sphere, unlike a true one, rays can be trapped by
/// total internal reflection for more bounces than any cap.) (Smooth shading is not energy-conserving by design: directions that the
/// shading normal sends below the geometric surface are dropped so that no light leaks.) With max_bounces = 1 for the diffuse one, a ray that re-hit the
/// triangle it left would end at the cap and return 0, so this also shows the ray offsets work
/// for triangles.
#[test]
fn white_furnace_meshes_vanish() {
    let dir = tempfile::tempdir().unwrap();
    StressMesh::displaced(48, 24, 0.0)
        .write_ply(&dir.path().join("sphere.ply"))
        .unwrap();
    for (material, bounces, smooth) in [
        ("type = \"diffuse\"\ncolor = [1.0, 1.0, 1.0]", 1, false),
        ("type = \"diffuse\"\ncolor = [1.0, 1.0, 1.0]", 8, false),
        ("type = \"specular\"\ncolor = [1.0, 1.0, 1.0]", 1, false),
    ] {
        let text = format!(
            r#"
[camera]
eye = [0.0, 0.0, -4.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 35.0
[render]
width = 24
height = 24
spp = 4
max_bounces = {bounces}
background = [1.0, 1.0, 1.0]
russian_roulette = false
[materials.m]
{material}
[[meshes]]
file = "sphere.ply"
material = "m"
smooth = {smooth}
"#
        );
        let path = dir.path().join("furnace.toml");
        std::fs::write(&path, text).unwrap();
        let scene = Scene::load(&path).unwrap().kernel_scene();
        for (device, image) in common::render_both(&scene, 4) {
            let worst = common::largest_deviation(&image, 1.0);
            assert!(
                worst < 1e-5,
                "{device}, {material:?}, smooth {smooth}, B = {bounces}: off by {worst}"
            );
        }
    }
}

/// `cornell-mesh.toml` (walls from an OBJ file, through the BVH) renders `cornell.toml`'s image:
/// the per-pixel Z-test of tests/suite/statistics.rs, with its thresholds and reasons (97% of pixel
/// channels within |z| ≤ 2.576, and |z| < 4 for the difference of the image means), at 64²
/// and 256 spp with different seeds. The mesh is rendered on the GPU where there is one.
#[test]
fn cornell_mesh_renders_the_cornell_box() {
    use glint::image::compare::compare;
    use glint::render::Renderer;
    let render = |renderer: &mut dyn Renderer| {
        while renderer.samples() < 256 {
            renderer.add_samples(64).unwrap();
        }
        (
            renderer.read_mean().unwrap(),
            renderer.read_variance().unwrap(),
        )
    };
    let mesh = common::sized(common::shipped_scene("cornell-mesh.toml"), 64, 1);
    assert_eq!(mesh.triangles.len(), 10);
    assert!(!mesh.bvh_nodes.is_empty());
    let a = match gpu() {
        Some(ctx) => render(&mut glint::gpu::GpuRenderer::new(ctx, &mesh).unwrap()),
        None => render(&mut glint::cpu::integrator::renderer::CpuRenderer::new(
            &mesh,
        )),
    };
    let b = render(&mut glint::cpu::integrator::renderer::CpuRenderer::new(
        &common::cornell_at(64, 2),
    ));
    let z = compare(&a.0, &b.0, Some((&a.1, &b.1)))
        .unwrap()
        .z_test
        .unwrap();
    eprintln!(
        "cornell-mesh vs cornell: pass rate {:.2}%, z of means {:.2}",
        100.0 * z.pass_rate,
        z.z_of_means
    );
    assert!(z.pass_rate >= 0.97, "{z:?}");
    assert!(z.z_of_means.abs() < 4.0, "{z:?}");
}

/// The WGSL triangle test is watertight too: 10⁶ rays on the GPU (through the probe kernel,
/// tests/suite/shaders/probe.wgsl) from points inside a closed tessellated sphere, aimed exactly at
/// its vertices and edges, all hit it. (The probe's kernel scans every triangle, so the mesh is
/// small: 120 triangles.)
#[test]
fn gpu_closed_mesh_has_no_leaks_at_edges_and_vertices() {
    let Some(ctx) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    StressMesh::displaced(12, 6, 0.0)
        .write_ply(&dir.path().join("mesh.ply"))
        .unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(
        &path,
        format!("{MESH_SCENE_HEADER}[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\nscale = 3.0\n"),
    )
    .unwrap();
    let scene = Scene::load(&path).unwrap().kernel_scene();
    assert_eq!(scene.triangles.len(), 120);
    let params = common::probe::ProbeParams {
        count: 1_000_000,
        seed: 17,
        position: [0.1, -0.2, 0.05],
        // Origins within ±1 of the centre; the sphere's facets are at least 3 cos(30°) away.
        alpha: 2.0,
        ..Default::default()
    };
    let out = common::probe::run_probe(ctx, "probe_watertight", params, &scene);
    let leaks = out.iter().filter(|v| v[0] == NO_HIT).count();
    assert_eq!(
        leaks, 0,
        "rays that slipped through the closed mesh on the GPU"
    );
}

/// A finely tessellated sphere (smooth-shaded, 256 segments × 128 rings, 65,024 triangles)
/// renders the analytic sphere's image, up to the tessellation error derived here, on the
/// sphere's pixels away from its silhouette.
///
/// Scene: a diffuse sphere (ρ = 0.8, radius 1) 0.5 above a diffuse floor (0.5) under a white
/// sky (L = 1), two bounces: the light a point receives varies smoothly with its position and
/// normal (no hard terminator). With Δ = π/128 the largest angle between neighbouring
/// vertices, the differences from the analytic sphere are bounded by:
/// 1. the shading normal's error θ: |ΔE| ≤ L ∫|Δn·ω| dω = 2π L θ, radiance 2ρLθ. θ is
///    measured below on the mesh itself (area-weighted vertex normals; interpolated normals of
///    unit vertex vectors are radial to second order);
/// 2. directions between the geometric and the shading tangent planes carry nothing (no light
///    leaks): a lune of 2ε sr, cosine ≤ ε, with ε ≤ Δ the angle between the two normals: ΔE ≤
///    2Lε², radiance 2ρLε²/π;
/// 3. the hit point lies up to the sagitta s = 1 − cos(Δ/√2) inside the sphere, which shifts
///    the floor's outline as seen from it by at most s/g (g = 0.5, the gap to the floor): ΔE ≤
///    2π L s/g, radiance 2ρLs/g.
///
/// Their sum δ (about 1.6·10⁻³ here) is added to the per-pixel Z-test's threshold
/// (2.576 √(VA + VB) + δ, 97% of pixel channels must pass, as in tests/suite/statistics.rs) and to
/// the image means' (4σ + δ). Pixels within a pixel's diagonal plus s of the silhouette are
/// left out, where the outlines themselves differ.
#[test]
fn tessellated_sphere_matches_the_analytic_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let (segments, rings) = (256, 128);
    let mesh = StressMesh::displaced(segments, rings, 0.0);
    mesh.write_ply(&dir.path().join("sphere.ply")).unwrap();
    let normal_error = mesh
        .positions
        .iter()
        .zip(&mesh.normals)
        .map(|(p, n)| p.normalize().angle_between(*n))
        .fold(0.0f32, f32::max) as f64;
    let delta_angle = std::f64::consts::PI / rings as f64;
    let sagitta = 1.0 - (delta_angle / 2f64.sqrt()).cos();
    let (rho, sky, gap) = (0.8, 1.0, 0.5);
    let delta = 2.0 * rho * sky * normal_error
        + 2.0 * rho * sky * delta_angle * delta_angle / std::f64::consts::PI
        + 2.0 * rho * sky * sagitta / gap;
    eprintln!("vertex normal error {normal_error:.2e} rad, sagitta {sagitta:.2e}, δ = {delta:.2e}");
    let (size, vfov) = (32u32, 35.0f64);
    let header = format!(
        r#"
[camera]
eye = [0.0, 0.0, -4.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = {vfov:?}
[render]
width = {size}
height = {size}
spp = 1
max_bounces = 2
background = [{sky:?}, {sky:?}, {sky:?}]
[materials.ball]
type = "diffuse"
color = [{rho:?}, {rho:?}, {rho:?}]
[materials.floor]
type = "diffuse"
color = [0.5, 0.5, 0.5]
[[quads]]
corner = [-20.0, -1.5, -20.0]
u = [0.0, 0.0, 40.0]
v = [40.0, 0.0, 0.0]
material = "floor"
"#
    );
    let load = |name: &str, text: String, seed: u32| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        common::sized(Scene::load(&path).unwrap(), size, seed)
    };
    let tessellated = load(
        "tessellated.toml",
        format!("{header}[[meshes]]\nfile = \"sphere.ply\"\nmaterial = \"ball\"\n"),
        1,
    );
    let analytic = load(
        "analytic.toml",
        format!(
            "{header}[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"ball\"\n"
        ),
        2,
    );
    let a = match gpu() {
        Some(ctx) => common::render_with_variance(
            &mut glint::gpu::GpuRenderer::new(ctx, &tessellated).unwrap(),
            256,
        ),
        None => common::render_with_variance(
            &mut glint::cpu::integrator::renderer::CpuRenderer::new(&tessellated),
            256,
        ),
    };
    let b = common::render_with_variance(
        &mut glint::cpu::integrator::renderer::CpuRenderer::new(&analytic),
        256,
    );
    // Pixels whose centre ray passes within 1 − s − (half a pixel diagonal at the sphere) of
    // the centre.
    let pixel_angle = (vfov.to_radians() / 2.0).tan() * 2.0 / size as f64;
    let margin = sagitta + 4.0 * pixel_angle * std::f64::consts::SQRT_2 / 2.0;
    let (mut tested, mut passed) = (0usize, 0usize);
    let (mut sum_a, mut sum_b, mut sum_var) = (0.0f64, 0.0f64, 0.0f64);
    for y in 0..size {
        for x in 0..size {
            let ndc = |i: u32| {
                ((i as f64 + 0.5) / size as f64 * 2.0 - 1.0) * (vfov.to_radians() / 2.0).tan()
            };
            let d = glam::DVec3::new(-ndc(x), -ndc(y), 1.0).normalize();
            let impact = glam::DVec3::new(0.0, 0.0, -4.0).cross(d).length();
            if impact > 1.0 - margin {
                continue;
            }
            let i = (y * size + x) as usize;
            for c in 0..3 {
                let (va, vb) = (a.1.pixels[i][c] as f64, b.1.pixels[i][c] as f64);
                let diff = (a.0.pixels[i][c] - b.0.pixels[i][c]) as f64;
                tested += 1;
                passed += (diff.abs() <= 2.575_829 * (va + vb).sqrt() + delta) as usize;
                sum_a += a.0.pixels[i][c] as f64;
                sum_b += b.0.pixels[i][c] as f64;
                sum_var += va + vb;
            }
        }
    }
    let n = tested as f64;
    let (mean_diff, sigma) = ((sum_a - sum_b) / n, sum_var.sqrt() / n);
    eprintln!(
        "{tested} pixel channels: {:.2}% within the Z-test's threshold + δ; means differ by \
         {mean_diff:.2e} (σ {sigma:.2e}, δ {delta:.2e})",
        100.0 * passed as f64 / n
    );
    assert!(tested > 1000, "{tested}");
    assert!(passed as f64 >= 0.97 * n, "{passed} of {tested}");
    assert!(
        mean_diff.abs() <= 4.0 * sigma + delta,
        "{mean_diff} vs {sigma} + {delta}"
    );
}

/// The furnace (tests/suite/closed_form.rs) with the enclosing sphere a closed triangle mesh: the
/// camera inside a mesh that emits 0.5 and reflects half the light. Every path gathers
/// 0.5 + 0.25 + … = 1 − 2^−(B+1) after B bounces, exactly, if every ray meets the mesh and
/// its emission is counted once per vertex. With light sampling (each triangle an emitter,
/// MIS with the BSDF) it holds in expectation: the image mean within 5σ of its variance image.
#[test]
fn furnace_inside_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    StressMesh::displaced(24, 12, 0.0)
        .write_ply(&dir.path().join("sphere.ply"))
        .unwrap();
    let bounces = 6;
    let expected = 1.0 - 0.5f64.powi(bounces + 1);
    for light_sampling in [false, true] {
        let text = format!(
            r#"
[camera]
eye = [0.1, -0.2, 0.05]
target = [0.5, 0.3, 1.0]
up = [0.0, 1.0, 0.0]
vfov = 70.0
[render]
width = 16
height = 16
spp = 1
max_bounces = {bounces}
light_sampling = {light_sampling}
russian_roulette = false
[materials.shell]
type = "diffuse"
color = [0.5, 0.5, 0.5]
emission = [0.5, 0.5, 0.5]
[[meshes]]
file = "sphere.ply"
material = "shell"
scale = 3.0
smooth = false
"#
        );
        let path = dir.path().join("furnace.toml");
        std::fs::write(&path, text).unwrap();
        let scene = Scene::load(&path).unwrap().kernel_scene();
        for (device, mut renderer) in common::renderers(&scene) {
            let (image, variance) = common::render_with_variance(renderer.as_mut(), 256);
            if light_sampling {
                let sigma = (variance.mean() / image.pixels.len() as f64).sqrt();
                let z = (image.mean() - expected) / sigma;
                assert!(
                    z.abs() < 5.0,
                    "{device}: {} vs {expected} (z {z})",
                    image.mean()
                );
            } else {
                let worst = common::largest_deviation(&image, expected as f32);
                assert!(worst < 1e-5, "{device}: off by {worst}");
            }
        }
    }
}
