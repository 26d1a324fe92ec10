//! Microfacet distributions (GGX and Beckmann, isotropic) and the rough dielectric BSDF
//! (Walter et al. 2007). Shadowing is Smith's separable form G1(wo)·G1(wi), as Mitsuba 3
//! uses, so that glint and Mitsuba agree on the same scene. GGX normals are sampled from
//! the distribution of visible normals (Heitz 2018); Beckmann from D(h)·cos θh.

use super::{fresnel_dielectric, BsdfSample};
use crate::math::{Rgb, Vec3, PI};

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MicrofacetKind {
    Ggx,
    Beckmann,
}

#[derive(Clone, Copy, Debug)]
pub struct Microfacet {
    pub kind: MicrofacetKind,
    pub alpha: f32,
}

impl Microfacet {
    pub fn new(kind: MicrofacetKind, alpha: f32) -> Microfacet {
        // Very small roughness makes D a near-delta that floats cannot represent.
        Microfacet { kind, alpha: alpha.max(1e-4) }
    }

    /// Normal distribution D(h), h in the upper hemisphere.
    pub fn d(&self, h: Vec3) -> f32 {
        let cos2 = h.z * h.z;
        if cos2 <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let tan2 = (1.0 - cos2) / cos2;
        let r = match self.kind {
            MicrofacetKind::Ggx => {
                let t = 1.0 + tan2 / a2;
                1.0 / (PI * a2 * cos2 * cos2 * t * t)
            }
            MicrofacetKind::Beckmann => (-tan2 / a2).exp() / (PI * a2 * cos2 * cos2),
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
        let cos2 = v.z * v.z;
        let tan2 = ((1.0 - cos2) / cos2).max(0.0);
        if tan2 == 0.0 {
            return 1.0;
        }
        match self.kind {
            MicrofacetKind::Ggx => 2.0 / (1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt()),
            MicrofacetKind::Beckmann => {
                let a = 1.0 / (self.alpha * tan2.sqrt());
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

    /// Samples a microfacet normal (upper hemisphere) for viewing direction `wo` (either side).
    pub fn sample_wm(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        match self.kind {
            MicrofacetKind::Ggx => {
                let w = if wo.z < 0.0 { -wo } else { wo };
                let a = self.alpha;
                let vh = Vec3 { x: a * w.x, y: a * w.y, z: w.z }.normalize();
                let lensq = vh.x * vh.x + vh.y * vh.y;
                let t1 = if lensq > 0.0 { Vec3 { x: -vh.y, y: vh.x, z: 0.0 } / lensq.sqrt() } else { Vec3::X };
                let t2 = vh.cross(t1);
                let r = u[0].sqrt();
                let phi = 2.0 * PI * u[1];
                let p1 = r * phi.cos();
                let mut p2 = r * phi.sin();
                let s = 0.5 * (1.0 + vh.z);
                p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
                let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
                Vec3 { x: a * nh.x, y: a * nh.y, z: nh.z.max(1e-6) }.normalize()
            }
            MicrofacetKind::Beckmann => {
                let tan2 = -self.alpha * self.alpha * (1.0 - u[0]).ln();
                let cos_t = 1.0 / (1.0 + tan2).sqrt();
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = 2.0 * PI * u[1];
                Vec3 { x: sin_t * phi.cos(), y: sin_t * phi.sin(), z: cos_t }
            }
        }
    }

    /// Density of `sample_wm` producing `h` (solid angle of normals).
    pub fn pdf_wm(&self, wo: Vec3, h: Vec3) -> f32 {
        match self.kind {
            MicrofacetKind::Ggx => {
                if wo.z == 0.0 {
                    return 0.0;
                }
                let w = if wo.z < 0.0 { -wo } else { wo };
                self.g1(w, h) * w.dot(h).max(0.0) * self.d(h) / w.z
            }
            MicrofacetKind::Beckmann => self.d(h) * h.z.max(0.0),
        }
    }
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

fn lobe_probabilities(f: f32, reflect: Rgb, transmit: Rgb) -> (f32, f32) {
    let pr = f * reflect.max_component().min(1.0).max(if reflect.is_black() { 0.0 } else { 1e-3 });
    let pt = (1.0 - f) * transmit.max_component().min(1.0).max(if transmit.is_black() { 0.0 } else { 1e-3 });
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
