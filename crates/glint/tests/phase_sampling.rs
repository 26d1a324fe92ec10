//! Phase functions: sampled directions follow `eval` (a chi-square test on bins of the
//! cosine from the travel direction and of the azimuth around it), every sample's pdf is
//! `eval`, the density integrates to one, and the mean cosine of Henyey-Greenstein samples
//! is its g. Cases cover isotropic scattering and g negative, zero, positive and near ±1.

mod common;

use common::bsdf_check::chi2_test;
use common::stats::{sidak, z_critical, FALSE_ALARM};
use glint::math::{Frame, Vec3};
use glint::media::Phase;
use glint::sampling::Rng;

const SAMPLES: u64 = 1_000_000;
const MU_BINS: usize = 48;
const PHI_BINS: usize = 8;
const CHI2_SIGNIFICANCE: f64 = 0.01;

fn cases() -> Vec<Phase> {
    let mut v = vec![Phase::Isotropic];
    // Beyond |g| = 0.99 the peak (width (1 - |g|)² in cosine) is finer than f32 directions
    // resolve, and the quadrature through `eval` of f32 directions would be the thing tested.
    for g in [-0.99, -0.9, -0.4, 0.0, 1e-7, 0.2, 0.7, 0.95, 0.99] {
        v.push(Phase::HenyeyGreenstein { g });
    }
    v
}

/// The incoming direction of every case: tilted, so that no axis is special.
fn wo() -> Vec3 {
    Vec3 { x: 0.3, y: -0.5, z: 0.8 }.normalize()
}

/// The direction at cosine `mu` from the travel direction and azimuth `phi` around it.
fn direction(frame: &Frame, mu: f64, phi: f64) -> Vec3 {
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    frame.to_world(Vec3 { x: (s * phi.cos()) as f32, y: (s * phi.sin()) as f32, z: mu as f32 })
}

/// ∫ f over [a, b] by adaptive Simpson (f is smooth but sharply peaked near |g| = 1).
fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, eps: f64, depth: u32) -> f64 {
    let m = 0.5 * (a + b);
    let (fa, fm, fb) = (f(a), f(m), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    #[allow(clippy::too_many_arguments)] // the textbook recursion's state, kept as it reads
    fn rec(f: &dyn Fn(f64) -> f64, a: f64, b: f64, fa: f64, fm: f64, fb: f64, whole: f64, eps: f64, d: u32) -> f64 {
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
        let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
        if d == 0 || (left + right - whole).abs() <= 15.0 * eps {
            return left + right + (left + right - whole) / 15.0;
        }
        rec(f, a, m, fa, flm, fm, left, 0.5 * eps, d - 1) + rec(f, m, b, fm, frm, fb, right, 0.5 * eps, d - 1)
    }
    rec(f, a, b, fa, fm, fb, whole, eps, depth)
}

fn bin_of(frame: &Frame, w: Vec3) -> usize {
    let local = frame.to_local(w);
    let mu = (local.z as f64).clamp(-1.0, 1.0);
    let mut phi = (local.y as f64).atan2(local.x as f64);
    if phi < 0.0 {
        phi += 2.0 * std::f64::consts::PI;
    }
    let i = (((mu + 1.0) * 0.5 * MU_BINS as f64) as usize).min(MU_BINS - 1);
    let j = ((phi / (2.0 * std::f64::consts::PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    i * PHI_BINS + j
}

#[test]
fn phase_sampling_follows_eval() {
    let cases = cases();
    let alpha = sidak(CHI2_SIGNIFICANCE, cases.len());
    let z = z_critical(FALSE_ALARM, cases.len());
    let wo = wo();
    let frame = Frame::from_normal(-wo);
    let mut failures = Vec::new();
    for (k, phase) in cases.iter().enumerate() {
        // Expected counts: N Δφ ∫ eval dμ over each bin (eval depends on μ only).
        let p_of_mu = |mu: f64| phase.eval(wo, direction(&frame, mu, 0.3)) as f64;
        let dphi = 2.0 * std::f64::consts::PI / PHI_BINS as f64;
        let mut expected = vec![0.0; MU_BINS * PHI_BINS];
        let mut total = 0.0;
        for i in 0..MU_BINS {
            let a = -1.0 + 2.0 * i as f64 / MU_BINS as f64;
            let b = -1.0 + 2.0 * (i + 1) as f64 / MU_BINS as f64;
            let p = simpson(&p_of_mu, a, b, 1e-10, 40) * dphi;
            total += p * PHI_BINS as f64;
            for j in 0..PHI_BINS {
                expected[i * PHI_BINS + j] = p * SAMPLES as f64;
            }
        }
        // Near |g| = 1, eval sees the peak through f32 directions (cosines rounded to 6e-8
        // against a peak (1 - |g|)² = 1e-4 wide, 0.1% of the peak value): the quadrature is
        // good to 3e-3 there (0.15% short for g = ±0.99).
        let near_one = matches!(phase, Phase::HenyeyGreenstein { g } if g.abs() > 0.98);
        if (total - 1.0).abs() > if near_one { 3e-3 } else { 1e-4 } {
            failures.push(format!("{phase:?}: the density integrates to {total}, not 1"));
        }
        let mut observed = vec![0u64; MU_BINS * PHI_BINS];
        let mut rng = Rng::for_key(7, 0xfa5e, k as u64);
        let (mut sum_mu, mut worst_pdf) = (0.0f64, 0.0f64);
        for _ in 0..SAMPLES {
            let s = phase.sample(wo, rng.next_2d());
            assert!(s.wi.is_finite() && (s.wi.length() - 1.0).abs() < 1e-4, "{phase:?}: bad direction {:?}", s.wi);
            let e = phase.eval(wo, s.wi) as f64;
            worst_pdf = worst_pdf.max((s.pdf as f64 - e).abs() / e.max(1e-30));
            sum_mu += -wo.dot(s.wi) as f64;
            observed[bin_of(&frame, s.wi)] += 1;
        }
        // Near |g| = 1 the density changes by orders of magnitude across f32 rounding of
        // the sampled direction; elsewhere pdf and eval are the same formula.
        if worst_pdf > if near_one { 0.5 } else { 2e-3 } {
            failures.push(format!("{phase:?}: a sample's pdf differs from eval by {worst_pdf:.2e} (relative)"));
        }
        match chi2_test(&observed, &expected) {
            Ok(o) if o.p_value < alpha => failures
                .push(format!("{phase:?}: chi-square {:.1} on {} dof, p = {:.2e}", o.statistic, o.dof, o.p_value)),
            Ok(_) => {}
            Err(e) => failures.push(format!("{phase:?}: {e}")),
        }
        // The mean cosine of Henyey-Greenstein is g (isotropic: 0); |μ| ≤ 1 bounds its
        // standard deviation by 1.
        let g = match phase {
            Phase::HenyeyGreenstein { g } => *g as f64,
            Phase::Isotropic => 0.0,
        };
        let mean_mu = sum_mu / SAMPLES as f64;
        if (mean_mu - g).abs() > z / (SAMPLES as f64).sqrt() {
            failures.push(format!("{phase:?}: mean cosine {mean_mu:.5}, expected {g}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
