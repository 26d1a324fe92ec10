//! Microfacet distributions (GGX and Beckmann, anisotropic) and the rough dielectric BSDF
//! (Walter et al. 2007). Shadowing is Smith's separable form G1(wo)·G1(wi), as Mitsuba 3
//! uses, so that glint and Mitsuba agree on the same scene. Normals of both distributions
//! are sampled from the distribution of visible normals (Heitz and d'Eon 2014, Heitz 2018),
//! as Mitsuba's default `sample_visible`. The roughness `alpha_u` runs along the local x
//! axis, which the shading frame aligns with the surface's dp/du as Mitsuba does.

use super::{fresnel_dielectric, BsdfSample};
pub use crate::describe::MicrofacetKind;
use crate::math::{Rgb, Vec3, PI};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub kind: MicrofacetKind,
    /// Roughness along the local x axis (the surface's dp/du, as in Mitsuba).
    pub alpha_u: f32,
    /// Roughness along the local y axis.
    pub alpha_v: f32,
}

impl Microfacet {
    /// An isotropic distribution.
    pub fn new(kind: MicrofacetKind, alpha: f32) -> Microfacet {
        Microfacet::anisotropic(kind, alpha, alpha)
    }

    /// Roughness `alpha_u` along local x and `alpha_v` along local y.
    pub fn anisotropic(kind: MicrofacetKind, alpha_u: f32, alpha_v: f32) -> Microfacet {
        // Very small roughness makes D a near-delta that floats cannot represent; Mitsuba
        // clamps at the same bound. NaN becomes the bound too (`max` ignores it).
        Microfacet { kind, alpha_u: alpha_u.max(1e-4), alpha_v: alpha_v.max(1e-4) }
    }

    pub fn is_anisotropic(&self) -> bool {
        self.alpha_u != self.alpha_v
    }

    /// α² tan²θ of direction `v` with the roughness projected onto its azimuth.
    fn projected_alpha2_tan2(&self, v: Vec3) -> f32 {
        let cos2 = v.z * v.z;
        let num = self.alpha_u * self.alpha_u * v.x * v.x + self.alpha_v * self.alpha_v * v.y * v.y;
        (num / cos2).max(0.0)
    }

    /// Normal distribution D(h), h in the upper hemisphere.
    pub fn d(&self, h: Vec3) -> f32 {
        let cos2 = h.z * h.z;
        if cos2 <= 0.0 || h.z <= 0.0 {
            return 0.0;
        }
        let (au, av) = (self.alpha_u, self.alpha_v);
        let (x, y) = (h.x / au, h.y / av);
        let r = match self.kind {
            MicrofacetKind::Ggx => {
                let t = x * x + y * y + cos2;
                1.0 / (PI * au * av * t * t)
            }
            MicrofacetKind::Beckmann => (-(x * x + y * y) / cos2).exp() / (PI * au * av * cos2 * cos2),
        };
        if r.is_finite() {
            r
        } else {
            0.0
        }
    }

    /// Smith's masking for direction `v` and microfacet normal `h`.
    pub fn g1(&self, v: Vec3, h: Vec3) -> f32 {
        if v.dot(h) * v.z <= 0.0 {
            return 0.0;
        }
        let a2t2 = self.projected_alpha2_tan2(v);
        if a2t2 == 0.0 {
            return 1.0;
        }
        match self.kind {
            MicrofacetKind::Ggx => 2.0 / (1.0 + (1.0 + a2t2).sqrt()),
            MicrofacetKind::Beckmann => {
                let a = 1.0 / a2t2.sqrt();
                if a >= 1.6 {
                    1.0
                } else {
                    (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
                }
            }
        }
    }

    pub fn g(&self, wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
        self.g1(wo, h) * self.g1(wi, h)
    }

    /// Samples a microfacet normal (upper hemisphere) from the distribution of normals
    /// visible from `wo` (either side), as Mitsuba's default `sample_visible`: the view is
    /// stretched to unit roughness, a visible normal drawn there, and the result unstretched.
    pub fn sample_wm(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        let w = if wo.z < 0.0 { -wo } else { wo };
        let (au, av) = (self.alpha_u, self.alpha_v);
        let vh = Vec3 { x: au * w.x, y: av * w.y, z: w.z }.normalize();
        let m = match self.kind {
            MicrofacetKind::Ggx => ggx_visible_normal_unit(vh, u),
            MicrofacetKind::Beckmann => beckmann_visible_normal_unit(vh, u),
        };
        Vec3 { x: au * m.x, y: av * m.y, z: m.z.max(1e-6) }.normalize()
    }

    /// Density of `sample_wm` producing `h` (solid angle of normals): G1(wo) ⟨wo, h⟩ D(h) / cos θo.
    pub fn pdf_wm(&self, wo: Vec3, h: Vec3) -> f32 {
        if wo.z == 0.0 {
            return 0.0;
        }
        let w = if wo.z < 0.0 { -wo } else { wo };
        if w.dot(h) <= 0.0 {
            return 0.0;
        }
        self.visible_fraction(w) * w.dot(h) * self.d(h) / w.z
    }

    /// The exact Smith masking 1 / (1 + Λ(v)) that normalises the visible normals seen from
    /// `v` (upper hemisphere). For GGX it is `g1`; for Beckmann `g1` is the rational fit
    /// Mitsuba shades with (within 0.35%), and the density of the sampled normals needs the
    /// exact Λ(a) = (erf(a) - 1) / 2 + exp(-a²) / (2a√π), a = 1 / (α tan θ).
    pub(crate) fn visible_fraction(&self, v: Vec3) -> f32 {
        let a2t2 = self.projected_alpha2_tan2(v);
        if a2t2 == 0.0 {
            return 1.0;
        }
        match self.kind {
            MicrofacetKind::Ggx => 2.0 / (1.0 + (1.0 + a2t2).sqrt()),
            MicrofacetKind::Beckmann => {
                let a = 1.0 / (a2t2 as f64).sqrt();
                let lambda = 0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt());
                (1.0 / (1.0 + lambda)) as f32
            }
        }
    }
}

