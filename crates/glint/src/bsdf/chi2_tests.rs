//! Statistical tests of every non-delta BSDF (the method of pbrt and Mitsuba): directions
//! drawn by `sample` are binned over the sphere and compared with the counts that `pdf`
//! predicts, by a chi-square goodness-of-fit test; sample weights must equal eval / pdf;
//! and the mean weight (the albedo) must match the integral of `eval` over the sphere.
//! The chi-square test compares the shape of the binned samples with the pdf (expected counts
//! scaled to the number of binned samples); the fraction of samples that land in no bin
//! (failed samples, delta lobes) is checked separately against 1 - ∫pdf, with a tolerance
//! that covers the quadrature error of that integral.

use super::*;
use crate::sampling::Rng;

const THETA_BINS: usize = 24;
const PHI_BINS: usize = 48;
const SUB: usize = 16; // pdf evaluations per bin side when integrating
const SAMPLES: usize = 300_000;
/// Family-wise significance for all chi-square tests in this file (Šidák-corrected below).
const ALPHA: f64 = 0.01;
const TESTS: f64 = 40.0;

fn dir(theta: f64, phi: f64) -> Vec3 {
    let (sin_t, cos_t) = theta.sin_cos();
    Vec3 { x: (sin_t * phi.cos()) as f32, y: (sin_t * phi.sin()) as f32, z: cos_t as f32 }
}

fn bin_of(w: Vec3) -> usize {
    let c = ((w.z as f64).clamp(-1.0, 1.0).acos() / std::f64::consts::PI * THETA_BINS as f64) as usize;
    let mut phi = (w.y as f64).atan2(w.x as f64);
    if phi < 0.0 {
        phi += 2.0 * std::f64::consts::PI;
    }
    let p = (phi / (2.0 * std::f64::consts::PI) * PHI_BINS as f64) as usize;
    c.min(THETA_BINS - 1) * PHI_BINS + p.min(PHI_BINS - 1)
}

/// Integrates `f(direction)` over each bin: bins are uniform in θ and φ (so that lobes at
/// the poles still span several bins), midpoint rule with the sin θ Jacobian.
fn integrate_bins(f: impl Fn(Vec3) -> f64) -> Vec<f64> {
    integrate_bins_with(f, SUB)
}

fn integrate_bins_with(f: impl Fn(Vec3) -> f64, sub: usize) -> Vec<f64> {
    let dc = std::f64::consts::PI / THETA_BINS as f64;
    let dp = 2.0 * std::f64::consts::PI / PHI_BINS as f64;
    let cell = dc * dp / (sub * sub) as f64;
    let mut out = vec![0.0; THETA_BINS * PHI_BINS];
    for ci in 0..THETA_BINS {
        for pi in 0..PHI_BINS {
            let mut s = 0.0;
            for a in 0..sub {
                for b in 0..sub {
                    let theta = (ci as f64 + (a as f64 + 0.5) / sub as f64) * dc;
                    let p = (pi as f64 + (b as f64 + 0.5) / sub as f64) * dp;
                    s += f(dir(theta, p)) * theta.sin();
                }
            }
            out[ci * PHI_BINS + pi] = s * cell;
        }
    }
    out
}

/// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes' series / continued fraction).
fn gamma_q(a: f64, x: f64) -> f64 {
    fn ln_gamma(x: f64) -> f64 {
        let c = [
            76.18009172947146,
            -86.50532032941677,
            24.01409824083091,
            -1.231739572450155,
            0.1208650973866179e-2,
            -0.5395239384953e-5,
        ];
        let t = x + 5.5 - (x + 0.5) * (x + 5.5).ln();
        let ser = c.iter().enumerate().fold(1.000000000190015, |s, (i, ci)| s + ci / (x + 1.0 + i as f64));
        -t + (2.5066282746310005 * ser / x).ln()
    }
    if x <= 0.0 {
        return 1.0;
    }
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - ln_gamma(a)).exp()
    } else {
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / 1e-300;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < 1e-300 {
                d = 1e-300;
            }
            c = b + an / c;
            if c.abs() < 1e-300 {
                c = 1e-300;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - ln_gamma(a)).exp() * h
    }
}

