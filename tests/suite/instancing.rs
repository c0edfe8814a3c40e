//! `[[meshes]] instances`: a mesh file placed many times. An entry with two or more instances
//! whose materials neither emit, nor are alpha-tested or blended, nor map normals is stored
//! once, in its own coordinates, and traced through the two-level structure (one BVH per
//! mesh, instances as leaves of the scene's BVH: src/kernel/scene/acceleration.rs, shaders/traverse/blas.wgsl);
//! other entries are flattened into the scene's triangles as before (`load_placed`). The
//! two-level scene renders the flattened one's image (the same paths, up to the rounding of
//! testing rays in each instance's coordinates) on both devices, finds the brute-force scan's
//! closest hit on both, and orders coincident instances by the closest-hit rule. Bad instances
//! are errors that name `meshes[i].instances[j].key`, and copied instances whose copies would
//! not fit are refused before anything is copied.

use crate::common;
use common::probe::{run_probe_bvh, ProbeParams};
use common::{gpu, render_cpu, render_gpu, MESH_SCENE_HEADER};
use glam::{Mat4, Vec3};
use glint::cpu::core::ray::Ray;
use glint::cpu::core::rng::Rng;
use glint::cpu::geometry::hit::NO_HIT;
use glint::cpu::geometry::instance::transform_point;
use glint::cpu::geometry::intersect::{
    closest_primitive, escapes, first_hit_is, scan_closest_primitive,
};
use glint::cpu::geometry::scene_geometry::Geometry;
use glint::cpu::scene_refs::SceneRefs;
use glint::kernel::types::{NO_INSTANCE, PRIMITIVE_QUAD};
use glint::kernel::KernelScene;
use glint::scene::stress::StressMesh;
use glint::scene::{Scene, SceneError};
use std::path::Path;

/// The placements the tests use: translated, rotated, scaled uniformly and per axis, and two
/// overlapping in part.
const PLACEMENTS: [&str; 4] = [
    "translate = [-2.0, 0.0, 0.0]",
    "translate = [2.0, 0.5, 1.0], rotate = [0.0, 90.0, 0.0], scale = 1.5",
    "translate = [0.0, -1.5, 0.0], rotate = [30.0, 0.0, 45.0], scale = [1.0, 0.5, 2.0]",
    "translate = [-1.5, 0.25, 0.0]",
];

/// A scene file in `dir` next to a small stress mesh (`mesh.ply`), loaded.
fn load(dir: &Path, toml: &str) -> Result<Scene, SceneError> {
    let mesh = dir.join("mesh.ply");
    if !mesh.exists() {
        StressMesh::new(24, 12).write_ply(&mesh).unwrap();
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    Scene::load(&path)
}

/// An emitting material, for [`instanced_and_flattened`]'s `material`.
const LAMP: &str = "\n[materials.lamp]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\nemission = [1.0, 0.5, 0.25]\n";

/// The mesh placed by `instances`, and by one `[[meshes]]` entry per placement, in `material`
/// (`white`, or `lamp` with [`LAMP`] defined).
fn instanced_and_flattened(dir: &Path, material: &str) -> (Scene, Scene) {
    let header = format!("{MESH_SCENE_HEADER}{LAMP}");
    let list = PLACEMENTS.map(|p| format!("{{ {p} }}")).join(", ");
    let instanced = format!(
        "{header}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"{material}\"\ninstances = [{list}]\n"
    );
    let mut flattened = header.clone();
    for p in PLACEMENTS {
        // An inline table's keys, one per line, are the entry's own.
        let keys = p
            .replace(", rotate", "\nrotate")
            .replace(", scale", "\nscale");
        flattened +=
            &format!("\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"{material}\"\n{keys}\n");
    }
    let instanced = load(dir, &instanced).unwrap_or_else(|e| panic!("{e}"));
    let flattened = load(dir, &flattened).unwrap_or_else(|e| panic!("{e}"));
    (instanced, flattened)
}

fn lit(scene: Scene) -> KernelScene {
    // Under a white sky, so that every path that escapes carries light.
    let mut scene = scene;
    scene.render.background = Vec3::ONE;
    common::sized(scene, 32, 7)
}

/// An opaque mesh with instances is stored once: one mesh of its triangles with four
/// placements, the kernel's triangles those once, four instances; placed, its triangles are
/// the flattened scene's, their vertices bit for bit (the same matrices, the mesh's own being
/// the identity), their normals to rounding (normalised once more).
#[test]
fn opaque_instances_are_stored_once() {
    let dir = tempfile::tempdir().unwrap();
    let (instanced, flattened) = instanced_and_flattened(dir.path(), "white");
    let per_mesh = StressMesh::new(24, 12).indices.len();
    assert!(instanced.triangles.is_empty());
    assert_eq!(instanced.instanced.len(), 1);
    assert_eq!(instanced.instanced[0].triangles.len(), per_mesh);
    assert_eq!(instanced.instanced[0].placements.len(), 4);
    assert_eq!(instanced.placed_triangle_count(), 4 * per_mesh as u64);
    let placed = instanced.flattened();
    assert_eq!(placed.triangles.len(), flattened.triangles.len());
    for (a, b) in placed.triangles.iter().zip(&flattened.triangles) {
        assert_eq!(a.vertices, b.vertices);
        if let (Some(na), Some(nb)) = (a.normals, b.normals) {
            for (x, y) in na.iter().zip(nb) {
                assert!((*x - y).abs().max_element() < 1e-6, "{x} {y}");
            }
        } else {
            assert_eq!(a.normals, b.normals);
        }
    }
    let kernel = lit(instanced);
    assert_eq!(kernel.triangles.len(), per_mesh);
    assert_eq!(kernel.instances.len(), 4);
    assert_eq!(kernel.params.triangle_count, 0);
}

/// The same image on the CPU: at 1 spp with the same seed, each pixel is one path, and 99% of
/// the instanced scene's paths are the flattened scene's to 1e-3 (tests/suite/gpu_vs_cpu.rs's bound:
/// a ray tested in an instance's coordinates rounds differently, and a path that grazes an
/// edge may go another way); and independent renders (other seeds, 64 spp) pass the
/// per-pixel Z-test of tests/suite/statistics.rs with its thresholds.
#[test]
fn instances_are_the_flattened_meshes_on_the_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let (instanced, flattened) = instanced_and_flattened(dir.path(), "white");
    let (instanced_kernel, flattened_kernel) = (lit(instanced.clone()), lit(flattened.clone()));
    assert!(!instanced_kernel.instances.is_empty() && flattened_kernel.instances.is_empty());
    common::assert_paths_agree(
        &render_cpu(&flattened_kernel, 1),
        &render_cpu(&instanced_kernel, 1),
        0.99,
    );
    use glint::image::compare::compare;
    use glint::render::Renderer;
    let render = |scene: &KernelScene| {
        let mut renderer = glint::cpu::integrator::renderer::CpuRenderer::new(scene);
        while renderer.samples() < 64 {
            renderer.add_samples(16).unwrap();
        }
        (
            renderer.read_mean().unwrap(),
            renderer.read_variance().unwrap(),
        )
    };
    let sized = |scene: &Scene, seed| {
        let mut scene = scene.clone();
        scene.render.background = Vec3::ONE;
        common::sized(scene, 24, seed)
    };
    let a = render(&sized(&instanced, 1));
    let b = render(&sized(&flattened, 2));
    let z = compare(&a.0, &b.0, Some((&a.1, &b.1)))
        .unwrap()
        .z_test
        .unwrap();
    eprintln!(
        "instanced vs flattened, CPU: pass rate {:.2}%, z of means {:.2}",
        100.0 * z.pass_rate,
        z.z_of_means
    );
    assert!(z.pass_rate >= 0.97, "{z:?}");
    assert!(z.z_of_means.abs() < 4.0, "{z:?}");
}

