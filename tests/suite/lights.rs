//! Point, spot and directional lights (`[[lights]]`): images against their closed forms on the
//! CPU reference and the GPU, GPU ≡ CPU on the shipped scene, and bad input.

use crate::common;
use common::{kernel_scene, render_both};
use glam::DVec3;
use glint::image::output::Image;
use glint::kernel::types::Params;
use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

const ALBEDO: f64 = 0.5;

/// A camera 6 above a diffuse floor of albedo 0.5 (y = 0, 40 × 40), looking straight down,
/// one scattering event: a floor point's radiance is only what next-event estimation brings
/// from the light, and the BSDF-sampled ray escapes into a black background.
fn floor_scene(light: &str, size: u32, spp: u32) -> glint::kernel::KernelScene {
    floor_scene_under("", 20.0, light, size, spp)
}

/// [`floor_scene`] with `render_extra` (lines of `[render]`, such as a background) added and a
/// floor reaching `half` from the origin along x and z.
fn floor_scene_under(
    render_extra: &str,
    half: f32,
    light: &str,
    size: u32,
    spp: u32,
) -> glint::kernel::KernelScene {
    kernel_scene(&format!(
        r#"
[camera]
eye = [0.3, 6.0, 0.2]
target = [0.3, 0.0, 0.2]
up = [0.0, 0.0, 1.0]
vfov = 70.0
[render]
width = {size}
height = {size}
spp = {spp}
max_bounces = 1
russian_roulette = false
{render_extra}
[materials.floor]
type = "diffuse"
color = [{ALBEDO}, {ALBEDO}, {ALBEDO}]
[[quads]]
corner = [-{half:?}, 0.0, -{half:?}]
u = [{width:?}, 0.0, 0.0]
v = [0.0, 0.0, {width:?}]
material = "floor"
{light}
"#,
        width = 2.0 * half
    ))
}

/// Where the ray through image point (x, y) (in pixels, from the top left) meets the floor.
fn floor_point(params: &Params, x: f64, y: f64) -> DVec3 {
    let ndc_x = x / params.width as f64 * 2.0 - 1.0;
    let ndc_y = 1.0 - y / params.height as f64 * 2.0;
    let v = |a: [f32; 3]| DVec3::from(a.map(|c| c as f64));
    let dir = v(params.forward) + ndc_x * v(params.right) + ndc_y * v(params.up);
    let eye = v(params.eye);
    eye + dir * (-eye.y / dir.y)
}

/// Each pixel against `radiance` (of a floor point, in f64), pixel by pixel. A pixel averages
/// its samples over its footprint (the camera jitters within it); the expected value is the
/// footprint's mean by the midpoint rule, and the tolerance is four standard errors of a
/// mean of `spp` samples of a quantity that varies by at most its spread over the footprint
/// (std ≤ spread / 2), plus 1e-4 relative for f32 rounding.
fn assert_matches(
    name: &str,
    image: &Image,
    params: &Params,
    spp: u32,
    radiance: impl Fn(DVec3) -> f64,
) {
    let n = 8;
    let mut worst: f64 = 0.0;
    for py in 0..image.height {
        for px in 0..image.width {
            let values: Vec<f64> = (0..n * n)
                .map(|k| {
                    let (i, j) = (k % n, k / n);
                    let x = px as f64 + (i as f64 + 0.5) / n as f64;
                    let y = py as f64 + (j as f64 + 0.5) / n as f64;
                    radiance(floor_point(params, x, y))
                })
                .collect();
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let spread = values.iter().cloned().fold(f64::MIN, f64::max)
                - values.iter().cloned().fold(f64::MAX, f64::min);
            let tolerance = 4.0 * (spread / 2.0) / (spp as f64).sqrt() + 1e-4 * mean + 1e-7;
            let got = image.pixels[(py * image.width + px) as usize];
            for c in got {
                let error = (c as f64 - mean).abs();
                assert!(
                    error <= tolerance,
                    "{name}: pixel ({px}, {py}) is {c}, expected {mean} ± {tolerance}"
                );
                worst = worst.max(error / mean.max(1e-12));
            }
        }
    }
    eprintln!("{name}: worst relative error {worst:.2e}");
}

