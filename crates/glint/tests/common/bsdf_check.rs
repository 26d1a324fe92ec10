//! A reusable harness that checks a BSDF's `sample` against its `pdf` and `eval` (the
//! method of pbrt's and Mitsuba's tests):
//! - directions are binned on a (θ, φ) grid over the whole sphere, the expected count of each
//!   bin is N times the pdf integrated over it (adaptive Simpson), and Pearson's chi-square
//!   statistic, after pooling cells with small expected counts, gives a p-value; samples that
//!   fail or choose a delta lobe form one more cell, expected N (1 - ∫ pdf);
//! - every non-delta sample's weight and pdf must equal eval/pdf and pdf recomputed from it;
//! - the mean weight of the non-delta samples (an albedo estimate) must match ∫ eval dω.
//!
//! A new BSDF is tested by adding one `BsdfCase` to the list in `tests/bsdf_sampling.rs`.

use super::stats::{chi2_survival, Estimate};
use glint::materials::ShadedBsdf;
use glint::math::Vec3;
use glint::sampling::Rng;

pub const THETA_BINS: usize = 16;
pub const PHI_BINS: usize = 32;
/// Cells with fewer expected samples are pooled (the usual rule of thumb for Pearson's test).
const MIN_EXPECTED: f64 = 5.0;

#[derive(Clone, Debug)]
pub struct BsdfCase {
    pub name: String,
    /// A BSDF, possibly in a tilted frame (normal and bump maps).
    pub bsdf: ShadedBsdf,
    pub wo: Vec3,
    /// Sampling never fails: every sample is valid or delta, so ∫ pdf = 1 - P(delta).
    pub complete: bool,
}

/// Unit direction at polar angle `theta_deg` from +z in the xz plane (above 90°: below the
/// surface).
pub fn dir(theta_deg: f32) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3 { x: t.sin(), y: 0.0, z: t.cos() }
}

