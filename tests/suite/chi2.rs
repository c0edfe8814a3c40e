//! χ² goodness-of-fit of every sampling routine, in the WGSL kernel (through the probe kernel,
//! tests/suite/shaders/probe.wgsl) and in the CPU mirror: the random stream, the cosine hemisphere,
//! light sampling (two emitters, inside an emitting sphere, triangle emitters), the environment
//! map on half-texel cells (64×32 rotated with a black band never sampled, 256×128 with a
//! one-texel sun 10⁵ times brighter), GGX, the dielectric's Fresnel choice, the rough dielectric
//! both ways, and the pbr mixture with transmission, coats, sheens and a tilted coat normal.
//! 10⁶ samples each against a pdf written independently in f64, cells expecting fewer than 5
//! pooled; significance 0.01, Šidák-corrected over the suite; a sample where the pdf is 0 fails.

use crate::common;
use common::chi2::{
    assert_fits, directions, directions_integrated, directions_with_absorbed, pearson, uniform_2d,
};
use common::probe::{run_probe, ProbeParams, PROBE_SCENE};
use glam::Vec3;
use glint::cpu::core::rng::Rng;
use glint::cpu::materials::diffuse::sample_cosine_hemisphere;
use std::f64::consts::PI;

const SAMPLES: u32 = 1_000_000;
const SEED: u32 = 2024;