/// On the GPU the instanced scene traces the flattened scene's paths, and the CPU's (1 spp,
/// so pixels are paths; tests/suite/gpu_vs_cpu.rs's 99% agreement bound).
#[test]
fn instances_are_the_flattened_meshes_on_the_gpu() {
    let Some(ctx) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (instanced, flattened) = instanced_and_flattened(dir.path(), "white");
    let (instanced, flattened) = (lit(instanced), lit(flattened));
    let image = render_gpu(ctx, &instanced, 1);
    common::assert_paths_agree(&render_gpu(ctx, &flattened, 1), &image, 0.99);
    common::assert_paths_agree(&render_cpu(&instanced, 1), &image, 0.99);
}

/// Emitting instances are flattened, as before: emitters like the flattened meshes'
/// triangles, the same emitter table (each placed triangle sampled by its power), to the bit,
/// and the same CPU image.
#[test]
fn emitting_instances_are_sampled_as_flattened_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let (instanced, flattened) = instanced_and_flattened(dir.path(), "lamp");
    assert!(instanced.instanced.is_empty());
    let (instanced, flattened) = (
        common::sized(instanced, 24, 3),
        common::sized(flattened, 24, 3),
    );
    let per_mesh = StressMesh::new(24, 12).indices.len();
    assert_eq!(instanced.emitters.len(), 4 * per_mesh);
    // Debug prints each f32 so that it reads back to the same bits.
    assert_eq!(
        format!("{:?}", instanced.emitters),
        format!("{:?}", flattened.emitters)
    );
    assert_eq!(
        render_cpu(&instanced, 2).pixels,
        render_cpu(&flattened, 2).pixels
    );
}

/// The mesh's own transform applies first, then the instance's: scale 2 then translate by x
/// is 2p + x (the other order would give 2p + 2x).
#[test]
fn the_mesh_transform_comes_before_the_instance() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\nscale = 2.0\n\
         rotate = [0.0, 0.0, 90.0]\ninstances = [{{ translate = [1.0, 0.0, 0.0] }}, {{ scale = 3.0 }}]\n"
    );
    let scene = load(dir.path(), &text)
        .unwrap_or_else(|e| panic!("{e}"))
        .flattened();
    let plain = load(
        dir.path(),
        &format!("{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\n"),
    )
    .unwrap();
    let n = plain.triangles.len();
    assert_eq!(scene.triangles.len(), 2 * n);
    let mesh = Mat4::from_rotation_z(90f32.to_radians()) * Mat4::from_scale(Vec3::splat(2.0));
    let placements = [
        Mat4::from_translation(Vec3::X) * mesh,
        Mat4::from_scale(Vec3::splat(3.0)) * mesh,
    ];
    for (k, placement) in placements.iter().enumerate() {
        for (placed, original) in scene.triangles[k * n..(k + 1) * n]
            .iter()
            .zip(&plain.triangles)
        {
            for (p, q) in placed.vertices.iter().zip(original.vertices) {
                let expected = placement.transform_point3(q);
                assert!((*p - expected).abs().max_element() < 1e-5, "{p} {expected}");
            }
        }
    }
}

/// Every kind of bad instance is refused with the instance and key named, at its line.
#[test]
fn bad_instances_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let header_lines = MESH_SCENE_HEADER.lines().count();
    let cases: [(&str, &[&str]); 8] = [
        ("[]", &["meshes[0].instances:", "at least once"]),
        ("[1.0]", &["meshes[0].instances[0]:", "must be a table"]),
        (
            "[{}, { scale = 0.0 }]",
            &["meshes[0].instances[1].scale:", "finite and > 0"],
        ),
        (
            "[{ scale = [1.0, -1.0, 1.0] }]",
            &["meshes[0].instances[0].scale:", "finite and > 0"],
        ),
        (
            "[{ translate = [1.0, 2.0] }]",
            &["meshes[0].instances[0].translate:", "exactly three"],
        ),
        (
            "[{ rotate = [0.0, nan, 0.0] }]",
            &["meshes[0].instances[0].rotate:", "finite"],
        ),
        (
            "[{ translate = [1e9, 0.0, 0.0] }]",
            &["meshes[0].instances[0].translate:", "within"],
        ),
        (
            "[{ translate = [0.0, 0.0, 0.0], shear = 1.0 }]",
            &["meshes[0].instances[0].shear:", "unknown key"],
        ),
    ];
    for (instances, needles) in cases {
        let text = format!(
            "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\ninstances = {instances}\n"
        );
        let e = load(dir.path(), &text).expect_err(instances);
        let message = e.to_string();
        assert!(message.contains("scene.toml:"), "{message}");
        // The line of `instances` (the header, a blank line, then four lines).
        assert_eq!(e.position.map(|p| p.0), Some(header_lines + 5), "{message}");
        for needle in needles {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
}

/// `count` instances of `file` in `material`, on a 100-wide grid.
fn many(file: &str, material: &str, count: usize) -> String {
    let list = (0..count)
        .map(|i| format!("{{ translate = [{}.0, {}.0, 0.0] }}", i % 100, i / 100))
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "{MESH_SCENE_HEADER}{LAMP}\n[[meshes]]\nfile = \"{file}\"\nmaterial = \"{material}\"\ninstances = [{list}]\n"
    )
}

