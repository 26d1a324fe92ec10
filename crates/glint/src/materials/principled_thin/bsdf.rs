//! The `principledthin` BSDF (see the module above for the model and its parameters).

use crate::bsdf::{fresnel_dielectric, BsdfSample, Scatter};
use crate::materials::principled::{
    compatible, disney_diffuse, lerp, principled_alphas, schlick, schlick_r0, schlick_weight, tint_of, AnisoGgx,
};
use crate::math::{Rgb, Vec3, INV_PI};
use crate::sampling::warp;

/// Mitsuba's four `*_sampling_rate` parameters: relative weights of the lobes when sampling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledThinRates {
    pub diffuse_reflectance: f32,
    pub diffuse_transmittance: f32,
    pub specular_reflectance: f32,
    pub specular_transmittance: f32,
}

impl Default for PrincipledThinRates {
    fn default() -> Self {
        PrincipledThinRates {
            diffuse_reflectance: 1.0,
            diffuse_transmittance: 1.0,
            specular_reflectance: 1.0,
            specular_transmittance: 1.0,
        }
    }
}

/// The parameters as the user gives them (`diff_trans` in Mitsuba's [0, 2]).
#[derive(Clone, Copy, Debug)]
pub struct PrincipledThinInputs {
    pub base_color: Rgb,
    pub roughness: f32,
    pub anisotropic: f32,
    pub spec_trans: f32,
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    pub diff_trans: f32,
    pub rates: PrincipledThinRates,
}

/// The thin principled BSDF at one point (textures looked up).
#[derive(Clone, Copy, Debug)]
pub struct PrincipledThin {
    pub base_color: Rgb,
    pub roughness: f32,
    pub spec_trans: f32,
    /// Relative index of refraction of the sheet.
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    /// Mitsuba's `diff_trans` halved: the fraction of the diffuse lobe transmitted, [0, 1].
    pub diff_trans: f32,
    /// The reflection lobe's distribution.
    pub dist: AnisoGgx,
    /// The transmission lobe's, its roughness scaled by 0.65 η - 0.35.
    pub trans_dist: AnisoGgx,
    pub rates: PrincipledThinRates,
}

/// Sampling probabilities of the four lobes (normalised).
struct LobeProbabilities {
    spec_reflect: f32,
    spec_trans: f32,
    diffuse_reflect: f32,
    diffuse_trans: f32,
}

impl PrincipledThin {
    pub fn new(p: &PrincipledThinInputs) -> PrincipledThin {
        let (alpha_x, alpha_y) = principled_alphas(p.roughness, p.anisotropic);
        let scaled = (0.65 * p.eta - 0.35) * p.roughness;
        let (trans_x, trans_y) = principled_alphas(scaled, p.anisotropic);
        PrincipledThin {
            base_color: p.base_color,
            roughness: p.roughness,
            spec_trans: p.spec_trans,
            eta: p.eta,
            spec_tint: p.spec_tint,
            sheen: p.sheen,
            sheen_tint: p.sheen_tint,
            flatness: p.flatness,
            diff_trans: p.diff_trans / 2.0,
            dist: AnisoGgx { alpha_x, alpha_y },
            trans_dist: AnisoGgx { alpha_x: trans_x, alpha_y: trans_y },
            rates: p.rates,
        }
    }

    fn probabilities(&self) -> Option<LobeProbabilities> {
        let r = &self.rates;
        let (st, dt) = (self.spec_trans, self.diff_trans);
        let mut p = LobeProbabilities {
            spec_reflect: st * r.specular_reflectance / 2.0,
            spec_trans: st * r.specular_transmittance / 2.0,
            diffuse_reflect: r.diffuse_reflectance * (1.0 - st) * (1.0 - dt),
            diffuse_trans: r.diffuse_transmittance * (1.0 - st) * dt,
        };
        let total = p.spec_reflect + p.spec_trans + p.diffuse_reflect + p.diffuse_trans;
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let rcp = 1.0 / total;
        p.spec_reflect *= rcp;
        p.spec_trans *= rcp;
        p.diffuse_reflect *= rcp;
        p.diffuse_trans *= rcp;
        Some(p)
    }

    /// Both directions moved to the side of `wo` (the sheet is symmetric: Mitsuba flips
    /// them through the origin), and the half vector of `wo` and `wi` mirrored to `wo`'s
    /// side: the microfacet normal of the reflection, or of the reflection that a
    /// transmission mirrors through the surface.
    fn front(wo: Vec3, wi: Vec3) -> (Vec3, Vec3, Vec3) {
        let (v, l) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        let l_r = Vec3 { x: l.x, y: l.y, z: l.z.abs() };
        (v, l, (v + l_r).normalize())
    }
}

