//! Scenes whose images are known in closed form, rendered on the CPU reference and on the GPU:
//! the furnace (every pixel exactly 1 − 2^−(B+1)), with and without light sampling; the white
//! furnace, in which a white diffuse sphere, a mirror, a smooth white metal and clear glass all
//! vanish under a white sky; rough GGX albedo against an independent quadrature; a white sphere
//! vanishing at three scales (which also catches self-intersection); `max_bounces = 0`; and a
//! floor under an emitting sphere against the irradiance formula, within 5σ of the estimator's
//! variance, which checks the cosine weighting; and an orthographic camera seeing a lamp head-on
//! in exactly the pixels its extent covers, at any distance.

use crate::common;
use common::{kernel_scene, largest_deviation, render_both};

const FURNACE: &str = r#"
[camera]
eye = [0.0, 0.0, 0.0]
target = [0.3, 0.2, 1.0]
up = [0.0, 1.0, 0.0]
vfov = 100.0
[render]
width = 32
height = 24
spp = 4
max_bounces = BOUNCES
light_sampling = LIGHT_SAMPLING
russian_roulette = false
[materials.furnace]
type = "diffuse"
color = [0.5, 0.5, 0.5]
emission = [1.0, 1.0, 1.0]
strength = 0.5
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "furnace"
"#;

/// Camera inside a sphere that reflects half and emits 0.5: a path with B scattering events
/// gathers 0.5 + 0.25 + … + 0.5^(B+1) = 1 − 2^−(B+1), whatever directions it takes. There is
/// no variance at all, so the tolerance is f32 rounding; a wrong albedo factor, emission
/// weight or bounce count is off by at least 2^−(B+1).
///
/// With light sampling the camera is inside the emitter, where cone sampling does not apply:
/// the sphere is sampled by area, which from a point on its inside is exactly the cosine
/// distribution, so light and BSDF samples each carry ρL with MIS weights of exactly ½. A
/// wrong pdf, a missing MIS weight or light counted twice moves every pixel by 10% or more.
/// That equality survives f32 because every light pdf is evaluated at the hit point itself
/// (projected onto the sphere) with a chord formula that stays accurate for nearly tangent
/// directions; we measured all of 49152 paths within 2e-6. The tolerance is 1e-5.
#[test]
fn furnace_is_one_minus_two_to_the_minus_bounces_plus_one() {
    for light_sampling in [true, false] {
        for bounces in [0u32, 1, 8, 30] {
            let scene = kernel_scene(
                &FURNACE
                    .replace("BOUNCES", &bounces.to_string())
                    .replace("LIGHT_SAMPLING", &light_sampling.to_string()),
            );
            let expected = 1.0 - 0.5f64.powi(bounces as i32 + 1);
            for (device, image) in render_both(&scene, 4) {
                let worst = image
                    .pixels
                    .iter()
                    .flatten()
                    .map(|&c| (c as f64 - expected).abs())
                    .fold(0.0, f64::max);
                let tolerance = if light_sampling { 1e-5 } else { 1e-6 };
                assert!(
                    worst < tolerance,
                    "{device}, light sampling {light_sampling}, B = {bounces}: off by {worst}"
                );
            }
        }
    }
}

/// The furnace scene shipped in scenes/ is 1 everywhere (to the light-sampling tolerance above).
#[test]
fn shipped_furnace_scene_is_one() {
    let scene = common::shipped_scene("furnace.toml").kernel_scene();
    for (device, image) in render_both(&scene, 2) {
        for p in &image.pixels {
            for c in p {
                assert!((c - 1.0).abs() < 1e-5, "{device}: {c}");
            }
        }
    }
}

const WHITE_SPHERE: &str = r#"
[camera]
eye = [CX, CY, CZ]
target = [SX, SY, SZ]
up = [0.0, 1.0, 0.0]
vfov = 30.0
[render]
width = 32
height = 32
spp = 4
max_bounces = BOUNCES
background = [1.0, 1.0, 1.0]
russian_roulette = false
[materials.white]
type = "diffuse"
color = [1.0, 1.0, 1.0]
[[spheres]]
center = [SX, SY, SZ]
radius = R
material = "white"
"#;

