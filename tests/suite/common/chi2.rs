//! χ² goodness-of-fit tests for sampling routines, in the style of Mitsuba's and pbrt's:
//! histogram the samples, integrate the pdf over each cell for the expected counts, pool cells
//! expecting fewer than 5, and compare with Pearson's χ² at significance 0.01, Šidák-corrected
//! over all the χ² tests in the suite.

use glam::Vec3;
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::PI;

/// Number of χ² tests in the whole suite (tests/suite/chi2.rs), for the Šidák correction. Keep it
/// in step when tests are added.
pub const CHI2_TESTS_IN_SUITE: u32 = 96;

/// Per-test significance such that the whole suite wrongly fails with probability 0.01.
pub fn sidak_alpha() -> f64 {
    1.0 - (1.0 - 0.01f64).powf(1.0 / CHI2_TESTS_IN_SUITE as f64)
}

#[derive(Debug)]
pub struct Chi2 {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
}

/// Pearson's χ² of observed against expected counts, pooling the cells that expect < 5.
/// Observations in a cell that expects nothing fail at once (a sample where the pdf is 0).
pub fn pearson(observed: &[u64], expected: &[f64]) -> Chi2 {
    let mut order: Vec<usize> = (0..observed.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut statistic, mut cells) = (0.0, 0usize);
    let (mut pooled_obs, mut pooled_exp) = (0.0, 0.0);
    for &i in &order {
        let (o, e) = (observed[i] as f64, expected[i]);
        if e <= 0.0 {
            assert_eq!(
                observed[i], 0,
                "{} samples in a cell where the pdf is 0",
                observed[i]
            );
            continue;
        }
        if e < 5.0 {
            pooled_obs += o;
            pooled_exp += e;
            if pooled_exp >= 5.0 {
                statistic += (pooled_obs - pooled_exp).powi(2) / pooled_exp;
                cells += 1;
                pooled_obs = 0.0;
                pooled_exp = 0.0;
            }
            continue;
        }
        statistic += (o - e).powi(2) / e;
        cells += 1;
    }
    if pooled_exp > 0.0 {
        statistic += (pooled_obs - pooled_exp).powi(2) / pooled_exp;
        cells += 1;
    }
    let dof = cells.saturating_sub(1).max(1);
    let p_value = ChiSquared::new(dof as f64).unwrap().sf(statistic);
    Chi2 {
        statistic,
        dof,
        p_value,
    }
}

/// Integral of f over [x0, x1] × [y0, y1] by the midpoint rule with n × n nodes. No node lies
/// on a cell edge, where the pdfs of lights and of GGX have their discontinuities (Simpson's
/// rule would evaluate them there and take the value from the wrong side).
fn midpoint_2d(f: &impl Fn(f64, f64) -> f64, x0: f64, x1: f64, y0: f64, y1: f64, n: usize) -> f64 {
    let (hx, hy) = ((x1 - x0) / n as f64, (y1 - y0) / n as f64);
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            sum += f(x0 + (i as f64 + 0.5) * hx, y0 + (j as f64 + 0.5) * hy);
        }
    }
    sum * hx * hy
}

/// χ² test of unit directions against a solid-angle pdf, on a grid of `cos_bins` × `phi_bins`
/// cells in (cos θ, φ) about `axis` (φ measured in a frame independent of the sampler's own).
/// A sample where the pdf is 0 is an error.
pub fn directions(
    samples: &[Vec3],
    axis: Vec3,
    pdf: impl Fn(Vec3) -> f64,
    cos_bins: usize,
    phi_bins: usize,
) -> Result<Chi2, String> {
    directions_integrated(samples, axis, pdf, cos_bins, phi_bins, 8)
}

/// [`directions`] with `steps` × `steps` integration nodes per cell: pdfs with edges (lights
/// seen from a point) need fine integration in the cells the edges cross.
pub fn directions_integrated(
    samples: &[Vec3],
    axis: Vec3,
    pdf: impl Fn(Vec3) -> f64,
    cos_bins: usize,
    phi_bins: usize,
    steps: usize,
) -> Result<Chi2, String> {
    let (observed, expected) = binned(
        samples,
        samples.len() as u64,
        axis,
        &pdf,
        cos_bins,
        phi_bins,
        steps,
    )?;
    Ok(pearson(&observed, &expected))
}

