//! Shading normals that deviate strongly from the geometric ones: light sampling on and off
//! must agree for every BSDF, on both devices. Before `valid_shading_normal`, a smooth-shaded
//! metal mesh under an environment map made pixels of 10¹⁰ with light sampling on (the GGX
//! evaluation divided by the cosine of wo below the shading normal, where the BSDF's own pdf
//! is 0, so light samples took the full MIS weight).

use crate::common;
use common::{render_with_variance, with_light_sampling};
use glint::image::compare::compare;
use glint::scene::Scene;
use std::f32::consts::PI;
use std::fmt::Write;
use std::path::Path;

/// A coarse sphere (`segments` × `rings` quads as triangle pairs) whose vertex normals lean
/// 60° away from the surface's, in a direction that turns around the sphere: many views of it
/// have wo below the interpolated normal while above the triangle.
fn leaning_sphere_obj(segments: usize, rings: usize) -> String {
    let mut obj = String::new();
    let lean = 60f32.to_radians();
    for r in 0..=rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = 2.0 * PI * s as f32 / segments as f32;
            let n = glam::Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            writeln!(obj, "v {} {} {}", n.x, n.y, n.z).unwrap();
            // Lean towards a tangent that alternates with the vertex, by a fixed angle.
            let tangent = glam::Vec3::new(-phi.sin(), 0.0, phi.cos());
            let sign = if (r + s) % 2 == 0 { 1.0 } else { -1.0 };
            let leaned = n * lean.cos() + tangent * (sign * lean.sin());
            let leaned = if leaned.length() > 0.0 {
                leaned.normalize()
            } else {
                n
            };
            writeln!(obj, "vn {} {} {}", leaned.x, leaned.y, leaned.z).unwrap();
        }
    }
    let index = |r: usize, s: usize| r * (segments + 1) + s + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (index(r, s), index(r, s + 1));
            let (c, d) = (index(r + 1, s + 1), index(r + 1, s));
            // At the poles one of the two triangles has no area.
            if r > 0 {
                writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}").unwrap();
            }
            if r + 1 < rings {
                writeln!(obj, "f {a}//{a} {c}//{c} {d}//{d}").unwrap();
            }
        }
    }
    obj
}

/// The leaning sphere in `material`, over a floor, lit by an environment map with a bright
/// patch (the case the bug was found in) and a small quad light.
fn scene(dir: &Path, material: &str) -> Scene {
    std::fs::write(dir.join("sphere.obj"), leaning_sphere_obj(10, 6)).unwrap();
    common::write_map(dir, "sky.exr", 32, 16, |x, y| {
        if (10..14).contains(&x) && (3..6).contains(&y) {
            [20.0, 18.0, 15.0]
        } else {
            [0.3, 0.4, 0.6]
        }
    });
    let text = format!(
        r#"
[camera]
eye = [0.0, 1.2, -3.2]
target = [0.0, 0.2, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
[render]
width = 20
height = 20
spp = 1
max_bounces = 6
[environment]
file = "sky.exr"
[materials.test]
{material}
[materials.floor]
type = "diffuse"
color = [0.5, 0.5, 0.5]
[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [8.0, 8.0, 8.0]
[[meshes]]
file = "sphere.obj"
material = "test"
smooth = true
translate = [0.0, 0.2, 0.0]
scale = 0.8
[[quads]]
corner = [-3.0, -0.6, -3.0]
u = [0.0, 0.0, 6.0]
v = [6.0, 0.0, 0.0]
material = "floor"
[[quads]]
corner = [1.0, 2.0, -1.0]
u = [0.5, 0.0, 0.0]
v = [0.0, 0.0, 0.5]
material = "lamp"
"#
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Light sampling on and off estimate the same image, so the z of the difference of the
/// image means (its variance Σ(VA + VB)/N² from both renders' variance images) is a standard
/// normal: |z| < 5 fails wrongly with probability 6·10⁻⁷. The bug made the light-sampled mean
/// 10⁷ times too large, and no pixel of either render may be far beyond the sky's radiance.
#[test]
fn light_sampling_on_and_off_agree_under_leaning_shading_normals() {
    let dir = tempfile::tempdir().unwrap();
    for material in [
        "type = \"diffuse\"\ncolor = [0.8, 0.8, 0.8]",
        "type = \"metal\"\ncolor = [1.0, 1.0, 1.0]\nroughness = 1.0",
        "type = \"metal\"\ncolor = [1.0, 1.0, 1.0]\nroughness = 0.4",
        "type = \"metal\"\ncolor = [0.9, 0.8, 0.6]\nroughness = 0.1",
        "type = \"metal\"\ncolor = [1.0, 1.0, 1.0]\nroughness = 0.0",
        "type = \"specular\"\ncolor = [0.9, 0.9, 0.9]",
        "type = \"dielectric\"\nior = 1.5",
    ] {
        let scene = scene(dir.path(), material);
        let on = with_light_sampling(&scene, true, 11);
        let off = with_light_sampling(&scene, false, 12);
        let mut runs = Vec::new();
        for (kernel_scene, light) in [(&on, "on"), (&off, "off")] {
            for (device, mut renderer) in common::renderers(kernel_scene) {
                let (image, variance) = render_with_variance(renderer.as_mut(), 128);
                let brightest = image.pixels.iter().flatten().fold(0.0f32, |m, v| m.max(*v));
                assert!(
                    brightest < 1e3,
                    "{device}, light sampling {light}, {material:?}: a pixel of {brightest}"
                );
                runs.push((device, light, image, variance));
            }
        }
        for (device, _, a, va) in runs.iter().filter(|r| r.1 == "on") {
            let (_, _, b, vb) = runs
                .iter()
                .find(|r| r.0 == *device && r.1 == "off")
                .unwrap();
            let c = compare(a, b, Some((va, vb))).unwrap();
            let z = c.z_test.as_ref().unwrap().z_of_means;
            assert!(
                z.abs() < 5.0,
                "{device}, {material:?}: light sampling on {:?}, off {:?} (z {z})",
                c.mean_a,
                c.mean_b
            );
        }
    }
}
