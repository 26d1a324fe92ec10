//! `hair`: Mitsuba's hair BSDF (Chiang et al. 2016), untextured: [`HairBsdf`] is its built
//! form, in a curve's frame.
//!
//! # The BSDF
//! Mitsuba's `hair`: the near-field hair model of Chiang et al. 2016 ("A Practical and
//! Controllable Hair and Fur Model for Production Path Tracing"), as Mitsuba 3 defines it.
//!
//! The local frame is a curve's: x around the fibre (the shading frame's `s`, dp/du), y along
//! it (`t`), z the normal. θ is a direction's angle to the fibre's normal plane (sin θ = y), φ
//! its azimuth in that plane (atan2(z, x)), and the offset across the fibre is
//! h = sin γ, γ the angle between the normal and the viewing direction in the normal plane.
//! Light leaves after p = 0 (reflection), 1 (transmission), 2 (one internal bounce) or more
//! (the rest, summed) internal paths: each term is a longitudinal lobe M_p (d'Eon et al.
//! 2011, with Mitsuba's scale tilt), an attenuation A_p (Fresnel and absorption along the
//! path through the fibre) and an azimuthal lobe N_p (a trimmed logistic around the
//! specular Δφ). At zero absorption the A_p sum to 1 and each M_p N_p to 1: energy is kept.
//!
//! # Differentiable
//! Every number and colour `traverse` lists for it. See `docs/differentiable.md`.

use super::{Bsdf, Describe, MaterialKind, Shade, TextureCache, TexturePoint};
use crate::bsdf::{fresnel_dielectric, BsdfSample, Scatter};
use crate::describe::slots::Slot;
use crate::describe::{checks, TextureDesc};
use crate::error::Error;
use crate::math::{Rgb, Vec3, PI};
use serde::{Deserialize, Serialize};

/// Terms modelled separately; the rest are summed into one.
const P_MAX: usize = 3;

/// Absorption of the pigments per unit concentration (d'Eon et al. 2011, relative to the
/// fibre's radius), as Mitsuba's RGB variants use them.
pub const EUMELANIN_SIGMA_A: Rgb = Rgb { r: 0.419, g: 0.697, b: 1.37 };
pub const PHEOMELANIN_SIGMA_A: Rgb = Rgb { r: 0.187, g: 0.4, b: 1.05 };

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HairBsdf {
    /// Absorption inside the fibre (per radius).
    sigma_a: Rgb,
    /// Relative index of refraction (interior / exterior).
    eta: f32,
    /// Longitudinal variance of each term.
    v: [f32; P_MAX + 1],
    /// Azimuthal logistic scale.
    s: f32,
    /// sin and cos of 2^k times the scale tilt, k = 0, 1, 2.
    sin_2k_alpha: [f32; 3],
    cos_2k_alpha: [f32; 3],
}

/// The angles of a direction in the fibre's frame.
struct Angles {
    sin_theta: f32,
    cos_theta: f32,
    phi: f32,
}

fn angles(w: Vec3) -> Angles {
    let sin_theta = w.y.clamp(-1.0, 1.0);
    Angles { sin_theta, cos_theta: (1.0 - sin_theta * sin_theta).max(0.0).sqrt(), phi: w.z.atan2(w.x) }
}

fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

fn safe_asin(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).asin()
}

/// γ, the angle between the normal and `w` projected into the normal plane (Mitsuba's sign).
fn gamma(w: Vec3) -> f32 {
    let proj = (w.x * w.x + w.z * w.z).sqrt();
    if !(proj > 0.0) {
        return 0.0;
    }
    let g = (w.z / proj).clamp(-1.0, 1.0).acos();
    if w.x < 0.0 {
        g
    } else {
        -g
    }
}

/// The modified Bessel function I0 for x <= 12, its power series summed until the terms
/// no longer change it (Mitsuba sums a fixed 11 terms, 2% short at 12: the lobes would then
/// lose energy).
fn i0(x: f32) -> f32 {
    let q = (x as f64) * (x as f64) / 4.0;
    let (mut sum, mut term) = (1.0f64, 1.0f64);
    for k in 1..64 {
        term *= q / (k * k) as f64;
        sum += term;
        if term < sum * 1e-12 {
            break;
        }
    }
    sum as f32
}

