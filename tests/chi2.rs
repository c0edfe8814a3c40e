//! χ² goodness-of-fit of every sampling routine, in the WGSL kernel (through the probe kernel
//! in tests/shaders/probe.wgsl) and in the CPU mirror: 10^6 samples each, significance 0.01
//! Šidák-corrected over the suite's CHI2_TESTS_IN_SUITE tests (tests/common/chi2.rs).

mod common;
use common::chi2::{assert_fits, directions, uniform_2d};
use common::probe::run_probe;
use glam::Vec3;
use glint::cpu::material::sample_cosine_hemisphere;
use glint::cpu::rng::Rng;
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
    let out = run_probe(ctx, "probe_uniform", Vec3::Z, SAMPLES / 2, SEED);
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
        let samples: Vec<Vec3> = run_probe(ctx, "probe_cosine_hemisphere", n, SAMPLES, seed)
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