fn normals() -> [(&'static str, Vec3); 4] {
    [
        ("+z", Vec3::Z),
        // The orthonormal basis has a branch on the sign of n.z.
        ("-z", -Vec3::Z),
        ("tilted", Vec3::new(0.3, -0.8, 0.52).normalize()),
        ("+x", Vec3::X),
    ]
}

fn probe(normal: Vec3, count: u32, seed: u32) -> ProbeParams {
    ProbeParams {
        normal: normal.into(),
        count,
        seed,
        ..Default::default()
    }
}

/// A scene for probes that read none of it.
fn empty_scene() -> glint::kernel::KernelScene {
    common::kernel_scene(PROBE_SCENE)
}

fn cosine_pdf(n: Vec3) -> impl Fn(Vec3) -> f64 {
    move |d: Vec3| (d.dot(n) as f64).max(0.0) / PI
}

/// The same draws as the probe kernel makes with `seed`: stream 1 of "pixel" i.
fn cpu_draws(i: u32, seed: u32) -> Rng {
    Rng::new(i, 0, 1, seed)
}

#[test]
fn cpu_uniform_stream() {
    let samples: Vec<[f32; 2]> = (0..SAMPLES / 2)
        .flat_map(|i| {
            let mut r = cpu_draws(i, SEED);
            [[r.next_f32(), r.next_f32()], [r.next_f32(), r.next_f32()]]
        })
        .collect();
    assert_fits("cpu rng pairs", &Ok(uniform_2d(&samples, 32)));
}

#[test]
fn gpu_uniform_stream() {
    let Some(ctx) = common::gpu() else { return };
    let out = run_probe(
        ctx,
        "probe_uniform",
        probe(Vec3::Z, SAMPLES / 2, SEED),
        &empty_scene(),
    );
    let samples: Vec<[f32; 2]> = out
        .iter()
        .flat_map(|v| [[v[0], v[1]], [v[2], v[3]]])
        .collect();
    assert_fits("gpu rng pairs", &Ok(uniform_2d(&samples, 32)));
}

#[test]
fn cpu_cosine_hemisphere() {
    // A seed per normal keeps the tests independent, as the Šidák correction assumes.
    for (k, (name, n)) in normals().into_iter().enumerate() {
        let samples: Vec<Vec3> = (0..SAMPLES)
            .map(|i| {
                let mut r = cpu_draws(i, SEED + 1 + k as u32);
                sample_cosine_hemisphere(n, (r.next_f32(), r.next_f32()))
            })
            .collect();
        assert_fits(
            &format!("cpu cosine hemisphere {name}"),
            &directions(&samples, n, cosine_pdf(n), 20, 40),
        );
    }
}

#[test]
fn gpu_cosine_hemisphere() {
    let Some(ctx) = common::gpu() else { return };
    for (k, (name, n)) in normals().into_iter().enumerate() {
        let seed = SEED + 11 + k as u32;
        let samples: Vec<Vec3> = run_probe(
            ctx,
            "probe_cosine_hemisphere",
            probe(n, SAMPLES, seed),
            &empty_scene(),
        )
        .iter()
        .map(|v| Vec3::new(v[0], v[1], v[2]))
        .collect();
        assert_fits(
            &format!("gpu cosine hemisphere {name}"),
            &directions(&samples, n, cosine_pdf(n), 20, 40),
        );
    }
}

/// The χ² machinery itself rejects a wrong pdf: cosine samples are not uniform on the
/// hemisphere, and a cosine pdf about the wrong axis puts samples where it says 0.
#[test]
fn chi2_rejects_wrong_pdfs() {
    let samples: Vec<Vec3> = (0..SAMPLES / 4)
        .map(|i| {
            let mut r = cpu_draws(i, SEED);
            sample_cosine_hemisphere(Vec3::Z, (r.next_f32(), r.next_f32()))
        })
        .collect();
    let uniform_hemisphere = |d: Vec3| if d.z > 0.0 { 1.0 / (2.0 * PI) } else { 0.0 };
    let result = directions(&samples, Vec3::Z, uniform_hemisphere, 20, 40).unwrap();
    assert!(result.p_value < 1e-12, "{result:?}");
    let wrong_axis = directions(&samples, Vec3::Z, cosine_pdf(Vec3::X), 20, 40);
    assert!(wrong_axis.unwrap_err().contains("pdf is 0"));
    let skewed: Vec<[f32; 2]> = (0..SAMPLES / 4)
        .map(|i| {
            let mut r = cpu_draws(i, SEED);
            [r.next_f32().powf(1.05), r.next_f32()]
        })
        .collect();
    assert!(uniform_2d(&skewed, 32).p_value < 1e-6);
}

// ---- Light sampling ------------------------------------------------------------------------

/// Two emitters of different power seen from the origin: a quad above and a sphere beside.
const TWO_LIGHTS: &str = r#"
[materials.quad_lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
strength = 2.0
[materials.ball_lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 0.5, 0.25]
strength = 9.0
[[quads]]
corner = [-1.5, 2.0, -1.0]
u = [3.0, 0.0, 0.0]
v = [0.0, 0.5, 3.0]
material = "quad_lamp"
[[spheres]]
center = [1.5, -0.3, 1.0]
radius = 0.8
material = "ball_lamp"
"#;

/// A point inside an emitting sphere.
const INSIDE_LIGHT: &str = r#"
[materials.lamp]
type = "diffuse"
color = [0.5, 0.5, 0.5]
emission = [1.0, 1.0, 1.0]
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 2.0
material = "lamp"
"#;

/// The solid-angle pdf with which light sampling from `p` produces `dir`, computed here in f64
/// from the geometry and the power-proportional selection, independently of the renderer.
fn reference_light_pdf(scene: &glint::scene::Scene, p: glam::DVec3, dir: glam::DVec3) -> f64 {
    use glam::DVec3;
    let power = |material: u32| {
        scene.materials[material as usize]
            .emitted_radiance
            .as_dvec3()
            .element_sum()
            / 3.0
    };
    let sphere_power: Vec<f64> = scene
        .spheres
        .iter()
        .map(|s| power(s.material) * 4.0 * PI * (s.radius as f64).powi(2))
        .collect();
    let quad_power: Vec<f64> = scene
        .quads
        .iter()
        .map(|q| power(q.material) * q.u.cross(q.v).length() as f64)
        .collect();
    let triangle_area = |t: &glint::scene::Triangle| {
        let [a, b, c] = t.vertices.map(|v| v.as_dvec3());
        0.5 * (b - a).cross(c - a).length()
    };
    let triangle_power: Vec<f64> = scene
        .triangles
        .iter()
        .map(|t| power(t.material) * triangle_area(t))
        .collect();
    let total: f64 = sphere_power
        .iter()
        .chain(&quad_power)
        .chain(&triangle_power)
        .sum();
    let mut pdf = 0.0;
    for (s, w) in scene.spheres.iter().zip(&sphere_power) {
        let (c, r) = (s.center.as_dvec3(), s.radius as f64);
        let oc = c - p;
        if oc.length() < r {
            // Inside: area sampling; the exit point along dir.
            let h = dir.dot(oc);
            let t = h + (h * h + r * r - oc.dot(oc)).sqrt();
            let n = (p + t * dir - c) / r;
            pdf += w / total * t * t / (n.dot(dir).abs() * 4.0 * PI * r * r);
        } else {
            // A sample drawn at the cone's very edge is a direction rounded to f32 (relative
            // error ~6e-8), which may land a hair outside it: the reference cone is wider by
            // 1e-6 in cos, a sliver of 2π·1e-6 sr that changes no cell's expected count.
            let cos_max = (1.0 - r * r / oc.dot(oc)).sqrt();
            if dir.dot(oc.normalize()) >= cos_max - 1e-6 {
                pdf += w / total / (2.0 * PI * (1.0 - cos_max));
            }
        }
    }
    for (q, w) in scene.quads.iter().zip(&quad_power) {
        let (corner, u, v) = (q.corner.as_dvec3(), q.u.as_dvec3(), q.v.as_dvec3());
        let n: DVec3 = u.cross(v).normalize();
        let t = n.dot(corner - p) / n.dot(dir);
        if t > 0.0 {
            let x = p + t * dir - corner;
            let (a, b) = (x.dot(u) / u.dot(u), x.dot(v) / v.dot(v));
            if (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) {
                pdf += w / total * t * t / (n.dot(dir).abs() * u.cross(v).length());
            }
        }
    }
    for (tri, w) in scene.triangles.iter().zip(&triangle_power) {
        let [a, b, c] = tri.vertices.map(|v| v.as_dvec3());
        let n: DVec3 = (b - a).cross(c - a).normalize();
        let t = n.dot(a - p) / n.dot(dir);
        if t > 0.0 {
            // Inside when the three sub-triangles' signed areas agree with the triangle's.
            let x = p + t * dir;
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(e0, e1)| (e1 - e0).cross(x - e0).dot(n) >= 0.0);
            if inside {
                pdf += w / total * t * t / (n.dot(dir).abs() * triangle_area(tri));
            }
        }
    }
    pdf
}

/// TWO_LIGHTS with four emitting triangles added (a fan, two materials), so light sampling
/// chooses among spheres, quads and triangles by power.
fn lights_with_triangles() -> glint::scene::Scene {
    let mut scene = common::scene(&format!(
        "{PROBE_SCENE}{TWO_LIGHTS}
[materials.tri_lamp]
type = \"diffuse\"
color = [0.0, 0.0, 0.0]
emission = [0.5, 1.0, 2.0]
strength = 3.0
[materials.tri_lamp_dim]
type = \"diffuse\"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
"
    ));
    let index = |name: &str| scene.materials.iter().position(|m| m.name == name).unwrap() as u32;
    let (bright, dim) = (index("tri_lamp"), index("tri_lamp_dim"));
    // A flat fan (on one tilted plane), so no direction from the origin meets two of them
    // and each sample's pdf is its own triangle's.
    let apex = Vec3::new(-1.25, -1.2, 1.8);
    let base = [
        Vec3::new(-2.0, -1.5, 1.0),
        Vec3::new(-0.5, -1.5, 1.2),
        Vec3::new(-0.5, -0.9, 2.6),
        Vec3::new(-2.0, -0.9, 2.4),
    ];
    for k in 0..4 {
        scene.triangles.push(glint::scene::Triangle {
            vertices: [base[k], base[(k + 1) % 4], apex],
            normals: None,
            material: if k % 2 == 0 { bright } else { dim },
            uvs: None,
            uvs1: None,
            tangents: None,
            colors: None,
        });
    }
    scene
}

fn light_cases() -> [(&'static str, glint::scene::Scene, Vec3); 3] {
    [
        (
            "two lights",
            common::scene(&format!("{PROBE_SCENE}{TWO_LIGHTS}")),
            Vec3::ZERO,
        ),
        (
            "inside a light",
            common::scene(&format!("{PROBE_SCENE}{INSIDE_LIGHT}")),
            Vec3::new(0.6, -0.4, 0.3),
        ),
        (
            "spheres, quads and triangles",
            lights_with_triangles(),
            Vec3::ZERO,
        ),
    ]
}

/// Checks light-sampled directions (and the pdf each sample reports) against the reference.
fn check_light_samples(name: &str, scene: &glint::scene::Scene, p: Vec3, samples: &[[f32; 4]]) {
    let dirs: Vec<Vec3> = samples
        .iter()
        .map(|s| Vec3::new(s[0], s[1], s[2]))
        .collect();
    for (d, s) in dirs.iter().zip(samples).step_by(997) {
        let reference = reference_light_pdf(scene, p.as_dvec3(), d.as_dvec3().normalize());
        assert!(
            (s[3] as f64 / reference - 1.0).abs() < 1e-3,
            "{name}: sample pdf {} vs {reference}",
            s[3]
        );
    }
    let pdf = |d: Vec3| reference_light_pdf(scene, p.as_dvec3(), d.as_dvec3().normalize());
    assert_fits(
        name,
        &directions_integrated(&dirs, Vec3::Z, pdf, 20, 40, 48),
    );
}

#[test]
fn cpu_light_sampling() {
    for (k, (name, scene, p)) in light_cases().into_iter().enumerate() {
        let kernel = scene.kernel_scene();
        let refs = glint::cpu::scene_refs::SceneRefs::of(&kernel, &kernel.params);
        let samples: Vec<[f32; 4]> = (0..SAMPLES)
            .map(|i| {
                let mut r = cpu_draws(i, SEED + 21 + k as u32);
                let s = glint::cpu::lights::sampling::sample_light(&refs, p, p, &mut r);
                [s.dir.x, s.dir.y, s.dir.z, s.pdf]
            })
            .collect();
        check_light_samples(&format!("cpu light sampling, {name}"), &scene, p, &samples);
    }
}

#[test]
fn gpu_light_sampling() {
    let Some(ctx) = common::gpu() else { return };
    for (k, (name, scene, p)) in light_cases().into_iter().enumerate() {
        let params = ProbeParams {
            position: p.into(),
            side_probe: p.into(),
            ..probe(Vec3::Z, SAMPLES, SEED + 31 + k as u32)
        };
        let samples = run_probe(ctx, "probe_light", params, &scene.kernel_scene());
        check_light_samples(&format!("gpu light sampling, {name}"), &scene, p, &samples);
    }
}

// ---- Emitter choice (the alias table) -------------------------------------------------------

/// Emitters of very unequal power: 60 quads of growing size in three strengths (some expect
/// fewer than five picks, which the χ² pools), two spheres, and lights_with_triangles' four
/// triangles.
fn many_emitters() -> glint::scene::Scene {
    let mut toml = String::new();
    for k in 0..60 {
        let side = 0.02 * (k + 1) as f32;
        toml += &format!(
            "[[quads]]\ncorner = [{x}, 3.0, 0.0]\nu = [{side}, 0.0, 0.0]\nv = [0.0, 0.0, {side}]\n\
             material = \"quad_lamp_{m}\"\n",
            x = k as f32,
            m = k % 3
        );
    }
    for (m, strength) in [0.01, 1.0, 40.0].iter().enumerate() {
        toml += &format!(
            "[materials.quad_lamp_{m}]\ntype = \"diffuse\"\ncolor = [0.0, 0.0, 0.0]\n\
             emission = [1.0, 0.5, 0.25]\nstrength = {strength}\n"
        );
    }
    toml += "[[spheres]]\ncenter = [0.0, -5.0, 0.0]\nradius = 0.3\nmaterial = \"ball_lamp\"\n";
    let mut scene = lights_with_triangles();
    let extra = common::scene(&format!("{PROBE_SCENE}{TWO_LIGHTS}{toml}"));
    // The triangles refer to materials by index: keep TWO_LIGHTS' materials first.
    let offset = scene.materials.len() as u32;
    scene.materials.extend(extra.materials);
    scene.quads.extend(extra.quads.into_iter().map(|mut q| {
        q.material += offset;
        q
    }));
    scene.spheres.extend(extra.spheres.into_iter().map(|mut s| {
        s.material += offset;
        s
    }));
    scene
}

/// Each emitter (primitive, index) with the probability of picking it, power / total power,
/// computed here in f64 from the scene alone.
fn reference_emitter_probabilities(scene: &glint::scene::Scene) -> Vec<((u32, u32), f64)> {
    use glint::kernel::types::{PRIMITIVE_QUAD, PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE};
    let power = |material: u32| {
        scene.materials[material as usize]
            .emitted_radiance
            .as_dvec3()
            .element_sum()
            / 3.0
    };
    let mut powers: Vec<((u32, u32), f64)> = Vec::new();
    for (i, s) in scene.spheres.iter().enumerate() {
        let p = power(s.material) * 4.0 * PI * (s.radius as f64).powi(2);
        powers.push(((PRIMITIVE_SPHERE, i as u32), p));
    }
    for (i, q) in scene.quads.iter().enumerate() {
        let p = power(q.material) * q.u.as_dvec3().cross(q.v.as_dvec3()).length();
        powers.push(((PRIMITIVE_QUAD, i as u32), p));
    }
    for (i, t) in scene.triangles.iter().enumerate() {
        let [a, b, c] = t.vertices.map(|v| v.as_dvec3());
        let p = power(t.material) * 0.5 * (b - a).cross(c - a).length();
        powers.push(((PRIMITIVE_TRIANGLE, i as u32), p));
    }
    powers.retain(|p| p.1 > 0.0);
    let total: f64 = powers.iter().map(|p| p.1).sum();
    powers.into_iter().map(|(e, p)| (e, p / total)).collect()
}

/// Picks (primitive, index, reported probability) against the emitters' probabilities, by χ²;
/// and every reported probability must be, exactly, the one light_pdf uses for that emitter
/// (the primitive's `light_probability`), so MIS stays consistent with the pick.
fn check_emitter_choices(name: &str, scene: &glint::scene::Scene, picks: &[[f32; 4]]) {
    use glint::kernel::types::{PRIMITIVE_QUAD, PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE};
    let kernel = scene.kernel_scene();
    let reference = reference_emitter_probabilities(scene);
    let ordinal: std::collections::HashMap<(u32, u32), usize> = reference
        .iter()
        .enumerate()
        .map(|(k, (e, _))| (*e, k))
        .collect();
    let mut observed = vec![0u64; reference.len()];
    for pick in picks {
        let (primitive, index) = (pick[0] as u32, pick[1] as u32);
        let k = *ordinal
            .get(&(primitive, index))
            .unwrap_or_else(|| panic!("{name}: picked ({primitive}, {index}), not an emitter"));
        observed[k] += 1;
        let light_probability = match primitive {
            PRIMITIVE_SPHERE => kernel.spheres[index as usize].light_probability,
            PRIMITIVE_QUAD => kernel.quads[index as usize].light_probability,
            PRIMITIVE_TRIANGLE => kernel.triangles[index as usize].light_probability,
            _ => unreachable!(),
        };
        assert_eq!(pick[2], light_probability, "{name}: ({primitive}, {index})");
    }
    let expected: Vec<f64> = reference
        .iter()
        .map(|(_, p)| p * picks.len() as f64)
        .collect();
    assert_fits(name, &Ok(pearson(&observed, &expected)));
}

fn cpu_emitter_choices(scene: &glint::kernel::KernelScene, seed: u32) -> Vec<[f32; 4]> {
    let refs = glint::cpu::scene_refs::SceneRefs::of(scene, &scene.params);
    (0..SAMPLES)
        .map(|i| {
            let mut r = cpu_draws(i, seed);
            let (u_slot, u_alias) = (r.next_f32(), r.next_f32());
            let e = glint::cpu::lights::sampling::pick_emitter(&refs, u_slot, u_alias);
            [e.primitive as f32, e.index as f32, e.probability, 0.0]
        })
        .collect()
}

#[test]
fn cpu_emitter_choice() {
    let scene = many_emitters();
    let picks = cpu_emitter_choices(&scene.kernel_scene(), SEED + 41);
    check_emitter_choices("cpu emitter choice", &scene, &picks);
}

/// The GPU's picks fit the probabilities, and are the CPU's, pick for pick.
#[test]
fn gpu_emitter_choice() {
    let Some(ctx) = common::gpu() else { return };
    let scene = many_emitters();
    let kernel = scene.kernel_scene();
    let picks = run_probe(
        ctx,
        "probe_emitter_choice",
        probe(Vec3::Z, SAMPLES, SEED + 43),
        &kernel,
    );
    check_emitter_choices("gpu emitter choice", &scene, &picks);
    let cpu = cpu_emitter_choices(&kernel, SEED + 43);
    let differ = picks.iter().zip(&cpu).filter(|(g, c)| g != c).count();
    assert_eq!(
        differ, 0,
        "{differ} of {SAMPLES} GPU picks differ from the CPU's"
    );
}

// ---- Metal (GGX, visible normals) ----------------------------------------------------------

/// The pdf of the reflected direction wi for GGX visible-normal sampling, G1(wo) D(h) / (4 cos θo),
/// written here in f64 from the formulas (also for wi below the surface, which is absorbed).
fn reference_ggx_pdf(wo: glam::DVec3, wi: glam::DVec3, n: glam::DVec3, alpha: f64) -> f64 {
    let h = wo + wi;
    // wi = −wo is a single point where h is undefined (a Simpson node falls exactly there).
    if h.length() < 1e-4 {
        return 0.0;
    }
    let h = h.normalize();
    let (cos_h, cos_o) = (h.dot(n), wo.dot(n));
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let d = a2 / (PI * (cos_h * cos_h * (a2 - 1.0) + 1.0).powi(2));
    let tan2 = (1.0 - cos_o * cos_o) / (cos_o * cos_o);
    let g1 = 2.0 / (1.0 + (1.0 + a2 * tan2).sqrt());
    g1 * d / (4.0 * cos_o)
}

fn metal_cases() -> Vec<(String, Vec3, Vec3, f32)> {
    let n = Vec3::new(0.2, 0.9, -0.3).normalize();
    let (t, _) = n.any_orthonormal_pair();
    let head_on = n;
    // cos θo = 1/2 exactly, so the discontinuity of the reference pdf (microfacet normals at
    // the horizon, where wi · n = −wo · n) falls on a cell edge of the (cos θ, φ) grid about n.
    let oblique = 0.5 * n + 0.75f32.sqrt() * t;
    let mut cases = Vec::new();
    for alpha in [0.2f32, 0.5, 1.0] {
        for (angle, wo) in [("0°", head_on), ("60°", oblique)] {
            cases.push((format!("alpha {alpha}, θo {angle}"), n, wo, alpha));
        }
    }
    cases
}

fn check_metal_samples(name: &str, n: Vec3, wo: Vec3, alpha: f32, samples: &[[f32; 4]]) {
    let dirs: Vec<Vec3> = samples
        .iter()
        .map(|s| Vec3::new(s[0], s[1], s[2]))
        .collect();
    for (d, s) in dirs.iter().zip(samples) {
        // Below the surface a sample is absorbed; above it carries G2/G1 in (0, 1].
        if d.dot(n) <= 0.0 {
            assert_eq!(s[3], 0.0, "{name}: weight below the surface");
        } else {
            assert!(s[3] > 0.0 && s[3] <= 1.0 + 1e-5, "{name}: weight {}", s[3]);
        }
    }
    let pdf = |d: Vec3| {
        reference_ggx_pdf(
            wo.as_dvec3(),
            d.as_dvec3().normalize(),
            n.as_dvec3(),
            alpha as f64,
        )
    };
    // Cells about n: the pdf is smooth inside every cell (its edges lie on cell edges).
    assert_fits(name, &directions_integrated(&dirs, n, pdf, 20, 40, 48));
}

#[test]
fn cpu_metal_sampling() {
    for (k, (name, n, wo, alpha)) in metal_cases().into_iter().enumerate() {
        let m = glint::kernel::types::Material {
            albedo: [1.0; 3],
            kind: glint::kernel::types::MATERIAL_METAL,
            alpha,
            ..Default::default()
        };
        let samples: Vec<[f32; 4]> = (0..SAMPLES)
            .map(|i| {
                let mut r = cpu_draws(i, SEED + 41 + k as u32);
                let s = glint::cpu::materials::material::bsdf_sample(&m, wo, n, n, true, &mut r);
                [s.dir.x, s.dir.y, s.dir.z, s.weight.x]
            })
            .collect();
        check_metal_samples(&format!("cpu metal, {name}"), n, wo, alpha, &samples);
    }
}

#[test]
fn gpu_metal_sampling() {
    let Some(ctx) = common::gpu() else { return };
    for (k, (name, n, wo, alpha)) in metal_cases().into_iter().enumerate() {
        let params = ProbeParams {
            wo: wo.into(),
            alpha,
            ..probe(n, SAMPLES, SEED + 61 + k as u32)
        };
        let samples = run_probe(ctx, "probe_metal", params, &empty_scene());
        check_metal_samples(&format!("gpu metal, {name}"), n, wo, alpha, &samples);
    }
}

// ---- Dielectric: reflection or refraction --------------------------------------------------

/// Unpolarised Fresnel reflectance, f64, from the textbook formulas.
fn reference_fresnel(cos_i: f64, eta_i: f64, eta_t: f64) -> f64 {
    let sin_t = eta_i / eta_t * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    let rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    (rs * rs + rp * rp) / 2.0
}

/// (name, front face, angle of incidence in degrees); glass of ior 1.5.
const DIELECTRIC_CASES: [(&str, bool, f32); 3] = [
    ("entering at 30°", true, 30.0),
    ("entering at 80°", true, 80.0),
    ("leaving at 20°", false, 20.0),
];
const GLASS_IOR: f32 = 1.5;

/// Reflection happens with the Fresnel probability (binomial χ² on the two outcomes), every
/// reflection is the mirror direction, and every refraction obeys Snell's law.
fn check_dielectric_samples(
    name: &str,
    front: bool,
    degrees: f32,
    n: Vec3,
    wo: Vec3,
    samples: &[[f32; 4]],
) {
    let (eta_i, eta_t) = if front {
        (1.0, GLASS_IOR as f64)
    } else {
        (GLASS_IOR as f64, 1.0)
    };
    let cos_i = (degrees as f64).to_radians().cos();
    let reflectance = reference_fresnel(cos_i, eta_i, eta_t);
    let mut reflected = 0u64;
    for s in samples {
        let d = Vec3::new(s[0], s[1], s[2]).as_dvec3();
        let n = n.as_dvec3();
        if d.dot(n) > 0.0 {
            reflected += 1;
            let mirror = 2.0 * wo.as_dvec3().dot(n) * n - wo.as_dvec3();
            assert!(
                (d - mirror).length() < 1e-5,
                "{name}: reflection {d} vs {mirror}"
            );
        } else {
            let sin_t = (1.0 - d.dot(n).powi(2)).sqrt();
            let sin_i = (1.0 - cos_i * cos_i).sqrt();
            assert!(
                (eta_i * sin_i - eta_t * sin_t).abs() < 1e-5,
                "{name}: Snell"
            );
        }
    }
    let total = samples.len() as f64;
    let result = pearson(
        &[reflected, samples.len() as u64 - reflected],
        &[total * reflectance, total * (1.0 - reflectance)],
    );
    eprintln!(
        "{name}: reflected {:.5} of samples, Fresnel {reflectance:.5}",
        reflected as f64 / total
    );
    assert_fits(name, &Ok(result));
}

fn dielectric_geometry(degrees: f32) -> (Vec3, Vec3) {
    let n = Vec3::new(-0.4, 0.1, 0.9).normalize();
    let (t, _) = n.any_orthonormal_pair();
    let theta = degrees.to_radians();
    (n, (theta.cos() * n + theta.sin() * t).normalize())
}

fn glass(front_face: bool) -> glint::kernel::types::Material {
    let _ = front_face;
    glint::kernel::types::Material {
        albedo: [1.0; 3],
        kind: glint::kernel::types::MATERIAL_DIELECTRIC,
        ior: GLASS_IOR,
        ..Default::default()
    }
}

#[test]
fn cpu_dielectric_choice() {
    for (k, (name, front, degrees)) in DIELECTRIC_CASES.into_iter().enumerate() {
        let (n, wo) = dielectric_geometry(degrees);
        let samples: Vec<[f32; 4]> = (0..SAMPLES)
            .map(|i| {
                let mut r = cpu_draws(i, SEED + 81 + k as u32);
                let s = glint::cpu::materials::material::bsdf_sample(
                    &glass(front),
                    wo,
                    n,
                    n,
                    front,
                    &mut r,
                );
                [s.dir.x, s.dir.y, s.dir.z, s.weight.x]
            })
            .collect();
        check_dielectric_samples(
            &format!("cpu glass, {name}"),
            front,
            degrees,
            n,
            wo,
            &samples,
        );
    }
}

#[test]
fn gpu_dielectric_choice() {
    let Some(ctx) = common::gpu() else { return };
    for (k, (name, front, degrees)) in DIELECTRIC_CASES.into_iter().enumerate() {
        let (n, wo) = dielectric_geometry(degrees);
        let params = ProbeParams {
            wo: wo.into(),
            ior: GLASS_IOR,
            front_face: front as u32,
            ..probe(n, SAMPLES, SEED + 91 + k as u32)
        };
        let samples = run_probe(ctx, "probe_dielectric", params, &empty_scene());
        check_dielectric_samples(
            &format!("gpu glass, {name}"),
            front,
            degrees,
            n,
            wo,
            &samples,
        );
    }
}

/// Beyond the critical angle (41.8° leaving glass of ior 1.5) every sample reflects: a
/// refraction there would be a sample where the pdf is 0.
#[test]
fn total_internal_reflection_always_reflects() {
    let (n, wo) = dielectric_geometry(60.0);
    for i in 0..100_000 {
        let mut r = cpu_draws(i, SEED);
        let s =
            glint::cpu::materials::material::bsdf_sample(&glass(false), wo, n, n, false, &mut r);
        assert!(s.dir.dot(n) > 0.0, "refracted beyond the critical angle");
        assert_eq!(s.weight, Vec3::ONE);
    }
}

// ---- Environment map ------------------------------------------------------------------------

/// A test environment map: its size, rotation and texels (linear radiance, top row first).
struct MapCase {
    name: &'static str,
    width: u32,
    height: u32,
    rotate: f32,
    texel: fn(u32, u32) -> [f32; 3],
}

fn map_cases() -> [MapCase; 2] {
    [
        // Smooth colour gradients, a black band at the bottom (pdf 0: never sampled), rotated.
        MapCase {
            name: "smooth 64x32, rotated 30°",
            width: 64,
            height: 32,
            rotate: 30.0,
            texel: |x, y| {
                if y >= 28 {
                    return [0.0; 3];
                }
                let (u, v) = (x as f32 / 64.0, y as f32 / 32.0);
                [0.2 + u, 0.5 + 0.4 * (6.0 * u).sin(), 1.0 - v]
            },
        },
        // A dim sky with a one-texel sun 10⁵ times brighter: most samples go to one texel.
        MapCase {
            name: "tiny sun 256x128",
            width: 256,
            height: 128,
            rotate: 0.0,
            texel: |x, y| {
                if (x, y) == (40, 30) {
                    return [1e5, 0.9e5, 0.8e5];
                }
                [
                    0.05 + 0.4 * x as f32 / 256.0,
                    0.3,
                    0.5 - 0.3 * y as f32 / 128.0,
                ]
            },
        },
    ]
}

/// A scene lit only by `case`'s map, written as EXR into `dir`.
fn environment_scene(case: &MapCase, dir: &std::path::Path) -> glint::scene::Scene {
    let path = dir.join(format!("{}x{}.exr", case.width, case.height));
    image::Rgb32FImage::from_fn(case.width, case.height, |x, y| {
        image::Rgb((case.texel)(x, y))
    })
    .save(&path)
    .unwrap();
    common::scene(&format!(
        "{PROBE_SCENE}[environment]\nfile = {:?}\nrotate = {}\n",
        path.to_str().unwrap(),
        case.rotate
    ))
}

/// The map-frame (u, v) of a scene direction, in f64: turned back by the rotation, then
/// u = atan2(x, −z)/2π, v = acos(y)/π (src/scene/environment.rs), written independently.
fn map_uv(case: &MapCase, d: glam::DVec3) -> (f64, f64) {
    let a = (case.rotate as f64).to_radians();
    let (c, s) = (a.cos(), a.sin());
    let m = glam::DVec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z).normalize();
    let u = m.x.atan2(-m.z).rem_euclid(2.0 * PI) / (2.0 * PI);
    (u, m.y.clamp(-1.0, 1.0).acos() / PI)
}

/// The reference pdf: luminance over ∫ luminance dω, with each texel's exact solid angle
/// (2π/W)(cos θ_j − cos θ_j+1), from the formulas rather than the renderer's tables.
fn reference_environment_pdf(case: &MapCase) -> impl Fn(glam::DVec3) -> f64 + '_ {
    let lum = |c: [f32; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
    let (w, h) = (case.width, case.height);
    let row_solid_angle = move |y: u32| {
        2.0 * PI / w as f64
            * ((PI * y as f64 / h as f64).cos() - (PI * (y + 1) as f64 / h as f64).cos())
    };
    let total: f64 = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| lum((case.texel)(x, y)) * row_solid_angle(y))
        .sum();
    move |d: glam::DVec3| {
        let (u, v) = map_uv(case, d);
        let x = ((u * w as f64) as u32).min(w - 1);
        let y = ((v * h as f64) as u32).min(h - 1);
        lum((case.texel)(x, y)) / total
    }
}

