//! Participating media against closed forms, on the CPU reference and the GPU: Beer's law
//! through a slab of chromatic absorbing medium (spectral MIS's surviving weight), the
//! single-scattering radiance of a slab lit head-on by a sun (next-event estimation from
//! medium vertices, shadow rays through an interface, the phase function's value), and white
//! furnaces in which a sphere of non-absorbing medium behind an interface vanishes for
//! g = −0.7, 0 and 0.7: under a constant sky exactly, and, with chromatic scattering, under a
//! uniform environment map, which light sampling reaches through the interface (MIS between
//! phase and light sampling).
//!
//! The statistical checks compare the image's mean with the closed form in units of its own
//! standard error, from the renderers' per-pixel variance of the mean: the pixels are
//! independent, so the mean's variance is their variances' sum over n². |z| < 5 fails a
//! correct renderer with probability below 10⁻⁶ per check (the seeds are fixed, so each run
//! passes or fails alike); a bias of the size of any mistake in the weights (a channel's pdf
//! in place of the mixture's, a missing transmittance, a phase function off by a factor)
//! is tens of standard errors.

use crate::common;
use common::{largest_deviation, render_both, render_with_variance, renderers};
use glint::kernel::KernelScene;
use glint::scene::Scene;
use std::path::Path;

/// A closed box mesh over [lo, hi], its faces wound outwards, as OBJ.
fn box_obj(lo: [f32; 3], hi: [f32; 3]) -> String {
    let corner = |i: usize| {
        glam::Vec3::from_array(std::array::from_fn(|a| {
            if i >> a & 1 == 1 {
                hi[a]
            } else {
                lo[a]
            }
        }))
    };
    let mut out = String::new();
    for i in 0..8 {
        let v = corner(i);
        out += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for side in 0..2 {
            // The face's corners in order around it, then turned to face outwards.
            let mut f: Vec<usize> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                .iter()
                .map(|&(x, y)| side << a | x << b | y << c)
                .collect();
            let normal = (corner(f[1]) - corner(f[0])).cross(corner(f[2]) - corner(f[0]));
            if (normal[a] > 0.0) != (side == 1) {
                f.reverse();
            }
            let f: Vec<usize> = f.iter().map(|i| i + 1).collect();
            out += &format!(
                "f {} {} {}\nf {} {} {}\n",
                f[0], f[1], f[2], f[0], f[2], f[3]
            );
        }
    }
    out
}

/// The scene `toml`, parsed in `dir`, where the slab's mesh file is.
fn scene_in(dir: &Path, toml: &str) -> Scene {
    let path = dir.join("media.toml");
    Scene::parse(toml, &path).unwrap_or_else(|e| panic!("{e}"))
}