/// Runs all checks for one BSDF and incident direction; panics with a description on failure.
fn check(name: &str, bsdf: Bsdf, wo: Vec3) {
    let wo = wo.normalize();
    let mut rng = Rng::new(0x5eed, name.len() as u64 * 7919 + (wo.z * 1000.0) as u64);
    let mut observed = vec![0.0f64; THETA_BINS * PHI_BINS + 1];
    let mut weight_sum = Rgb::BLACK;
    let mut weight_sq = 0.0f64;
    for _ in 0..SAMPLES {
        let s = bsdf.sample(wo, rng.next_f32(), rng.next_2d());
        let Some(s) = s else {
            observed[THETA_BINS * PHI_BINS] += 1.0;
            continue;
        };
        weight_sum += s.weight;
        weight_sq += (s.weight.average() as f64).powi(2);
        if s.delta {
            observed[THETA_BINS * PHI_BINS] += 1.0;
            continue;
        }
        observed[bin_of(s.wi)] += 1.0;
        // The weight must be eval / pdf.
        let (e, p) = (bsdf.eval(wo, s.wi), bsdf.pdf(wo, s.wi));
        assert!((p - s.pdf).abs() <= 1e-3 * p.max(1.0), "{name}: sample pdf {} vs pdf() {p}", s.pdf);
        if p > 1e-3 {
            let expect = e / p;
            let d = (expect - s.weight).max_component().abs().max((s.weight - expect).max_component().abs());
            assert!(
                d <= 2e-3 * expect.max_component().max(1.0),
                "{name}: weight {:?} vs eval/pdf {expect:?}",
                s.weight
            );
        }
    }

    // Chi-square test of the binned directions against the integrated pdf.
    let mut expected = integrate_bins(|w| bsdf.pdf(wo, w) as f64);
    let total_pdf: f64 = expected.iter().sum();
    assert!(total_pdf <= 1.0 + 2e-3, "{name}: pdf integrates to {total_pdf} > 1");
    // Quadrature error, estimated from the same integral on a grid half as fine.
    let coarse: f64 = integrate_bins_with(|w| bsdf.pdf(wo, w) as f64, SUB / 2).iter().sum();
    let quadrature_error = (total_pdf - coarse).abs();
    let unbinned = observed.pop().unwrap();
    let binned = SAMPLES as f64 - unbinned;
    let lost = unbinned / SAMPLES as f64;
    let lost_se = (lost * (1.0 - lost) / SAMPLES as f64).sqrt();
    assert!(
        (lost - (1.0 - total_pdf)).abs() < 5.0 * lost_se + 3.0 * quadrature_error + 1e-3,
        "{name} (wo.z = {}): {lost} of samples unbinned but the pdf leaves {} of its mass out",
        wo.z,
        1.0 - total_pdf
    );
    if binned < 1.0 {
        return;
    }
    for e in expected.iter_mut() {
        *e *= binned / total_pdf;
    }
    // Pool cells with small expected counts (the chi-square approximation needs >= 5).
    let (mut chi2, mut cells, mut pool_o, mut pool_e) = (0.0, 0usize, 0.0, 0.0);
    for (o, e) in observed.iter().zip(&expected) {
        if *e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pool_e >= 5.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        cells += 1;
    } else {
        // Too little expected mass to test by chi-square: samples there must be rare.
        assert!(pool_o <= 5.0 + 10.0 * pool_e, "{name}: {pool_o} samples where the pdf expects {pool_e}");
    }
    let dof = (cells.max(2) - 1) as f64;
    let p_value = gamma_q(dof / 2.0, chi2 / 2.0);
    let threshold = 1.0 - (1.0 - ALPHA).powf(1.0 / TESTS);
    assert!(p_value > threshold, "{name} (wo.z = {}): chi-square {chi2:.1} on {dof} dof, p = {p_value:.2e}", wo.z);

    // Albedo: mean weight vs ∫ eval dω (only valid when no delta lobe carries energy).
    if !bsdf.has_delta_lobe() {
        let integral = integrate_bins(|w| bsdf.eval(wo, w).average() as f64).iter().sum::<f64>();
        let mean = weight_sum.average() as f64 / SAMPLES as f64;
        let var = (weight_sq / SAMPLES as f64 - mean * mean).max(0.0);
        let se = (var / SAMPLES as f64).sqrt();
        // 5 standard errors, plus the quadrature error of a smooth integrand on this grid.
        assert!((mean - integral).abs() < 5.0 * se + 2e-3, "{name}: albedo {mean} vs ∫eval {integral} (se {se})");
    }
}