/// χ² of sampled directions on a grid aligned with the texels, each split in 2×2 cells equal
/// in φ and in cos θ (so the within-texel distribution is tested too); the pdf is constant over
/// each cell, so the expected counts are exact: N · pdf · the cell's solid angle. Also checks
/// the pdf each sample reports against the reference.
fn check_environment_samples(case: &MapCase, name: &str, samples: &[[f32; 4]]) {
    let pdf = reference_environment_pdf(case);
    let (w, h) = (case.width as usize, case.height as usize);
    let (cols, rows) = (2 * w, 2 * h);
    let cos_edge = |y: usize, half: usize| {
        // cos θ at the top of texel row y (half 0), halfway in cos θ (1), at its bottom (2).
        let top = (PI * y as f64 / h as f64).cos();
        let bottom = (PI * (y + 1) as f64 / h as f64).cos();
        top + (bottom - top) * half as f64 / 2.0
    };
    let mut observed = vec![0u64; cols * rows];
    for (k, s) in samples.iter().enumerate() {
        let d = glam::DVec3::new(s[0] as f64, s[1] as f64, s[2] as f64);
        assert!(
            (d.length() - 1.0).abs() < 1e-4,
            "{name}: not a unit vector: {d}"
        );
        let reference = pdf(d);
        assert!(reference > 0.0, "{name}: sample {d} where the pdf is 0");
        if k % 997 == 0 {
            assert!(
                (s[3] as f64 / reference - 1.0).abs() < 1e-3,
                "{name}: sample pdf {} vs {reference}",
                s[3]
            );
        }
        let (u, v) = map_uv(case, d);
        let x = ((u * w as f64) as usize).min(w - 1);
        let y = ((v * h as f64) as usize).min(h - 1);
        let column = (((u * w as f64) - x as f64) * 2.0).clamp(0.0, 1.0) as usize;
        let cos = (v * PI).cos();
        let lower_half = (cos < cos_edge(y, 1)) as usize;
        observed[(2 * y + lower_half) * cols + 2 * x + column.min(1)] += 1;
    }
    let mut expected = vec![0.0; observed.len()];
    for y in 0..h {
        for half in 0..2 {
            let cell_solid_angle = PI / w as f64 * (cos_edge(y, half) - cos_edge(y, half + 1));
            for x in 0..w {
                let theta = PI * (y as f64 + 0.5) / h as f64;
                let phi = 2.0 * PI * (x as f64 + 0.5) / w as f64;
                let m = glam::DVec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    -theta.sin() * phi.cos(),
                );
                // Back to the scene frame: turned by +rotate about +y.
                let a = (case.rotate as f64).to_radians();
                let d = glam::DVec3::new(
                    a.cos() * m.x + a.sin() * m.z,
                    m.y,
                    a.cos() * m.z - a.sin() * m.x,
                );
                let p = pdf(d) * cell_solid_angle * samples.len() as f64;
                for column in 0..2 {
                    expected[(2 * y + half) * cols + 2 * x + column] = p;
                }
            }
        }
    }
    assert_fits(name, &Ok(pearson(&observed, &expected)));
}