/// Copied instances (here emitting ones) are bounded: 10⁴ and 200 instances of a
/// 2·10⁵-triangle mesh (2·10⁹ and 4·10⁷ triangles) are more than one mesh's copies may place
/// (2²⁵), and the error says so before any copy is made (the first would otherwise need
/// hundreds of GiB). Stored once (opaque, not emitting), the same 10⁴ instances load: 2·10⁵
/// triangles held, 2·10⁹ placed.
#[test]
fn instance_counts_are_bounded_before_copying() {
    let dir = tempfile::tempdir().unwrap();
    let big = StressMesh::new(400, 251);
    assert_eq!(big.indices.len(), 200_000);
    big.write_ply(&dir.path().join("big.ply")).unwrap();
    for count in [10_000, 200] {
        let e = load(dir.path(), &many("big.ply", "lamp", count)).expect_err("too many triangles");
        let message = e.to_string();
        let placed = format!("placed {count} times");
        for needle in ["meshes[0].file", &placed, "more than the 33554432"] {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
    let scene =
        load(dir.path(), &many("big.ply", "white", 10_000)).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.triangles.is_empty());
    assert_eq!(scene.instanced[0].triangles.len(), 200_000);
    assert_eq!(scene.placed_triangle_count(), 2_000_000_000);
}

/// A scene for closest hits: the mesh at six placements, the last two coincident copies of the
/// first (instances 4 and 5 at instance 0's place: only the rule orders them), in front of a
/// wall (quad 0, behind everything), with a sphere and a plain copy of the mesh (flattened,
/// one instance) among them.
fn hits_scene(dir: &Path) -> KernelScene {
    let mut placements: Vec<&str> = PLACEMENTS.to_vec();
    placements.extend([PLACEMENTS[0], PLACEMENTS[0]]);
    let list = placements
        .iter()
        .map(|p| format!("{{ {p} }}"))
        .collect::<Vec<_>>()
        .join(", ");
    let toml = format!(
        "{MESH_SCENE_HEADER}\n[[quads]]\ncorner = [-20.0, -20.0, 6.0]\nu = [40.0, 0.0, 0.0]\n\
         v = [0.0, 40.0, 0.0]\nmaterial = \"white\"\n\
         [[spheres]]\ncenter = [0.5, 1.5, -1.0]\nradius = 0.6\nmaterial = \"white\"\n\
         [[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\ntranslate = [1.0, -0.5, -2.0]\n\
         instances = [{{ scale = 0.5 }}]\n\
         [[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\ninstances = [{list}]\n"
    );
    let scene = load(dir, &toml).unwrap_or_else(|e| panic!("{e}"));
    let kernel = scene.kernel_scene();
    assert_eq!(kernel.instances.len(), 6);
    assert!(kernel.params.triangle_count > 0);
    kernel
}

/// A ray from the camera's side, aimed at a random point of a random instance's random
/// triangle (placed), or anywhere.
fn random_ray(scene: &KernelScene, rng: &mut Rng) -> Ray {
    let mut u = || rng.next_f32();
    let origin = Vec3::new(u() * 8.0 - 4.0, u() * 8.0 - 4.0, -8.0 + u() * 4.0);
    let (a, b, c) = (u(), u(), u());
    let pick = |n: usize, x: f32| ((x * n as f32) as usize).min(n - 1);
    let inst = &scene.instances[pick(scene.instances.len(), a)];
    let tri =
        &scene.triangles[inst.first_triangle as usize + pick(inst.triangle_count as usize, b)];
    let local = Vec3::from(tri.v0).lerp(Vec3::from(tri.v1), c);
    let aim = if u() < 0.9 {
        transform_point(&inst.to_world, local)
    } else {
        Vec3::new(u(), u(), 0.0) * 10.0 - 5.0
    };
    Ray {
        origin,
        dir: (aim - origin).normalize(),
    }
}

/// 10⁵ rays on the CPU: the two-level traversal finds the scan's closest hit (every primitive
/// and every instance's every triangle, in the rule's order), bit for bit, with its instance;
/// shadow rays agree (any hit; the wall behind is never first where an instance is in front);
/// and the coincident instances are met, each hit on them on the lowest (instance 0).
#[test]
fn instanced_closest_hits_are_the_scans_on_the_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let scene = hits_scene(dir.path());
    let refs = SceneRefs::of(&scene, &scene.params);
    let geometry = refs.geometry();
    let scan = Geometry {
        bvh_nodes: &[],
        bvh_primitives: &[],
        ..geometry
    };
    let mut rng = Rng::new(11, 0, 0, 5);
    let (mut through_instances, mut on_copies) = (0, 0);
    for i in 0..100_000u32 {
        let ray = random_ray(&scene, &mut rng);
        let expected = scan_closest_primitive(&scan, &ray);
        let found = closest_primitive(&geometry, &ray);
        assert_eq!(
            (
                found.t.to_bits(),
                found.primitive,
                found.index,
                found.instance
            ),
            (
                expected.t.to_bits(),
                expected.primitive,
                expected.index,
                expected.instance
            ),
            "ray {i}: {ray:?}"
        );
        assert_eq!(escapes(&geometry, &ray), expected.t == NO_HIT, "ray {i}");
        if expected.t == NO_HIT {
            continue;
        }
        if expected.instance == NO_INSTANCE {
            assert!(
                first_hit_is(&geometry, &ray, expected.primitive, expected.index),
                "ray {i}"
            );
        } else {
            through_instances += 1;
            // Instances 4 and 5 are instance 0's copies: never the hit.
            assert!(expected.instance < 4, "ray {i}: {expected:?}");
            on_copies += (expected.instance == 0) as u32;
            assert!(
                !first_hit_is(&geometry, &ray, PRIMITIVE_QUAD, 0),
                "ray {i}: the wall is behind instance {}",
                expected.instance
            );
        }
    }
    eprintln!("{through_instances} hits through instances, {on_copies} on the coincident ones");
    assert!(through_instances > 50_000, "{through_instances}");
    assert!(on_copies > 5_000, "{on_copies}");
}

