//! pbrt-v4's `coateddiffuse`, a layered BSDF evaluated by random walks. Its `eval` and `pdf`
//! are unbiased stochastic estimates (seeded by a hash of their arguments and the BSDF's
//! `seed`), and a sample's weight is the walk's throughput, so the checks of
//! `bsdf_sampling.rs` (weight = eval/pdf to rounding, adaptive quadrature of the pdf) do not
//! apply. What must hold instead, each with a tolerance from its sample counts:
//! - sampled directions follow the *mean* of `pdf` (chi-square, the noise of the mean's
//!   estimate added to each cell's variance);
//! - the mean sample weight in each band of directions equals the integral of `eval` there;
//! - the mean of f(wo, wi) equals the mean of f(wi, wo) (reciprocity);
//! - with a white base, no absorption and a smooth coating, the directional albedo is the
//!   closed form of the walk truncated at `maxdepth`, and tends to 1;
//! - with no slab and a smooth coating the BSDF is Mitsuba's nonlinear smooth `plastic` up
//!   to the fit `plastic` uses for the internal diffuse reflectance;
//! - the JSON reader builds it, renders it, and rejects bad parameters in one line.

mod common;

use common::load::load;
use common::scenes::render_with;
use common::scratch::ScratchDir;
use common::stats::{chi2_survival, sidak, z_critical, FALSE_ALARM};
use glint::bsdf::{fresnel_dielectric, Scatter};
use glint::materials::{CoatedDiffuse, PlasticParams};
use glint::math::{rgb, Rgb, Vec3};
use glint::sampling::{warp, Rng};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Unit direction at polar angle `deg` in the xz plane.
fn dir(deg: f32) -> Vec3 {
    let t = deg.to_radians();
    Vec3 { x: t.sin(), y: 0.0, z: t.cos() }
}

fn coated(f: impl FnOnce(&mut CoatedDiffuse)) -> CoatedDiffuse {
    let mut c = CoatedDiffuse::default();
    f(&mut c);
    c
}

/// Bins of the upper hemisphere: equal bands of cos θ times equal sectors of φ, so that every
/// cell has the solid angle 2π / (MU_BINS PHI_BINS).
const MU_BINS: usize = 8;
const PHI_BINS: usize = 16;
const CELLS: usize = MU_BINS * PHI_BINS;
const CELL_SOLID_ANGLE: f64 = 2.0 * PI / CELLS as f64;
/// Samples per case, and `pdf` / `eval` points per cell for their integrals.
const SAMPLES: usize = 200_000;
const POINTS_PER_CELL: usize = 1024;
/// Bound on the rounding of a path's weight: a product of up to ~2 maxdepth f32 factors
/// (1/η² on the way in, η² on the way out, ratios of 1), each within half an ulp (6e-8).
const ROUNDING: f64 = 2e-4;
/// Cells with fewer expected samples are pooled.
const MIN_EXPECTED: f64 = 5.0;

fn cell_of(w: Vec3) -> usize {
    let i = (((1.0 - w.z as f64) * MU_BINS as f64) as usize).min(MU_BINS - 1);
    let mut phi = (w.y as f64).atan2(w.x as f64);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    i * PHI_BINS + j
}

/// A uniformly random direction in cell `k`.
fn point_in_cell(k: usize, rng: &mut Rng) -> Vec3 {
    let (i, j) = (k / PHI_BINS, k % PHI_BINS);
    let mu = 1.0 - (i as f64 + rng.next_f64()) / MU_BINS as f64;
    let phi = (j as f64 + rng.next_f64()) * 2.0 * PI / PHI_BINS as f64;
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    Vec3 { x: (s * phi.cos()) as f32, y: (s * phi.sin()) as f32, z: mu as f32 }
}

struct Case {
    name: String,
    bsdf: CoatedDiffuse,
    wo: Vec3,
}

