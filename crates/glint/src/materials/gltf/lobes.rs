//! The pieces of the glTF BRDF that glint's other BSDFs do not have: Schlick's weight, the
//! Smith visibility terms in the forms the glTF texts give them, and the "Charlie" sheen of
//! `KHR_materials_sheen` (Conty and Kulla 2017) with its directional albedo, tabulated here
//! by quadrature of the same formulas.

use crate::math::PI;
use std::sync::OnceLock;

/// Schlick's (1 - c)^5.
pub(super) fn schlick_weight(c: f32) -> f32 {
    let m = (1.0 - c).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Appendix B's visibility ν = G / (4 |cos o| |cos i|) with the height-correlated Smith G.
pub(super) fn vis_height_correlated(alpha: f32, co: f32, ci: f32) -> f32 {
    let a2 = alpha * alpha;
    let (co, ci) = (co.abs(), ci.abs());
    let s = co * (a2 + (1.0 - a2) * ci * ci).sqrt() + ci * (a2 + (1.0 - a2) * co * co).sqrt();
    if s > 0.0 {
        0.5 / s
    } else {
        0.0
    }
}

/// `KHR_materials_transmission`'s visibility ν_T with the separable Smith G.
pub(super) fn vis_separable(alpha: f32, co: f32, ci: f32) -> f32 {
    let a2 = alpha * alpha;
    let one = |c: f32| c.abs() + (a2 + (1.0 - a2) * c * c).sqrt();
    1.0 / (one(co) * one(ci))
}

/// The sheen roughness below which the Charlie distribution is clamped: at 0.07 its
/// exponent 1/r² is 204, already a narrow grazing band; below, `powf` of a sine runs out of
/// float range and the visibility fit (made for r in [0, 1]) has nothing to hold.
pub const SHEEN_MIN_ROUGHNESS: f32 = 0.07;

/// Charlie's α_g = r² for sheen roughness `r`, clamped as above.
pub(super) fn sheen_alpha(roughness: f32) -> f32 {
    let r = roughness.clamp(SHEEN_MIN_ROUGHNESS, 1.0);
    r * r
}

/// The Charlie distribution D_S(h) from cos θ_h (normalised: ∫ D cos θ_h dω = 1).
pub(super) fn charlie_d(alpha_g: f32, cos_h: f32) -> f32 {
    let inv = 1.0 / alpha_g;
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI)
}

/// The extension's fitted exponent l(x) of the sheen's Λ.
fn sheen_l(x: f32, alpha_g: f32) -> f32 {
    let t = (1.0 - alpha_g) * (1.0 - alpha_g);
    let mix = |a: f32, b: f32| a * (1.0 - t) + b * t;
    let (a, b, c) = (mix(21.5473, 25.3245), mix(3.82987, 3.32435), mix(0.19823, 0.16801));
    let (d, e) = (mix(-1.97760, -1.27393), mix(-4.32054, -4.85967));
    a / (1.0 + b * x.powf(c)) + d * x + e
}

fn sheen_lambda(cos: f32, alpha_g: f32) -> f32 {
    let c = cos.abs();
    if c < 0.5 {
        sheen_l(c, alpha_g).exp()
    } else {
        (2.0 * sheen_l(0.5, alpha_g) - sheen_l(1.0 - c, alpha_g)).exp()
    }
}

/// The Charlie visibility ν_S = 1 / ((1 + Λ(o) + Λ(i)) 4 |cos o| |cos i|).
pub(super) fn charlie_vis(alpha_g: f32, co: f32, ci: f32) -> f32 {
    let denom = (1.0 + sheen_lambda(co, alpha_g) + sheen_lambda(ci, alpha_g)) * 4.0 * co.abs() * ci.abs();
    if denom > 0.0 && denom.is_finite() {
        1.0 / denom
    } else {
        0.0
    }
}

/// Directional albedo E(μ) = ∫ D_S ν_S cos θi dωi of the sheen lobe seen from cos θo = `mu`,
/// by the midpoint rule over half vectors (θ_h, φ_h): dωi = 4 |o·h| dω_h, so the integrand
/// is D_S(h) (o·h) / (μ (1 + Λ(o) + Λ(i))), zero where the reflected direction is below
/// the surface (there Λ(i) is already huge, so the integrand is continuous).
pub fn sheen_albedo_quadrature(mu: f32, roughness: f32, n_theta: usize, n_phi: usize) -> f64 {
    let alpha_g = sheen_alpha(roughness);
    let mu = mu.clamp(1e-3, 1.0);
    let (so, co) = ((1.0 - mu * mu).max(0.0).sqrt(), mu);
    let lambda_o = sheen_lambda(co, alpha_g) as f64;
    let (dt, dp) = (0.5 * std::f64::consts::PI / n_theta as f64, std::f64::consts::PI / n_phi as f64);
    let mut sum = 0.0f64;
    for i in 0..n_theta {
        let th = (i as f64 + 0.5) * dt;
        let (st, ct) = th.sin_cos();
        let d = charlie_d(alpha_g, ct as f32) as f64;
        for j in 0..n_phi {
            // φ over [0, π], doubled: the integrand is symmetric about wo's plane.
            let ph = (j as f64 + 0.5) * dp;
            let oh = so as f64 * st * ph.cos() + co as f64 * ct;
            if oh <= 0.0 {
                continue;
            }
            let ci = 2.0 * oh * ct - co as f64;
            if ci <= 0.0 {
                continue;
            }
            let lambda_i = sheen_lambda(ci as f32, alpha_g) as f64;
            sum += d * oh / (co as f64 * (1.0 + lambda_o + lambda_i)) * st * 2.0;
        }
    }
    sum * dt * dp
}