/// The same on the GPU, through the probe kernel's closest-hit entry point
/// (tests/suite/shaders/probe.wgsl): the kernel's two-level traversal and its scan find the same
/// hit, bit for bit, through the same instance, for 2.5·10⁴ rays, and its shadow tests agree.
#[test]
fn instanced_closest_hits_are_the_scans_on_the_gpu() {
    let Some(ctx) = gpu() else { return };
    check_closest_hits_on_the_gpu(ctx, run_probe_bvh, 25_000);
}

/// The probe's closest-hit check (see [`instanced_closest_hits_are_the_scans_on_the_gpu`]) on
/// [`hits_scene`] for `rays` rays, in the kernel variant `probe` runs.
fn check_closest_hits_on_the_gpu(
    ctx: &glint::gpu::GpuContext,
    probe: fn(&glint::gpu::GpuContext, &str, ProbeParams, &KernelScene) -> Vec<[f32; 4]>,
    rays: u32,
) {
    let dir = tempfile::tempdir().unwrap();
    let scene = hits_scene(dir.path());
    let params = ProbeParams {
        count: 2 * rays,
        seed: 31,
        position: [-1.0, 0.0, 0.0],
        alpha: 5.0,
        normal: [1.0; 3],
        ..Default::default()
    };
    let out = probe(ctx, "probe_closest_hit", params, &scene);
    let (mut hits, mut wrong) = (0, Vec::new());
    for (i, pair) in out.chunks(2).enumerate() {
        let (found, expected) = (pair[0], pair[1]);
        let hit = |v: [f32; 4]| (v[0].to_bits(), v[1].to_bits(), v[2].to_bits());
        let flags = found[3] as u32;
        let want = if expected[0] == NO_HIT { 4 } else { 1 };
        hits += (expected[0] != NO_HIT) as u32;
        if hit(found) != hit(expected) || flags != want {
            wrong.push(format!(
                "ray {i}: found {found:?} (flags {flags}), expected {expected:?}"
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "{} disagreements in {rays} rays, the first: {:#?}",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );
    assert!(hits > rays / 4, "{hits}");
}

/// Coincident instances render as one: the mesh placed twice at the same place renders the
/// image of it placed once, bit for bit on the CPU and on the GPU (the lower instance is
/// always the hit, and its transform is the same).
#[test]
fn coincident_instances_render_as_one() {
    let dir = tempfile::tempdir().unwrap();
    let scene = |list: &str| {
        let text = format!(
            "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\ninstances = [{list}]\n"
        );
        lit(load(dir.path(), &text).unwrap_or_else(|e| panic!("{e}")))
    };
    let (one, p) = (
        "{ rotate = [10.0, 20.0, 0.0] }",
        "{ translate = [3.0, 0.0, 0.0] }",
    );
    let single = scene(&format!("{one}, {p}"));
    let doubled = scene(&format!("{one}, {one}, {p}, {one}"));
    assert_eq!(doubled.instances.len(), 4);
    assert_eq!(
        render_cpu(&single, 1).pixels,
        render_cpu(&doubled, 1).pixels
    );
    if let Some(ctx) = gpu() {
        assert_eq!(
            render_gpu(ctx, &single, 1).pixels,
            render_gpu(ctx, &doubled, 1).pixels
        );
    }
}

/// A glTF file of one triangle (accessor 0) with three instances' TRANSLATION (1), ROTATION (2)
/// and SCALE (3) accessors, and a SCALE with one element too few (4); `nodes` is its node
/// list (the scene places node 0).
fn instancing_gltf(nodes: &str) -> String {
    use base64::Engine as _;
    let floats: [&[f32]; 4] = [
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        &[-1.0, 0.0, 0.0, 1.0, 0.5, 0.0, 0.0, -1.0, 0.25],
        &[
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            0.382_683_43,
            0.0,
            0.923_879_5,
            0.5,
            0.5,
            0.5,
            0.5,
        ],
        &[1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 1.0, 0.5, 3.0],
    ];
    let mut bytes = Vec::new();
    let mut views = Vec::new();
    for f in floats {
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}}}"#,
            bytes.len(),
            4 * f.len()
        ));
        bytes.extend(f.iter().flat_map(|x| x.to_le_bytes()));
    }
    let accessor = |view: usize, kind: &str, count: usize| {
        format!(
            r#"{{"bufferView": {view}, "componentType": 5126, "count": {count}, "type": "{kind}"}}"#
        )
    };
    let accessors = [
        accessor(0, "VEC3", 3),
        accessor(1, "VEC3", 3),
        accessor(2, "VEC4", 3),
        accessor(3, "VEC3", 3),
        accessor(3, "VEC3", 2),
    ]
    .join(", ");
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["EXT_mesh_gpu_instancing"],
"buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
"bufferViews": [{}], "accessors": [{accessors}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
"nodes": [{nodes}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
        bytes.len(),
        base64::engine::general_purpose::STANDARD.encode(&bytes),
        views.join(", ")
    )
}

