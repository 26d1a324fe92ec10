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
//! This module holds what every BSDF shares: the [`Scatter`] trait, [`BsdfSample`], Fresnel
//! and microfacet distributions. Each BSDF lives with its material in `materials/` (a
//! `materials::Bsdf` is the material evaluated at one point: textures already looked up),
//! and the closed `materials::Bsdf` enum is made there from one list.

mod fresnel;
mod microfacet;

pub use fresnel::{fresnel_conductor, fresnel_dielectric, reflect_local, refract_local, DielectricFresnel};
/// For the rough dielectric's kernel in the path tracer's vertex lanes.
pub(crate) use microfacet::lobe_weight;
pub use microfacet::{
    eval_rough_dielectric, pdf_rough_dielectric, sample_rough_dielectric, Microfacet, MicrofacetKind,
};

use crate::math::{Rgb, Vec3};

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

/// What every BSDF answers, in the local shading frame (see the conventions above). No
/// method but `passage_transmission` (which only passages answer) has a default, so that a
/// new BSDF states each answer.
pub trait Scatter {
    /// True when every lobe is a delta: light sampling is pointless there.
    fn is_delta(&self) -> bool;

    /// True when the BSDF has a delta lobe (beside smooth ones, or alone).
    fn has_delta_lobe(&self) -> bool;

    /// The BSDF times |cos θi|.
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb;

    /// The solid-angle density with which `sample` produces `wi` (0 for delta lobes).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// Samples `wi` given `wo`. `u_lobe` chooses among lobes, `u` drives the direction.
    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample>;

    /// Fraction of light reflected diffusely (the Whitted integrator's mix and the albedo
    /// guide); the delta directions themselves come from `sample`.
    fn diffuse_reflectance(&self) -> Rgb;

    /// What passes straight through towards `-wo` without scattering (Mitsuba's null
    /// transmission), for the passages the volumetric path tracer crosses without counting
    /// a bounce (`null`, a thin dielectric); `None`, the default, for every other surface.
    fn passage_transmission(&self, _wo: Vec3) -> Option<Rgb> {
        None
    }
}