fn bin_of(w: Vec3) -> usize {
    // In f64: an f32 acos rounds directions just above the horizon to π/2 or beyond.
    let theta = (w.z as f64).clamp(-1.0, 1.0).acos();
    let mut phi = (w.y as f64).atan2(w.x as f64);
    if phi < 0.0 {
        phi += 2.0 * std::f64::consts::PI;
    }
    let i = ((theta / std::f64::consts::PI * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let j = ((phi / (2.0 * std::f64::consts::PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    i * PHI_BINS + j
}

/// What N samples of a BSDF produced.
#[derive(Clone, Debug, Default)]
pub struct Samples {
    pub n: u64,
    /// Non-delta samples per (θ, φ) bin.
    pub bins: Vec<u64>,
    pub failed: u64,
    pub delta: u64,
    /// Sums of the channel-averaged weight and its square over non-delta samples.
    pub weight_sum: f64,
    pub weight_sq_sum: f64,
    /// Worst relative disagreement of `weight` with eval/pdf, and of `pdf` with `Bsdf::pdf`.
    pub worst_weight_error: f64,
    pub worst_pdf_error: f64,
    /// Samples with a non-finite or non-unit direction, or a negative or non-finite weight.
    pub malformed: u64,
}

fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-30)
}

pub fn draw_samples(case: &BsdfCase, n: u64, seed: u64) -> Samples {
    let mut s = Samples { n, bins: vec![0; THETA_BINS * PHI_BINS], ..Default::default() };
    let mut rng = Rng::for_key(seed, 0x5eed, 0);
    for _ in 0..n {
        let u_lobe = rng.next_f32();
        let u = rng.next_2d();
        let Some(bs) = case.bsdf.sample(case.wo, u_lobe, u) else {
            s.failed += 1;
            continue;
        };
        if bs.delta {
            s.delta += 1;
            continue;
        }
        let w = bs.weight.average() as f64;
        let valid_weight = w >= 0.0 && w.is_finite();
        if !bs.wi.is_finite() || (bs.wi.length() - 1.0).abs() > 1e-4 || !valid_weight {
            s.malformed += 1;
            continue;
        }
        s.bins[bin_of(bs.wi)] += 1;
        s.weight_sum += w;
        s.weight_sq_sum += w * w;
        let pdf = case.bsdf.pdf(case.wo, bs.wi) as f64;
        let eval = case.bsdf.eval(case.wo, bs.wi).average() as f64;
        s.worst_pdf_error = s.worst_pdf_error.max(rel_err(bs.pdf as f64, pdf));
        s.worst_weight_error = s.worst_weight_error.max(rel_err(w, eval / pdf));
    }
    s
}

impl Samples {
    /// The albedo estimate E[weight · 1{non-delta}] and its standard error.
    pub fn albedo(&self) -> Estimate {
        let n = self.n as f64;
        let mean = self.weight_sum / n;
        let var = (self.weight_sq_sum / n - mean * mean).max(0.0) * n / (n - 1.0);
        Estimate { mean, se: (var / n).sqrt() }
    }
}

/// Adaptive Simpson quadrature of a pair of functions on [a, b] (error judged on both).
fn simpson(f: &dyn Fn(f64) -> [f64; 2], a: f64, b: f64, eps: f64, min_depth: u32, max_depth: u32) -> [f64; 2] {
    #[allow(clippy::too_many_arguments)] // the recursion carries the interval's samples
    fn rec(
        f: &dyn Fn(f64) -> [f64; 2],
        a: f64,
        b: f64,
        fa: [f64; 2],
        fm: [f64; 2],
        fb: [f64; 2],
        whole: [f64; 2],
        eps: f64,
        depth: u32,
        min_depth: u32,
    ) -> [f64; 2] {
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let h = (b - a) / 12.0;
        let left = [h * (fa[0] + 4.0 * flm[0] + fm[0]), h * (fa[1] + 4.0 * flm[1] + fm[1])];
        let right = [h * (fm[0] + 4.0 * frm[0] + fb[0]), h * (fm[1] + 4.0 * frm[1] + fb[1])];
        let diff = [left[0] + right[0] - whole[0], left[1] + right[1] - whole[1]];
        // Converged when the Richardson error estimate is below the absolute tolerance or
        // a relative one (what matters for a bin's expected count is its relative error).
        let tol = |k: usize| 15.0 * eps.max(REL_EPS * (left[k] + right[k]).abs());
        if depth == 0 || (min_depth == 0 && diff[0].abs() <= tol(0) && diff[1].abs() <= tol(1)) {
            return [left[0] + right[0] + diff[0] / 15.0, left[1] + right[1] + diff[1] / 15.0];
        }
        let md = min_depth.saturating_sub(1);
        let l = rec(f, a, m, fa, flm, fm, left, 0.5 * eps, depth - 1, md);
        let r = rec(f, m, b, fm, frm, fb, right, 0.5 * eps, depth - 1, md);
        [l[0] + r[0], l[1] + r[1]]
    }
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let h = (b - a) / 6.0;
    let whole = [h * (fa[0] + 4.0 * fm[0] + fb[0]), h * (fa[1] + 4.0 * fm[1] + fb[1])];
    rec(f, a, b, fa, fm, fb, whole, eps, max_depth, min_depth)
}

/// ∫ pdf over each (θ, φ) bin, and ∫ eval (channel average) over the sphere.
pub struct Integrals {
    pub pdf_bins: Vec<f64>,
    pub eval_total: f64,
}

impl Integrals {
    pub fn pdf_total(&self) -> f64 {
        self.pdf_bins.iter().sum()
    }
}

/// Quadrature tolerances: absolute per bin, and relative per panel.
const BIN_EPS: f64 = 1e-9;
const REL_EPS: f64 = 1e-6;
const EDGE: f64 = 1e-9;

pub fn integrate(case: &BsdfCase) -> Integrals {
    let (bsdf, wo) = (&case.bsdf, case.wo);
    let f = |theta: f64, phi: f64| -> [f64; 2] {
        let (st, ct) = theta.sin_cos();
        let wi = Vec3 { x: (st * phi.cos()) as f32, y: (st * phi.sin()) as f32, z: ct as f32 };
        let pdf = bsdf.pdf(wo, wi) as f64;
        let eval = bsdf.eval(wo, wi).average() as f64;
        [pdf * st, eval * st]
    };
    let dt = std::f64::consts::PI / THETA_BINS as f64;
    let dp = 2.0 * std::f64::consts::PI / PHI_BINS as f64;
    let mut pdf_bins = vec![0.0; THETA_BINS * PHI_BINS];
    let mut eval_total = 0.0;
    for i in 0..THETA_BINS {
        for j in 0..PHI_BINS {
            let (t0, p0) = (i as f64 * dt, j as f64 * dp);
            let inner = |t: f64| simpson(&|p| f(t, p), p0, p0 + dp, BIN_EPS / dt, 3, 12);
            // Simpson's rule samples the interval ends; keep them a hair inside the bin so
            // that the pdf's jump at the horizon (θ = π/2, a bin edge) is not smeared into
            // the neighbouring bin (the mass left out is ~1e-8 of a bin).
            let v = simpson(&inner, t0 + EDGE, t0 + dt - EDGE, BIN_EPS, 3, 12);
            pdf_bins[i * PHI_BINS + j] = v[0];
            eval_total += v[1];
        }
    }
    Integrals { pdf_bins, eval_total }
}

#[derive(Debug)]
pub struct Chi2Outcome {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
}

/// Pearson's test of observed against expected counts (pbrt-v3's pooling: cells with
/// expected counts under MIN_EXPECTED are merged, smallest first). Err when a sample landed
/// where the pdf integrates to exactly zero.
pub fn chi2_test(observed: &[u64], expected: &[f64]) -> Result<Chi2Outcome, String> {
    let mut cells: Vec<(f64, u64, usize)> =
        expected.iter().zip(observed).enumerate().map(|(i, (&e, &o))| (e, o, i)).collect();
    cells.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    let (mut pooled_e, mut pooled_o, mut pooled_cells) = (0.0, 0u64, 0usize);
    let (mut stat, mut dof) = (0.0f64, 0usize);
    for &(e, o, i) in &cells {
        if e <= 0.0 {
            if o > 0 {
                return Err(format!("{o} samples in cell {i}, where the pdf is zero"));
            }
        } else if e < MIN_EXPECTED || (pooled_cells > 0 && pooled_e < MIN_EXPECTED) {
            pooled_e += e;
            pooled_o += o;
            pooled_cells += 1;
        } else {
            stat += (o as f64 - e).powi(2) / e;
            dof += 1;
        }
    }
    if pooled_cells > 0 {
        stat += (pooled_o as f64 - pooled_e).powi(2) / pooled_e;
        dof += 1;
    }
    let dof = dof.saturating_sub(1).max(1);
    Ok(Chi2Outcome { statistic: stat, dof, p_value: chi2_survival(stat, dof as f64) })
}

/// The chi-square test of `samples` against `integrals`: the (θ, φ) bins plus one cell for
/// failed and delta samples.
pub fn chi2_of(samples: &Samples, integrals: &Integrals) -> Result<Chi2Outcome, String> {
    let n = samples.n as f64;
    let mut expected: Vec<f64> = integrals.pdf_bins.iter().map(|p| p * n).collect();
    let mut observed = samples.bins.clone();
    // Quadrature error can make 1 - ∫pdf slightly negative; a tiny positive expectation
    // lets that cell be pooled instead of declared impossible.
    expected.push((n * (1.0 - integrals.pdf_total())).max(1e-9));
    observed.push(samples.failed + samples.delta + samples.malformed);
    chi2_test(&observed, &expected)
}