/// The instances' node: moved by its own translation, then the instances' T·R·S.
const INSTANCED_NODE: &str = r#"{"mesh": 0, "translation": [0.0, 0.0, 5.0], "extensions":
{"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 1, "ROTATION": 2, "SCALE": 3}}}}"#;

/// `model.gltf` holding `gltf`, placed by a scene in `dir`.
fn load_gltf(dir: &Path, gltf: &str) -> Result<Scene, SceneError> {
    std::fs::write(dir.join("model.gltf"), gltf).unwrap();
    load(
        dir,
        &format!("{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"model.gltf\"\nmaterial = \"white\"\n"),
    )
}

/// EXT_mesh_gpu_instancing places the mesh once per instance, each at the node's transform
/// times its T·R·S: the same triangles, bit for bit, as child nodes with those T·R·S under a
/// node with the instanced node's translation.
#[test]
fn gltf_gpu_instancing_is_child_nodes() {
    let dir = tempfile::tempdir().unwrap();
    // Both are stored once (one triangle, three placements); placed, they are compared.
    let instanced = load_gltf(dir.path(), &instancing_gltf(INSTANCED_NODE))
        .unwrap_or_else(|e| panic!("{e}"))
        .flattened();
    // Listed last first: the hierarchy's walk takes the last child first.
    let children = r#"{"translation": [0.0, 0.0, 5.0], "children": [3, 2, 1]},
{"mesh": 0, "translation": [-1.0, 0.0, 0.0]},
{"mesh": 0, "translation": [1.0, 0.5, 0.0], "rotation": [0.0, 0.38268343, 0.0, 0.9238795], "scale": [2.0, 2.0, 2.0]},
{"mesh": 0, "translation": [0.0, -1.0, 0.25], "rotation": [0.5, 0.5, 0.5, 0.5], "scale": [1.0, 0.5, 3.0]}"#;
    let nodes = load_gltf(dir.path(), &instancing_gltf(children))
        .unwrap_or_else(|e| panic!("{e}"))
        .flattened();
    assert_eq!(instanced.triangles.len(), 3);
    assert_eq!(instanced.triangles, nodes.triangles);
    // The second instance: scaled by 2, turned 45° about y, moved by (1, 0.5, 0) and (0, 0, 5).
    let expected = Mat4::from_translation(Vec3::new(1.0, 0.5, 5.0))
        * Mat4::from_rotation_y(45f32.to_radians())
        * Mat4::from_scale(Vec3::splat(2.0));
    let v = instanced.triangles[1].vertices[1];
    assert!(
        (v - expected.transform_point3(Vec3::X)).length() < 1e-5,
        "{v}"
    );
}

/// Bad EXT_mesh_gpu_instancing data is an error naming the node, the attribute and the fault.
#[test]
fn bad_gltf_gpu_instancing_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let field = "nodes[0].extensions.EXT_mesh_gpu_instancing.attributes";
    let cases: [(&str, &[&str]); 5] = [
        (
            r#"{"TRANSLATION": 1, "SCALE": 4}"#,
            &["SCALE", "holds 2", "holds 3"],
        ),
        (
            r#"{"TRANSLATION": 2}"#,
            &["TRANSLATION: accessors[2]", "VEC4"],
        ),
        (
            r#"{"TRANSLATION": 9}"#,
            &["TRANSLATION: accessor 9 does not exist"],
        ),
        (r#"{"SHEAR": 1}"#, &["SHEAR: not an attribute"]),
        (r#"{"_ID": 1}"#, &["names none of"]),
    ];
    for (attributes, needles) in cases {
        let node = format!(
            r#"{{"mesh": 0, "extensions": {{"EXT_mesh_gpu_instancing": {{"attributes": {attributes}}}}}}}"#
        );
        let e = load_gltf(dir.path(), &instancing_gltf(&node)).expect_err(attributes);
        let message = e.to_string();
        assert!(message.contains(field), "{message}");
        for needle in needles {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
}

/// A glTF file's punctual lights are placed with every instance: tests/models'
/// lights-cameras.gltf (3 lights, its point light at (1, 3, 1)) placed twice has 6, the
/// second instance's point light moved with it.
#[test]
fn gltf_lights_are_placed_with_every_instance() {
    use glint::scene::light::LightKind;
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models/lights-cameras.gltf"),
        dir.path().join("model.gltf"),
    )
    .unwrap();
    let scene = load(
        dir.path(),
        &format!(
            "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"model.gltf\"\nmaterial = \"white\"\n\
             instances = [{{}}, {{ translate = [0.0, 0.0, 2.0] }}]\n"
        ),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.lights.len(), 6);
    for (light, z) in [(&scene.lights[0], 1.0), (&scene.lights[3], 3.0)] {
        assert!(
            matches!(light.kind, LightKind::Point { position, .. } if position == Vec3::new(1.0, 3.0, z)),
            "{light:?}"
        );
    }
}

// The hardware traversal (ray queries) of instances: one BLAS per instanced mesh, one TLAS
// instance per placement (src/gpu/acceleration.rs, shaders/traverse/hardware.wgsl).

/// Ray queries find the scan's closest hit through the same instance, bit for bit, and agree
/// on shadow rays, on [`hits_scene`] (coincident instances, where only the rule decides, and
/// an instance overlapping another), for the software check's 2.5·10⁴ rays. Not 10⁵: there
/// one grazing ray finds a triangle behind the scan's, a limit of lavapipe's triangle test
/// that the scene without its instanced mesh meets too (README.md, "Hardware traversal").
#[test]
fn instanced_closest_hits_are_the_scans_with_ray_queries() {
    let Some(ctx) = common::gpu_with_ray_queries() else {
        return;
    };
    check_closest_hits_on_the_gpu(ctx, common::probe::run_probe_hardware, 25_000);
}

/// `--traversal hardware` traces scenes with instances, and `auto` picks as for any scene; the
/// hardware traversal traces the software traversal's paths and the CPU's (1 spp, so pixels
/// are paths; tests/suite/gpu_vs_cpu.rs's 99% bound, as the instanced scenes above), and draws
/// coincident instances as one, bit for bit.
#[test]
fn hardware_traversal_traces_instances() {
    use glint::gpu::renderer::GpuRenderer;
    use glint::gpu::traversal::{Traversal, TraversalChoice};
    use glint::render::render_image;
    let Some(ctx) = common::gpu_with_ray_queries() else {
        return;
    };
    assert_eq!(
        TraversalChoice::Hardware.resolve(ctx).unwrap(),
        Traversal::Hardware
    );
    let dir = tempfile::tempdir().unwrap();
    let (instanced, _) = instanced_and_flattened(dir.path(), "white");
    let scene = lit(instanced);
    let hardware = |scene: &KernelScene| {
        let mut renderer = GpuRenderer::with_traversal(ctx, scene, Traversal::Hardware).unwrap();
        render_image(&mut renderer, 1, 1).unwrap()
    };
    let image = hardware(&scene);
    common::assert_paths_agree(&render_gpu(ctx, &scene, 1), &image, 0.99);
    common::assert_paths_agree(&render_cpu(&scene, 1), &image, 0.99);
    let coincident = |list: &str| {
        let text = format!(
            "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\ninstances = [{list}]\n"
        );
        lit(load(dir.path(), &text).unwrap_or_else(|e| panic!("{e}")))
    };
    let (one, p) = (
        "{ rotate = [10.0, 20.0, 0.0] }",
        "{ translate = [3.0, 0.0, 0.0] }",
    );
    assert_eq!(
        hardware(&coincident(&format!("{one}, {p}"))).pixels,
        hardware(&coincident(&format!("{one}, {one}, {p}, {one}"))).pixels
    );
}

/// The hardware traversal's geometry keeps the two levels: [`hits_scene`]'s instanced mesh is
/// one BLAS input of its triangles in its own coordinates (those of its own BVH, each once),
/// which its six placements share, after the triangles placed as they are and the boxes; the
/// references of each part start where its instances' custom data will point.
#[test]
fn hardware_geometry_holds_each_instanced_mesh_once() {
    use glint::gpu::acceleration::{widened_triangle, HardwareGeometry};
    let dir = tempfile::tempdir().unwrap();
    let scene = hits_scene(dir.path());
    let geometry = HardwareGeometry::of(&scene);
    assert_eq!(geometry.meshes.len(), 1);
    assert_eq!(geometry.instance_meshes, [0; 6]);
    let inst = &scene.instances[0];
    let own = scene.params.triangle_count as usize;
    assert_eq!(inst.first_triangle as usize, own);
    assert_eq!(geometry.triangle_references.len(), own);
    assert_eq!(geometry.box_references.len(), 2);
    let mesh = &geometry.meshes[0];
    assert_eq!(mesh.triangle_references.len(), inst.triangle_count as usize);
    assert_eq!(mesh.vertices.len(), 3 * mesh.triangle_references.len());
    for (k, &reference) in mesh.triangle_references.iter().enumerate() {
        let t = &scene.triangles[(reference & 0x3fff_ffff) as usize];
        assert_eq!(
            mesh.vertices[3 * k..3 * k + 3],
            widened_triangle(t.v0, t.v1, t.v2)
        );
    }
    assert_eq!(geometry.mesh_reference_starts(), [own + 2]);
    let references = geometry.references();
    assert_eq!(&references[own + 2..], mesh.triangle_references);
}

// -------------------------------------------------------------------------------------------
// glTF meshes placed many times by the file itself: nodes that reuse a mesh, and
// EXT_mesh_gpu_instancing, are stored once under `instances`' rule (src/scene/mesh/reuse.rs):
// a primitive placed two or more times whose material neither emits, nor is alpha-tested or
// blended, nor maps normals. Its triangles keep their vertex normals, colours and both
// texture coordinates, as a TOML instance's do.

/// A node's or a GPU instance's translation, rotation (a unit quaternion, x y z w) and scale.
type Trs = ([f32; 3], [f32; 4], [f32; 3]);

/// Three placements: translated, turned 90° about y and scaled by 1.5, and turned 45° about
/// z and scaled per axis.
const REUSE_TRS: [Trs; 3] = [
    ([-2.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0]),
    (
        [2.0, 0.5, 1.0],
        [
            0.0,
            std::f32::consts::FRAC_1_SQRT_2,
            0.0,
            std::f32::consts::FRAC_1_SQRT_2,
        ],
        [1.5, 1.5, 1.5],
    ),
    (
        [0.0, -1.5, 0.0],
        [0.0, 0.0, 0.382_683_43, 0.923_879_5],
        [1.0, 0.5, 2.0],
    ),
];

/// A glTF opaque grey, and one that also emits.
const GREY: &str =
    r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0}}"#;
const GLOWING: &str = r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0}, "emissiveFactor": [1.0, 0.5, 0.25]}"#;

