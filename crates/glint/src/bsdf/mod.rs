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
//!
//! # Adding a BSDF
//! Write its type in a module of its own with an `impl Scatter` (the compiler names any
//! method it lacks), and add one line to the `bsdfs!` list below: that line makes the
//! [`Bsdf`] variant, its dispatch and its `From` conversion. docs/rendering.md ("Adding a
//! material") lists what else a material touches.

mod blend;
mod conductor;
mod dielectric;
mod diffuse;
mod fresnel;
mod gltf_lobes;
mod gltf_pbr;
mod hair;
mod microfacet;
mod null;
mod perturbed;
mod phong;
mod plastic;
mod pplastic;
mod principled;

pub use crate::describe::principled_eta_of_specular;
pub use blend::{BlendBsdf, BlendPart};
pub use conductor::{Conductor, RoughConductor};
pub use dielectric::{Dielectric, RoughDielectric, ThinDielectric};
pub use diffuse::Diffuse;
pub use fresnel::{fresnel_conductor, fresnel_dielectric, reflect_local, refract_local, DielectricFresnel};
pub use gltf_lobes::{sheen_albedo, sheen_albedo_quadrature, SHEEN_ALBEDO_TOLERANCE, SHEEN_MIN_ROUGHNESS};
pub use gltf_pbr::GltfPbr;
pub use hair::{HairBsdf, EUMELANIN_SIGMA_A, PHEOMELANIN_SIGMA_A};
pub use microfacet::{Microfacet, MicrofacetKind};
pub use null::{Black, Null};
pub use perturbed::{bump_shadowing, flip_invalid, normal_map_frame, ShadedBsdf};
pub use phong::Phong;
pub use plastic::PlasticParams;
pub use pplastic::PPlasticParams;
pub use principled::{principled_alphas, AnisoGgx, Principled, PrincipledInputs, PrincipledRates};

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

/// Makes the closed [`Bsdf`] enum from one list of `Variant(Type)`, each type a
/// [`Scatter`]: the enum, its static dispatch of every `Scatter` method (one arm per
/// variant, no wildcard) and `From<Type> for Bsdf`.
macro_rules! bsdfs {
    ($($(#[doc = $doc:literal])* $variant:ident($ty:ty),)+) => {
        /// Not `Copy`: a blend owns its two parts (see `blend.rs`); every other variant is
        /// plain data.
        #[derive(Clone, Debug)]
        pub enum Bsdf {
            $($(#[doc = $doc])* $variant($ty),)+
        }

        // Inherent, so that callers of a `Bsdf` need not import `Scatter`.
        impl Bsdf {
            /// See [`Scatter::is_delta`].
            pub fn is_delta(&self) -> bool {
                match self { $(Bsdf::$variant(b) => b.is_delta(),)+ }
            }

            /// See [`Scatter::has_delta_lobe`].
            pub fn has_delta_lobe(&self) -> bool {
                match self { $(Bsdf::$variant(b) => b.has_delta_lobe(),)+ }
            }

            /// See [`Scatter::eval`].
            pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
                match self { $(Bsdf::$variant(b) => b.eval(wo, wi),)+ }
            }

            /// See [`Scatter::pdf`].
            pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
                match self { $(Bsdf::$variant(b) => b.pdf(wo, wi),)+ }
            }

            /// See [`Scatter::sample`].
            pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
                match self { $(Bsdf::$variant(b) => b.sample(wo, u_lobe, u),)+ }
            }

            /// See [`Scatter::diffuse_reflectance`].
            pub fn diffuse_reflectance(&self) -> Rgb {
                match self { $(Bsdf::$variant(b) => b.diffuse_reflectance(),)+ }
            }

            /// See [`Scatter::passage_transmission`].
            pub fn passage_transmission(&self, wo: Vec3) -> Option<Rgb> {
                match self { $(Bsdf::$variant(b) => b.passage_transmission(wo),)+ }
            }
        }

        $(impl From<$ty> for Bsdf {
            fn from(b: $ty) -> Bsdf {
                Bsdf::$variant(b)
            }
        })+
    };
}

bsdfs! {
    /// Lambertian reflection.
    Diffuse(Diffuse),
    /// Diffuse plus a normalised Phong lobe (the Whitted integrator's glossy term).
    Phong(Phong),
    /// Perfectly smooth metal with complex index of refraction per channel.
    Conductor(Conductor),
    /// Microfacet metal (GGX or Beckmann).
    RoughConductor(RoughConductor),
    /// Smooth glass: `eta` is n_inside / n_outside.
    Dielectric(Dielectric),
    /// Rough glass with a microfacet interface.
    RoughDielectric(RoughDielectric),
    /// An infinitely thin slab of glass: reflection and straight-through transmission with
    /// the inter-reflections summed (Mitsuba's `thindielectric`).
    ThinDielectric(ThinDielectric),
    /// Diffuse base under a smooth or rough dielectric coating (Mitsuba's `plastic` and
    /// `roughplastic`), with the internal-scattering correction of the diffuse term.
    Plastic(PlasticParams),
    /// Absorbs everything (light sources with no material).
    Black(Black),
    /// Passes light straight through, unchanged (Mitsuba's `null`): a medium's boundary.
    Null(Null),
    /// Mitsuba's `principled` (Disney) BSDF.
    Principled(Principled),
    /// Mitsuba's `blendbsdf`: a weighted mixture of two BSDFs.
    Blend(BlendBsdf),
    /// Mitsuba's `pplastic` as its unpolarized variants render it.
    PPlastic(PPlasticParams),
    /// Mitsuba's `hair` (Chiang et al. 2016), in a curve's frame (x around, y along).
    Hair(HairBsdf),
    /// The glTF 2.0 metallic-roughness BRDF with the KHR material extensions.
    GltfPbr(GltfPbr),
}
