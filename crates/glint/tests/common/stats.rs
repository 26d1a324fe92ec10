//! Special functions and estimators for statistical tests: the regularized incomplete gamma
//! function (chi-square and normal tail probabilities both come from it), critical values
//! for a given false-alarm rate, and means with standard errors from rendered images.

use glint::render::RenderOutput;

/// False-alarm rate of one statistical `#[test]` (all its comparisons together, Šidák
/// corrected): with about 20 such tests the suite fails spuriously on a fresh seed with
/// probability near 0.2%.
pub const FALSE_ALARM: f64 = 1e-4;

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; about 15 significant digits).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection formula.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularized upper incomplete gamma function Q(a, x) = Γ(a, x) / Γ(a): the series for
/// x < a + 1, Lentz's continued fraction otherwise (Numerical Recipes §6.2).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "gamma_q({a}, {x})");
    if x == 0.0 {
        return 1.0;
    }
    let ln_prefix = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        let (mut ap, mut sum, mut del) = (a, 1.0 / a, 1.0 / a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * ln_prefix.exp()).max(0.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        ln_prefix.exp() * h
    }
}

/// P(X ≥ x) for X chi-square distributed with `dof` degrees of freedom.
pub fn chi2_survival(x: f64, dof: f64) -> f64 {
    gamma_q(0.5 * dof, 0.5 * x)
}

/// P(|Z| ≥ z) for a standard normal Z (Z² is chi-square with one degree of freedom).
pub fn normal_two_sided_p(z: f64) -> f64 {
    chi2_survival(z * z, 1.0)
}

/// The z such that P(|Z| ≥ z) = alpha, by bisection.
pub fn normal_critical(alpha: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if normal_two_sided_p(mid) > alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Per-comparison significance keeping the family-wise rate at `alpha` over `m`
/// independent comparisons (Šidák).
pub fn sidak(alpha: f64, m: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / m.max(1) as f64)
}

/// Critical |z| for `m` comparisons sharing the family-wise false-alarm rate `alpha`.
pub fn z_critical(alpha: f64, m: usize) -> f64 {
    normal_critical(sidak(alpha, m))
}

/// A Monte Carlo estimate and its standard error.
#[derive(Clone, Copy, Debug)]
pub struct Estimate {
    pub mean: f64,
    pub se: f64,
}

impl Estimate {
    /// z-score of the difference between two independent estimates (0 for two identical
    /// noiseless ones, such as two black regions).
    pub fn z_against(&self, other: &Estimate) -> f64 {
        let se = (self.se * self.se + other.se * other.se).sqrt();
        let diff = self.mean - other.mean;
        if diff == 0.0 {
            0.0
        } else {
            diff / se
        }
    }
}

/// Mean of channel `c` over the pixels in `[x0, x1) × [y0, y1)` and its standard error, from
/// the per-pixel variance of the mean that the renderer returns (pixels are independent).
pub fn region_estimate(out: &RenderOutput, c: usize, x0: usize, y0: usize, x1: usize, y1: usize) -> Estimate {
    let var = out.variance.as_ref().expect("render with `variance: true`");
    let w = out.image.width;
    let (mut sum, mut var_sum) = (0.0f64, 0.0f64);
    for y in y0..y1 {
        for x in x0..x1 {
            sum += out.image.pixels[y * w + x].channel(c) as f64;
            var_sum += var.pixels[y * w + x].channel(c) as f64;
        }
    }
    let n = ((x1 - x0) * (y1 - y0)) as f64;
    Estimate { mean: sum / n, se: var_sum.sqrt() / n }
}

/// Mean of channel `c` over the whole image.
pub fn image_estimate(out: &RenderOutput, c: usize) -> Estimate {
    region_estimate(out, c, 0, 0, out.image.width, out.image.height)
}

/// Means of channel `c` over square blocks of `block` pixels on a side (the image size must
/// be a multiple of it), row by row.
pub fn block_estimates(out: &RenderOutput, c: usize, block: usize) -> Vec<Estimate> {
    let (w, h) = (out.image.width, out.image.height);
    assert!(w % block == 0 && h % block == 0, "{w}x{h} is not a multiple of {block}");
    let mut v = Vec::new();
    for by in (0..h).step_by(block) {
        for bx in (0..w).step_by(block) {
            v.push(region_estimate(out, c, bx, by, bx + block, by + block));
        }
    }
    v
}

/// Checks a render whose every pixel has the same expected value `exact` (channel 0): the
/// whole-image mean and each `block`×`block` block mean must lie within `k` standard errors.
/// Returns a description of each failure.
pub fn check_constant_image(label: &str, out: &RenderOutput, exact: f64, block: usize, k: f64) -> Vec<String> {
    let mut failures = Vec::new();
    let whole = image_estimate(out, 0);
    println!(
        "{label}: mean {:.5} ± {:.5} (exact {exact:.5}, z = {:.2})",
        whole.mean,
        whole.se,
        (whole.mean - exact) / whole.se
    );
    let mut check = |what: String, e: Estimate| {
        // Written so that a NaN fails too.
        let within = (e.mean - exact).abs() <= k * e.se;
        if !within {
            failures.push(format!(
                "{label}: {what} mean {:.5} ± {:.5}, exact {exact:.5} ({:.1} standard errors, limit {k:.2})",
                e.mean,
                e.se,
                (e.mean - exact) / e.se
            ));
        }
    };
    check("image".into(), whole);
    for (i, e) in block_estimates(out, 0, block).into_iter().enumerate() {
        check(format!("block {i}"), e);
    }
    failures
}

/// Number of comparisons `check_constant_image` makes.
pub fn constant_image_comparisons(out_width: usize, out_height: usize, block: usize) -> usize {
    1 + (out_width / block) * (out_height / block)
}