/// ln I0(x): the series below 12, the asymptotic expansion (to its third term) above.
fn log_i0(x: f32) -> f32 {
    if x > 12.0 {
        let x = x as f64;
        let series = 1.0 + 1.0 / (8.0 * x) + 9.0 / (128.0 * x * x) + 225.0 / (3072.0 * x * x * x);
        (x - 0.5 * (2.0 * std::f64::consts::PI * x).ln() + series.ln()) as f32
    } else {
        i0(x).ln()
    }
}

/// d'Eon's longitudinal lobe for variance `v` (density over cos θo dθo, times 1/(2π)).
fn longitudinal(sin_i: f32, cos_i: f32, sin_o: f32, cos_o: f32, v: f32) -> f32 {
    let kappa = 1.0 / v;
    let c = cos_i * cos_o * kappa;
    let s = sin_i * sin_o * kappa;
    let m = if kappa > 10.0 {
        (-s + log_i0(c) - kappa + std::f32::consts::LN_2 + (0.5 * kappa).ln()).exp()
    } else {
        (-s).exp() * i0(c) * kappa / (2.0 * kappa.sinh())
    };
    m / (2.0 * PI)
}

fn logistic(x: f32, s: f32) -> f32 {
    let x = x.abs();
    let e = (-x / s).exp();
    e / (s * (1.0 + e) * (1.0 + e))
}

fn logistic_cdf(x: f32, s: f32) -> f32 {
    1.0 / (1.0 + (-x / s).exp())
}

fn trimmed_logistic(x: f32, s: f32) -> f32 {
    logistic(x, s) / (logistic_cdf(PI, s) - logistic_cdf(-PI, s))
}

fn trimmed_logistic_sample(u: f32, s: f32) -> f32 {
    let k = logistic_cdf(PI, s) - logistic_cdf(-PI, s);
    let x = -s * (1.0 / (u * k + logistic_cdf(-PI, s)) - 1.0).ln();
    x.clamp(-PI, PI)
}

/// The azimuthal lobe of term `p` at Δφ.
fn azimuthal(delta_phi: f32, p: usize, s: f32, gamma_i: f32, gamma_t: f32) -> f32 {
    let perfect = 2.0 * p as f32 * gamma_t - 2.0 * gamma_i + p as f32 * PI;
    let mut phi = (delta_phi - perfect) % (2.0 * PI);
    if phi < -PI {
        phi += 2.0 * PI;
    }
    if phi > PI {
        phi -= 2.0 * PI;
    }
    trimmed_logistic(phi, s)
}

/// What every query needs about the viewing direction.
struct Incident {
    a: Angles,
    gamma_i: f32,
    gamma_t: f32,
    /// A_p, and the probabilities of choosing each term (by luminance).
    attenuation: [Rgb; P_MAX + 1],
    term_pdf: [f32; P_MAX + 1],
}

impl HairBsdf {
    /// The model of Mitsuba's parameters: absorption (per radius), relative index of
    /// refraction, the two roughnesses in [0, 1] and the scale tilt in degrees.
    pub fn new(sigma_a: Rgb, eta: f32, longitudinal_roughness: f32, azimuthal_roughness: f32, tilt: f32) -> HairBsdf {
        let mut sin_2k_alpha = [tilt.to_radians().sin(), 0.0, 0.0];
        let mut cos_2k_alpha = [safe_sqrt(1.0 - sin_2k_alpha[0] * sin_2k_alpha[0]), 0.0, 0.0];
        for i in 1..3 {
            sin_2k_alpha[i] = 2.0 * cos_2k_alpha[i - 1] * sin_2k_alpha[i - 1];
            cos_2k_alpha[i] = cos_2k_alpha[i - 1] * cos_2k_alpha[i - 1] - sin_2k_alpha[i - 1] * sin_2k_alpha[i - 1];
        }
        let (bl, ba) = (longitudinal_roughness, azimuthal_roughness);
        let s = (PI / 8.0).sqrt() * (0.265 * ba + 1.194 * ba * ba + 5.372 * ba.powi(22));
        let v0 = (0.726 * bl + 0.812 * bl * bl + 3.7 * bl.powi(20)).powi(2);
        HairBsdf { sigma_a, eta, v: [v0, 0.25 * v0, 4.0 * v0, 4.0 * v0], s, sin_2k_alpha, cos_2k_alpha }
    }

    /// The absorption of pigment concentrations (Mitsuba's `eumelanin`, `pheomelanin`).
    pub fn pigment_absorption(eumelanin: f32, pheomelanin: f32) -> Rgb {
        EUMELANIN_SIGMA_A * eumelanin + PHEOMELANIN_SIGMA_A * pheomelanin
    }