/// How a glTF file places its mesh.
#[derive(Clone, Copy, PartialEq)]
enum Reuse {
    /// One node per placement, all using mesh 0.
    Nodes,
    /// One node per placement, each with its own copy of the mesh (the same accessors):
    /// nothing reused, so everything is flattened, as every glTF file was before.
    DistinctMeshes,
    /// One node with EXT_mesh_gpu_instancing.
    GpuInstancing,
}

/// A glTF file of `mesh` (positions, normals, vertex colours, TEXCOORD_0 and _1, u32 indices)
/// in `material` (a glTF material), placed at each of `placements` as `reuse` says.
fn reuse_gltf(mesh: &StressMesh, material: &str, placements: &[Trs], reuse: Reuse) -> String {
    use base64::Engine as _;
    let n = mesh.positions.len();
    let colors: Vec<f32> = mesh
        .normals
        .iter()
        .flat_map(|v| [0.3 + 0.7 * v.x.abs(), 0.3 + 0.7 * v.y.abs(), 0.3, 1.0])
        .collect();
    let uvs: Vec<f32> = mesh
        .positions
        .iter()
        .flat_map(|p| [0.5 + 0.5 * p.x, 0.5 + 0.5 * p.y])
        .collect();
    let mut arrays: Vec<(Vec<u8>, usize, &str, u32)> = vec![
        (
            f32_bytes(mesh.positions.iter().flat_map(|p| p.to_array())),
            n,
            "VEC3",
            5126,
        ),
        (
            f32_bytes(mesh.normals.iter().flat_map(|p| p.to_array())),
            n,
            "VEC3",
            5126,
        ),
        (f32_bytes(colors), n, "VEC4", 5126),
        (f32_bytes(uvs), n, "VEC2", 5126),
        (
            mesh.indices
                .iter()
                .flatten()
                .flat_map(|i| i.to_le_bytes())
                .collect(),
            3 * mesh.indices.len(),
            "SCALAR",
            5125,
        ),
    ];
    if reuse == Reuse::GpuInstancing {
        let m = placements.len();
        arrays.push((
            f32_bytes(placements.iter().flat_map(|p| p.0)),
            m,
            "VEC3",
            5126,
        ));
        arrays.push((
            f32_bytes(placements.iter().flat_map(|p| p.1)),
            m,
            "VEC4",
            5126,
        ));
        arrays.push((
            f32_bytes(placements.iter().flat_map(|p| p.2)),
            m,
            "VEC3",
            5126,
        ));
    }
    let (mut bytes, mut views, mut accessors) = (Vec::new(), Vec::new(), Vec::new());
    for (k, (data, count, kind, component)) in arrays.iter().enumerate() {
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}}}"#,
            bytes.len(),
            data.len()
        ));
        accessors.push(format!(
            r#"{{"bufferView": {k}, "componentType": {component}, "count": {count}, "type": "{kind}"}}"#
        ));
        bytes.extend(data);
    }
    let trs = |p: &Trs| {
        format!(
            r#""translation": {:?}, "rotation": {:?}, "scale": {:?}"#,
            p.0, p.1, p.2
        )
    };
    let copies = if reuse == Reuse::DistinctMeshes {
        placements.len()
    } else {
        1
    };
    // The hierarchy's walk takes the last child first: listed last first, the nodes are
    // placed in the placements' order.
    let nodes = match reuse {
        Reuse::GpuInstancing => vec![
            r#"{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 5, "ROTATION": 6, "SCALE": 7}}}}"#
                .to_string(),
        ],
        _ => std::iter::once(format!(
            r#"{{"children": {:?}}}"#,
            (1..=placements.len()).rev().collect::<Vec<_>>()
        ))
        .chain(placements.iter().enumerate().map(|(k, p)| {
            let mesh = if reuse == Reuse::Nodes { 0 } else { k };
            format!(r#"{{"mesh": {mesh}, {}}}"#, trs(p))
        }))
        .collect(),
    };
    let primitive = r#"{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "COLOR_0": 2, "TEXCOORD_0": 3, "TEXCOORD_1": 3}, "indices": 4, "material": 0}]}"#;
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["EXT_mesh_gpu_instancing"],
"buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
"bufferViews": [{}], "accessors": [{}], "materials": [{material}],
"meshes": [{}], "nodes": [{}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
        bytes.len(),
        base64::engine::general_purpose::STANDARD.encode(&bytes),
        views.join(", "),
        accessors.join(", "),
        vec![primitive; copies].join(", "),
        nodes.join(", ")
    )
}

