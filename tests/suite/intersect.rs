//! Ray-sphere and ray-quad intersection on the CPU mirror, including the awkward cases: hits
//! and misses, grazing rays, rays starting inside spheres, hits behind the origin, and
//! self-intersection at several scales.

use glam::Vec3;
use glint::cpu::core::ray::Ray;
use glint::cpu::geometry::hit::{hit_quad, hit_sphere, NO_HIT};
use glint::cpu::geometry::intersect::{closest_primitive, first_hit_is, intersect_scene};
use glint::cpu::geometry::scene_geometry::Geometry;
use glint::cpu::geometry::surface::{offset_ray_origin, sphere_point};
use glint::kernel::types::{Quad, Sphere};
use glint::scene::{Material, MaterialKind, Quad as SceneQuad, Scene};

fn sphere(center: [f32; 3], radius: f32) -> Sphere {
    Sphere {
        center,
        radius,
        ..Default::default()
    }
}

fn ray(origin: [f32; 3], dir: [f32; 3]) -> Ray {
    Ray {
        origin: Vec3::from(origin),
        dir: Vec3::from(dir).normalize(),
    }
}

/// A kernel quad built the way the scene loader builds it.
fn quad(corner: [f32; 3], u: [f32; 3], v: [f32; 3]) -> Quad {
    let scene = Scene {
        name: "t".into(),
        camera: glint::scene::Camera {
            eye: Vec3::ZERO,
            target: Vec3::Z,
            up: Vec3::Y,
            projection: glint::scene::Projection::Perspective { vfov: 40.0 },
            aperture: 0.0,
            focus_distance: 1.0,
        },
        render: glint::scene::RenderSettings {
            width: 1,
            height: 1,
            spp: 1,
            max_bounces: 1,
            background: Vec3::ZERO,
            seed: 0,
            light_sampling: true,
            russian_roulette: true,
            sampler: Default::default(),
            integrator: Default::default(),
            light_sampler: Default::default(),
        },
        materials: vec![Material {
            name: "m".into(),
            kind: MaterialKind::Diffuse,
            color: Vec3::ONE,
            emitted_radiance: Vec3::ZERO,
            color_texture: None,
            roughness_texture: None,
            emission_texture: None,
            normal_texture: None,
            alpha: glint::scene::Alpha::OPAQUE,
        }],
        spheres: vec![],
        quads: vec![SceneQuad {
            corner: corner.into(),
            u: u.into(),
            v: v.into(),
            material: 0,
        }],
        triangles: vec![],
        instanced: vec![],
        textures: Default::default(),
        environment: None,
        lights: vec![],
        media: Default::default(),
    };
    scene.kernel_scene().quads[0]
}

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

#[test]
fn sphere_hit_from_outside_gives_the_near_root() {
    let t = hit_sphere(
        &sphere([0.0, 0.0, 10.0], 2.0),
        &ray([0.0; 3], [0.0, 0.0, 1.0]),
    );
    assert!(close(t, 8.0, 1e-6), "{t}");
}

#[test]
fn sphere_miss_and_sphere_behind_the_origin() {
    let s = sphere([0.0, 0.0, 10.0], 2.0);
    assert_eq!(hit_sphere(&s, &ray([0.0; 3], [0.0, 1.0, 0.0])), NO_HIT);
    assert_eq!(hit_sphere(&s, &ray([0.0; 3], [0.0, 0.0, -1.0])), NO_HIT);
    // Just outside the silhouette.
    assert_eq!(
        hit_sphere(&s, &ray([2.001, 0.0, 0.0], [0.0, 0.0, 1.0])),
        NO_HIT
    );
}

#[test]
fn ray_starting_inside_a_sphere_hits_the_far_side() {
    let s = sphere([1.0, 2.0, 3.0], 5.0);
    let t = hit_sphere(&s, &ray([1.0, 2.0, 3.0], [1.0, 0.0, 0.0]));
    assert!(close(t, 5.0, 1e-6), "{t}");
    let t = hit_sphere(&s, &ray([1.0, 2.0, 5.0], [0.0, 0.0, -1.0]));
    assert!(close(t, 7.0, 1e-6), "{t}");
}

#[test]
fn grazing_ray_at_the_silhouette() {
    let s = sphere([0.0, 0.0, 10.0], 2.0);
    // Tangent: the discriminant is 0 and the hit is at the tangent point.
    let t = hit_sphere(&s, &ray([2.0, 0.0, 0.0], [0.0, 0.0, 1.0]));
    assert!(close(t, 10.0, 1e-3), "{t}");
    let t = hit_sphere(&s, &ray([1.9999, 0.0, 0.0], [0.0, 0.0, 1.0]));
    assert!(t > 9.0 && t < 10.0, "{t}");
}

#[test]
fn small_sphere_far_away_is_hit_precisely() {
    // The naive discriminant h² − c loses a 0.01 sphere 10^4 units away in f32 rounding.
    let s = sphere([0.0, 0.0, 10000.0], 0.01);
    let t = hit_sphere(&s, &ray([0.005, 0.0, 0.0], [0.0, 0.0, 1.0]));
    let expected = 10000.0 - (0.01f32 * 0.01 - 0.005 * 0.005).sqrt();
    assert!(close(t, expected, 1e-6), "{t} vs {expected}");
    assert_eq!(
        hit_sphere(&s, &ray([0.0101, 0.0, 0.0], [0.0, 0.0, 1.0])),
        NO_HIT
    );
}

