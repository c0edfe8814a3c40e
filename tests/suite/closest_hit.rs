//! The closest-hit rule (`hit_comes_first` in src/cpu/geometry/intersect.rs and shaders/geometry/intersect.wgsl):
//! the smallest t, then the lowest primitive reference (spheres, quads, triangles, each by index),
//! whatever the structure. On 10⁵ rays per scene, the scan, the binary and 4-wide BVHs (with and
//! without every coincident copy) and the hardware traversal find the same hit, t and primitive
//! bit for bit, and agree on shadow rays, on the CPU and (through the probe kernel) the GPU. The
//! scenes: spheres, quads and a cube mesh each copied 20 times in place, and 2000 nested spheres.

use crate::common;
use common::probe::{run_probe_bvh, run_probe_bvh_wide, run_probe_hardware, ProbeParams};
use common::{gpu, gpu_with_ray_queries};
use glam::Vec3;
use glint::cpu::core::ray::Ray;
use glint::cpu::core::rng::Rng;
use glint::cpu::geometry::hit::{ClosestPrimitive, NO_HIT};
use glint::cpu::geometry::intersect::{
    closest_primitive, escapes, first_hit_is, scan_closest_primitive,
};
use glint::cpu::geometry::scene_geometry::Geometry;
use glint::cpu::scene_refs::SceneRefs;
use glint::kernel::bvh;
use glint::kernel::types::{PRIMITIVE_QUAD, PRIMITIVE_SPHERE};
use glint::kernel::KernelScene;
use glint::scene::stress::StressMesh;
use glint::scene::Scene;