fn cases() -> Vec<Case> {
    let mut v = Vec::new();
    let mut add = |name: &str, bsdf: CoatedDiffuse, wos: &[f32]| {
        for &deg in wos {
            v.push(Case { name: format!("{name}, wo at {deg}°"), bsdf, wo: dir(deg) });
        }
    };
    add("pbrt defaults (smooth, absorbing)", CoatedDiffuse::default(), &[0.0, 70.0]);
    let smooth_medium = coated(|c| {
        (c.eta, c.thickness, c.albedo, c.g) = (1.33, 1.0, rgb(0.9, 0.7, 0.5), -0.3);
        c.reflectance = rgb(0.2, 0.6, 0.8);
    });
    add("smooth, scattering slab g -0.3", smooth_medium, &[30.0]);
    let rough_medium = coated(|c| {
        (c.roughness, c.thickness, c.albedo, c.g) = (0.3, 0.5, rgb(0.8, 0.6, 0.4), 0.5);
        c.reflectance = Rgb::splat(0.7);
    });
    add("GGX 0.3, scattering slab g 0.5", rough_medium, &[40.0, 80.0]);
    let shallow = coated(|c| (c.roughness, c.thickness, c.max_depth, c.reflectance) = (0.1, 0.2, 2, Rgb::splat(0.9)));
    add("GGX 0.1, maxdepth 2", shallow, &[60.0]);
    v
}

/// What sampling and the cell integrals of one case gave.
struct Checked {
    case: Case,
    counts: Vec<u64>,
    /// Delta reflections and failed samples.
    other: u64,
    /// Per band of cos θ: sum of sample weights and of their squares (channel average).
    weight: Vec<(f64, f64)>,
    /// Per cell: the integral of the mean pdf and of the mean eval, each with its variance.
    pdf: Vec<(f64, f64)>,
    eval: Vec<(f64, f64)>,
}

/// The integral over cell `k` of f (uniform random points) and the variance of that estimate.
fn cell_integral(k: usize, rng: &mut Rng, f: impl Fn(Vec3) -> f64) -> (f64, f64) {
    let m = POINTS_PER_CELL as f64;
    let (mut s, mut s2) = (0.0, 0.0);
    for _ in 0..POINTS_PER_CELL {
        let v = f(point_in_cell(k, rng));
        s += v;
        s2 += v * v;
    }
    let mean = s / m;
    let var = (s2 / m - mean * mean).max(0.0) / (m - 1.0);
    (CELL_SOLID_ANGLE * mean, CELL_SOLID_ANGLE * CELL_SOLID_ANGLE * var)
}

fn check(case: Case, seed: u64) -> Checked {
    let mut rng = Rng::new(seed, 11);
    let (mut counts, mut other, mut weight) = (vec![0u64; CELLS], 0u64, vec![(0.0, 0.0); MU_BINS]);
    for _ in 0..SAMPLES {
        let s = case.bsdf.sample(case.wo, rng.next_f32(), rng.next_2d());
        match s {
            Some(s) if !s.delta => {
                let w = s.weight.average() as f64;
                assert!(w.is_finite() && w >= 0.0 && s.wi.z > 0.0, "{}: bad sample {s:?}", case.name);
                let k = cell_of(s.wi);
                counts[k] += 1;
                weight[k / PHI_BINS].0 += w;
                weight[k / PHI_BINS].1 += w * w;
            }
            _ => other += 1,
        }
    }
    let mut rng = Rng::new(seed, 12);
    let pdf = (0..CELLS).map(|k| cell_integral(k, &mut rng, |wi| case.bsdf.pdf(case.wo, wi) as f64)).collect();
    let eval =
        (0..CELLS).map(|k| cell_integral(k, &mut rng, |wi| case.bsdf.eval(case.wo, wi).average() as f64)).collect();
    Checked { case, counts, other, weight, pdf, eval }
}

fn checked() -> &'static [Checked] {
    static RESULTS: OnceLock<Vec<Checked>> = OnceLock::new();
    RESULTS.get_or_init(|| cases().into_par_iter().enumerate().map(|(i, c)| check(c, 300 + i as u64)).collect())
}

