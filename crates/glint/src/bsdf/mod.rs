//! Scattering functions, evaluated in the local shading frame (normal = +z).
//!
//! # Conventions (the same everywhere in glint)
//! - `wo` points from the surface towards the viewer (the previous path vertex); `wi` points
//!   from the surface towards the light (the sampled next direction). Both are unit vectors
//!   pointing *away* from the surface, in the local frame.
//! - `eval(wo, wi)` returns the BSDF value **multiplied by |cos θi|**, i.e. the integrand of
//!   the reflection integral apart from incident radiance (Mitsuba's convention).
//! - `sample` returns a [`BsdfSample`] whose `weight` is `eval(wo, wi) / pdf`, already divided
//!   by the pdf; for delta lobes `pdf` is 1 by convention and `delta` is set.
//! - `pdf(wo, wi)` is the solid-angle density with which `sample` produces `wi`; it is 0 for
//!   delta lobes.
//! - Radiance is transported (camera paths), so refraction scales by (η_i/η_t)².
//!
//! A `Bsdf` is the material evaluated at one point: textures already looked up.

mod blend;
mod fresnel;
mod hair;
mod microfacet;
mod perturbed;
mod phong;
mod principled;

pub use blend::{BlendBsdf, BlendPart};
pub use fresnel::{fresnel_conductor, fresnel_dielectric, reflect_local, refract_local, DielectricFresnel};
pub use hair::{HairBsdf, EUMELANIN_SIGMA_A, PHEOMELANIN_SIGMA_A};
pub use microfacet::{Microfacet, MicrofacetKind};
pub use perturbed::{bump_shadowing, flip_invalid, normal_map_frame, ShadedBsdf};
pub use phong::Phong;
pub use principled::{
    principled_alphas, principled_eta_of_specular, AnisoGgx, Principled, PrincipledInputs, PrincipledRates,
};

use crate::math::{Rgb, Vec3, INV_PI};
use crate::sampling::warp;

impl BsdfSample {
    /// A non-delta sample of direction `wi` for a BSDF whose `eval` and `pdf` give `value`
    /// and `pdf` there; `None` when the direction is below the surface or has no density.
    #[inline]
    pub fn non_delta(wi: Vec3, value: Rgb, pdf: f32) -> Option<BsdfSample> {
        if wi.z <= 0.0 || !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample { wi, weight: value / pdf, pdf, delta: false, eta: 1.0 })
    }
}

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    /// eval(wo, wi) / pdf.
    pub weight: Rgb,
    pub pdf: f32,
    /// A delta lobe was chosen (perfect mirror or refraction).
    pub delta: bool,
    /// Relative index of refraction crossed (1 for reflection): a refracted sample's
    /// weight carries the 1/eta^2 radiance scaling, which Russian roulette must not count.
    pub eta: f32,
}

/// Not `Copy`: a blend owns its two parts (see `blend.rs`); every other variant is plain data.
#[derive(Clone, Debug)]
pub enum Bsdf {
    /// Lambertian reflection.
    Diffuse { reflectance: Rgb },
    /// Diffuse plus a normalised Phong lobe (the Whitted integrator's glossy term).
    Phong(Phong),
    /// Perfectly smooth metal with complex index of refraction per channel.
    Conductor { eta: Rgb, k: Rgb, specular: Rgb },
    /// Microfacet metal (GGX or Beckmann).
    RoughConductor { dist: Microfacet, eta: Rgb, k: Rgb, specular: Rgb },
    /// Smooth glass: `eta` is n_inside / n_outside.
    Dielectric { eta: f32, reflect: Rgb, transmit: Rgb },
    /// Rough glass with a microfacet interface.
    RoughDielectric { dist: Microfacet, eta: f32, reflect: Rgb, transmit: Rgb },
    /// An infinitely thin slab of glass: reflection and straight-through transmission with
    /// the inter-reflections summed (Mitsuba's `thindielectric`).
    ThinDielectric { eta: f32, reflect: Rgb, transmit: Rgb },
    /// Diffuse base under a smooth or rough dielectric coating (Mitsuba's `plastic` and
    /// `roughplastic`), with the internal-scattering correction of the diffuse term.
    Plastic(crate::bsdf::PlasticParams),
    /// Absorbs everything (light sources with no material).
    Black,
    /// Passes light straight through, unchanged (Mitsuba's `null`): a medium's boundary.
    Null,
    /// Mitsuba's `principled` (Disney) BSDF.
    Principled(Principled),
    /// Mitsuba's `blendbsdf`: a weighted mixture of two BSDFs.
    Blend(BlendBsdf),
    /// Mitsuba's `pplastic` as its unpolarized variants render it.
    PPlastic(PPlasticParams),
    /// Mitsuba's `hair` (Chiang et al. 2016), in a curve's frame (x around, y along).
    Hair(HairBsdf),
}