#[test]
fn cpu_environment_sampling() {
    let dir = tempfile::tempdir().unwrap();
    for (k, case) in map_cases().iter().enumerate() {
        let kernel = environment_scene(case, dir.path()).kernel_scene();
        let refs = glint::cpu::scene_refs::SceneRefs::of(&kernel, &kernel.params);
        let samples: Vec<[f32; 4]> = (0..SAMPLES)
            .map(|i| {
                let mut r = cpu_draws(i, SEED + 101 + k as u32);
                let s = glint::cpu::lights::sampling::sample_light(
                    &refs,
                    Vec3::ZERO,
                    Vec3::ZERO,
                    &mut r,
                );
                [s.dir.x, s.dir.y, s.dir.z, s.pdf]
            })
            .collect();
        check_environment_samples(case, &format!("cpu environment, {}", case.name), &samples);
    }
}

#[test]
fn gpu_environment_sampling() {
    let Some(ctx) = common::gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    for (k, case) in map_cases().iter().enumerate() {
        let kernel = environment_scene(case, dir.path()).kernel_scene();
        let samples = run_probe(
            ctx,
            "probe_light",
            probe(Vec3::Z, SAMPLES, SEED + 111 + k as u32),
            &kernel,
        );
        check_environment_samples(case, &format!("gpu environment, {}", case.name), &samples);
    }
}