fn f32_bytes(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
    values.into_iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// `model.gltf` holding `gltf`, placed by a scene in `dir` with its own materials, and
/// `instances` (a TOML list) if given.
fn load_reuse(dir: &Path, gltf: &str, instances: Option<&str>) -> Result<Scene, SceneError> {
    std::fs::write(dir.join("model.gltf"), gltf).unwrap();
    let instances = instances.map_or(String::new(), |list| format!("instances = {list}\n"));
    load(
        dir,
        &format!("{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"model.gltf\"\n{instances}"),
    )
}

/// The small mesh the reuse tests place.
fn reuse_mesh() -> StressMesh {
    StressMesh::new(24, 12)
}

/// A mesh reused by three nodes, and one placed three times by EXT_mesh_gpu_instancing, are
/// stored once: its triangles once, three placements, the kernel's triangles those once and
/// three instances; with their vertex normals, colours and both texture coordinates. Placed,
/// they are the triangles of the same file with a mesh per node (flattened as before), their
/// vertices bit for bit (the same matrices, the mesh's own coordinates the file's), their
/// normals to rounding. With an entry's two `instances`, the file's three uses make six
/// placements, instance after instance, each with the uses in order.
#[test]
fn gltf_reused_meshes_are_stored_once() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = reuse_mesh();
    let per_mesh = mesh.indices.len();
    let flat = load_reuse(
        dir.path(),
        &reuse_gltf(&mesh, GREY, &REUSE_TRS, Reuse::DistinctMeshes),
        None,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(flat.instanced.is_empty());
    assert_eq!(flat.triangles.len(), 3 * per_mesh);
    for reuse in [Reuse::Nodes, Reuse::GpuInstancing] {
        let scene = load_reuse(
            dir.path(),
            &reuse_gltf(&mesh, GREY, &REUSE_TRS, reuse),
            None,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.triangles.is_empty());
        assert_eq!(scene.instanced.len(), 1);
        assert_eq!(scene.instanced[0].triangles.len(), per_mesh);
        assert_eq!(scene.instanced[0].placements.len(), 3);
        for t in &scene.instanced[0].triangles {
            assert!(t.normals.is_some() && t.colors.is_some());
            assert!(t.uvs.is_some() && t.uvs1.is_some());
        }
        let placed = scene.flattened();
        assert_eq!(placed.triangles.len(), flat.triangles.len());
        for (a, b) in placed.triangles.iter().zip(&flat.triangles) {
            assert_eq!(a.vertices, b.vertices);
            assert_eq!((a.colors, a.uvs, a.uvs1), (b.colors, b.uvs, b.uvs1));
            for (x, y) in a.normals.unwrap().iter().zip(b.normals.unwrap()) {
                assert!((*x - y).abs().max_element() < 1e-6, "{x} {y}");
            }
        }
        let kernel = lit(scene);
        assert_eq!(kernel.triangles.len(), per_mesh);
        assert_eq!(kernel.instances.len(), 3);
        assert_eq!(kernel.params.triangle_count, 0);
    }
    let both = load_reuse(
        dir.path(),
        &reuse_gltf(&mesh, GREY, &REUSE_TRS, Reuse::Nodes),
        Some("[{}, { translate = [0.0, 0.0, 3.0] }]"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(both.instanced.len(), 1);
    let placements = &both.instanced[0].placements;
    assert_eq!(placements.len(), 6);
    for (k, placement) in placements.iter().enumerate() {
        let (t, r, s) = REUSE_TRS[k % 3];
        let node = Mat4::from_scale_rotation_translation(
            Vec3::from(s),
            glam::Quat::from_array(r),
            Vec3::from(t),
        );
        let expected = Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0 * (k / 3) as f32)) * node;
        assert!(placement.abs_diff_eq(expected, 1e-6), "{k}: {placement}");
    }
}

/// The reused mesh, stored once, renders the image of the same file flattened: on the CPU at
/// 1 spp, 99% of paths agree to 1e-3 (the bound of `instances_are_the_flattened_meshes_on_the_cpu`,
/// from tests/suite/gpu_vs_cpu.rs: a ray tested in an instance's coordinates rounds differently),
/// for nodes and for EXT_mesh_gpu_instancing.
#[test]
fn gltf_reused_meshes_are_the_flattened_meshes_on_the_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = reuse_mesh();
    let scene = |reuse| {
        lit(load_reuse(
            dir.path(),
            &reuse_gltf(&mesh, GREY, &REUSE_TRS, reuse),
            None,
        )
        .unwrap_or_else(|e| panic!("{e}")))
    };
    let flat = render_cpu(&scene(Reuse::DistinctMeshes), 1);
    for reuse in [Reuse::Nodes, Reuse::GpuInstancing] {
        let instanced = scene(reuse);
        assert_eq!(instanced.instances.len(), 3);
        common::assert_paths_agree(&flat, &render_cpu(&instanced, 1), 0.99);
    }
}