const HEADER: &str = r#"
[camera]
eye = [0.0, 0.0, -10.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0

[render]
width = 16
height = 16
spp = 1
max_bounces = 4

[materials.white]
type = "diffuse"
color = [0.5, 0.5, 0.5]

[materials.red]
type = "diffuse"
color = [0.5, 0.1, 0.1]
"#;

/// A cube from −1 to 1, as 12 triangles.
const CUBE_OBJ: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 7 3\nf 4 8 7\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";

/// How many copies of each object the copies scene holds.
const COPIES: usize = 20;
/// How far apart in their kind the copies of one object are in the copies scene (they are
/// interleaved): 3 spheres, 3 quads and the cube's 12 triangles.
const COPY_STRIDE: [u32; 3] = [3, 3, 12];

fn load(dir: &std::path::Path, toml: &str) -> Scene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Coincident copies of everything, interleaved and with alternating materials, among a
/// displaced sphere mesh: 3 spheres, 3 quads and a cube mesh, each 20 times in place.
fn copies_scene(dir: &std::path::Path) -> KernelScene {
    load(dir, &copies_toml(dir, true)).kernel_scene()
}

/// [`copies_scene`]'s file, its cube's copies flattened (`[[meshes]]` entries) or, without
/// `flattened`, one entry's 20 coincident instances in white (stored once, src/kernel/scene/acceleration.rs).
fn copies_toml(dir: &std::path::Path, flattened: bool) -> String {
    std::fs::write(dir.join("cube.obj"), CUBE_OBJ).unwrap();
    StressMesh::new(24, 12)
        .write_ply(&dir.join("mesh.ply"))
        .unwrap();
    let mut toml = HEADER.to_string();
    toml += "[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\nscale = 2.0\ntranslate = [2.0, 0.0, 0.0]\n";
    let spheres = [
        ([0.0, 0.0, 0.0], 1.5),
        ([-2.0, 1.0, 0.5], 1.0),
        ([0.5, -2.0, 1.0], 0.7),
    ];
    let quads = [
        ([-3.0, -3.0, 1.0], [6.0, 0.0, 0.0], [0.0, 6.0, 0.0]),
        ([-1.0, -3.0, -3.0], [0.0, 0.0, 6.0], [0.0, 6.0, 0.0]),
        ([-3.0, 0.3, -3.0], [0.0, 0.0, 6.0], [6.0, 0.0, 0.0]),
    ];
    for copy in 0..COPIES {
        let material = ["white", "red"][copy % 2];
        for (center, radius) in spheres {
            toml += &format!(
                "[[spheres]]\ncenter = {center:?}\nradius = {radius}\nmaterial = \"{material}\"\n"
            );
        }
        for (corner, u, v) in quads {
            toml += &format!(
                "[[quads]]\ncorner = {corner:?}\nu = {u:?}\nv = {v:?}\nmaterial = \"{material}\"\n"
            );
        }
        if flattened {
            toml += &format!("[[meshes]]\nfile = \"cube.obj\"\nmaterial = \"{material}\"\nscale = 1.2\ntranslate = [-1.0, 1.0, -1.0]\n");
        }
    }
    if !flattened {
        let instances = vec!["{}"; COPIES].join(", ");
        toml += &format!("[[meshes]]\nfile = \"cube.obj\"\nmaterial = \"white\"\nscale = 1.2\ntranslate = [-1.0, 1.0, -1.0]\ninstances = [{instances}]\n");
    }
    toml
}

/// 2000 concentric spheres whose radii differ by a little: a stack the builder makes a chain of
/// 2000 levels over, far deeper than the traversal stack; each sphere is hit at its own t.
fn stack_scene(dir: &std::path::Path) -> KernelScene {
    let mut toml = HEADER.to_string();
    for i in 0..2000 {
        toml += &format!(
            "[[spheres]]\ncenter = [0.5, -0.25, 0.0]\nradius = {}\nmaterial = \"white\"\n",
            2.0 - i as f32 * 1e-4
        );
    }
    load(dir, &toml).kernel_scene()
}

/// `scene` with its BVH over every primitive, copies too (the default tree leaves copies out).
fn with_copies_in_the_tree(scene: &KernelScene) -> KernelScene {
    let tree = bvh::build_with_copies(&scene.spheres, &scene.quads, &scene.triangles).unwrap();
    KernelScene {
        bvh_wide_nodes: tree.wide_nodes(),
        bvh_nodes: tree.nodes,
        bvh_primitives: tree.primitives,
        ..scene.clone()
    }
}

fn unit_vector(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A ray from within the cube of side 8 around the origin, aimed anywhere or at a random point
/// of a random sphere, quad or triangle.
fn random_ray(scene: &KernelScene, i: u32, rng: &mut Rng) -> Ray {
    let mut u = || rng.next_f32();
    let origin = Vec3::new(u(), u(), u()) * 8.0 - 4.0;
    let pick = |n: usize, x: f32| ((x * n as f32) as usize).min(n - 1);
    let (a, b) = (u(), u());
    let offset = Vec3::new(u(), u(), u()) - 0.5;
    let aim = match i % 4 {
        1 if !scene.spheres.is_empty() => {
            let s = &scene.spheres[pick(scene.spheres.len(), a)];
            Vec3::from(s.center) + 2.0 * s.radius * offset
        }
        2 if !scene.quads.is_empty() => {
            let q = &scene.quads[pick(scene.quads.len(), a)];
            Vec3::from(q.corner) + b * Vec3::from(q.edge_u) + offset.x * Vec3::from(q.edge_v)
        }
        3 if !scene.triangles.is_empty() => {
            let t = &scene.triangles[pick(scene.triangles.len(), a)];
            Vec3::from(t.v0).lerp(Vec3::from(t.v1), b)
        }
        _ => {
            return Ray {
                origin,
                dir: unit_vector(rng),
            }
        }
    };
    Ray {
        origin,
        dir: (aim - origin).normalize(),
    }
}

/// The primitive `stride[kind]` after `hit` in its kind, if there is one: its next copy in the
/// copies scene (where the copies of each object are that far apart).
fn later(scene: &KernelScene, hit: &ClosestPrimitive, stride: [u32; 3]) -> Option<u32> {
    let count = match hit.primitive {
        PRIMITIVE_SPHERE => scene.spheres.len(),
        PRIMITIVE_QUAD => scene.quads.len(),
        _ => scene.triangles.len(),
    };
    let index = hit.index + stride[hit.primitive as usize];
    ((index as usize) < count).then_some(index)
}

/// 10⁵ rays through `scene` on the CPU: the scan, the BVH without copies and the BVH with
/// every copy all find the same hit, bit for bit, and agree on every shadow ray, including one
/// aimed at the primitive `stride` after the hit ([`later`]), which must be behind it. Returns
/// how many rays hit something and how many of those hit an object `copied` says has copies.
fn check_cpu(
    scene: &KernelScene,
    stride: [u32; 3],
    copied: impl Fn(&ClosestPrimitive) -> bool,
) -> (u32, u32) {
    let full = with_copies_in_the_tree(scene);
    let (refs, full_refs) = (
        SceneRefs::of(scene, &scene.params),
        SceneRefs::of(&full, &full.params),
    );
    let scan = Geometry {
        bvh_nodes: &[],
        bvh_primitives: &[],
        ..refs.geometry()
    };
    fn binary(g: Geometry) -> Geometry {
        Geometry {
            bvh_wide_nodes: &[],
            ..g
        }
    }
    let structures = [
        ("bvh", binary(refs.geometry())),
        ("bvh with copies", binary(full_refs.geometry())),
        (
            "wide bvh",
            Geometry {
                bvh_wide_nodes: &scene.bvh_wide_nodes,
                ..refs.geometry()
            },
        ),
        (
            "wide bvh with copies",
            Geometry {
                bvh_wide_nodes: &full.bvh_wide_nodes,
                ..full_refs.geometry()
            },
        ),
    ];
    assert!(structures.iter().all(|(_, g)| !g.bvh_nodes.is_empty()));
    assert!(structures[2..]
        .iter()
        .all(|(_, g)| !g.bvh_wide_nodes.is_empty()));
    let mut rng = Rng::new(7, 0, 0, 13);
    let (mut hits, mut on_copies) = (0, 0);
    for i in 0..100_000u32 {
        let ray = random_ray(scene, i, &mut rng);
        let expected = scan_closest_primitive(&scan, &ray);
        for (name, geometry) in &structures {
            let found = closest_primitive(geometry, &ray);
            assert_eq!(
                (found.t.to_bits(), found.primitive, found.index),
                (expected.t.to_bits(), expected.primitive, expected.index),
                "{name}, ray {i}: {ray:?}"
            );
            assert_eq!(
                escapes(geometry, &ray),
                expected.t == NO_HIT,
                "{name}, ray {i}"
            );
            if expected.t == NO_HIT {
                continue;
            }
            assert!(
                first_hit_is(geometry, &ray, expected.primitive, expected.index),
                "{name}, ray {i}"
            );
            // A later primitive (a copy, hit at the same t, where there are copies) is behind it.
            if let Some(index) = later(scene, &expected, stride) {
                assert!(
                    !first_hit_is(geometry, &ray, expected.primitive, index),
                    "{name}, ray {i}"
                );
            }
        }
        if expected.t != NO_HIT {
            hits += 1;
            if copied(&expected) {
                on_copies += 1;
            }
        }
    }
    (hits, on_copies)
}

/// Rays each GPU check traces. Fewer than the CPU's 10⁵: on lavapipe the scan that gives the
/// expected hit costs a pass over every primitive per ray, and 10⁵ rays made these four tests
/// take 7 of CI's minutes; 2.5·10⁴ still meet every stacked and copied primitive many times.
const GPU_RAYS: u32 = 25_000;

/// The GPU traversals [`check_gpu`] runs.
#[derive(Clone, Copy, Debug)]
enum GpuTraversal {
    /// The binary BVH (shaders/traverse/bvh.wgsl).
    Binary,
    /// The 4-wide BVH (shaders/traverse/wide.wgsl).
    Wide,
    /// Ray queries (shaders/traverse/hardware.wgsl).
    Hardware,
}

/// The same on the GPU, through the probe kernel (tests/suite/shaders/probe.wgsl): the kernel's
/// `traversal` and its scan
/// find the same hit, bit for bit, for [`GPU_RAYS`] rays, and its shadow tests agree (with
/// `stride` as in [`check_cpu`]). Returns how many rays hit something.
fn check_gpu(
    ctx: &glint::gpu::GpuContext,
    scene: &KernelScene,
    stride: [u32; 3],
    traversal: GpuTraversal,
) -> u32 {
    let rays = GPU_RAYS;
    let params = ProbeParams {
        count: 2 * rays,
        seed: 29,
        position: [0.0; 3],
        alpha: 8.0,
        normal: stride.map(|s| s as f32),
        ..Default::default()
    };
    let probe = match traversal {
        GpuTraversal::Binary => run_probe_bvh,
        GpuTraversal::Wide => run_probe_bvh_wide,
        GpuTraversal::Hardware => run_probe_hardware,
    };
    let out = probe(ctx, "probe_closest_hit", params, scene);
    let mut hits = 0;
    // Every disagreement, so a failure says how many and which rays.
    let mut wrong = Vec::new();
    for (i, pair) in out.chunks(2).enumerate() {
        let (found, expected) = (pair[0], pair[1]);
        let hit = |v: [f32; 4]| (v[0], v[1].to_bits(), v[2].to_bits());
        if hit(found) != hit(expected) || found[0].to_bits() != expected[0].to_bits() {
            wrong.push(format!(
                "ray {i}: found {:?}, expected {:?}",
                hit(found),
                hit(expected)
            ));
        }
        let flags = found[3] as u32;
        if expected[0] == NO_HIT {
            if flags != 4 {
                wrong.push(format!(
                    "ray {i}: flags {flags}, but a miss escapes, and no shadow test ran"
                ));
            }
        } else {
            hits += 1;
            if flags != 1 {
                wrong.push(format!(
                    "ray {i}: flags {flags}, but the hit is first, the later primitive behind it"
                ));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "{} disagreements with the scan in {} rays ({traversal:?}), the first: {:#?}",
        wrong.len(),
        rays,
        &wrong[..wrong.len().min(10)]
    );
    hits
}

#[test]
fn every_cpu_traversal_finds_the_lowest_of_coincident_copies() {
    let dir = tempfile::tempdir().unwrap();
    let scene = copies_scene(dir.path());
    let mesh_triangles = scene.triangles.len() - 12 * COPIES;
    let (hits, copied) = check_cpu(&scene, COPY_STRIDE, |hit| match hit.primitive {
        PRIMITIVE_SPHERE | PRIMITIVE_QUAD => true,
        _ => hit.index as usize >= mesh_triangles,
    });
    eprintln!("{hits} hits, {copied} on objects with 20 coincident copies");
    // Every hit on a copied object must be on its first copy: a later one fails the
    // comparison with the scan above. Most rays aim at one, so most hits are.
    assert!(copied > 50_000, "{copied} of {hits}");
}

#[test]
fn every_cpu_traversal_finds_the_closest_of_a_deep_stack() {
    let dir = tempfile::tempdir().unwrap();
    let scene = stack_scene(dir.path());
    let (hits, _) = check_cpu(&scene, [1; 3], |_| false);
    assert!(hits > 30_000, "{hits}");
}

#[test]
fn every_gpu_traversal_finds_the_lowest_of_coincident_copies() {
    let Some(ctx) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = copies_scene(dir.path());
    // The wide tree is the GPU's; the binary one, which it traverses only in scenes with
    // instances (tests/suite/instancing.rs checks those against the scan too), is checked on the
    // tree with every copy alone: each kernel variant costs minutes of lavapipe compilation
    // on CI's cold shader cache.
    let with_copies = with_copies_in_the_tree(&scene);
    for (tree, traversal) in [
        (&scene, GpuTraversal::Wide),
        (&with_copies, GpuTraversal::Wide),
        (&with_copies, GpuTraversal::Binary),
    ] {
        let hits = check_gpu(ctx, tree, COPY_STRIDE, traversal);
        assert!(hits > GPU_RAYS / 2, "{hits}");
    }
}

#[test]
fn every_gpu_traversal_finds_the_closest_of_a_deep_stack() {
    let Some(ctx) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = stack_scene(dir.path());
    for traversal in [GpuTraversal::Binary, GpuTraversal::Wide] {
        let hits = check_gpu(ctx, &scene, [1; 3], traversal);
        assert!(hits > GPU_RAYS * 3 / 10, "{hits}");
    }
}

/// The hardware traversal (ray queries against a TLAS, every candidate decided by glint's own
/// tests and the rule) finds the scan's hit, bit for bit, on the same rays: over the tree's
/// primitives, and over every copy too, where the hardware proposes coincident candidates in
/// its own order and only the rule can pick the lowest.
#[test]
fn hardware_traversal_finds_the_lowest_of_coincident_copies() {
    let Some(ctx) = gpu_with_ray_queries() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = copies_scene(dir.path());
    for tree in [scene.clone(), with_copies_in_the_tree(&scene)] {
        let hits = check_gpu(ctx, &tree, COPY_STRIDE, GpuTraversal::Hardware);
        assert!(hits > GPU_RAYS / 2, "{hits}");
    }
}

#[test]
fn hardware_traversal_finds_the_closest_of_a_deep_stack() {
    let Some(ctx) = gpu_with_ray_queries() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = stack_scene(dir.path());
    let hits = check_gpu(ctx, &scene, [1; 3], GpuTraversal::Hardware);
    assert!(hits > GPU_RAYS * 3 / 10, "{hits}");
}

/// The same with the cube as 20 coincident instances of one mesh (one TLAS instance per
/// placement over one BLAS): the hardware proposes the placements' candidates in its own
/// order, and the hit must be the scan's, through instance 0 (the probe flags any other).
#[test]
fn hardware_traversal_finds_the_lowest_of_coincident_instances() {
    let Some(ctx) = gpu_with_ray_queries() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = load(dir.path(), &copies_toml(dir.path(), false)).kernel_scene();
    assert_eq!(scene.instances.len(), COPIES);
    let hits = check_gpu(ctx, &scene, COPY_STRIDE, GpuTraversal::Hardware);
    assert!(hits > GPU_RAYS / 2, "{hits}");
}