fn white_sphere(center: [f32; 3], radius: f32, bounces: u32) -> glint::kernel::KernelScene {
    let eye = [center[0], center[1], center[2] - 4.0 * radius];
    let mut text = WHITE_SPHERE
        .replace("BOUNCES", &bounces.to_string())
        .replace("R", &radius.to_string());
    for (name, v) in [
        ("CX", eye[0]),
        ("CY", eye[1]),
        ("CZ", eye[2]),
        ("SX", center[0]),
        ("SY", center[1]),
        ("SZ", center[2]),
    ] {
        text = text.replace(name, &format!("{v:?}"));
    }
    kernel_scene(&text)
}

/// A white (albedo 1) convex diffuse object under a uniform white sky vanishes: every bounce
/// off it leaves it and sees the sky, with weight exactly 1. With max_bounces = 1 a ray that
/// re-hit the surface it left would end at the bounce cap and return 0, so this also proves
/// there is no self-intersection, at the Cornell box's scale and for a 0.01-unit sphere far
/// from the origin.
#[test]
fn white_sphere_under_white_sky_vanishes_at_every_scale() {
    for (center, radius) in [
        ([0.0, 0.0, 0.0], 1.0),
        ([278.0, 90.0, 190.0], 90.0),
        ([1000.0, 500.0, -300.0], 0.01),
    ] {
        let scene = white_sphere(center, radius, 1);
        for (device, image) in render_both(&scene, 4) {
            let worst = largest_deviation(&image, 1.0);
            assert!(
                worst < 1e-6,
                "{device}, sphere r = {radius} at {center:?}: off by {worst}"
            );
        }
    }
}

/// With max_bounces = 0 only emitters (and the sky) are seen: a sample is 1 where it sees the
/// sky and 0 on the unlit sphere, so with 4 samples every pixel is k/4 (up to the f32 rounding
/// of the running mean). Ignoring the
/// cap would make the white sphere scatter the sky and vanish (no black pixels).
#[test]
fn zero_bounces_sees_only_emitters() {
    let scene = white_sphere([0.0, 0.0, 0.0], 1.0, 0);
    for (device, image) in render_both(&scene, 4) {
        for p in &image.pixels {
            let k = p[0] * 4.0;
            assert!((k - k.round()).abs() < 1e-6, "{device}: {p:?} is not k/4");
        }
        let black = image.pixels.iter().filter(|p| p[0] == 0.0).count();
        let white = image.pixels.iter().filter(|p| p[0] == 1.0).count();
        assert!(
            black > 100 && white > 100,
            "{device}: {black} black, {white} white"
        );
    }
}

/// A diffuse floor of albedo ρ below an emitting sphere (radiance L, radius r, centre at height
/// d), with one bounce: the floor's radiance is ρ/π · E with irradiance E = π L (r/d)², so
/// ρ L (r/d)². This checks the cosine weighting: sampling the hemisphere uniformly instead
/// gives ρ L (1 − √(1 − (r/d)²)) = 0.54× the right value for r/d = 1/2.
///
/// Each camera path is ρL with probability p = (r/d)² and 0 otherwise, so over N paths the
/// mean has standard deviation ρL √(p(1 − p)/N). With N = 48·48·64 = 147456 that is 0.45% of
/// the mean; the tolerance is 5σ (2.3%). The narrow field of view keeps the pixels within
/// 0.05 units of the point below the sphere, where E varies by < 0.1%.
#[test]
fn floor_under_an_emitting_sphere_matches_the_irradiance_formula() {
    let scene = common::floor_under_lamp(48, 64, 11);
    let (rho, l, p) = (0.6f64, 4.0f64, 0.25f64);
    let expected = rho * l * p;
    let n = 48.0 * 48.0 * 64.0;
    let sigma = rho * l * (p * (1.0 - p) / n).sqrt();
    for (device, image) in render_both(&scene, 64) {
        let mean = image.mean();
        assert!(
            (mean - expected).abs() < 5.0 * sigma,
            "{device}: {mean} vs {expected} ± {sigma}"
        );
    }
}

