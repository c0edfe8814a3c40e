//! The glTF PBR material (`type = "pbr"`, src/cpu/materials/pbr.rs): energy conservation in a white
//! furnace at every angle and roughness, reciprocity, GPU ≡ CPU, and bad input. Its sampler's
//! χ² tests are in tests/suite/chi2.rs.

use crate::common;
use common::{gpu, render_cpu, render_gpu, render_with_variance, PathAgreement};
use glam::Vec3;
use glint::cpu::core::rng::Rng;
use glint::cpu::materials::material::{bsdf_eval, bsdf_sample};
use glint::kernel::types::{Material, MATERIAL_PBR};
use std::path::Path;

fn pbr(base: f32, metallic: f32, roughness: f32, specular: f32, ior: f32) -> Material {
    Material {
        albedo: [base; 3],
        kind: MATERIAL_PBR,
        alpha: roughness * roughness,
        ior,
        metallic,
        specular,
        specular_color: [1.0; 3],
        ..Default::default()
    }
}

/// The BSDF's albedo ∫f cos dωi at cos θo = `mu`, by its own sampler: the mean of the sample
/// weights, and the standard error of that mean.
fn albedo(m: &Material, mu: f32, samples: u32, seed: u32) -> (f64, f64) {
    let n = Vec3::Z;
    let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for i in 0..samples {
        let mut rng = Rng::new(i, 0, 7, seed);
        let w = bsdf_sample(m, wo, n, n, true, &mut rng).weight.x as f64;
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / samples as f64;
    let variance = (sum2 / samples as f64 - mean * mean).max(0.0);
    (mean, (variance / samples as f64).sqrt())
}

/// A white material neither absorbs nor creates energy: its albedo is 1 at every angle, for
/// the conductor and for the dielectric layer over a white base, at every roughness, with the
/// specular layer weakened and with another index of refraction. The issue's bound is 1%; the
/// estimate's own error (5 standard errors) is allowed on top, and is far smaller (about 0.1%).
/// (Single-scattering GGX alone, glint's `metal`, loses up to 60–70% at roughness 1.)
#[test]
fn a_white_pbr_material_reflects_everything_at_every_angle() {
    for metallic in [0.0, 0.5, 1.0] {
        for roughness in [0.0, 0.25, 0.5, 0.75, 1.0] {
            for (specular, ior) in [(1.0, 1.5), (0.5, 1.5), (1.0, 2.5)] {
                if metallic == 1.0 && (specular, ior) != (1.0, 1.5) {
                    continue;
                }
                let m = pbr(1.0, metallic, roughness, specular, ior);
                for mu in [0.05, 0.2, 0.5, 0.8, 1.0] {
                    let (mean, error) = albedo(&m, mu, 40_000, 11);
                    assert!(
                        (mean - 1.0).abs() < 0.01 + 5.0 * error,
                        "metallic {metallic}, roughness {roughness}, specular {specular}, \
                         ior {ior}, cos θo {mu}: albedo {mean} ± {error}"
                    );
                }
            }
        }
    }
}

/// The GGX albedo tables (src/tables/ggx.rs) read between their grid points, where every
/// material's α falls, agree with the albedo integrated there directly on a grid 64 times
/// finer: within 0.4% of the albedo, a small part of the furnaces' 1% (deterministic: no
/// sampling noise). Worst measured: 0.3% for roughness 1 head-on (μ = 1 lies beyond the last
/// column). With rows evenly spaced in α, a roughness-0.1 coat read between the rows at α
/// 0.001 and 0.032 was 2% off at cos θ 0.05–0.1.
#[test]
fn the_ggx_tables_are_accurate_between_their_grid_points() {
    use glint::cpu::materials::ggx_energy::ggx_albedo;
    use glint::tables::ggx::albedo_split_at_resolution;
    let mut worst = 0.0f64;
    for roughness in [0.0f32, 0.05, 0.1, 0.15, 0.2, 0.3, 0.45, 0.7, 1.0] {
        let alpha = (roughness * roughness).max(1e-3);
        for mu in [0.05f32, 0.1, 0.2, 0.35, 0.5, 0.8, 1.0] {
            let (a, b) = ggx_albedo(mu, alpha);
            let (exact_a, exact_b) = albedo_split_at_resolution(mu as f64, alpha as f64, 1024, 256);
            // The coat's albedo weighs A by its f0 = 0.04, the white metal's E by 1.
            for (name, read, exact) in [
                ("A", a as f64, exact_a),
                ("B", b as f64, exact_b),
                ("E", (a + b) as f64, exact_a + exact_b),
            ] {
                worst = worst.max((read - exact).abs());
                assert!(
                    (read - exact).abs() < 0.004,
                    "roughness {roughness}, cos θ {mu}: {name} read {read}, integrated {exact}"
                );
            }
        }
    }
    eprintln!("GGX tables between grid points: worst error {worst:.5}");
}

/// The white stacks the coat's and the sheen's furnaces lie over, as (metallic, roughness):
/// dielectric and metal at roughness 0, 0.5 and 1, and half metal at 0.3.
const WHITE_STACKS: [(f32, f32); 7] = [
    (0.0, 0.0),
    (0.0, 0.5),
    (0.0, 1.0),
    (0.5, 0.3),
    (1.0, 0.0),
    (1.0, 0.5),
    (1.0, 1.0),
];

/// KHR_materials_clearcoat's coat (f0 0.04, weight 1) over white stacks: the coat's
/// reciprocal albedo scaling keeps the white furnace within 1% at every coat roughness (0 is
/// the coat's smallest α, 10⁻³), plus 5 standard errors of the estimate (from the sample
/// weights' variance). Measured before the GGX tables were spaced in roughness and the coat's
/// and the base's scalings normalised together: up to 2.5% off for coat roughness 0.1. Before
/// the specular lobes' scaling was normalised over their spread (`src/tables/clearcoat.rs`):
/// up to −4.3% over full metal of roughness 0.5 under a coat of roughness 0 or 0.1.
#[test]
fn a_coat_over_a_white_pbr_stack_reflects_everything() {
    let mut worst = 0.0f64;
    for coat_roughness in [0.0, 0.1, 0.5, 1.0] {
        for (metallic, roughness) in WHITE_STACKS {
            let m = Material {
                clearcoat: 1.0,
                clearcoat_alpha: coat_roughness * coat_roughness,
                ..pbr(1.0, metallic, roughness, 1.0, 1.5)
            };
            for mu in [0.05, 0.2, 0.5, 0.8, 1.0] {
                let (mean, error) = albedo(&m, mu, 40_000, 12);
                worst = worst.max((mean - 1.0).abs());
                if std::env::var("GLINT_PRINT_FURNACE").is_ok() {
                    eprintln!("coat {coat_roughness} metallic {metallic} roughness {roughness} mu {mu}: {mean:.4} ± {error:.4}");
                    continue;
                }
                assert!(
                    (mean - 1.0).abs() < 0.01 + 5.0 * error,
                    "coat roughness {coat_roughness}, metallic {metallic}, roughness \
                     {roughness}, cos θo {mu}: albedo {mean} ± {error}"
                );
            }
        }
    }
    eprintln!("coat over white stacks: worst |albedo − 1| {worst:.4}");
}

/// The albedo at cos θo = `mu` about the base's normal (z), with the coat's own normal
/// `coat_n` (as a clearcoatNormalTexture tilts it), by the sampler: mean and standard error.
fn albedo_with_coat_normal(m: &Material, mu: f32, coat_n: Vec3, samples: u32) -> (f64, f64) {
    let n = Vec3::Z;
    let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for i in 0..samples {
        let mut rng = Rng::new(i, 0, 7, 14);
        let w = bsdf_sample(m, wo, n, coat_n, true, &mut rng).weight.x as f64;
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / samples as f64;
    let variance = (sum2 / samples as f64 - mean * mean).max(0.0);
    (mean, (variance / samples as f64).sqrt())
}

/// The coat's normal turned `degrees` from z towards azimuth `phi` (radians).
fn tilted(degrees: f32, phi: f32) -> Vec3 {
    let t = degrees.to_radians();
    Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
}

/// A coat whose own normal is tilted from the base's (clearcoatNormalTexture) over a white
/// stack never creates energy: the coat's lobe is cut where the base's surface ends, and the
/// base is dimmed by the coat's albedo about the coat's normal, so the albedo stays ≤ 1 (plus
/// 5 standard errors of the estimate, from the sample weights' variance). What the tilt loses
/// is bounded too, so a change that darkens tilted coats more fails: measured, up to 35% (42%
/// before the coat's scaling of specular lobes was normalised over their spread)
/// (metal under a smooth coat tilted 15°, cos θo 0.2, whose mirror direction grazes the
/// coat's horizon, where the coat reflects nearly all), within 5% for the rough coat over the
/// dielectric stack but at the 30° tilt's grazing cases.
#[test]
fn a_tilted_coat_over_a_white_stack_creates_no_energy() {
    const LOSS: f64 = 0.40;
    let mut worst = (0.0f64, 0.0f64);
    for coat_roughness in [0.1, 0.5] {
        for (metallic, roughness) in [(0.0, 0.5), (1.0, 0.3)] {
            let m = Material {
                clearcoat: 1.0,
                clearcoat_alpha: coat_roughness * coat_roughness,
                ..pbr(1.0, metallic, roughness, 1.0, 1.5)
            };
            for (degrees, phi) in [(15.0, 0.0), (30.0, 3.1), (30.0, 1.6), (45.0, 0.5)] {
                let coat_n = tilted(degrees, phi);
                for mu in [0.2f32, 0.5, 0.8, 1.0] {
                    let wo_z_coat = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu).dot(coat_n);
                    if wo_z_coat <= 0.05 {
                        continue;
                    }
                    let (mean, error) = albedo_with_coat_normal(&m, mu, coat_n, 40_000);
                    worst = (worst.0.max(mean - 1.0), worst.1.max(1.0 - mean));
                    let case = format!(
                        "coat roughness {coat_roughness}, metallic {metallic}, roughness \
                         {roughness}, coat normal {degrees}° at {phi}, cos θo {mu}: albedo \
                         {mean} ± {error}"
                    );
                    if std::env::var("GLINT_PRINT_FURNACE").is_ok() {
                        eprintln!("{case}");
                        continue;
                    }
                    assert!(mean < 1.0 + 5.0 * error, "{case}");
                    assert!(mean > 1.0 - LOSS - 5.0 * error, "{case}");
                }
            }
        }
    }
    eprintln!(
        "tilted coats: most gained {:.4}, most lost {:.4}",
        worst.0, worst.1
    );
}

/// The coat's lobe about its own tilted normal is reciprocal: over a black base (nothing but
/// the coat reflects), f(wo, wi) = f(wi, wo), where bsdf_eval's f · cos θi has the cosine
/// about the coat's normal; to f32 rounding.
#[test]
fn a_tilted_coat_is_reciprocal() {
    let mut rng = Rng::new(5, 6, 7, 8);
    let n = Vec3::Z;
    let random_direction = |rng: &mut Rng| {
        let z: f32 = rng.next_f32().max(0.02);
        let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
        let s = (1.0 - z * z).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    };
    let mut checked = 0;
    for k in 0..4000 {
        let m = Material {
            clearcoat: rng.next_f32(),
            clearcoat_alpha: rng.next_f32().max(0.05),
            ..pbr(0.0, 0.0, rng.next_f32(), 0.0, 1.5)
        };
        let coat_n = tilted(
            50.0 * rng.next_f32(),
            std::f32::consts::TAU * rng.next_f32(),
        );
        let (wo, wi) = (random_direction(&mut rng), random_direction(&mut rng));
        let (cos_o, cos_i) = (wo.dot(coat_n), wi.dot(coat_n));
        if cos_o <= 0.0 || cos_i <= 0.0 {
            // Below the coat's normal its lobe is black both ways.
            assert_eq!(
                bsdf_eval(&m, wo, wi, n, coat_n, true),
                Vec3::ZERO,
                "case {k}"
            );
            assert_eq!(
                bsdf_eval(&m, wi, wo, n, coat_n, true),
                Vec3::ZERO,
                "case {k}"
            );
            continue;
        }
        if cos_o <= 0.02 || cos_i <= 0.02 {
            // Too grazing for f32 rounding to keep the ratio (as the_pbr_brdf_is_reciprocal).
            continue;
        }
        checked += 1;
        let forward = bsdf_eval(&m, wo, wi, n, coat_n, true) / cos_i;
        let backward = bsdf_eval(&m, wi, wo, n, coat_n, true) / cos_o;
        let scale = forward.max_element().max(1e-3);
        assert!(
            forward.max_element() > 0.0,
            "case {k}: the coat reflects nothing ({m:?}, coat normal {coat_n})"
        );
        assert!(
            (forward - backward).abs().max_element() <= 2e-4 * scale,
            "case {k}: f(wo, wi) = {forward}, f(wi, wo) = {backward} ({m:?}, coat normal \
             {coat_n}, wo {wo}, wi {wi})"
        );
    }
    assert!(checked > 2000, "{checked} cases above both normals");
}

/// A coat over a black base reflects what the coat alone reflects: more at grazing angles,
/// never more than everything, and f0 = 4% head-on when smooth, less when rough.
#[test]
fn a_coat_over_a_black_base_reflects_the_coats_share() {
    for coat_roughness in [0.1, 0.5, 1.0] {
        let m = Material {
            clearcoat: 1.0,
            clearcoat_alpha: coat_roughness * coat_roughness,
            ..pbr(0.0, 0.0, 0.5, 0.0, 1.5)
        };
        let (head_on, error) = albedo(&m, 1.0, 40_000, 13);
        // Smooth: f0 = 4%. Rougher coats reflect less head-on (their microfacets send light
        // off to be shadowed, and the multiple scattering that returns it is F_avg² small).
        let expected = if coat_roughness < 0.2 {
            0.035..0.045
        } else {
            0.005..0.04
        };
        assert!(
            expected.contains(&head_on),
            "coat roughness {coat_roughness}: head-on albedo {head_on} ± {error}"
        );
        let (grazing, _) = albedo(&m, 0.1, 40_000, 13);
        assert!(
            grazing > head_on && grazing < 1.0,
            "{coat_roughness}: {grazing}"
        );
    }
}

/// KHR_materials_sheen's white sheen over white stacks, with the extension's own albedo
/// scaling min(1 − E(μo), 1 − E(μi)): it never creates energy, and loses what the min takes
/// where E(μi) > E(μo), most head-on: measured, up to 7.0% at sheen roughness 0.3, 12.6% at
/// 0.6 and 13.2% at 1 (cos θo 1, over a rough base). The bound is that loss (README.md gives
/// it), so a change that loses more fails; 5 standard errors allowed as above.
#[test]
fn a_white_sheen_over_a_white_pbr_stack_loses_at_most_what_its_scaling_takes() {
    let mut worst = 0.0f64;
    for sheen_roughness in [0.3, 0.6, 1.0] {
        for (metallic, roughness) in WHITE_STACKS {
            let m = Material {
                sheen_color: [1.0; 3],
                sheen_roughness,
                ..pbr(1.0, metallic, roughness, 1.0, 1.5)
            };
            for mu in [0.05, 0.2, 0.5, 0.8, 1.0] {
                let (mean, error) = albedo(&m, mu, 40_000, 14);
                worst = worst.max(1.0 - mean);
                if std::env::var("GLINT_PRINT_FURNACE").is_ok() {
                    eprintln!("sheen {sheen_roughness} metallic {metallic} roughness {roughness} mu {mu}: {mean:.4} ± {error:.4}");
                    continue;
                }
                assert!(
                    mean < 1.0 + 5.0 * error && mean > 1.0 - SHEEN_LOSS_BOUND - 5.0 * error,
                    "sheen roughness {sheen_roughness}, metallic {metallic}, roughness \
                     {roughness}, cos θo {mu}: albedo {mean} ± {error}"
                );
            }
        }
    }
    eprintln!("white sheen over white stacks: worst loss {worst:.4}");
}

/// The most a white sheen over a white stack loses (see the test above).
const SHEEN_LOSS_BOUND: f64 = 0.14;

/// f(wo, wi) = f(wi, wo) for the reflection: bsdf_eval returns f · cos θi, so f(wo, wi) cos θo (the eval with
/// the roles swapped, times cos θo / cos θi) must match, to f32 rounding.
#[test]
fn the_pbr_brdf_is_reciprocal() {
    let mut rng = Rng::new(1, 2, 3, 4);
    let n = Vec3::Z;
    let random_direction = |rng: &mut Rng| {
        let z: f32 = rng.next_f32().max(0.02);
        let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
        let s = (1.0 - z * z).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    };
    for k in 0..2000 {
        let m = Material {
            albedo: [rng.next_f32(), rng.next_f32(), rng.next_f32()],
            // The transmission lobe's reflection too, from outside and inside (its
            // refraction's reciprocity is in tests/suite/transmission.rs).
            transmission: rng.next_f32(),
            // A coat and a sheen on a third of the cases each.
            clearcoat: if k % 3 == 0 { rng.next_f32() } else { 0.0 },
            clearcoat_alpha: rng.next_f32(),
            sheen_color: if k % 3 == 1 {
                [rng.next_f32(), rng.next_f32(), rng.next_f32()]
            } else {
                [0.0; 3]
            },
            sheen_roughness: rng.next_f32(),
            ..pbr(
                0.0,
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
                1.0 + 2.0 * rng.next_f32(),
            )
        };
        let (wo, wi) = (random_direction(&mut rng), random_direction(&mut rng));
        let forward = bsdf_eval(&m, wo, wi, n, n, k % 2 == 0) / wi.z;
        let backward = bsdf_eval(&m, wi, wo, n, n, k % 2 == 0) / wo.z;
        let scale = forward.max_element().max(1e-3);
        assert!(
            (forward - backward).abs().max_element() <= 2e-4 * scale,
            "case {k}: f(wo, wi) = {forward}, f(wi, wo) = {backward} ({m:?}, wo {wo}, wi {wi})"
        );
    }
}

/// The shipped material grid on both devices, one path per pixel: the same paths (see
/// tests/suite/gpu_vs_cpu.rs for why 99%).
#[test]
fn gpu_and_cpu_trace_the_same_paths_through_pbr_materials() {
    let Some(ctx) = gpu() else { return };
    let mut agreement = PathAgreement::default();
    for seed in [1, 2] {
        let scene = common::sized(common::shipped_scene("materials.toml"), 48, seed);
        agreement.add(&render_cpu(&scene, 1), &render_gpu(ctx, &scene, 1));
    }
    agreement.check(0.99);
}

/// The white furnace through the whole renderer, on both devices: white spheres of the grid's
/// settings under a white sky; each image's mean within 1% of 1 (plus 5 standard errors from
/// the variance image).
#[test]
fn white_pbr_spheres_vanish_in_a_white_furnace() {
    for (metallic, roughness) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.5), (0.5, 0.3)] {
        let scene = common::kernel_scene(&format!(
            r#"
[camera]
eye = [0.0, 0.0, -4.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 30.0
[render]
width = 24
height = 24
spp = 1
max_bounces = 64
light_sampling = false
background = [1.0, 1.0, 1.0]
[materials.m]
type = "pbr"
base_color = [1.0, 1.0, 1.0]
metallic = {metallic}
roughness = {roughness}
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "m"
"#
        ));
        for (device, mut renderer) in common::renderers(&scene) {
            let (image, variance) = render_with_variance(renderer.as_mut(), 64);
            let sigma = (variance.mean() / image.pixels.len() as f64).sqrt();
            let mean = image.mean();
            assert!(
                (mean - 1.0).abs() < 0.01 + 5.0 * sigma,
                "{device}, metallic {metallic}, roughness {roughness}: mean {mean} (σ {sigma})"
            );
        }
    }
}