/// A point light of intensity I at height h: a floor point at distance d sees irradiance
/// I cos θ / d², cos θ = h / d, and reflects ρ/π of it. Delta lights take an MIS weight of 1:
/// a power-heuristic weight against the diffuse BSDF's pdf cos θ/π (with the light's pdf, its
/// selection probability 1) would be 1/(1 + (cos θ/π)²), darkening pixels by up to 9%, far
/// beyond the tolerance.
#[test]
fn point_light_on_a_floor_is_rho_i_cos_over_pi_d2() {
    let (position, intensity) = (DVec3::new(-0.5, 2.0, 0.7), 7.0);
    let scene = floor_scene(
        "[[lights]]\ntype = \"point\"\nposition = [-0.5, 2.0, 0.7]\nintensity = 7.0\n",
        32,
        16,
    );
    for (device, image) in render_both(&scene, 16) {
        assert_matches(&format!("{device} point"), &image, &scene.params, 16, |x| {
            let to_light = position - x;
            let d2 = to_light.length_squared();
            ALBEDO * intensity * (to_light.y / d2.sqrt()) / (PI * d2)
        });
    }
}

/// A directional light of irradiance E at angle θ from the normal: every floor point
/// reflects ρ E cos θ / π, with no variance at all.
#[test]
fn directional_light_on_a_floor_is_rho_e_cos_over_pi() {
    let direction = DVec3::new(0.3, -1.0, 0.4).normalize();
    let scene = floor_scene(
        "[[lights]]\ntype = \"directional\"\ndirection = [0.3, -1.0, 0.4]\nintensity = 3.0\n\
         color = [1.0, 1.0, 1.0]\n",
        16,
        4,
    );
    for (device, image) in render_both(&scene, 4) {
        assert_matches(
            &format!("{device} directional"),
            &image,
            &scene.params,
            4,
            |_| ALBEDO * 3.0 * -direction.y / PI,
        );
    }
}

/// The white furnace with every kind of light present: the floor under a uniform sky of radiance
/// 1, lit also by a point light, a spot, a delta sun and a sun disk 2° across. The floor bounds
/// a half-space, so only the sky and the lights reach it, each unoccluded: with one bounce a
/// pixel is ρ (1 + Σ Eᵢ/π), Eᵢ the irradiance light i gives the point (the sky's is π; the
/// disk's, wholly above the horizon, E cos θ exactly, its radiance being E/(π sin² half-angle)).
/// Delta lights must take MIS weight 1 and the disk a weight shared with the BSDF rays that see
/// it: either wrong moves pixels by several percent. The tolerance: five standard errors from
/// each pixel's own sample variance (the pick of one light per sample is most of the noise),
/// plus the closed form's spread over the pixel's footprint and 1e-4 relative for rounding.
#[test]
fn the_furnace_with_every_kind_of_light_is_rho_times_one_plus_irradiance_over_pi() {
    let point = DVec3::new(-0.5, 2.0, 0.7);
    let spot = DVec3::new(1.0, 2.5, -0.5);
    let sun = DVec3::new(0.3, -1.0, 0.4).normalize();
    let disk = DVec3::new(-0.2, -1.0, 0.1).normalize();
    // A floor just wider than the view (±4.2 at the camera's 70°): the suns' power for the
    // choice of light grows with the scene's bounding radius, and on the 40 × 40 floor they
    // would leave the point light 2% of the picks, a heavy-tailed estimate the variance of
    // 256 samples does not capture. The sky sees only the upper half-space either way.
    let scene = floor_scene_under(
        "background = [1.0, 1.0, 1.0]",
        5.0,
        "[[lights]]\ntype = \"point\"\nposition = [-0.5, 2.0, 0.7]\nintensity = 7.0\n\
         [[lights]]\ntype = \"spot\"\nposition = [1.0, 2.5, -0.5]\ndirection = [0.0, -1.0, 0.0]\n\
         intensity = 9.0\ninner_angle = 20.0\nouter_angle = 40.0\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0.3, -1.0, 0.4]\nintensity = 0.8\n\
         [[lights]]\ntype = \"directional\"\ndirection = [-0.2, -1.0, 0.1]\nintensity = 0.6\n\
         angle = 2.0\n",
        16,
        1024,
    );
    let irradiance = |x: DVec3| {
        let to_point = point - x;
        let d2 = to_point.length_squared();
        let from_point = 7.0 * (to_point.y / d2.sqrt()) / d2;
        let to_spot = spot - x;
        let d2 = to_spot.length_squared();
        let cos = to_spot.y / d2.sqrt();
        let from_spot = 9.0 * gltf_spot_falloff(cos, 20.0, 40.0) * cos / d2;
        from_point + from_spot + 0.8 * -sun.y + 0.6 * -disk.y
    };
    let radiance = |x: DVec3| ALBEDO * (1.0 + irradiance(x) / PI);
    let params = &scene.params;
    for (device, mut renderer) in common::renderers(&scene) {
        let (image, variance) = common::render_with_variance(renderer.as_mut(), 1024);
        let mut worst: f64 = 0.0;
        for py in 0..image.height {
            for px in 0..image.width {
                let n = 8;
                let values: Vec<f64> = (0..n * n)
                    .map(|k| {
                        let x = px as f64 + ((k % n) as f64 + 0.5) / n as f64;
                        let y = py as f64 + ((k / n) as f64 + 0.5) / n as f64;
                        radiance(floor_point(params, x, y))
                    })
                    .collect();
                let mean = values.iter().sum::<f64>() / values.len() as f64;
                let spread = values.iter().cloned().fold(f64::MIN, f64::max)
                    - values.iter().cloned().fold(f64::MAX, f64::min);
                let i = (py * image.width + px) as usize;
                for c in 0..3 {
                    let got = image.pixels[i][c] as f64;
                    let standard_error = (variance.pixels[i][c] as f64).sqrt();
                    let tolerance = 5.0 * standard_error + 2.0 * spread / 32.0 + 1e-4 * mean;
                    let error = (got - mean).abs();
                    assert!(
                        error <= tolerance,
                        "{device}: pixel ({px}, {py}) is {got}, expected {mean} ± {tolerance}"
                    );
                    worst = worst.max(error / tolerance);
                }
            }
        }
        eprintln!("{device} furnace with lights: worst error {worst:.2} of its tolerance");
    }
}