// ---- Sun disks -------------------------------------------------------------------------------

/// A sun of 2° angular diameter (no other emitter), travelling along `SUN_DIRECTION`.
const SUN: &str = r#"
[materials.grey]
type = "diffuse"
color = [0.5, 0.5, 0.5]
[[spheres]]
center = [0.0, -50.0, 0.0]
radius = 1.0
material = "grey"
[[lights]]
type = "directional"
direction = [0.3, -0.9, 0.2]
intensity = 2.0
angle = 2.0
"#;

/// Sun-disk samples, uniform in the disk's solid angle: (1 − cos θ) / (1 − cos θmax) and
/// φ / 2π about the axis are then uniform on [0, 1]², which the χ² checks on 32 × 32 cells;
/// every sample reports the uniform pdf 1 / (2π (1 − cos θmax)) and lies in the cone.
fn check_sun_samples(name: &str, samples: &[[f32; 4]]) {
    use glam::DVec3;
    let axis = -DVec3::new(0.3, -0.9, 0.2).normalize();
    let half = 1.0f64.to_radians();
    let one_minus_cos_max = 1.0 - half.cos();
    let expected_pdf = 1.0 / (2.0 * PI * one_minus_cos_max);
    let (t, b) = {
        let t = axis.cross(DVec3::Y).normalize();
        (t, axis.cross(t))
    };
    let cells: Vec<[f32; 2]> = samples
        .iter()
        .map(|s| {
            let d = DVec3::new(s[0] as f64, s[1] as f64, s[2] as f64).normalize();
            assert!(
                (s[3] as f64 / expected_pdf - 1.0).abs() < 1e-4,
                "{name}: pdf {} vs {expected_pdf}",
                s[3]
            );
            let one_minus_cos = 0.5 * (d - axis).length_squared();
            let u = one_minus_cos / one_minus_cos_max;
            assert!(u <= 1.0 + 1e-3, "{name}: {d} is outside the disk ({u})");
            let phi = d.dot(b).atan2(d.dot(t)).rem_euclid(2.0 * PI) / (2.0 * PI);
            [u.min(0.999_999) as f32, (phi as f32).min(0.999_999)]
        })
        .collect();
    assert_fits(name, &Ok(uniform_2d(&cells, 32)));
}