/// A visible normal of the unit-roughness GGX distribution seen from `v` (upper hemisphere):
/// uniform on the projected hemisphere, warped towards the view (Heitz 2018).
fn ggx_visible_normal_unit(v: Vec3, u: [f32; 2]) -> Vec3 {
    let lensq = v.x * v.x + v.y * v.y;
    let t1 = if lensq > 0.0 { Vec3 { x: -v.y, y: v.x, z: 0.0 } / lensq.sqrt() } else { Vec3::X };
    let t2 = v.cross(t1);
    let r = u[0].sqrt();
    let phi = 2.0 * PI * u[1];
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + v.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    t1 * p1 + t2 * p2 + v * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt()
}

/// A visible normal of the unit-roughness Beckmann distribution seen from `v`. In slope
/// space, with `v` turned to azimuth 0 at polar angle θ, visible slopes (x, y) have density
/// ∝ exp(-x² - y²) (cot θ - x) for x < cot θ: y is normal with variance 1/2 and x follows
/// the CDF C(x) ∝ cot θ √π (1 + erf x) + exp(-x²), inverted here by safeguarded Newton.
fn beckmann_visible_normal_unit(v: Vec3, u: [f32; 2]) -> Vec3 {
    let sin_t = (v.x * v.x + v.y * v.y).sqrt();
    let (x, y) = beckmann_visible_slopes(v.z as f64, sin_t as f64, u);
    // Turn the slopes back to the view's azimuth.
    let (cos_p, sin_p) = if sin_t > 0.0 { (v.x / sin_t, v.y / sin_t) } else { (1.0, 0.0) };
    let (sx, sy) = (cos_p * x - sin_p * y, sin_p * x + cos_p * y);
    Vec3 { x: -sx, y: -sy, z: 1.0 }.normalize()
}

fn beckmann_visible_slopes(cos_t: f64, sin_t: f64, u: [f32; 2]) -> (f32, f32) {
    let sqrt_pi = std::f64::consts::PI.sqrt();
    // Keep samples off 0 and 1, where the inverse CDFs run to infinity.
    let clamp = |x: f32| (x as f64).clamp(1e-6, 1.0 - 1e-6);
    let (u0, u1) = (clamp(u[0]), clamp(u[1]));
    let y = inverse_erf(2.0 * u1 - 1.0);
    // Beyond |x| = 6 the Gaussian holds under 1e-15 of the mass.
    let cot = if sin_t > 0.0 { (cos_t / sin_t).min(1e6) } else { 1e6 };
    let unnormalised = |x: f64| cot * sqrt_pi * libm::erfc(-x) + (-x * x).exp();
    let (mut lo, mut hi) = (-6.0f64, cot.min(6.0));
    let target = u0 * unnormalised(hi);
    let mut x = 0.5 * (lo + hi).clamp(-1.0, 1.0);
    for _ in 0..40 {
        let f = unnormalised(x) - target;
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let slope = 2.0 * (cot - x) * (-x * x).exp();
        let mut next = x - f / slope;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() < 1e-9 {
            x = next;
            break;
        }
        x = next;
    }
    (x as f32, y as f32)
}

/// erf⁻¹(z) for z in (-1, 1), by Newton's method on `libm::erf` from a logarithmic start.
fn inverse_erf(z: f64) -> f64 {
    let two_over_sqrt_pi = 2.0 / std::f64::consts::PI.sqrt();
    // Start from the tail asymptote sign(z) sqrt(-ln(1 - |z|)), which is within a factor of
    // two everywhere, then Newton (erf is convex on each side, so it converges monotonically).
    let mut x = z.signum() * (-(1.0 - z.abs()).ln()).sqrt() * 0.9;
    for _ in 0..30 {
        let step = (libm::erf(x) - z) / (two_over_sqrt_pi * (-x * x).exp());
        x -= step;
        if step.abs() < 1e-12 {
            break;
        }
    }
    x
}