/// glTF KHR_lights_punctual's spot falloff, written out here from the extension's text:
/// clamp(cd · scale + offset, 0, 1)², scale = 1 / max(0.001, cos inner − cos outer),
/// offset = −cos outer · scale, cd the cosine between the spot's axis and the direction from
/// the light to the point.
fn gltf_spot_falloff(cd: f64, inner_degrees: f64, outer_degrees: f64) -> f64 {
    let (ci, co) = (
        inner_degrees.to_radians().cos(),
        outer_degrees.to_radians().cos(),
    );
    let scale = 1.0 / (ci - co).max(0.001);
    (cd * scale - co * scale).clamp(0.0, 1.0).powi(2)
}

/// A spot pointing straight down from height 2.5, cone 30°–45°: the floor is lit fully within
/// 1.44 of the point below it, not at all beyond 2.5, with glTF's falloff between; the 32²
/// image's pixels cover all three zones.
#[test]
fn spot_light_falls_off_as_gltf_says() {
    let position = DVec3::new(0.2, 2.5, 0.1);
    let (inner, outer) = (30.0, 45.0);
    let scene = floor_scene(
        "[[lights]]\ntype = \"spot\"\nposition = [0.2, 2.5, 0.1]\ndirection = [0.0, -1.0, 0.0]\n\
         intensity = 9.0\ninner_angle = 30.0\nouter_angle = 45.0\n",
        32,
        16,
    );
    let radiance = |x: DVec3| {
        let to_light = position - x;
        let d2 = to_light.length_squared();
        let cos_theta = to_light.y / d2.sqrt();
        let falloff = gltf_spot_falloff(cos_theta, inner, outer);
        ALBEDO * 9.0 * falloff * cos_theta / (PI * d2)
    };
    // The zones: pixel centres inside the inner cone, between, and outside the outer one.
    let params = &scene.params;
    let mut zones = [0; 3];
    for py in 0..32 {
        for px in 0..32 {
            let x = floor_point(params, px as f64 + 0.5, py as f64 + 0.5);
            let to_light = position - x;
            let angle = (to_light.y / to_light.length()).acos().to_degrees();
            zones[(angle > inner) as usize + (angle > outer) as usize] += 1;
        }
    }
    assert!(zones.iter().all(|&z| z > 50), "{zones:?}");
    for (device, image) in render_both(&scene, 16) {
        assert_matches(&format!("{device} spot"), &image, params, 16, radiance);
    }
}