fn angles() -> [Vec3; 3] {
    [Vec3 { x: 0.17, y: 0.02, z: 0.98 }, Vec3 { x: 0.6, y: -0.3, z: 0.64 }, Vec3 { x: 0.95, y: 0.1, z: 0.15 }]
}

#[test]
fn diffuse() {
    for wo in angles() {
        check("diffuse", Bsdf::Diffuse { reflectance: Rgb::splat(0.7) }, wo);
    }
}

#[test]
fn phong() {
    for wo in angles() {
        check("phong", Bsdf::Phong(Phong { kd: Rgb::splat(0.3), ks: Rgb::splat(0.5), exponent: 20.0 }), wo);
    }
}

#[test]
fn rough_conductors() {
    let (eta, k) = (Rgb { r: 0.2, g: 0.9, b: 1.1 }, Rgb { r: 3.9, g: 2.4, b: 2.1 });
    for kind in [MicrofacetKind::Ggx, MicrofacetKind::Beckmann] {
        for alpha in [0.2, 0.5] {
            for wo in angles() {
                let b = Bsdf::RoughConductor { dist: Microfacet::new(kind, alpha), eta, k, specular: Rgb::WHITE };
                check(&format!("roughconductor {kind:?} {alpha}"), b, wo);
            }
        }
    }
}

#[test]
fn rough_dielectric_from_both_sides() {
    for alpha in [0.2, 0.5] {
        for wo in angles() {
            for side in [1.0, -1.0] {
                let b = Bsdf::RoughDielectric {
                    dist: Microfacet::new(MicrofacetKind::Ggx, alpha),
                    eta: 1.5,
                    reflect: Rgb::WHITE,
                    transmit: Rgb::WHITE,
                };
                check(&format!("roughdielectric {alpha} side {side}"), b, Vec3 { z: wo.z * side, ..wo });
            }
        }
    }
}

#[test]
fn plastics() {
    for wo in angles() {
        check("plastic", Bsdf::Plastic(PlasticParams::new(Rgb::splat(0.5), Rgb::WHITE, 1.49, None)), wo);
        let rough = Some(Microfacet::new(MicrofacetKind::Ggx, 0.3));
        check("roughplastic", Bsdf::Plastic(PlasticParams::new(Rgb::splat(0.5), Rgb::WHITE, 1.49, rough)), wo);
    }
}

#[test]
fn gamma_q_matches_known_values() {
    // Q(1, x) = exp(-x); chi-square with 2 dof at 5.991 has p = 0.05.
    assert!((gamma_q(1.0, 2.0) - (-2.0f64).exp()).abs() < 1e-10);
    assert!((gamma_q(1.0, 5.991 / 2.0) - 0.05).abs() < 1e-3);
    // 10 dof at 23.209: p = 0.01.
    assert!((gamma_q(5.0, 23.209 / 2.0) - 0.01).abs() < 1e-4);
}