/// A sphere of `material` under a uniform white sky, seen by a camera outside it.
fn white_furnace(material: &str) -> glint::kernel::KernelScene {
    kernel_scene(&format!(
        r#"
[camera]
eye = [0.0, 0.0, -4.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 35.0
[render]
width = 32
height = 32
spp = 8
max_bounces = 64
background = [1.0, 1.0, 1.0]
russian_roulette = false
[materials.m]
{material}
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "m"
"#
    ))
}

/// The white furnace: under a uniform white sky, an object that neither absorbs nor emits
/// vanishes, since every path ends in the sky with weight 1. A white diffuse sphere, a perfect
/// mirror, a mirror-smooth white metal and clear glass (Fresnel reflection or refraction, η²
/// radiance scaling in and out) each leave every pixel at 1, up to f32 rounding; glass paths
/// stay inside for more than 64 bounces with probability below 10⁻⁸⁰.
#[test]
fn white_furnace_objects_vanish() {
    for material in [
        "type = \"diffuse\"\ncolor = [1.0, 1.0, 1.0]",
        "type = \"specular\"\ncolor = [1.0, 1.0, 1.0]",
        "type = \"metal\"\ncolor = [1.0, 1.0, 1.0]\nroughness = 0.0",
        "type = \"dielectric\"\nior = 1.5",
        "type = \"dielectric\"\nior = 2.4",
    ] {
        for (device, image) in render_both(&white_furnace(material), 8) {
            let worst = largest_deviation(&image, 1.0);
            assert!(worst < 1e-5, "{device}, {material:?}: off by {worst}");
        }
    }
}

/// Directional albedo of single-scattering GGX (white, F = 1) for light leaving at cos θo =
/// `mu`, by midpoint quadrature over the hemisphere of incoming directions, written here from
/// the formulas (D, height-correlated Smith G2) independently of the renderer's code.
fn ggx_albedo_quadrature(mu: f64, alpha: f64) -> f64 {
    let lambda = |cos: f64| {
        let tan2 = (1.0 - cos * cos) / (cos * cos);
        ((1.0 + alpha * alpha * tan2).sqrt() - 1.0) / 2.0
    };
    let d = |m_z: f64| {
        let a2 = alpha * alpha;
        let x = m_z * m_z * (a2 - 1.0) + 1.0;
        a2 / (std::f64::consts::PI * x * x)
    };
    let wo = glam::DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let n = 600;
    let mut sum = 0.0;
    for i in 0..n {
        let cos_i = (i as f64 + 0.5) / n as f64;
        let sin_i = (1.0 - cos_i * cos_i).sqrt();
        for j in 0..n {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n as f64;
            let wi = glam::DVec3::new(sin_i * phi.cos(), sin_i * phi.sin(), cos_i);
            let h = (wo + wi).normalize();
            let g2 = 1.0 / (1.0 + lambda(mu) + lambda(cos_i));
            // f cos θi dω with dω = d(cos θi) dφ.
            sum += d(h.z) * g2 / (4.0 * mu) / n as f64 * (std::f64::consts::TAU / n as f64);
        }
    }
    sum
}

/// A white metal (F0 = 1, so Fresnel is 1) under a uniform white sky reflects its directional
/// albedo, which single-scattering GGX keeps below 1: the light that would bounce again between
/// microfacets is lost. A flat quad seen head-on (and at 60°) through a narrow lens isolates
/// one outgoing direction, compared with the quadrature above. Each path's value is the
/// sample weight G2/G1 in [0, 1], so the tolerance is 5σ of the image mean from the render's
/// own variance image, plus 0.3% for the quadrature and the 0.5° field of view.
///
/// Measured: roughness 0.5, 0.75, 1 keep 0.916, 0.627, 0.307 head-on (a loss of up to 69% at
/// roughness 1) and more towards grazing angles (0.76 at cos θ = 0.1, roughness 1).
#[test]
fn rough_metal_reflects_the_ggx_directional_albedo() {
    for (roughness, tilt_degrees) in [(0.5f64, 0.0f64), (0.75, 0.0), (1.0, 0.0), (1.0, 60.0)] {
        let tilt = tilt_degrees.to_radians();
        // The camera looks at the origin from direction (0, sin, −cos): cos θo = cos(tilt).
        let scene = kernel_scene(&format!(
            r#"
[camera]
eye = [0.0, {ey}, {ez}]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 0.5
[render]
width = 16
height = 16
spp = 256
max_bounces = 1
background = [1.0, 1.0, 1.0]
[materials.m]
type = "metal"
color = [1.0, 1.0, 1.0]
roughness = {roughness}
[[quads]]
corner = [-5.0, -5.0, 0.0]
u = [10.0, 0.0, 0.0]
v = [0.0, 10.0, 0.0]
material = "m"
"#,
            ey = 10.0 * tilt.sin(),
            ez = -10.0 * tilt.cos(),
        ));
        let expected = ggx_albedo_quadrature(tilt.cos(), roughness * roughness);
        let mut renderer = glint::cpu::integrator::renderer::CpuRenderer::new(&scene);
        use glint::render::Renderer;
        renderer.add_samples(256).unwrap();
        let mean = renderer.read_mean().unwrap().mean();
        let variance = renderer.read_variance().unwrap().mean() / (16.0 * 16.0);
        let tolerance = 5.0 * variance.sqrt() + 0.003 * expected;
        eprintln!("white GGX metal, roughness {roughness}, θo = {tilt_degrees}°: rendered {mean:.4}, quadrature {expected:.4} ± {tolerance:.4}");
        assert!((mean - expected).abs() < tolerance, "{mean} vs {expected}");
    }
}

/// An orthographic camera looking head-on (along −z, image-right +x, image-up +y) at a lamp of
/// radiance (2, 1, 0.5) on a black background. The view is 3 units high over 24 rows and 4 wide
/// over 32 columns, so a pixel is 0.125 units square (exact in binary), and the lamp's
/// extent, x in [−1, 1] and y in [−0.75, 0.75], is exactly columns 8 to 23 and rows 6 to 17.
/// Every sample sees what lies straight ahead of its point on the image plane: every pixel of
/// the rectangle is exactly the radiance and every other pixel exactly 0, whatever the lamp's
/// distance (a perspective camera would shrink it with distance). A wrong half-extent, a jitter
/// not on the image plane, or rays from the eye would put lamp in other pixels or dark
/// samples in the lamp's. The lamp reflects nothing (black), so bounces add nothing to it.
#[test]
fn an_orthographic_camera_sees_a_lamp_in_exactly_its_pixels() {
    for lamp_z in [0.0, -40.0] {
        let scene = kernel_scene(&format!(
            r#"
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
projection = "orthographic"
height = 3.0
[render]
width = 32
height = 24
spp = 8
max_bounces = 2
[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 0.5, 0.25]
strength = 2.0
[[quads]]
corner = [-1.0, -0.75, {lamp_z:?}]
u = [2.0, 0.0, 0.0]
v = [0.0, 1.5, 0.0]
material = "lamp"
"#
        ));
        for (device, image) in render_both(&scene, 8) {
            for y in 0..24 {
                for x in 0..32 {
                    let inside = (8..24).contains(&x) && (6..18).contains(&y);
                    let expected = if inside { [2.0, 1.0, 0.5] } else { [0.0; 3] };
                    assert_eq!(
                        image.pixels[y * 32 + x],
                        expected,
                        "{device}, lamp at z = {lamp_z}: pixel ({x}, {y})"
                    );
                }
            }
        }
    }
}