/// The half vector of a (wo, wi) pair, oriented to +z, and the relative index `etap` used
/// (1 for reflection). `None` for degenerate configurations.
fn half_vector(eta: f32, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, bool)> {
    let (co, ci) = (wo.z, wi.z);
    if co == 0.0 || ci == 0.0 {
        return None;
    }
    let reflect = co * ci > 0.0;
    let etap = if reflect {
        1.0
    } else if co > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let wm = wi * etap + wo;
    if wm.length_squared() == 0.0 {
        return None;
    }
    let mut wm = wm.normalize();
    if wm.z < 0.0 {
        wm = -wm;
    }
    // Microfacets seen from behind contribute nothing.
    if wm.dot(wi) * ci < 0.0 || wm.dot(wo) * co < 0.0 {
        return None;
    }
    Some((wm, etap, reflect))
}

/// A tint's share in the choice between reflection and transmission: its largest channel,
/// at most 1, and at least 1e-3 unless the tint is black.
pub(crate) fn lobe_weight(tint: Rgb) -> f32 {
    tint.max_component().min(1.0).max(if tint.is_black() { 0.0 } else { 1e-3 })
}

fn lobe_probabilities(f: f32, reflect: Rgb, transmit: Rgb) -> (f32, f32) {
    let pr = f * lobe_weight(reflect);
    let pt = (1.0 - f) * lobe_weight(transmit);
    let s = pr + pt;
    if s <= 0.0 {
        (0.0, 0.0)
    } else {
        (pr / s, pt / s)
    }
}

pub fn eval_rough_dielectric(d: &Microfacet, eta: f32, reflect: Rgb, transmit: Rgb, wo: Vec3, wi: Vec3) -> Rgb {
    let Some((wm, etap, is_reflect)) = half_vector(eta, wo, wi) else {
        return Rgb::BLACK;
    };
    let f = fresnel_dielectric(wo.dot(wm), eta).reflectance;
    let dg = d.d(wm) * d.g(wo, wi, wm);
    if is_reflect {
        reflect * (dg * f / (4.0 * wo.z.abs()))
    } else {
        let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2) * wo.z.abs();
        let ft = dg * (1.0 - f) * (wi.dot(wm) * wo.dot(wm) / denom).abs() / (etap * etap);
        transmit * ft
    }
}

pub fn pdf_rough_dielectric(d: &Microfacet, eta: f32, reflect: Rgb, transmit: Rgb, wo: Vec3, wi: Vec3) -> f32 {
    let Some((wm, etap, is_reflect)) = half_vector(eta, wo, wi) else {
        return 0.0;
    };
    let f = fresnel_dielectric(wo.dot(wm), eta).reflectance;
    let (pr, pt) = lobe_probabilities(f, reflect, transmit);
    if is_reflect {
        d.pdf_wm(wo, wm) / (4.0 * wo.dot(wm).abs()) * pr
    } else {
        let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
        d.pdf_wm(wo, wm) * wi.dot(wm).abs() / denom * pt
    }
}

pub fn sample_rough_dielectric(
    d: &Microfacet,
    eta: f32,
    reflect: Rgb,
    transmit: Rgb,
    wo: Vec3,
    u_lobe: f32,
    u: [f32; 2],
) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let wm = d.sample_wm(wo, u);
    let cos_om = wo.dot(wm);
    let fr = fresnel_dielectric(cos_om, eta);
    let (pr, _) = lobe_probabilities(fr.reflectance, reflect, transmit);
    let mut eta_crossed = 1.0;
    let wi = if u_lobe < pr {
        let wi = wm * (2.0 * cos_om) - wo;
        if wi.z * wo.z <= 0.0 {
            return None;
        }
        wi
    } else {
        if fr.reflectance >= 1.0 {
            return None;
        }
        // Refract wo about wm: cos_t has the opposite sign of cos_om.
        let wi = -wo / fr.eta_ti + wm * (cos_om / fr.eta_ti + fr.cos_t);
        if wi.z * wo.z >= 0.0 {
            return None;
        }
        eta_crossed = fr.eta_ti;
        wi.normalize()
    };
    let pdf = pdf_rough_dielectric(d, eta, reflect, transmit, wo, wi);
    if pdf <= 0.0 || !pdf.is_finite() {
        return None;
    }
    let value = eval_rough_dielectric(d, eta, reflect, transmit, wo, wi);
    Some(BsdfSample { wi, weight: value / pdf, pdf, delta: false, eta: eta_crossed })
}