    /// (sin, cos) of the viewing direction's θ tilted by the scales for term `p`.
    fn reframe(&self, sin_i: f32, cos_i: f32, p: usize) -> (f32, f32) {
        let (s, c) = match p {
            0 => (
                sin_i * self.cos_2k_alpha[1] - cos_i * self.sin_2k_alpha[1],
                cos_i * self.cos_2k_alpha[1] + sin_i * self.sin_2k_alpha[1],
            ),
            1 => (
                sin_i * self.cos_2k_alpha[0] + cos_i * self.sin_2k_alpha[0],
                cos_i * self.cos_2k_alpha[0] - sin_i * self.sin_2k_alpha[0],
            ),
            2 => (
                sin_i * self.cos_2k_alpha[2] + cos_i * self.sin_2k_alpha[2],
                cos_i * self.cos_2k_alpha[2] - sin_i * self.sin_2k_alpha[2],
            ),
            _ => (sin_i, cos_i),
        };
        (s, c.abs())
    }

    fn incident(&self, wo: Vec3) -> Incident {
        let a = angles(wo);
        let gamma_i = gamma(wo);
        let h = gamma_i.sin();
        let sin_theta_t = a.sin_theta / self.eta;
        let cos_theta_t = safe_sqrt(1.0 - sin_theta_t * sin_theta_t);
        let eta_p = safe_sqrt(self.eta * self.eta - a.sin_theta * a.sin_theta) / a.cos_theta;
        let sin_gamma_t = h / eta_p;
        let cos_gamma_t = safe_sqrt(1.0 - sin_gamma_t * sin_gamma_t);
        let gamma_t = safe_asin(sin_gamma_t);
        let length = 2.0 * cos_gamma_t / cos_theta_t;
        let tr = Rgb {
            r: (-self.sigma_a.r * length).exp(),
            g: (-self.sigma_a.g * length).exp(),
            b: (-self.sigma_a.b * length).exp(),
        };
        let cos_gamma_i = safe_sqrt(1.0 - h * h);
        let f = fresnel_dielectric(a.cos_theta * cos_gamma_i, self.eta).reflectance;
        let mut ap = [Rgb::BLACK; P_MAX + 1];
        ap[0] = Rgb::splat(f);
        ap[1] = tr * ((1.0 - f) * (1.0 - f));
        for p in 2..P_MAX {
            ap[p] = ap[p - 1] * tr * f;
        }
        let rest = Rgb { r: 1.0 - tr.r * f, g: 1.0 - tr.g * f, b: 1.0 - tr.b * f };
        ap[P_MAX] = ap[P_MAX - 1] * tr * f / rest;
        let lum = ap.map(|c| 0.212671 * c.r + 0.715160 * c.g + 0.072169 * c.b);
        let total: f32 = lum.iter().sum();
        let term_pdf = lum.map(|l| l / total);
        Incident { a, gamma_i, gamma_t, attenuation: ap, term_pdf }
    }

    /// The four lobes' products M_p N_p at `wi` (each a density per solid angle).
    fn lobes(&self, inc: &Incident, wi: Vec3) -> [f32; P_MAX + 1] {
        let o = angles(wi);
        let delta_phi = o.phi - inc.a.phi;
        let mut out = [0.0; P_MAX + 1];
        for (p, slot) in out.iter_mut().enumerate().take(P_MAX) {
            let (sin_ip, cos_ip) = self.reframe(inc.a.sin_theta, inc.a.cos_theta, p);
            *slot = longitudinal(sin_ip, cos_ip, o.sin_theta, o.cos_theta, self.v[p])
                * 2.0
                * PI
                * azimuthal(delta_phi, p, self.s, inc.gamma_i, inc.gamma_t);
        }
        out[P_MAX] = longitudinal(inc.a.sin_theta, inc.a.cos_theta, o.sin_theta, o.cos_theta, self.v[P_MAX]);
        out
    }
}