impl Scatter for PrincipledThin {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z == 0.0 {
            return Rgb::BLACK;
        }
        let (v, l, wh) = Self::front(wo, wi);
        let (cos_v, cos_l) = (v.z, l.z);
        let (reflect, refract) = (cos_l > 0.0, cos_l < 0.0);
        let (st, dt) = (self.spec_trans, self.diff_trans);
        let mut value = Rgb::BLACK;
        if st > 0.0 {
            let f_d = fresnel_dielectric(v.dot(wh), self.eta).reflectance;
            if reflect && compatible(wh, v, l, cos_v, true) {
                let f_schlick = if self.spec_tint > 0.0 {
                    schlick(tint_of(self.base_color) * schlick_r0(self.eta), v.dot(wh), self.eta)
                } else {
                    Rgb::BLACK
                };
                let f = f_schlick.map(|s| lerp(f_d, s, self.spec_tint));
                let d = self.dist.d(wh);
                let g = self.dist.g(v, l, wh);
                value += f * (st * d * g / (4.0 * cos_v));
            }
            if refract && compatible(wh, v, l, cos_v, false) {
                let d = self.trans_dist.d(wh);
                let g = self.trans_dist.g(v, l, wh);
                value += self.base_color * (st * (1.0 - f_d) * d * g / (4.0 * cos_v));
            }
        }
        if reflect && st < 1.0 && dt < 1.0 {
            let cos_d = wh.dot(l);
            let lobe = disney_diffuse(self.roughness, self.flatness, cos_l, cos_v, cos_d);
            let w = (1.0 - st) * (1.0 - dt);
            value += self.base_color * (w * cos_l * INV_PI * lobe);
            if self.sheen > 0.0 {
                let fd = schlick_weight(cos_d.abs());
                let c_sheen = Rgb::WHITE * (1.0 - self.sheen_tint) + tint_of(self.base_color) * self.sheen_tint;
                value += c_sheen * (self.sheen * w * fd * cos_l);
            }
        }
        if refract && st < 1.0 && dt > 0.0 {
            value += self.base_color * ((1.0 - st) * dt * INV_PI * -cos_l);
        }
        value
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z == 0.0 {
            return 0.0;
        }
        let Some(p) = self.probabilities() else { return 0.0 };
        let (v, l, wh) = Self::front(wo, wi);
        let (cos_v, cos_l) = (v.z, l.z);
        let (reflect, refract) = (cos_l > 0.0, cos_l < 0.0);
        let mut pdf = 0.0;
        if self.spec_trans > 0.0 {
            // d(wh)/d(wi) of the reflection that the transmission mirrors: the same for both.
            let l_r = Vec3 { x: l.x, y: l.y, z: cos_l.abs() };
            let dwh_dwi = (1.0 / (4.0 * l_r.dot(wh))).abs();
            if reflect && compatible(wh, v, l, cos_v, true) {
                pdf += p.spec_reflect * self.dist.pdf_visible(v, wh) * dwh_dwi;
            }
            if refract && compatible(wh, v, l, cos_v, false) {
                pdf += p.spec_trans * self.trans_dist.pdf_visible(v, wh) * dwh_dwi;
            }
        }
        if reflect {
            pdf += p.diffuse_reflect * warp::cosine_hemisphere_pdf(cos_l);
        }
        if refract {
            pdf += p.diffuse_trans * warp::cosine_hemisphere_pdf(-cos_l);
        }
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let p = self.probabilities()?;
        let flip = wo.z < 0.0;
        let v = if flip { -wo } else { wo };
        let l = if u_lobe < p.spec_reflect {
            let m = self.dist.sample_visible(v, u);
            let l = m * (2.0 * v.dot(m)) - v;
            if !(l.z > 0.0 && compatible(m, v, l, v.z, true)) {
                return None;
            }
            l
        } else if u_lobe < p.spec_reflect + p.spec_trans {
            // The reflection off a microfacet of the scaled distribution, mirrored through
            // the surface: a thin sheet does not bend the ray.
            let m = self.trans_dist.sample_visible(v, u);
            let r = m * (2.0 * v.dot(m)) - v;
            let l = Vec3 { x: r.x, y: r.y, z: -r.z };
            if !(l.z < 0.0 && compatible(m, v, l, v.z, false)) {
                return None;
            }
            l
        } else if u_lobe < p.spec_reflect + p.spec_trans + p.diffuse_reflect {
            warp::cosine_hemisphere(u)
        } else if p.diffuse_trans > 0.0 {
            -warp::cosine_hemisphere(u)
        } else {
            return None;
        };
        let wi = if flip { -l } else { l };
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        let value = self.eval(wo, wi);
        Some(BsdfSample { wi, weight: value / pdf, pdf, delta: false, eta: 1.0 })
    }

    /// The base colour (Mitsuba's `eval_diffuse_reflectance`).
    fn diffuse_reflectance(&self) -> Rgb {
        self.base_color
    }
}