/// Nodes of the albedo table: √cos θ in [0, 1] (E changes fastest at grazing angles) and
/// roughness in [SHEEN_MIN_ROUGHNESS, 1].
const TABLE_MU: usize = 32;
const TABLE_R: usize = 32;

fn albedo_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = Vec::with_capacity(TABLE_MU * TABLE_R);
        for ri in 0..TABLE_R {
            let r = SHEEN_MIN_ROUGHNESS + (1.0 - SHEEN_MIN_ROUGHNESS) * ri as f32 / (TABLE_R - 1) as f32;
            for mi in 0..TABLE_MU {
                let mu = (mi as f32 / (TABLE_MU - 1) as f32).powi(2);
                t.push(sheen_albedo_quadrature(mu, r, 128, 32) as f32);
            }
        }
        t
    })
}

/// The sheen lobe's directional albedo E(μ, roughness), bilinear in the table above (the
/// `albedo_table_is_accurate` test bounds its error).
pub fn sheen_albedo(mu: f32, roughness: f32) -> f32 {
    let t = albedo_table();
    let x = mu.clamp(0.0, 1.0).sqrt() * (TABLE_MU - 1) as f32;
    let r = roughness.clamp(SHEEN_MIN_ROUGHNESS, 1.0);
    let y = (r - SHEEN_MIN_ROUGHNESS) / (1.0 - SHEEN_MIN_ROUGHNESS) * (TABLE_R - 1) as f32;
    let (x0, y0) = ((x as usize).min(TABLE_MU - 2), (y as usize).min(TABLE_R - 2));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |i: usize, j: usize| t[j * TABLE_MU + i];
    let lo = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
    let hi = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
    lo * (1.0 - fy) + hi * fy
}

/// The largest error of [`sheen_albedo`] against a fine quadrature for cos θ >= 0.1,
/// measured by the test below at cell centres (where bilinear interpolation is worst:
/// 7.4e-3, at the smallest roughness) and rounded up. Closer to grazing E changes steeply
/// (and exceeds 1 for roughness under about 0.3: the extension's fitted Λ is not an exact
/// Smith term), and the table is coarser than that.
pub const SHEEN_ALBEDO_TOLERANCE: f32 = 8e-3;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn charlie_distribution_is_normalised() {
        for r in [0.1f32, 0.5, 1.0] {
            let a = sheen_alpha(r);
            let n = 20_000;
            let s: f64 = (0..n)
                .map(|i| {
                    let th = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                    charlie_d(a, th.cos() as f32) as f64 * th.cos() * th.sin()
                })
                .sum::<f64>()
                * std::f64::consts::FRAC_PI_2
                / n as f64
                * 2.0
                * std::f64::consts::PI;
            assert!((s - 1.0).abs() < 1e-3, "r {r}: ∫ D cos = {s}");
        }
    }

    #[test]
    fn albedo_table_is_accurate() {
        let mut worst = 0.0f32;
        for ri in 0..TABLE_R - 1 {
            let r = SHEEN_MIN_ROUGHNESS + (1.0 - SHEEN_MIN_ROUGHNESS) * (ri as f32 + 0.5) / (TABLE_R - 1) as f32;
            for mi in 0..TABLE_MU - 1 {
                let mu = ((mi as f32 + 0.5) / (TABLE_MU - 1) as f32).powi(2);
                let fine = sheen_albedo_quadrature(mu, r, 512, 128) as f32;
                let err = (sheen_albedo(mu, r) - fine).abs();
                if mu >= 0.1 {
                    if err > worst {
                        println!("E({mu}, {r}) = {fine}, table {}", sheen_albedo(mu, r));
                    }
                    worst = worst.max(err);
                }
            }
        }
        println!("worst sheen albedo table error {worst:.2e}");
        assert!(worst <= SHEEN_ALBEDO_TOLERANCE, "table error {worst} > {SHEEN_ALBEDO_TOLERANCE}");
    }
}