/// The same on the GPU: the stored-once scene traces the flattened one's paths, and the CPU's
/// (1 spp, tests/suite/gpu_vs_cpu.rs's 99% bound).
#[test]
fn gltf_reused_meshes_are_the_flattened_meshes_on_the_gpu() {
    let Some(ctx) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let mesh = reuse_mesh();
    let scene = |reuse| {
        lit(load_reuse(
            dir.path(),
            &reuse_gltf(&mesh, GREY, &REUSE_TRS, reuse),
            None,
        )
        .unwrap_or_else(|e| panic!("{e}")))
    };
    let flat = render_gpu(ctx, &scene(Reuse::DistinctMeshes), 1);
    for reuse in [Reuse::Nodes, Reuse::GpuInstancing] {
        let instanced = scene(reuse);
        assert_eq!(instanced.instances.len(), 3);
        let image = render_gpu(ctx, &instanced, 1);
        common::assert_paths_agree(&flat, &image, 0.99);
        common::assert_paths_agree(&render_cpu(&instanced, 1), &image, 0.99);
    }
}

/// An emitting mesh reused by nodes is copied, as before: the file with a mesh per node has
/// the same triangles and the same emitter table, to the bit, and the same CPU image; and the
/// copies light the scene (under a black sky, the pixels that see them, about a fifth of the
/// frame, carry light).
#[test]
fn gltf_reused_emitting_meshes_stay_flattened() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = reuse_mesh();
    let scene = |reuse| {
        load_reuse(
            dir.path(),
            &reuse_gltf(&mesh, GLOWING, &REUSE_TRS, reuse),
            None,
        )
        .unwrap_or_else(|e| panic!("{e}"))
    };
    let (reused, flat) = (scene(Reuse::Nodes), scene(Reuse::DistinctMeshes));
    assert!(reused.instanced.is_empty());
    assert_eq!(reused.triangles, flat.triangles);
    assert_eq!(reused.render.background, Vec3::ZERO);
    let (reused, flat) = (common::sized(reused, 24, 3), common::sized(flat, 24, 3));
    assert_eq!(reused.emitters.len(), 3 * mesh.indices.len());
    assert_eq!(
        format!("{:?}", reused.emitters),
        format!("{:?}", flat.emitters)
    );
    let image = render_cpu(&reused, 2);
    assert_eq!(image.pixels, render_cpu(&flat, 2).pixels);
    let lit_pixels = image.pixels.iter().filter(|p| p[0] > 0.0).count();
    assert!(lit_pixels > image.pixels.len() / 6, "{lit_pixels}");
}

/// A placement count that used to be refused now loads when stored once: a 2·10⁵-triangle
/// mesh placed 200 times by EXT_mesh_gpu_instancing (4·10⁷ triangles, more than the 2²⁵ one
/// entry may copy) holds its triangles once. Emitting, it would be copied, and is refused
/// with the copy limit named, before any copy is made.
#[test]
fn gltf_instance_counts_beyond_the_copy_limit_load_stored_once() {
    let dir = tempfile::tempdir().unwrap();
    let big = StressMesh::new(400, 251);
    assert_eq!(big.indices.len(), 200_000);
    let grid: Vec<Trs> = (0..200)
        .map(|i| {
            (
                [(i % 20) as f32 * 3.0, (i / 20) as f32 * 3.0, 10.0],
                [0.0, 0.0, 0.0, 1.0],
                [1.0; 3],
            )
        })
        .collect();
    let scene = load_reuse(
        dir.path(),
        &reuse_gltf(&big, GREY, &grid, Reuse::GpuInstancing),
        None,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.triangles.is_empty());
    assert_eq!(scene.instanced[0].triangles.len(), 200_000);
    assert_eq!(scene.placed_triangle_count(), 40_000_000);
    let e = load_reuse(
        dir.path(),
        &reuse_gltf(&big, GLOWING, &grid, Reuse::GpuInstancing),
        None,
    )
    .expect_err("too many copies");
    let message = e.to_string();
    for needle in [
        "meshes[0].file",
        "40000000 triangles",
        "more than the 33554432",
    ] {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
}

/// A use that cannot be inverted (a node scaled by 0, as files do to hide one) leaves the
/// reused mesh copied, as before: the other two uses' triangles in the scene's, the hidden
/// one's, all of zero area, skipped; stored once, rays could not be taken into its coordinates.
#[test]
fn gltf_reuse_with_a_zero_scale_node_is_copied() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = reuse_mesh();
    let mut placements = REUSE_TRS;
    placements[1].2 = [0.0; 3];
    let scene = load_reuse(
        dir.path(),
        &reuse_gltf(&mesh, GREY, &placements, Reuse::Nodes),
        None,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.instanced.is_empty());
    assert_eq!(scene.triangles.len(), 2 * mesh.indices.len());
}

// --- What `render --json` says of an instanced scene ---

/// `--json` tells stored from placed triangles: an instanced mesh's triangles once in
/// `triangles`, once per instance in `placed_triangles`, with the instance count.
#[test]
fn render_json_counts_stored_and_placed_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let list = PLACEMENTS.map(|p| format!("{{ {p} }}")).join(", ");
    let toml = format!(
        "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\ninstances = [{list}]\n"
    );
    load(dir.path(), &toml).unwrap_or_else(|e| panic!("{e}"));
    let out = common::run_render_with(
        "--cpu",
        &dir.path().join("scene.toml"),
        &dir.path().join("out.png"),
        &["--width", "8", "--height", "8", "--spp", "1", "--json"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let per_mesh = StressMesh::new(24, 12).indices.len() as u64;
    assert_eq!(summary["triangles"], per_mesh);
    assert_eq!(summary["instances"], 4);
    assert_eq!(summary["placed_triangles"], 4 * per_mesh);
}