/// Pearson's statistic of observed counts against expected ones whose estimate has a
/// variance: each cell's squared deviation over its expected count plus that variance
/// (cells with small expectations pooled). Returned with the p-value for as many degrees of
/// freedom as cells: conservative, since the multinomial part has one fewer.
fn chi2(cells: Vec<(u64, f64, f64)>) -> (f64, usize, f64) {
    let mut cells = cells;
    cells.sort_by(|a, b| a.1.partial_cmp(&b.1).unwrap());
    let (mut pooled, mut any_pooled) = ((0u64, 0.0f64, 0.0f64), false);
    let (mut stat, mut dof) = (0.0, 0usize);
    for (o, e, var) in cells {
        if e < MIN_EXPECTED || (any_pooled && pooled.1 < MIN_EXPECTED) {
            pooled = (pooled.0 + o, pooled.1 + e.max(0.0), pooled.2 + var);
            any_pooled = true;
        } else {
            stat += (o as f64 - e).powi(2) / (e + var);
            dof += 1;
        }
    }
    if any_pooled {
        let (o, e, var) = pooled;
        let denom = e + var;
        stat += if denom > 0.0 {
            (o as f64 - e).powi(2) / denom
        } else if o > 0 {
            f64::INFINITY
        } else {
            0.0
        };
        dof += 1;
    }
    (stat, dof, chi2_survival(stat, dof as f64))
}