/// The samples' counts per (cos θ, φ) cell, and what `total` samples drawn with `pdf` expect.
fn binned(
    samples: &[Vec3],
    total: u64,
    axis: Vec3,
    pdf: &impl Fn(Vec3) -> f64,
    cos_bins: usize,
    phi_bins: usize,
    steps: usize,
) -> Result<(Vec<u64>, Vec<f64>), String> {
    let (t, b) = axis.any_orthonormal_pair();
    let (t, b, n) = (t.as_dvec3(), b.as_dvec3(), axis.as_dvec3());
    let mut observed = vec![0u64; cos_bins * phi_bins];
    for s in samples {
        let d = s.as_dvec3();
        if (d.length() - 1.0).abs() > 1e-4 {
            return Err(format!("not a unit vector: {s}"));
        }
        if pdf(*s) <= 0.0 {
            return Err(format!("sample {s} where the pdf is 0"));
        }
        let cos = d.dot(n).clamp(-1.0, 1.0);
        let phi = d.dot(b).atan2(d.dot(t)).rem_euclid(2.0 * PI);
        let i = (((cos + 1.0) / 2.0 * cos_bins as f64) as usize).min(cos_bins - 1);
        let j = ((phi / (2.0 * PI) * phi_bins as f64) as usize).min(phi_bins - 1);
        observed[i * phi_bins + j] += 1;
    }
    // dω = d(cos θ) dφ.
    let density = |cos: f64, phi: f64| {
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let d = (t * (sin * phi.cos()) + b * (sin * phi.sin()) + n * cos).as_vec3();
        pdf(d)
    };
    let mut expected = vec![0.0; observed.len()];
    for i in 0..cos_bins {
        for j in 0..phi_bins {
            let (c0, c1) = (
                -1.0 + 2.0 * i as f64 / cos_bins as f64,
                -1.0 + 2.0 * (i + 1) as f64 / cos_bins as f64,
            );
            let (p0, p1) = (
                2.0 * PI * j as f64 / phi_bins as f64,
                2.0 * PI * (j + 1) as f64 / phi_bins as f64,
            );
            expected[i * phi_bins + j] =
                total as f64 * midpoint_2d(&density, c0, c1, p0, p1, steps);
        }
    }
    Ok((observed, expected))
}

/// [`directions_integrated`] for a sampler that absorbs some of its samples (a reflection below
/// the surface, a refraction above it): `pdf` is the density of the kept samples, integrating
/// to less than 1, and the `absorbed` ones fill one more cell, which expects the rest.
pub fn directions_with_absorbed(
    kept: &[Vec3],
    absorbed: u64,
    axis: Vec3,
    pdf: impl Fn(Vec3) -> f64,
    cos_bins: usize,
    phi_bins: usize,
    steps: usize,
) -> Result<Chi2, String> {
    let total = kept.len() as u64 + absorbed;
    let (mut observed, mut expected) = binned(kept, total, axis, &pdf, cos_bins, phi_bins, steps)?;
    let kept_mass: f64 = expected.iter().sum();
    observed.push(absorbed);
    expected.push((total as f64 - kept_mass).max(0.0));
    Ok(pearson(&observed, &expected))
}

/// χ² test of points in [0, 1)² against the uniform distribution on a `bins` × `bins` grid.
pub fn uniform_2d(samples: &[[f32; 2]], bins: usize) -> Chi2 {
    let mut observed = vec![0u64; bins * bins];
    for s in samples {
        assert!(
            (0.0..1.0).contains(&s[0]) && (0.0..1.0).contains(&s[1]),
            "{s:?} outside [0, 1)²"
        );
        let i = (s[0] as f64 * bins as f64) as usize;
        let j = (s[1] as f64 * bins as f64) as usize;
        observed[i * bins + j] += 1;
    }
    let expected = vec![samples.len() as f64 / (bins * bins) as f64; bins * bins];
    pearson(&observed, &expected)
}

/// Asserts the test passes at the Šidák-corrected level, and prints the p-value for the record.
pub fn assert_fits(name: &str, result: &Result<Chi2, String>) {
    let result = result.as_ref().unwrap_or_else(|e| panic!("{name}: {e}"));
    let alpha = sidak_alpha();
    eprintln!(
        "χ² {name}: statistic {:.1}, dof {}, p = {:.4} (threshold {alpha:.5})",
        result.statistic, result.dof, result.p_value
    );
    assert!(
        result.p_value > alpha,
        "{name}: p = {} ≤ {alpha}",
        result.p_value
    );
}