#[test]
fn cpu_sun_disk_sampling() {
    let kernel = common::kernel_scene(&format!("{PROBE_SCENE}{SUN}"));
    let refs = glint::cpu::scene_refs::SceneRefs::of(&kernel, &kernel.params);
    let samples: Vec<[f32; 4]> = (0..SAMPLES)
        .map(|i| {
            let mut r = cpu_draws(i, SEED + 51);
            let s =
                glint::cpu::lights::sampling::sample_light(&refs, Vec3::ZERO, Vec3::ZERO, &mut r);
            [s.dir.x, s.dir.y, s.dir.z, s.pdf]
        })
        .collect();
    check_sun_samples("cpu sun disk", &samples);
}

#[test]
fn gpu_sun_disk_sampling() {
    let Some(ctx) = common::gpu() else { return };
    let kernel = common::kernel_scene(&format!("{PROBE_SCENE}{SUN}"));
    let samples = run_probe(
        ctx,
        "probe_light",
        probe(Vec3::Z, SAMPLES, SEED + 53),
        &kernel,
    );
    check_sun_samples("gpu sun disk", &samples);
}

/// The PBR material's sampler: with probability p (from the lobes' albedos) the visible-normal
/// GGX reflection, else a cosine lobe. Its density over the whole sphere is
/// p · D_vis + (1 − p) · max(cos, 0)/π, with the GGX density written independently above;
/// samples below the surface are absorbed (weight 0) but still drawn with that density.
#[test]
fn cpu_pbr_sampling() {
    for (k, (name, n, wo, alpha)) in metal_cases().into_iter().enumerate() {
        for metallic in [0.0f32, 1.0] {
            let m = glint::kernel::types::Material {
                albedo: [0.8, 0.5, 0.3],
                kind: glint::kernel::types::MATERIAL_PBR,
                alpha,
                ior: 1.5,
                metallic,
                specular: 1.0,
                specular_color: [1.0; 3],
                ..Default::default()
            };
            let p = glint::cpu::materials::pbr::pbr_lobes(&m, wo.dot(n), wo.dot(n), true)
                .specular_probability() as f64;
            let dirs: Vec<Vec3> = (0..SAMPLES)
                .map(|i| {
                    let mut r = cpu_draws(i, SEED + 97 + k as u32);
                    let s =
                        glint::cpu::materials::material::bsdf_sample(&m, wo, n, n, true, &mut r);
                    let pdf = glint::cpu::materials::material::bsdf_pdf(&m, wo, s.dir, n, n, true);
                    let above = s.dir.dot(n) > 0.0;
                    assert_eq!(
                        s.weight == Vec3::ZERO,
                        !above,
                        "{name}: weight {}",
                        s.weight
                    );
                    if above {
                        assert!(
                            (s.pdf - pdf).abs() <= 1e-4 * pdf,
                            "{name}: pdf {} vs {pdf}",
                            s.pdf
                        );
                    }
                    s.dir
                })
                .collect();
            let pdf = |d: Vec3| {
                let d = d.as_dvec3().normalize();
                let cos = d.dot(n.as_dvec3()).max(0.0);
                p * reference_ggx_pdf(wo.as_dvec3(), d, n.as_dvec3(), alpha as f64)
                    + (1.0 - p) * cos / PI
            };
            assert_fits(
                &format!("cpu pbr, metallic {metallic}, {name}"),
                &directions_integrated(&dirs, n, pdf, 20, 40, 48),
            );
        }
    }
}

// ---- Rough dielectric (Walter et al. 2007): reflection and refraction ---------------------

/// The density of the rough dielectric's kept samples (a reflection above the surface, a
/// refraction below it), written here in f64 from Walter et al.'s formulas with the indices
/// η_o (wo's side) and η_i (the other side): m from the visible normals, G1(wo) D(m) (wo·m) /
/// cos θo, then reflection with probability F(wo·m) (Jacobian 1 / (4 wo·m)) or refraction
/// (Jacobian η_i² |wi·m| / (η_o wo·m + η_i wi·m)²). `n` is the normal on wo's side.
fn reference_rough_dielectric_pdf(
    wo: glam::DVec3,
    wi: glam::DVec3,
    n: glam::DVec3,
    alpha: f64,
    eta_o: f64,
    eta_i: f64,
) -> f64 {
    let (cos_o, cos_i) = (wo.dot(n), wi.dot(n));
    if cos_o <= 0.0 || cos_i == 0.0 {
        return 0.0;
    }
    let reflected = cos_i > 0.0;
    let h = if reflected {
        wo + wi
    } else {
        -(eta_o * wo + eta_i * wi)
    };
    if h.length() < 1e-9 {
        return 0.0;
    }
    let mut m = h.normalize();
    if m.dot(n) < 0.0 {
        m = -m;
    }
    let (wo_m, wi_m) = (wo.dot(m), wi.dot(m));
    if wo_m <= 0.0 || (reflected && wi_m <= 0.0) || (!reflected && wi_m >= 0.0) {
        return 0.0;
    }
    let cos_m = m.dot(n);
    let a2 = alpha * alpha;
    let d = a2 / (PI * (cos_m * cos_m * (a2 - 1.0) + 1.0).powi(2));
    let tan2 = (1.0 - cos_o * cos_o) / (cos_o * cos_o);
    let g1 = 2.0 / (1.0 + (1.0 + a2 * tan2).sqrt());
    let visible = g1 * d * wo_m / cos_o;
    let f = reference_fresnel(wo_m, eta_o, eta_i);
    if reflected {
        f * visible / (4.0 * wo_m)
    } else {
        let denominator = eta_o * wo_m + eta_i * wi_m;
        (1.0 - f) * visible * eta_i * eta_i * wi_m.abs() / (denominator * denominator)
    }
}

/// The compensated rough dielectric's density: the single-scattering reference above with the
/// probability the sampler gives it, else a cosine lobe below (probability t) or above, with
/// the shares the code's tables give (src/cpu/materials/rough_dielectric.rs says how they are chosen).
fn reference_compensated_pdf(
    wo: glam::DVec3,
    wi: glam::DVec3,
    n: glam::DVec3,
    alpha: f64,
    eta_o: f64,
    eta_i: f64,
) -> f64 {
    let (cos_o, cos_i) = (wo.dot(n), wi.dot(n));
    if cos_o <= 0.0 || cos_i == 0.0 {
        return 0.0;
    }
    let (single, transmitted) =
        glint::cpu::materials::rough_dielectric::rough_dielectric_lobe_shares(
            alpha as f32,
            (eta_i / eta_o) as f32,
            cos_o as f32,
        );
    let (single, transmitted) = (single as f64, transmitted as f64);
    let share = if cos_i > 0.0 {
        1.0 - transmitted
    } else {
        transmitted
    };
    single * reference_rough_dielectric_pdf(wo, wi, n, alpha, eta_o, eta_i)
        + (1.0 - single) * share * cos_i.abs() / PI
}

/// (name, entering, θo in degrees): light entering glass at 60°, leaving it at 30° (inside
/// the critical angle, 41.8°) and at 60° (beyond it: only microfacets tilted towards wo
/// refract).
const ROUGH_DIELECTRIC_CASES: [(&str, bool, f32); 3] = [
    ("entering at 60°", true, 60.0),
    ("leaving at 30°", false, 30.0),
    ("leaving at 60°", false, 60.0),
];

/// The kept samples' directions and the number absorbed.
fn split_absorbed(samples: &[(Vec3, bool)]) -> (Vec<Vec3>, u64) {
    let kept: Vec<Vec3> = samples.iter().filter(|s| s.1).map(|s| s.0).collect();
    let absorbed = (samples.len() - kept.len()) as u64;
    (kept, absorbed)
}