#[test]
fn sampled_directions_follow_the_mean_pdf() {
    let all = checked();
    let alpha = sidak(FALSE_ALARM, all.len());
    let n = SAMPLES as f64;
    let mut failures = Vec::new();
    for c in all {
        let mut cells: Vec<(u64, f64, f64)> =
            c.counts.iter().zip(&c.pdf).map(|(&o, &(p, var))| (o, n * p, n * n * var)).collect();
        let mass: f64 = c.pdf.iter().map(|p| p.0).sum();
        let mass_var: f64 = c.pdf.iter().map(|p| p.1).sum();
        cells.push((c.other, n * (1.0 - mass), n * n * mass_var));
        let (stat, dof, p) = chi2(cells);
        println!("{:45} chi2 {stat:8.1} dof {dof:4} p {p:.3e} (∫ mean pdf {mass:.4})", c.case.name);
        if p < alpha {
            failures.push(format!("{}: chi2 {stat:.1} with {dof} cells, p = {p:.2e} < {alpha:.1e}", c.case.name));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn mean_sample_weight_matches_integrated_eval_in_each_band() {
    let all = checked();
    let k = z_critical(FALSE_ALARM, all.len() * MU_BINS);
    let n = SAMPLES as f64;
    let mut failures = Vec::new();
    for c in all {
        for band in 0..MU_BINS {
            let (s, s2) = c.weight[band];
            let mean = s / n;
            let se_w = ((s2 / n - mean * mean).max(0.0) / (n - 1.0)).sqrt();
            let cells = &c.eval[band * PHI_BINS..(band + 1) * PHI_BINS];
            let integral: f64 = cells.iter().map(|e| e.0).sum();
            let se_e = cells.iter().map(|e| e.1).sum::<f64>().sqrt();
            let se = (se_w * se_w + se_e * se_e).sqrt();
            let z = (mean - integral) / se;
            if band == 0 || band == MU_BINS - 1 {
                println!(
                    "{:45} band {band}: weights {mean:.5} ± {se_w:.5}, ∫eval {integral:.5} ± {se_e:.5}",
                    c.case.name
                );
            }
            if !(z.abs() <= k) {
                failures.push(format!(
                    "{} band {band}: mean weight {mean:.5} ± {se_w:.5}, ∫ eval {integral:.5} ± {se_e:.5} (z = {z:.1})",
                    c.case.name
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The two checks above can see a walk counted one event too deep: samples of the
/// `maxdepth 2` case against the pdf and eval of the same BSDF with `maxdepth 3`.
#[test]
fn the_checks_see_maxdepth_off_by_one() {
    let c = checked().iter().find(|c| c.case.bsdf.max_depth == 2).unwrap();
    let deeper = CoatedDiffuse { max_depth: 3, ..c.case.bsdf };
    let twin = check(Case { name: "maxdepth 3 twin".into(), bsdf: deeper, wo: c.case.wo }, 77);
    let n = SAMPLES as f64;
    let mut cells: Vec<(u64, f64, f64)> =
        c.counts.iter().zip(&twin.pdf).map(|(&o, &(p, var))| (o, n * p, n * n * var)).collect();
    let mass: f64 = twin.pdf.iter().map(|p| p.0).sum();
    cells.push((c.other, n * (1.0 - mass), n * n * twin.pdf.iter().map(|p| p.1).sum::<f64>()));
    let (stat, dof, p) = chi2(cells);
    println!("samples of maxdepth 2 against the pdf of maxdepth 3: chi2 {stat:.1}, dof {dof}, p {p:.2e}");
    assert!(p < 1e-6, "the chi-square test does not see the extra depth (p = {p:.2e})");
    let weights: f64 = c.weight.iter().map(|w| w.0).sum::<f64>() / n;
    let integral: f64 = twin.eval.iter().map(|e| e.0).sum();
    let se = (c.weight.iter().map(|w| w.1).sum::<f64>() / n / n + twin.eval.iter().map(|e| e.1).sum::<f64>()).sqrt();
    println!("mean weight {weights:.5}, ∫ eval of maxdepth 3 {integral:.5} ± {se:.5}");
    assert!((integral - weights).abs() > 10.0 * se, "the weight check does not see the extra depth");
}

/// 2 ∫ F(μ) μ dμ for light inside the coating meeting it from below: the fraction of
/// cosine-distributed light the smooth coating reflects back (midpoint rule, 10⁶ panels;
/// F is continuous with a square-root kink at the critical angle, so the error is ~1e-9).
fn internal_diffuse_reflectance(eta: f32) -> f64 {
    let n = 1_000_000;
    (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n as f64;
            2.0 * fresnel_dielectric(-mu as f32, eta).reflectance as f64 * mu / n as f64
        })
        .sum()
}

/// The directional albedo of `bsdf` seen from `wo` two ways, each with its standard error:
/// the mean sample weight (delta reflections included), and the smooth reflection `delta`
/// plus ∫ eval dω by cosine-weighted directions.
fn albedos(bsdf: &CoatedDiffuse, wo: Vec3, delta: f64, n: usize, seed: u64) -> [(f64, f64); 2] {
    let mut rng = Rng::new(seed, 5);
    let (mut s, mut s2, mut e, mut e2) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..n {
        let w = bsdf.sample(wo, rng.next_f32(), rng.next_2d()).map_or(0.0, |s| s.weight.average() as f64);
        s += w;
        s2 += w * w;
        let wi = warp::cosine_hemisphere(rng.next_2d());
        let v = if wi.z > 0.0 {
            bsdf.eval(wo, wi).average() as f64 / warp::cosine_hemisphere_pdf(wi.z) as f64
        } else {
            0.0
        };
        e += v;
        e2 += v * v;
    }
    let nf = n as f64;
    let est = |s: f64, s2: f64| (s / nf, ((s2 / nf - (s / nf).powi(2)).max(0.0) / (nf - 1.0)).sqrt());
    let (em, ese) = est(e, e2);
    [est(s, s2), (delta + em, ese)]
}

/// With a white base, a smooth coating and no slab, every path that leaves carries weight 1
/// and light leaves the base with probability 1 - F_in per visit (F_in the coating's internal
/// diffuse reflectance): after the coating's reflection F_o, the directional albedo is
/// F_o + (1 - F_o)(1 - F_in^K), K = ⌈maxdepth / 2⌉ the visits to the base a path of at most
/// maxdepth events has (base and coating alternate). It tends to 1: energy is conserved.
#[test]
fn white_furnace_albedo_is_the_truncated_series() {
    let eta = 1.5f32;
    let f_in = internal_diffuse_reflectance(eta);
    let configs: Vec<(u32, f32)> = [1, 2, 3, 10, 1000].iter().flat_map(|&d| [(d, 0.0), (d, 75.0)]).collect();
    let k = z_critical(FALSE_ALARM, 2 * configs.len());
    let failures: Vec<String> = configs
        .par_iter()
        .enumerate()
        .flat_map(|(i, &(depth, deg))| {
            let bsdf = coated(|c| (c.reflectance, c.thickness, c.eta, c.max_depth) = (Rgb::WHITE, 0.0, eta, depth));
            let wo = dir(deg);
            let f_o = fresnel_dielectric(wo.z, eta).reflectance as f64;
            let exact = f_o + (1.0 - f_o) * (1.0 - f_in.powi(depth.div_ceil(2) as i32));
            let est = albedos(&bsdf, wo, f_o, 100_000, 40 + i as u64);
            println!(
                "maxdepth {depth:4}, wo {deg:2}°: expected {exact:.5}, weights {:.5} ± {:.5}, eval {:.5} ± {:.5}",
                est[0].0, est[0].1, est[1].0, est[1].1
            );
            est.iter()
                .zip(["weights", "eval"])
                .filter(|((m, se), _)| !((m - exact).abs() <= k * se + ROUNDING))
                .map(|((m, se), what)| {
                    format!("maxdepth {depth}, wo {deg}°: {what} {m:.5} ± {se:.5}, expected {exact:.5}")
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A white base under a non-absorbing scattering slab and a smooth coating loses nothing:
/// the albedo is 1 (within the standard error; paths of over 1000 events are negligible).
/// A rough coating reflects at most everything: glint's microfacet interface (one scattering
/// on the microsurface) loses some energy, so only the bound is checked there.
#[test]
fn white_furnace_with_a_scattering_slab_and_a_rough_coating() {
    let scattering = coated(|c| {
        (c.reflectance, c.albedo, c.g, c.thickness, c.max_depth) = (Rgb::WHITE, Rgb::WHITE, 0.3, 1.0, 1000);
    });
    let rough = coated(|c| (c.reflectance, c.roughness, c.thickness, c.max_depth) = (Rgb::WHITE, 0.3, 0.0, 1000));
    let k = z_critical(FALSE_ALARM, 8);
    let mut failures = Vec::new();
    for (i, deg) in [10.0f32, 70.0].into_iter().enumerate() {
        let wo = dir(deg);
        let f_o = fresnel_dielectric(wo.z, 1.5).reflectance as f64;
        for (what, m, se) in albedos(&scattering, wo, f_o, 100_000, 60 + i as u64)
            .iter()
            .zip(["weights", "eval"])
            .map(|(e, w)| (w, e.0, e.1))
        {
            println!("scattering slab, wo {deg}°: {what} {m:.5} ± {se:.5}");
            if !((m - 1.0).abs() <= k * se + ROUNDING) {
                failures.push(format!("scattering slab, wo {deg}°: {what} albedo {m:.5} ± {se:.5}, not 1"));
            }
        }
        for (what, m, se) in
            albedos(&rough, wo, 0.0, 100_000, 70 + i as u64).iter().zip(["weights", "eval"]).map(|(e, w)| (w, e.0, e.1))
        {
            println!("GGX 0.3 coating, wo {deg}°: {what} {m:.5} ± {se:.5}");
            if !(m <= 1.0 + k * se + ROUNDING) {
                failures.push(format!("GGX 0.3 coating, wo {deg}°: {what} albedo {m:.5} ± {se:.5} above 1"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The mean over `seeds` seeds of f(wo, wi) = eval / cos θi, channel `c` (3: the average),
/// and its standard error.
fn mean_f(bsdf: &CoatedDiffuse, wo: Vec3, wi: Vec3, c: usize, seeds: std::ops::Range<u32>) -> (f64, f64) {
    let n = seeds.len() as f64;
    let (mut s, mut s2) = (0.0, 0.0);
    for seed in seeds {
        let v = CoatedDiffuse { seed, ..*bsdf }.eval(wo, wi);
        let x = if c == 3 { v.average() } else { v.to_array()[c] } as f64 / wi.z as f64;
        s += x;
        s2 += x * x;
    }
    (s / n, ((s2 / n - (s / n).powi(2)).max(0.0) / (n - 1.0)).sqrt())
}

/// Helmholtz reciprocity in expectation: the mean of f(wo, wi) over independent seeds equals
/// that of f(wi, wo) (the walk enters towards wo and leaves by next-event estimation towards
/// wi, so a wrong factor on either side breaks the symmetry).
#[test]
fn coated_diffuse_is_reciprocal_in_expectation() {
    let bsdfs = [
        (
            "GGX 0.3, scattering slab",
            coated(|c| {
                (c.roughness, c.thickness, c.albedo, c.g, c.reflectance) =
                    (0.3, 0.5, Rgb::splat(0.8), 0.5, Rgb::splat(0.7));
            }),
        ),
        (
            "smooth, absorbing slab, eta 1.33",
            coated(|c| {
                (c.eta, c.thickness, c.reflectance) = (1.33, 0.5, rgb(0.8, 0.5, 0.2));
            }),
        ),
    ];
    let pairs = 12;
    let k = z_critical(FALSE_ALARM, bsdfs.len() * pairs);
    let mut rng = Rng::new(9, 9);
    let mut failures = Vec::new();
    for (name, bsdf) in &bsdfs {
        for _ in 0..pairs {
            let mut pick = || loop {
                let w = warp::uniform_hemisphere(rng.next_2d());
                if w.z > 0.1 {
                    break w;
                }
            };
            let (wo, wi) = (pick(), pick());
            let (a, sa) = mean_f(bsdf, wo, wi, 3, 0..2000);
            let (b, sb) = mean_f(bsdf, wi, wo, 3, 2000..4000);
            let z = (a - b) / (sa * sa + sb * sb).sqrt();
            assert!(a > 0.0 && b > 0.0, "{name}: zero BSDF at {wo:?} {wi:?}");
            if !(z.abs() <= k) {
                failures.push(format!(
                    "{name}: wo {wo:?} wi {wi:?}: f {a:.5} ± {sa:.5}, reversed {b:.5} ± {sb:.5} (z = {z:.1})"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// With no slab (thickness 0) and a smooth coating the walk sums the same series Mitsuba's
/// nonlinear smooth `plastic` does in closed form: ρ (1 - F_o)(1 - F_i) cos θi /
/// (π η² (1 - ρ F_in)), maxdepth 1000 leaving out (ρ F_in)^500. `plastic` takes F_in from a
/// fit within δ = 5e-3 of the integral (its unit test), which moves its value by at most
/// ρ δ / (1 - ρ (F_fit + δ)) relatively: the tolerance beside the statistical one.
#[test]
fn without_a_slab_a_smooth_coating_is_nonlinear_plastic() {
    let rho = rgb(0.8, 0.5, 0.2);
    let bsdf = coated(|c| (c.reflectance, c.thickness, c.max_depth) = (rho, 0.0, 1000));
    let plastic = PlasticParams { nonlinear: true, ..PlasticParams::new(rho, Rgb::WHITE, 1.5, None) };
    let delta = 5e-3;
    let pairs = [(0.0, 0.0), (30.0, 60.0), (75.0, 20.0), (50.0, 85.0)];
    let k = z_critical(FALSE_ALARM, pairs.len() * 3);
    let mut failures = Vec::new();
    for (a, b) in pairs {
        let (wo, wi) = (dir(a), Vec3 { x: -dir(b).x * 0.6, y: dir(b).x * 0.8, z: dir(b).z });
        let p = plastic.eval(wo, wi);
        for c in 0..3 {
            let (m, se) = mean_f(&bsdf, wo, wi, c, 0..3000);
            let r = rho.to_array()[c] as f64;
            let pc = p.to_array()[c] as f64 / wi.z as f64;
            let sys = pc * r * delta / (1.0 - r * (plastic.fdr_internal as f64 + delta));
            println!("wo {a}°, wi {b}°, channel {c}: coated {m:.5} ± {se:.5}, plastic {pc:.5} (fit ± {sys:.5})");
            if !((m - pc).abs() <= k * se + sys) {
                failures
                    .push(format!("wo {a}° wi {b}° channel {c}: coated {m:.5} ± {se:.5}, plastic {pc:.5} ± {sys:.5}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

const SCENE: &str = r#"{
  "camera": { "position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 30 },
  "film": { "width": 16, "height": 16 },
  "materials": { "coat": MATERIAL },
  "shapes": [ { "type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "coat" } ],
  "lights": [ { "type": "constant", "radiance": 1 } ]
}"#;

fn scene_file(dir: &ScratchDir, name: &str, material: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, SCENE.replace("MATERIAL", material)).unwrap();
    p
}

/// A coated sphere under a uniform environment of radiance 1 through the JSON reader: the
/// background is 1, and the sphere shows its directional albedo, which is positive and (a
/// convex object seeing only the environment) below 1. Every path schedule gives the same
/// bits (`render_with` checks).
#[test]
fn a_json_coateddiffuse_sphere_renders() {
    let dir = ScratchDir::new("coated-render");
    let material = r#"{ "type": "coateddiffuse", "reflectance": [0.8, 0.6, 0.3], "roughness": 0.2,
        "thickness": 0.1, "ior": 1.5, "albedo": 0.5, "g": 0.2, "maxdepth": 8, "nsamples": 2 }"#;
    let loaded = load(&scene_file(&dir, "sphere.json", material), &[], None).unwrap();
    let out = render_with(&loaded.world, &loaded.integrator, 16, 3);
    let px = &out.image.pixels;
    assert!(px.iter().all(|p| p.to_array().iter().all(|v| v.is_finite() && *v >= 0.0)));
    assert_eq!(px[0].to_array(), [1.0; 3], "background");
    let centre: Vec<f32> = (6..10).flat_map(|y| (6..10).map(move |x| px[y * 16 + x].average())).collect();
    let mean = centre.iter().sum::<f32>() / centre.len() as f32;
    println!("sphere centre mean {mean}");
    assert!(mean > 0.1 && mean < 1.0, "sphere centre mean {mean}");
}

#[test]
fn bad_coateddiffuse_parameters_are_one_line_errors() {
    let dir = ScratchDir::new("coated-errors");
    for (name, material, says) in [
        ("thickness.json", r#"{ "type": "coateddiffuse", "thickness": -1 }"#, "thickness -1"),
        ("albedo.json", r#"{ "type": "coateddiffuse", "albedo": 1.5 }"#, "albedo"),
        ("g.json", r#"{ "type": "coateddiffuse", "g": 1 }"#, "g 1"),
        ("depth.json", r#"{ "type": "coateddiffuse", "maxdepth": 0 }"#, "maxdepth 0"),
        ("samples.json", r#"{ "type": "coateddiffuse", "nsamples": 100000 }"#, "nsamples 100000"),
        ("eta.json", r#"{ "type": "coateddiffuse", "eta": 0 }"#, "eta 0"),
        ("both.json", r#"{ "type": "coateddiffuse", "eta": 1.5, "ior": 1.5 }"#, "'eta' or 'ior'"),
    ] {
        let e = match load(&scene_file(&dir, name, material), &[], None) {
            Ok(_) => panic!("{name} loaded"),
            Err(e) => e,
        };
        println!("{e}");
        assert!(!e.contains('\n') && e.contains(name) && e.contains("'coat'") && e.contains(says), "{name}: {e}");
    }
}