fn scene_error(material: &str) -> String {
    let text = format!(
        "[camera]\neye = [0.0, 0.0, -4.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         vfov = 30.0\n[render]\nwidth = 8\nheight = 8\nspp = 1\nmax_bounces = 2\n\
         [materials.m]\n{material}\n[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\n\
         material = \"m\"\n"
    );
    glint::scene::Scene::parse(&text, Path::new("bad.toml"))
        .expect_err("the scene should be rejected")
        .to_string()
}

#[test]
fn bad_pbr_materials_are_named_errors() {
    for (material, needles) in [
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nmetallic = 1.5",
            &["materials.m.metallic", "[0, 1]"][..],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nroughness = -0.1",
            &["materials.m.roughness", "[0, 1]"],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nior = 1000.0",
            &["materials.m.ior", "index of refraction"],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nspecular = 2.0",
            &["materials.m.specular", "[0, 1]"],
        ),
        (
            "type = \"pbr\"\nmetallic = 0.5",
            &["materials.m.base_color", "missing"],
        ),
        (
            "type = \"pbr\"\ncolor = [0.5, 0.5, 0.5]",
            &["materials.m.color", "does not apply"],
        ),
        (
            "type = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\nmetallic = 0.5",
            &["materials.m.metallic", "does not apply"],
        ),
        (
            "type = \"pbr\"\nbase_color = [1.5, 0.5, 0.5]",
            &["materials.m.base_color", "[0, 1]"],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nclearcoat = 1.5",
            &["materials.m.clearcoat", "[0, 1]", "1.5"],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nclearcoat_roughness = -0.5",
            &["materials.m.clearcoat_roughness", "[0, 1]"],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nsheen_color = [2.0, 0.0, 0.0]",
            &["materials.m.sheen_color", "[0, 1]"],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nsheen_roughness = 3.0",
            &["materials.m.sheen_roughness", "[0, 1]"],
        ),
        (
            "type = \"pbr\"\nbase_color = [0.5, 0.5, 0.5]\nclearcoat = { texture = \"nope.png\" }",
            &["materials.m.clearcoat", "nope.png"],
        ),
        (
            "type = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\nsheen_color = [1.0, 1.0, 1.0]",
            &["materials.m.sheen_color", "does not apply"],
        ),
    ] {
        let message = scene_error(material);
        assert!(message.starts_with("bad.toml:"), "{message}");
        for needle in needles {
            assert!(
                message.contains(needle),
                "{material:?}: {message:?} lacks {needle:?}"
            );
        }
    }
}