/// The rough dielectric's sampler (in its local frame, n = +z) against the reference density,
/// both ways through the surface, at GGX α 0.04, 0.25 and 1 (roughness 0.2, 0.5, 1).
#[test]
fn cpu_rough_dielectric_sampling() {
    let n = Vec3::Z;
    for (k, alpha) in [0.04f32, 0.25, 1.0].into_iter().enumerate() {
        for (c, (name, entering, degrees)) in ROUGH_DIELECTRIC_CASES.into_iter().enumerate() {
            let theta = (degrees as f64).to_radians();
            // cos θo exact in f64 for the reference; φ = 0.
            let wo = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32).normalize();
            let etap = if entering { GLASS_IOR } else { 1.0 / GLASS_IOR };
            let (eta_o, eta_i) = if entering {
                (1.0, GLASS_IOR as f64)
            } else {
                (GLASS_IOR as f64, 1.0)
            };
            let samples: Vec<(Vec3, bool)> = (0..SAMPLES)
                .map(|i| {
                    let mut r = cpu_draws(i, SEED + 131 + (3 * k + c) as u32);
                    let u = (r.next_f32(), r.next_f32());
                    let s = glint::cpu::materials::rough_dielectric::rough_dielectric_sample(
                        alpha,
                        etap,
                        wo,
                        u,
                        r.next_f32(),
                    );
                    (s.wi, s.weight > 0.0)
                })
                .collect();
            let (kept, absorbed) = split_absorbed(&samples);
            let pdf = |d: Vec3| {
                reference_compensated_pdf(
                    wo.as_dvec3(),
                    d.as_dvec3().normalize(),
                    n.as_dvec3(),
                    alpha as f64,
                    eta_o,
                    eta_i,
                )
            };
            // The kept samples' pdf as the code computes it matches the reference.
            for d in kept.iter().take(2000) {
                let mine = glint::cpu::materials::rough_dielectric::rough_dielectric_pdf(
                    alpha, etap, wo, *d,
                );
                let want = pdf(*d);
                assert!(
                    ((mine as f64) - want).abs() <= 2e-3 * want + 1e-6,
                    "{name}, α {alpha}: pdf {mine} vs reference {want} at {d}"
                );
            }
            assert_fits(
                &format!("cpu rough dielectric, α {alpha}, {name}"),
                &directions_with_absorbed(&kept, absorbed, n, pdf, 20, 40, 48),
            );
        }
    }
}

/// (transmission, GGX α, entering) of the pbr transmission tests: the rough dielectric alone
/// (transmission 1) and half of it over the diffuse stack, at roughness 0.3 and 0.8.
fn pbr_transmission_cases() -> Vec<(f32, f32, bool)> {
    let mut cases = Vec::new();
    for transmission in [1.0f32, 0.5] {
        for alpha in [0.09f32, 0.64] {
            for entering in [true, false] {
                cases.push((transmission, alpha, entering));
            }
        }
    }
    cases
}

/// The pbr transmission tests' normal and wo (60° from it).
fn pbr_transmission_geometry() -> (Vec3, Vec3) {
    let n = Vec3::new(0.2, 0.9, -0.3).normalize();
    let (t, _) = n.any_orthonormal_pair();
    (n, 0.5 * n + 0.75f32.sqrt() * t)
}

fn pbr_glass(albedo: [f32; 3], alpha: f32, transmission: f32) -> glint::kernel::types::Material {
    glint::kernel::types::Material {
        albedo,
        kind: glint::kernel::types::MATERIAL_PBR,
        alpha,
        ior: GLASS_IOR,
        metallic: 0.0,
        specular: 1.0,
        specular_color: [1.0; 3],
        transmission,
        ..Default::default()
    }
}

/// The pbr material with transmission: a mixture of the specular lobe, the cosine lobe and
/// the rough dielectric with the probabilities `pbr_lobes` reports (which the CPU's material
/// `m` gives; the GPU's is the same). Kept samples' density is p_s D_vis + p_c cos/π above
/// the surface, plus p_t times the rough dielectric's (references above); the rest
/// (reflections below the surface, refractions above it) are absorbed.
fn check_pbr_transmission_samples(
    name: &str,
    m: &glint::kernel::types::Material,
    entering: bool,
    samples: &[(Vec3, bool)],
) {
    let (n, wo) = pbr_transmission_geometry();
    let lobes = glint::cpu::materials::pbr::pbr_lobes(m, wo.dot(n), wo.dot(n), entering);
    let p_s = lobes.specular_probability() as f64;
    let p_t = lobes.transmission_probability() as f64;
    if m.transmission == 1.0 {
        assert_eq!(p_t, 1.0, "transmission 1 samples only the rough dielectric");
    }
    let (eta_o, eta_i) = if entering {
        (1.0, GLASS_IOR as f64)
    } else {
        (GLASS_IOR as f64, 1.0)
    };
    let (kept, absorbed) = split_absorbed(samples);
    let alpha = m.alpha as f64;
    let pdf = |d: Vec3| {
        let d = d.as_dvec3().normalize();
        let (wo, n) = (wo.as_dvec3(), n.as_dvec3());
        let cos = d.dot(n);
        let mut p = p_t * reference_compensated_pdf(wo, d, n, alpha, eta_o, eta_i);
        if cos > 0.0 {
            p += p_s * reference_ggx_pdf(wo, d, n, alpha) + (1.0 - p_s - p_t) * cos / PI;
        }
        p
    };
    assert_fits(
        name,
        &directions_with_absorbed(&kept, absorbed, n, pdf, 20, 40, 48),
    );
}

fn pbr_transmission_name(device: &str, transmission: f32, alpha: f32, entering: bool) -> String {
    let side = if entering { "entering" } else { "leaving" };
    format!("{device} pbr, transmission {transmission}, α {alpha}, {side}")
}

#[test]
fn cpu_pbr_transmission_sampling() {
    let (n, wo) = pbr_transmission_geometry();
    for (k, (transmission, alpha, entering)) in pbr_transmission_cases().into_iter().enumerate() {
        let m = pbr_glass([0.8, 0.5, 0.3], alpha, transmission);
        let samples: Vec<(Vec3, bool)> = (0..SAMPLES)
            .map(|i| {
                let mut r = cpu_draws(i, SEED + 151 + k as u32);
                let s =
                    glint::cpu::materials::material::bsdf_sample(&m, wo, n, n, entering, &mut r);
                let kept = s.weight != Vec3::ZERO;
                if kept {
                    // Rough refraction is not delta: light sampling reaches it too
                    // (tests/suite/rough_glass.rs checks the smooth case).
                    assert!(!s.is_delta, "is_delta at {}", s.dir);
                }
                (s.dir, kept)
            })
            .collect();
        let name = pbr_transmission_name("cpu", transmission, alpha, entering);
        check_pbr_transmission_samples(&name, &m, entering, &samples);
    }
}

/// The WGSL sampler (tests/suite/shaders/probe.wgsl's probe_pbr: a white base) against the same
/// reference.
#[test]
fn gpu_pbr_transmission_sampling() {
    let Some(ctx) = common::gpu() else { return };
    let (n, wo) = pbr_transmission_geometry();
    for (k, (transmission, alpha, entering)) in pbr_transmission_cases().into_iter().enumerate() {
        let m = pbr_glass([1.0; 3], alpha, transmission);
        let params = ProbeParams {
            wo: wo.into(),
            alpha,
            ior: GLASS_IOR,
            front_face: entering as u32,
            transmission,
            ..probe(n, SAMPLES, SEED + 171 + k as u32)
        };
        let samples: Vec<(Vec3, bool)> = run_probe(ctx, "probe_pbr", params, &empty_scene())
            .iter()
            .map(|s| (Vec3::new(s[0], s[1], s[2]), s[3] != 0.0))
            .collect();
        let name = pbr_transmission_name("gpu", transmission, alpha, entering);
        check_pbr_transmission_samples(&name, &m, entering, &samples);
    }
}

// ---- The pbr stack with KHR_materials_clearcoat and KHR_materials_sheen -------------------

/// (clearcoat, coat α, sheen, sheen roughness, base α) of the layered pbr tests: a smooth and
/// a rough coat, a sheen, and both, each over a white dielectric stack.
const PBR_LAYER_CASES: [(f32, f32, f32, f32, f32); 4] = [
    (1.0, 0.01, 0.0, 0.0, 0.25),
    (0.7, 0.36, 0.0, 0.0, 0.04),
    (0.0, 0.0, 1.0, 0.5, 0.25),
    (1.0, 0.09, 0.8, 1.0, 0.64),
];

fn pbr_layered(
    clearcoat: f32,
    coat_alpha: f32,
    sheen: f32,
    sheen_roughness: f32,
    alpha: f32,
) -> glint::kernel::types::Material {
    glint::kernel::types::Material {
        clearcoat,
        clearcoat_alpha: coat_alpha,
        sheen_color: [sheen; 3],
        sheen_roughness,
        ..pbr_glass([1.0; 3], alpha, 0.0)
    }
}