impl Scatter for HairBsdf {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    /// A fibre has no diffuse part for the Whitted integrator's mix.
    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }

    /// BSDF times |cos|, for light arriving from `wi` and leaving towards `wo`.
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let inc = self.incident(wo);
        let lobes = self.lobes(&inc, wi);
        let mut value = Rgb::BLACK;
        for (a, l) in inc.attenuation.iter().zip(lobes) {
            value += *a * l;
        }
        if value.r.is_finite() && value.g.is_finite() && value.b.is_finite() {
            value
        } else {
            Rgb::BLACK
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let inc = self.incident(wo);
        let pdf: f32 = self.lobes(&inc, wi).iter().zip(inc.term_pdf).map(|(l, p)| l * p).sum();
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    /// Chooses a term by `u_lobe` (its remainder drives the azimuth) and samples its lobes.
    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let inc = self.incident(wo);
        let mut p = 0;
        let mut rest = u_lobe;
        while p < P_MAX && rest >= inc.term_pdf[p] {
            rest -= inc.term_pdf[p];
            p += 1;
        }
        let u_phi = if inc.term_pdf[p] > 0.0 { (rest / inc.term_pdf[p]).clamp(0.0, 1.0) } else { 0.5 };
        let (sin_ip, cos_ip) = self.reframe(inc.a.sin_theta, inc.a.cos_theta, p);
        let v = self.v[p];
        let cos_theta = (1.0 + v * (u[0] + (1.0 - u[0]) * (-2.0 / v).exp()).ln()).clamp(-1.0, 1.0);
        let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
        let cos_phi = (2.0 * PI * u[1]).cos();
        let sin_theta_o = -cos_theta * sin_ip + sin_theta * cos_phi * cos_ip;
        let cos_theta_o = safe_sqrt(1.0 - sin_theta_o * sin_theta_o);
        let delta_phi = if p < P_MAX {
            2.0 * p as f32 * inc.gamma_t - 2.0 * inc.gamma_i + p as f32 * PI + trimmed_logistic_sample(u_phi, self.s)
        } else {
            2.0 * PI * u_phi
        };
        let phi_o = inc.a.phi + delta_phi;
        let wi = Vec3 { x: cos_theta_o * phi_o.cos(), y: sin_theta_o, z: cos_theta_o * phi_o.sin() }.normalize();
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) || !wi.is_finite() {
            return None;
        }
        Some(BsdfSample { wi, weight: self.eval(wo, wi) / pdf, pdf, delta: false, eta: 1.0 })
    }
}

/// `hair`'s parameters (Mitsuba's, with the pigments or `sigma_a` times `scale` folded into
/// `sigma_a` by the reader).
///
/// | Parameter | Type | Default (Mitsuba) | |
/// |---|---|---|---|
/// | `sigma_a` | colour | from eumelanin 1.3, pheomelanin 0 | absorption per fibre radius |
/// | `eta` | float | 1.55 | interior over exterior index |
/// | `longitudinal_roughness` | float | 0.3 | in [0, 1] |
/// | `azimuthal_roughness` | float | 0.3 | in [0, 1] |
/// | `scale_tilt` | float | 2 | degrees |
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HairDesc {
    pub sigma_a: Rgb,
    pub eta: f32,
    pub longitudinal_roughness: f32,
    pub azimuthal_roughness: f32,
    pub scale_tilt: f32,
}

impl Describe for HairDesc {
    type Built = HairBsdf;

    fn build(&self, _textures: &mut TextureCache) -> Result<HairBsdf, Error> {
        Ok(HairBsdf::new(
            self.sigma_a,
            self.eta,
            self.longitudinal_roughness,
            self.azimuthal_roughness,
            self.scale_tilt,
        ))
    }

    fn validate(&self) -> Result<(), String> {
        checks::eta(self.eta)?;
        let s = self.sigma_a;
        if !(s.r >= 0.0 && s.g >= 0.0 && s.b >= 0.0 && s.max_component().is_finite()) {
            return Err(format!("hair absorption {s:?} must be finite and not negative"));
        }
        for (name, v) in
            [("longitudinal_roughness", self.longitudinal_roughness), ("azimuthal_roughness", self.azimuthal_roughness)]
        {
            if !(0.0..=1.0).contains(&v) {
                return Err(format!("hair {name} {v} must be in [0, 1]"));
            }
        }
        if !self.scale_tilt.is_finite() {
            return Err(format!("hair scale_tilt {} must be finite", self.scale_tilt));
        }
        Ok(())
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        Vec::new()
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        Vec::new()
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        Vec::new()
    }
}

impl Shade for HairBsdf {
    #[inline]
    fn bsdf_at(&self, _p: &TexturePoint) -> Bsdf {
        Bsdf::Hair(*self)
    }

    fn albedo(&self, _uv: [f32; 2]) -> Rgb {
        Rgb::BLACK
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