/// The kernel's falloff, exactly at the inner and outer angles and between them.
#[test]
fn spot_falloff_at_and_between_its_angles() {
    let light = glint::scene::light::Light {
        kind: glint::scene::light::LightKind::Spot {
            position: glam::Vec3::ZERO,
            direction: glam::Vec3::NEG_Y,
            inner_angle: 20.0,
            outer_angle: 35.0,
        },
        color: glam::Vec3::ONE,
        intensity: 1.0,
    };
    let kernel = light.kernel_light(1.0);
    for degrees in [0.0, 10.0, 20.0, 24.0, 27.5, 31.0, 35.0, 40.0, 90.0f64] {
        let r = degrees.to_radians();
        let from_light = glam::Vec3::new(r.sin() as f32, -r.cos() as f32, 0.0);
        let got = glint::cpu::lights::punctual::spot_falloff(&kernel, from_light) as f64;
        let expected = gltf_spot_falloff(r.cos(), 20.0, 35.0);
        assert!(
            (got - expected).abs() < 1e-5,
            "{degrees}°: {got} vs {expected}"
        );
    }
    assert_eq!(
        glint::cpu::lights::punctual::spot_falloff(&kernel, glam::Vec3::NEG_Y),
        1.0
    );
}

/// The GPU and the CPU trace the same paths through scenes/lights.toml (a sun disk, a sphere
/// light and a spot), 1 sample per pixel; the 99% bound is tests/suite/gpu_vs_cpu.rs's.
#[test]
fn gpu_and_cpu_trace_the_same_paths_under_lights() {
    let Some(ctx) = common::gpu() else { return };
    let mut agreement = common::PathAgreement::default();
    for seed in [1, 2] {
        let scene = common::sized(common::shipped_scene("lights.toml"), 64, seed);
        agreement.add(
            &common::render_cpu(&scene, 1),
            &common::render_gpu(ctx, &scene, 1),
        );
    }
    agreement.check(0.99);
}

const GOOD_LIGHT: &str = r#"
[camera]
eye = [0.0, 1.0, -5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
[render]
width = 8
height = 8
spp = 1
max_bounces = 1
[materials.white]
type = "diffuse"
color = [0.5, 0.5, 0.5]
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"
[[lights]]
type = "spot"
position = [0.0, 3.0, 0.0]
direction = [0.0, -1.0, 0.0]
intensity = 10.0
inner_angle = 10.0
outer_angle = 30.0
"#;

/// Bad lights name the file, the line and the field, and `glint render` exits with 2.
#[test]
fn bad_lights_are_errors_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    for (from, to, needles) in [
        (
            "intensity = 10.0",
            "intensity = -1.0",
            &["lights[0].intensity", "≥ 0"][..],
        ),
        (
            "outer_angle = 30.0",
            "outer_angle = 5.0",
            &["lights[0].outer_angle", "inner_angle"][..],
        ),
        (
            "direction = [0.0, -1.0, 0.0]",
            "direction = [0.0, 0.0, 0.0]",
            &["lights[0].direction", "zero"][..],
        ),
        (
            "type = \"spot\"",
            "type = \"area\"",
            &["lights[0].type", "unknown light type"][..],
        ),
        (
            "inner_angle = 10.0",
            "angle = 10.0",
            &["lights[0].angle", "does not apply"][..],
        ),
        (
            "direction = [0.0, -1.0, 0.0]\n",
            "",
            &["lights[0].direction", "missing"][..],
        ),
        (
            "type = \"spot\"\nposition = [0.0, 3.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\n\
             intensity = 10.0\ninner_angle = 10.0\nouter_angle = 30.0",
            "type = \"directional\"\ndirection = [0.0, -1.0, 0.0]\nintensity = 1e9\n\
             angle = 0.001",
            &["lights[0].angle", "radiance"][..],
        ),
        (
            "type = \"spot\"\nposition = [0.0, 3.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\n\
             intensity = 10.0\ninner_angle = 10.0\nouter_angle = 30.0",
            "type = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = 10.0\nradius = 1e-7",
            &["lights[0].radius", "radiance"][..],
        ),
    ] {
        assert!(GOOD_LIGHT.contains(from), "{from}");
        let text = GOOD_LIGHT.replacen(from, to, 1);
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, &text).unwrap();
        let e = glint::scene::Scene::load(&path).expect_err(to);
        let message = e.to_string();
        assert!(message.contains("bad.toml:"), "{message}");
        for n in needles {
            assert!(message.contains(n), "{message:?} lacks {n:?}");
        }
        let out = Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(["render", "bad.toml", "-o", "x.png", "--cpu"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(needles[0]), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!Path::new(&dir.path().join("x.png")).exists());
    }
    // The good scene parses.
    common::scene(GOOD_LIGHT);
}