/// The layered pbr sampler: a mixture of the base's visible-normal GGX lobe, the coat's (about
/// the coat's own normal `coat_n`), a uniform hemisphere for the sheen and the cosine lobe,
/// with the probabilities `pbr_lobes` reports; the GGX densities are the independent reference
/// above.
fn check_pbr_layer_samples(
    name: &str,
    m: &glint::kernel::types::Material,
    coat_n: Vec3,
    dirs: &[Vec3],
) {
    let (n, wo) = pbr_transmission_geometry();
    let lobes = glint::cpu::materials::pbr::pbr_lobes(m, wo.dot(n), wo.dot(coat_n), true);
    let p_s = lobes.specular_probability() as f64;
    let p_c = lobes.coat_probability() as f64;
    let p_h = lobes.sheen_probability() as f64;
    assert_eq!(
        p_c > 0.0,
        m.clearcoat > 0.0,
        "{name}: coat probability {p_c}"
    );
    assert_eq!(
        p_h > 0.0,
        m.sheen_color[0] > 0.0,
        "{name}: sheen probability {p_h}"
    );
    let pdf = |d: Vec3| {
        let d = d.as_dvec3().normalize();
        let (wo, n) = (wo.as_dvec3(), n.as_dvec3());
        let coat_alpha = (m.clearcoat_alpha as f64).max(1e-3);
        // The GGX lobes' reflections below the surface are drawn (and absorbed) too.
        let ggx = p_s * reference_ggx_pdf(wo, d, n, m.alpha as f64)
            + p_c * reference_ggx_pdf(wo, d, coat_n.as_dvec3(), coat_alpha);
        let cos = d.dot(n);
        if cos <= 0.0 {
            return ggx;
        }
        ggx + p_h / (2.0 * PI) + (1.0 - p_s - p_c - p_h) * cos / PI
    };
    assert_fits(name, &directions_integrated(dirs, n, pdf, 20, 40, 48));
}

/// The coat's own shading normal of the tilted-coat tests (KHR_materials_clearcoat's
/// clearcoatNormalTexture): the base's normal turned 35° sideways from the plane of n and wo,
/// so wo sees both (cos θo 0.5 about n, 0.41 about it) and the coat's reflections fall partly
/// below the base's surface (drawn there, and absorbed).
fn tilted_coat_normal() -> Vec3 {
    let (n, wo) = pbr_transmission_geometry();
    let side = n.cross(wo).normalize();
    let angle = 35f32.to_radians();
    (angle.cos() * n + angle.sin() * side).normalize()
}

#[test]
fn cpu_pbr_layer_sampling() {
    let (n, wo) = pbr_transmission_geometry();
    for (coat_n, tilt) in [(n, ""), (tilted_coat_normal(), ", coat normal tilted")] {
        for (k, (coat, coat_alpha, sheen, sheen_roughness, alpha)) in
            PBR_LAYER_CASES.into_iter().enumerate()
        {
            if coat == 0.0 && !tilt.is_empty() {
                continue;
            }
            let m = pbr_layered(coat, coat_alpha, sheen, sheen_roughness, alpha);
            let dirs: Vec<Vec3> = (0..SAMPLES)
                .map(|i| {
                    let mut r = cpu_draws(i, SEED + 191 + k as u32);
                    let s = glint::cpu::materials::material::bsdf_sample(
                        &m, wo, n, coat_n, true, &mut r,
                    );
                    let pdf =
                        glint::cpu::materials::material::bsdf_pdf(&m, wo, s.dir, n, coat_n, true);
                    // The coat's α 0.01 lobe turns the direction's f32 rounding between frames
                    // into relative pdf differences near 1e-3.
                    if s.dir.dot(n) > 0.0 {
                        assert!((s.pdf - pdf).abs() <= 1e-2 * pdf, "pdf {} vs {pdf}", s.pdf);
                    }
                    s.dir
                })
                .collect();
            check_pbr_layer_samples(
                &format!(
                    "cpu pbr, coat {coat} α {coat_alpha}, sheen {sheen} r {sheen_roughness}{tilt}"
                ),
                &m,
                coat_n,
                &dirs,
            );
        }
    }
}

/// The WGSL sampler (probe_pbr with the coat and sheen set) against the same reference.
#[test]
fn gpu_pbr_layer_sampling() {
    let Some(ctx) = common::gpu() else { return };
    let (n, wo) = pbr_transmission_geometry();
    for (coat_n, tilt) in [(n, ""), (tilted_coat_normal(), ", coat normal tilted")] {
        for (k, (coat, coat_alpha, sheen, sheen_roughness, alpha)) in
            PBR_LAYER_CASES.into_iter().enumerate()
        {
            if coat == 0.0 && !tilt.is_empty() {
                continue;
            }
            let m = pbr_layered(coat, coat_alpha, sheen, sheen_roughness, alpha);
            let params = ProbeParams {
                wo: wo.into(),
                alpha,
                ior: GLASS_IOR,
                front_face: 1,
                clearcoat: coat,
                clearcoat_alpha: coat_alpha,
                sheen,
                sheen_roughness,
                coat_normal: coat_n.into(),
                ..probe(n, SAMPLES, SEED + 211 + k as u32)
            };
            let dirs: Vec<Vec3> = run_probe(ctx, "probe_pbr", params, &empty_scene())
                .iter()
                .map(|s| Vec3::new(s[0], s[1], s[2]))
                .collect();
            check_pbr_layer_samples(
                &format!(
                    "gpu pbr, coat {coat} α {coat_alpha}, sheen {sheen} r {sheen_roughness}{tilt}"
                ),
                &m,
                coat_n,
                &dirs,
            );
        }
    }
}

/// Henyey–Greenstein's density, written here from its formula in f64, independently of the
/// renderer's: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}), θ from the direction of travel.
fn hg_pdf(axis: Vec3, g: f64) -> impl Fn(Vec3) -> f64 {
    move |d: Vec3| {
        let cos = d.dot(axis) as f64;
        (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
    }
}

/// The media's phase sampling (src/cpu/media/phase.rs) against its density, backwards,
/// isotropic and forwards, about a tilted axis; and the density it returns agrees with the
/// formula. A seed per g keeps the tests independent.
#[test]
fn cpu_henyey_greenstein() {
    use glint::cpu::media::phase::{hg_phase, sample_hg};
    let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
    for (k, g) in [-0.7f32, 0.0, 0.7].into_iter().enumerate() {
        let samples: Vec<Vec3> = (0..SAMPLES)
            .map(|i| {
                let mut r = cpu_draws(i, SEED + 301 + k as u32);
                sample_hg(g, axis, r.next_f32(), r.next_f32())
            })
            .collect();
        for d in &samples[..1000] {
            let want = hg_pdf(axis, g as f64)(*d);
            let got = hg_phase(g, axis.dot(*d)) as f64;
            assert!(
                (got - want).abs() <= 1e-4 * want,
                "g {g}: pdf {got} against {want}"
            );
        }
        assert_fits(
            &format!("cpu henyey-greenstein g = {g}"),
            &directions(&samples, axis, hg_pdf(axis, g as f64), 40, 20),
        );
    }
}

#[test]
fn gpu_henyey_greenstein() {
    let Some(ctx) = common::gpu() else { return };
    let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
    for (k, g) in [-0.7f32, 0.0, 0.7].into_iter().enumerate() {
        let params = ProbeParams {
            alpha: g,
            ..probe(axis, SAMPLES, SEED + 311 + k as u32)
        };
        let out = run_probe(ctx, "probe_hg", params, &empty_scene());
        let samples: Vec<Vec3> = out.iter().map(|v| Vec3::new(v[0], v[1], v[2])).collect();
        for (d, v) in samples.iter().zip(&out).take(1000) {
            let want = hg_pdf(axis, g as f64)(*d);
            assert!(
                (v[3] as f64 - want).abs() <= 1e-4 * want,
                "g {g}: pdf {} against {want}",
                v[3]
            );
        }
        assert_fits(
            &format!("gpu henyey-greenstein g = {g}"),
            &directions(&samples, axis, hg_pdf(axis, g as f64), 40, 20),
        );
    }
}