/// A slab z ∈ [0, 1], 100 wide, of `medium`, bounded by an interface, seen head-on through an
/// orthographic camera 0.2 units across from z = −2, with `more` added to the scene; light
/// scattered once at most (max_bounces 1).
fn slab_scene(dir: &Path, medium: &str, more: &str, spp: u32, seed: u32) -> KernelScene {
    std::fs::write(
        dir.join("slab.obj"),
        box_obj([-50.0, -50.0, 0.0], [50.0, 50.0, 1.0]),
    )
    .unwrap();
    let toml = format!(
        r#"
[camera]
eye = [0.0, 0.0, -2.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
projection = "orthographic"
height = 0.2
[render]
width = 16
height = 16
spp = {spp}
max_bounces = 1
seed = {seed}
russian_roulette = false
[materials.boundary]
type = "interface"
[media.slab]
{medium}
[[meshes]]
file = "slab.obj"
material = "boundary"
medium = "slab"
{more}
"#
    );
    scene_in(dir, &toml).kernel_scene()
}

/// Renders `scene` at `spp` on the CPU and, where there is one, the GPU, and asserts each
/// image's mean is `want` ([`assert_mean_is`]).
fn assert_mean_on_each_device(name: &str, scene: &KernelScene, spp: u32, want: [f64; 3]) {
    for (device, mut renderer) in renderers(scene) {
        let (image, variance) = render_with_variance(renderer.as_mut(), spp);
        assert_mean_is(&format!("{device} {name}"), &image, &variance, want);
    }
}

/// The image's mean per channel and its z against `want`, from the variance of each pixel's
/// mean; asserts |z| < 5 in every channel.
fn assert_mean_is(
    name: &str,
    image: &glint::image::output::Image,
    variance: &glint::image::output::Image,
    want: [f64; 3],
) {
    let n = image.pixels.len() as f64;
    for c in 0..3 {
        let mean = image.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n;
        let var = variance.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / (n * n);
        let z = (mean - want[c]) / var.sqrt().max(1e-12);
        eprintln!(
            "{name}, channel {c}: mean {mean:.5}, closed form {:.5}, z = {z:.2}",
            want[c]
        );
        assert!(
            z.abs() < 5.0,
            "{name}, channel {c}: mean {mean} against {} (z = {z:.2})",
            want[c]
        );
    }
}

/// An emitter of radiance 1 behind a slab of σa = (0.2, 0.7, 1.5), σs = 0: each pixel's
/// expectation is exp(−σa), Beer's law, whichever channel each free flight samples.
#[test]
fn a_slab_transmits_by_beers_law() {
    let dir = tempfile::tempdir().unwrap();
    let sigma_a = [0.2f64, 0.7, 1.5];
    let lamp = r#"
[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
[[quads]]
corner = [-60.0, -60.0, 3.0]
u = [120.0, 0.0, 0.0]
v = [0.0, 120.0, 0.0]
material = "lamp"
"#;
    let scene = slab_scene(
        dir.path(),
        "sigma_a = [0.2, 0.7, 1.5]\nsigma_s = [0.0, 0.0, 0.0]",
        lamp,
        256,
        1,
    );
    // No scattering event on the way to the lamp: the two interfaces crossed are not counted
    // against max_bounces (with them counted, as once, this image was black).
    let scene = KernelScene {
        params: glint::kernel::types::Params {
            max_bounces: 0,
            ..scene.params
        },
        ..scene
    };
    assert_mean_on_each_device("Beer slab", &scene, 256, sigma_a.map(|a| (-a).exp()));
}

/// A sun of irradiance E = 2 shining along +z into the slab (σs = (0.3, 0.6, 1.2), σa = 0.1,
/// g = 0.3), seen from the side it enters, with light scattered once only (max_bounces 1; the
/// interface crossed is not counted): L = E σs p(−1) (1 − exp(−2 σt)) / (2 σt), the integral over
/// depth z of light attenuated by exp(−σt z) both ways, scattered straight back (cos θ = −1).
#[test]
fn a_slab_lit_head_on_scatters_once_as_the_closed_form_says() {
    let dir = tempfile::tempdir().unwrap();
    let sun = r#"
[[lights]]
type = "directional"
direction = [0.0, 0.0, 1.0]
intensity = 2.0
"#;
    let scene = slab_scene(
        dir.path(),
        "sigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.3, 0.6, 1.2]\ng = 0.3",
        sun,
        256,
        2,
    );
    let g: f64 = 0.3;
    let phase_back = (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g).powi(3));
    let want = [0.3f64, 0.6, 1.2].map(|s| {
        let t = s + 0.1;
        2.0 * s * phase_back * (1.0 - (-2.0 * t).exp()) / (2.0 * t)
    });
    assert_mean_on_each_device("single scattering", &scene, 256, want);
}

/// A unit sphere of medium `medium` behind an interface, under `sky`, seen from outside.
fn furnace(medium: &str, sky: &str) -> String {
    format!(
        r#"
[camera]
eye = [0.0, 0.0, -4.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 35.0
[render]
width = 16
height = 16
spp = 4
max_bounces = 256
russian_roulette = false
{sky}
[materials.boundary]
type = "interface"
[media.cloud]
{medium}
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "boundary"
medium = "cloud"
"#
    )
}

/// Under a constant white sky (no emitter: every path ends in the sky), a grey medium that
/// only scatters leaves every path's weight 1 (σs Tr over the mixture's density σt Tr, phase
/// over its pdf), so every pixel is 1 up to rounding, for g = −0.7, 0 and 0.7. A path stays
/// in the sphere (optical radius 2) for 256 segments with negligible probability.
#[test]
fn white_furnace_media_vanish_under_a_constant_sky() {
    for g in [-0.7, 0.0, 0.7] {
        let text = furnace(
            &format!("sigma_s = [2.0, 2.0, 2.0]\ng = {g}"),
            "background = [1.0, 1.0, 1.0]",
        );
        for (device, image) in render_both(&common::kernel_scene(&text), 4) {
            let worst = largest_deviation(&image, 1.0);
            assert!(worst < 1e-4, "{device}, g = {g}: off by {worst}");
        }
    }
}

/// Under a uniform environment map of radiance 1, which light sampling reaches from medium
/// vertices through the interface, a chromatic non-absorbing medium (σs = (0.5, 1.5, 3)) still
/// vanishes: the image's mean is 1 in every channel within 5 standard errors, for g = −0.7, 0
/// and 0.7, with next-event estimation weighted against phase sampling.
#[test]
fn white_furnace_media_vanish_under_a_uniform_map() {
    let dir = tempfile::tempdir().unwrap();
    common::write_map(dir.path(), "white.exr", 16, 8, |_, _| [1.0; 3]);
    for (k, g) in [-0.7, 0.0, 0.7].into_iter().enumerate() {
        let text = furnace(
            &format!("sigma_s = [0.5, 1.5, 3.0]\ng = {g}"),
            &format!("seed = {}\n[environment]\nfile = \"white.exr\"", 10 + k),
        );
        let scene = scene_in(dir.path(), &text).kernel_scene();
        assert!(scene.params.light_sampling != 0 && !scene.emitters.is_empty());
        assert_mean_on_each_device(&format!("furnace map g = {g}"), &scene, 64, [1.0; 3]);
    }
}

/// Interfaces are not scattering events: a white diffuse sphere (radius 0.5) inside a sphere
/// of clear medium (radius 1, behind an interface) under a uniform map of radiance 1, at
/// max_bounces 1, is a white furnace (one bounce off a convex white surface sees the map
/// everywhere), so the image's mean is 1 in every channel within 5 standard errors, on both
/// devices. Measured on the CPU with the two faults this catches: crossings counted as
/// bounces (the camera ray's crossing used the one bounce; the sphere was black), mean 0.473,
/// z = −390; a path that had made its last bounce stopping at the interface instead of
/// leaving through it (the BSDF-sampled share of the light lost), mean 0.899, z = −119.
#[test]
fn interfaces_crossed_are_not_bounces() {
    let dir = tempfile::tempdir().unwrap();
    common::write_map(dir.path(), "white.exr", 16, 8, |_, _| [1.0; 3]);
    let text = furnace(
        "sigma_a = [0.0, 0.0, 0.0]\nsigma_s = [0.0, 0.0, 0.0]",
        "seed = 3\n[environment]\nfile = \"white.exr\"",
    )
    .replace("max_bounces = 256", "max_bounces = 1")
        + r#"
[materials.white]
type = "diffuse"
color = [1.0, 1.0, 1.0]
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 0.5
material = "white"
"#;
    let scene = scene_in(dir.path(), &text).kernel_scene();
    assert_mean_on_each_device("white sphere behind an interface", &scene, 64, [1.0; 3]);
}

/// `subsurface_color` and `subsurface_radius` on a pbr material: a medium inside every sphere of
/// it, its coefficients Chiang, Kutz and Burley's fit (src/scene/validate/media.rs), the surface
/// fully transmissive; and a render through it is finite and lit.
#[test]
fn a_subsurface_material_fills_its_spheres_with_the_fitted_medium() {
    let text = r#"
[camera]
eye = [0.0, 1.0, -4.0]
target = [0.0, 0.6, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 30.0
[render]
width = 12
height = 12
spp = 16
max_bounces = 32
background = [1.0, 1.0, 1.0]
[materials.wax]
type = "pbr"
base_color = [1.0, 1.0, 1.0]
subsurface_color = [0.5, 0.5, 0.5]
subsurface_radius = [1.0, 0.5, 2.0]
[[spheres]]
center = [0.0, 0.6, 0.0]
radius = 0.6
material = "wax"
"#;
    let scene = Scene::parse(text, Path::new("wax.toml")).unwrap();
    assert_eq!(scene.media.list.len(), 1);
    assert_eq!(scene.media.boundaries.len(), 1);
    let medium = &scene.media.list[0];
    // A = 0.5: α = 1 − exp(0.5 (−5.09406 + 0.5 (2.61188 − 0.5 · 4.31805))) = 0.912298;
    // σt = 1 / (d (1.9 − 0.5 + 3.5 · 0.3²)) = 0.583090 / d.
    for (c, d) in [1.0f32, 0.5, 2.0].into_iter().enumerate() {
        let extinction = medium.sigma_a[c] + medium.sigma_s[c];
        assert!((extinction * d - 0.583090).abs() < 1e-5, "{medium:?}");
        assert!(
            (medium.sigma_s[c] / extinction - 0.912298).abs() < 1e-5,
            "{medium:?}"
        );
    }
    let (material, _) = scene.media.boundaries[0];
    assert!(matches!(
        scene.materials[material as usize].kind,
        glint::scene::MaterialKind::Pbr { transmission, .. } if transmission == 1.0
    ));
    let image = common::render_cpu(&scene.kernel_scene(), 16);
    let center = image.pixels[6 * 12 + 6];
    assert!(
        center.iter().all(|v| v.is_finite() && *v > 0.0),
        "{center:?}"
    );
}