mod plastic;
mod pplastic;
pub use plastic::PlasticParams;
pub use pplastic::PPlasticParams;

impl Bsdf {
    /// True when every lobe is a delta: light sampling is pointless there.
    pub fn is_delta(&self) -> bool {
        match self {
            Bsdf::Conductor { .. } | Bsdf::Dielectric { .. } | Bsdf::ThinDielectric { .. } | Bsdf::Null => true,
            Bsdf::Plastic(p) => p.is_delta_only(),
            Bsdf::Blend(b) => b.is_delta(),
            _ => false,
        }
    }

    /// True when the BSDF has a delta lobe beside smooth ones (smooth plastic).
    pub fn has_delta_lobe(&self) -> bool {
        match self {
            Bsdf::Plastic(p) => p.dist.is_none(),
            Bsdf::Blend(b) => b.has_delta_lobe(),
            _ => self.is_delta(),
        }
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match self {
            Bsdf::Diffuse { reflectance } => {
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    return Rgb::BLACK;
                }
                *reflectance * (INV_PI * wi.z)
            }
            Bsdf::Phong(p) => p.eval(wo, wi),
            Bsdf::RoughConductor { dist, eta, k, specular } => {
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    return Rgb::BLACK;
                }
                let h = (wo + wi).normalize();
                let d = dist.d(h);
                if d == 0.0 {
                    return Rgb::BLACK;
                }
                let f = fresnel_conductor(wi.dot(h), *eta, *k);
                let g = dist.g(wo, wi, h);
                *specular * f * (d * g / (4.0 * wo.z))
            }
            Bsdf::RoughDielectric { dist, eta, reflect, transmit } => {
                microfacet::eval_rough_dielectric(dist, *eta, *reflect, *transmit, wo, wi)
            }
            Bsdf::Plastic(p) => p.eval(wo, wi),
            Bsdf::PPlastic(p) => p.eval(wo, wi),
            Bsdf::Principled(p) => p.eval(wo, wi),
            Bsdf::Blend(b) => b.eval(wo, wi),
            Bsdf::Hair(h) => h.eval(wo, wi),
            Bsdf::Conductor { .. }
            | Bsdf::Dielectric { .. }
            | Bsdf::ThinDielectric { .. }
            | Bsdf::Black
            | Bsdf::Null => Rgb::BLACK,
        }
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bsdf::Diffuse { .. } => {
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    0.0
                } else {
                    warp::cosine_hemisphere_pdf(wi.z)
                }
            }
            Bsdf::Phong(p) => p.pdf(wo, wi),
            Bsdf::RoughConductor { dist, .. } => {
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    return 0.0;
                }
                let h = (wo + wi).normalize();
                dist.pdf_wm(wo, h) / (4.0 * wo.dot(h))
            }
            Bsdf::RoughDielectric { dist, eta, reflect, transmit } => {
                microfacet::pdf_rough_dielectric(dist, *eta, *reflect, *transmit, wo, wi)
            }
            Bsdf::Plastic(p) => p.pdf(wo, wi),
            Bsdf::Principled(p) => p.pdf(wo, wi),
            Bsdf::Blend(b) => b.pdf(wo, wi),
            Bsdf::PPlastic(p) => p.pdf(wo, wi),
            Bsdf::Hair(h) => h.pdf(wo, wi),
            _ => 0.0,
        }
    }

    /// Samples `wi` given `wo`. `u_lobe` chooses among lobes, `u` drives the direction.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        match self {
            Bsdf::Diffuse { reflectance } => {
                if wo.z <= 0.0 {
                    return None;
                }
                let wi = warp::cosine_hemisphere(u);
                if wi.z <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    weight: *reflectance,
                    pdf: warp::cosine_hemisphere_pdf(wi.z),
                    delta: false,
                    eta: 1.0,
                })
            }
            Bsdf::Phong(p) => p.sample(wo, u_lobe, u),
            Bsdf::Conductor { eta, k, specular } => {
                if wo.z <= 0.0 {
                    return None;
                }
                let wi = reflect_local(wo);
                Some(BsdfSample {
                    wi,
                    weight: *specular * fresnel_conductor(wo.z, *eta, *k),
                    pdf: 1.0,
                    delta: true,
                    eta: 1.0,
                })
            }
            Bsdf::RoughConductor { dist, .. } => {
                if wo.z <= 0.0 {
                    return None;
                }
                let h = dist.sample_wm(wo, u);
                let wi = (h * (2.0 * wo.dot(h)) - wo).normalize();
                BsdfSample::non_delta(wi, self.eval(wo, wi), self.pdf(wo, wi))
            }
            Bsdf::Dielectric { eta, reflect, transmit } => {
                let fr = fresnel_dielectric(wo.z, *eta);
                if u_lobe < fr.reflectance {
                    Some(BsdfSample { wi: reflect_local(wo), weight: *reflect, pdf: 1.0, delta: true, eta: 1.0 })
                } else {
                    let wi = refract_local(wo, &fr);
                    let scale = 1.0 / (fr.eta_ti * fr.eta_ti);
                    Some(BsdfSample { wi, weight: *transmit * scale, pdf: 1.0, delta: true, eta: fr.eta_ti })
                }
            }
            Bsdf::ThinDielectric { eta, reflect, transmit } => {
                let mut r = fresnel_dielectric(wo.z.abs(), *eta).reflectance;
                // Sum of the geometric series of internal bounces (Mitsuba thindielectric).
                if r < 1.0 {
                    r *= 2.0 / (1.0 + r);
                }
                if u_lobe < r {
                    Some(BsdfSample { wi: reflect_local(wo), weight: *reflect, pdf: 1.0, delta: true, eta: 1.0 })
                } else {
                    Some(BsdfSample { wi: -wo, weight: *transmit, pdf: 1.0, delta: true, eta: 1.0 })
                }
            }
            Bsdf::RoughDielectric { dist, eta, reflect, transmit } => {
                microfacet::sample_rough_dielectric(dist, *eta, *reflect, *transmit, wo, u_lobe, u)
            }
            Bsdf::Plastic(p) => p.sample(wo, u_lobe, u),
            Bsdf::PPlastic(p) => p.sample(wo, u_lobe, u),
            Bsdf::Black => None,
            Bsdf::Null => Some(BsdfSample { wi: -wo, weight: Rgb::WHITE, pdf: 1.0, delta: true, eta: 1.0 }),
            Bsdf::Principled(p) => p.sample(wo, u_lobe, u),
            Bsdf::Blend(b) => b.sample(wo, u_lobe, u),
            Bsdf::Hair(h) => h.sample(wo, u_lobe, u),
        }
    }

    /// Fraction of light reflected and transmitted (for the Whitted integrator's mix);
    /// the delta directions themselves come from `sample`.
    pub fn diffuse_reflectance(&self) -> Rgb {
        match self {
            Bsdf::Diffuse { reflectance } => *reflectance,
            Bsdf::Phong(p) => p.kd,
            Bsdf::Plastic(p) => p.diffuse,
            Bsdf::Principled(p) => p.diffuse_reflectance(),
            Bsdf::Blend(b) => b.diffuse_reflectance(),
            Bsdf::PPlastic(p) => p.diffuse,
            _ => Rgb::BLACK,
        }
    }
}