#[test]
fn quad_hit_inside_bounds_and_misses_outside() {
    let q = quad([0.0, 0.0, 5.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]);
    let t = hit_quad(&q, &ray([1.0, 1.0, 0.0], [0.0, 0.0, 1.0]));
    assert!(close(t, 5.0, 1e-6), "{t}");
    // Both sides are hit (two-sided surfaces).
    let t = hit_quad(&q, &ray([1.0, 1.0, 9.0], [0.0, 0.0, -1.0]));
    assert!(close(t, 4.0, 1e-6), "{t}");
    for origin in [
        [-0.01, 1.0, 0.0],
        [2.01, 1.0, 0.0],
        [1.0, -0.01, 0.0],
        [1.0, 3.01, 0.0],
    ] {
        assert_eq!(
            hit_quad(&q, &ray(origin, [0.0, 0.0, 1.0])),
            NO_HIT,
            "{origin:?}"
        );
    }
}

#[test]
fn quad_parallel_ray_and_quad_behind() {
    let q = quad([0.0, 0.0, 5.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]);
    assert_eq!(hit_quad(&q, &ray([1.0, 1.0, 5.0], [1.0, 0.0, 0.0])), NO_HIT);
    assert_eq!(
        hit_quad(&q, &ray([1.0, 1.0, 0.0], [0.0, 0.0, -1.0])),
        NO_HIT
    );
}

#[test]
fn quad_grazing_ray_at_an_edge_is_inside_the_closed_bounds() {
    let q = quad([0.0, 0.0, 5.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]);
    let t = hit_quad(&q, &ray([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]));
    assert!(close(t, 5.0, 1e-6), "{t}");
}

#[test]
fn nearest_hit_wins_and_the_normal_faces_the_ray() {
    let spheres = [sphere([0.0, 0.0, 10.0], 1.0), sphere([0.0, 0.0, 5.0], 1.0)];
    let quads = [quad([-5.0, -5.0, 20.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0])];
    let r = ray([0.0; 3], [0.0, 0.0, 1.0]);
    let hit = intersect_scene(&Geometry::new(&spheres, &quads), &r);
    assert!(close(hit.t, 4.0, 1e-6));
    assert!(hit.front_face);
    assert!((hit.normal - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
    // From inside, the normal is flipped to face the ray and front_face is false.
    let hit = intersect_scene(
        &Geometry::new(&spheres, &[]),
        &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]),
    );
    assert!(!hit.front_face);
    assert!((hit.normal - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
    assert_eq!(
        intersect_scene(
            &Geometry::new(&spheres, &quads),
            &ray([0.0; 3], [0.0, 1.0, 0.0])
        )
        .t,
        NO_HIT
    );
}

/// Shadow rays ask only which primitive comes first; it must be the one the full
/// intersection finds, including when the nearer of two is a sphere or a quad, and for misses.
#[test]
fn shadow_test_agrees_with_the_full_intersection() {
    let spheres = [sphere([0.0, 0.0, 10.0], 1.0), sphere([0.0, 0.0, 5.0], 1.0)];
    let quads = [
        quad([-5.0, -5.0, 20.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0]),
        quad([-5.0, -5.0, 7.0], [10.0, 0.0, 0.0], [0.0, 4.0, 0.0]),
    ];
    // Rays that met a sphere, a quad, nothing.
    let mut met = [0usize; 3];
    for i in 0..2000 {
        // Directions spread over the sphere (a Fibonacci lattice), from two origins.
        let z = 1.0 - (i as f32 + 0.5) / 1000.0 % 2.0;
        let phi = i as f32 * 2.399_963;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let origin = if i % 2 == 0 {
            [0.0; 3]
        } else {
            [0.5, 0.3, 7.5]
        };
        let ray = ray(origin, [r * phi.cos(), r * phi.sin(), z]);
        let hit = intersect_scene(&Geometry::new(&spheres, &quads), &ray);
        let closest = closest_primitive(&Geometry::new(&spheres, &quads), &ray);
        assert_eq!(closest.t, hit.t);
        if hit.t == NO_HIT {
            met[2] += 1;
            continue;
        }
        met[hit.primitive as usize] += 1;
        for (primitive, count) in [(0, spheres.len()), (1, quads.len())] {
            for index in 0..count as u32 {
                let same = (primitive, index) == (hit.primitive, hit.index);
                assert_eq!(
                    first_hit_is(&Geometry::new(&spheres, &quads), &ray, primitive, index),
                    same
                );
            }
        }
    }
    // Rays met spheres, quads and nothing, so every branch was compared.
    assert!(met.iter().all(|&n| n > 20), "{met:?}");
}

/// A ray leaving a surface from an offset origin never re-hits that surface, at the scale of
/// the Cornell box and of a 0.01-unit object far from the origin alike.
#[test]
fn offset_origin_prevents_self_intersection_at_every_scale() {
    for (center, radius) in [
        ([278.0, 90.0, 190.0], 90.0),
        ([0.0, 0.0, 0.0], 0.01),
        ([1000.0, -2000.0, 500.0], 0.01),
        ([0.0, 0.0, 0.0], 1000.0),
    ] {
        let s = sphere(center, radius);
        let mut failures = 0;
        for i in 0..2000 {
            // Points spread over the sphere, and directions leaving the outside surface.
            let a = i as f32 * 2.399_963; // golden angle
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
            let r = (1.0 - z * z).sqrt();
            let n = Vec3::new(r * a.cos(), r * a.sin(), z);
            let p = sphere_point(Vec3::from(center), radius, n);
            let tangentish = n.any_orthonormal_vector();
            let dir = (tangentish + 0.05 * n).normalize();
            let out = Ray {
                origin: offset_ray_origin(p.position, p.error, n),
                dir,
            };
            if hit_sphere(&s, &out) != NO_HIT {
                failures += 1;
            }
        }
        assert_eq!(failures, 0, "sphere {center:?} r={radius}");
    }
}
