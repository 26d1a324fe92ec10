//! `dielectric`, `roughdielectric` and `thindielectric`: glass of relative index `eta`
//! (interior over exterior), its reflection and transmission tinted by `reflect` and
//! `transmit`; smooth, rough with a (textured) microfacet roughness, or an infinitely thin
//! slab (BSDFs: [`Dielectric`], [`RoughDielectric`], [`ThinDielectric`]).
//!
//! # The BSDF
//! Glass (Mitsuba's `dielectric`, `roughdielectric` and `thindielectric`): `eta` is
//! n_inside / n_outside; `reflect` and `transmit` tint the two directions.

use super::{roughness_map, Bsdf, MaterialKind, RoughnessMap, Shade, TextureCache, TexturePoint};
use crate::bsdf::{eval_rough_dielectric, pdf_rough_dielectric, sample_rough_dielectric};
use crate::bsdf::{fresnel_dielectric, reflect_local, refract_local, BsdfSample, Microfacet, Scatter};
use crate::describe::Roughness;
use crate::error::Error;
use crate::math::{Rgb, Vec3};

/// Smooth glass: one reflected and one refracted direction.
#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
}

/// Rough glass with a microfacet interface.
#[derive(Clone, Copy, Debug)]
pub struct RoughDielectric {
    pub dist: Microfacet,
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
}

/// An infinitely thin slab of glass: reflection and straight-through transmission with the
/// inter-reflections summed.
#[derive(Clone, Copy, Debug)]
pub struct ThinDielectric {
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
}

impl ThinDielectric {
    /// The slab's reflectance at `cos` (either side): the geometric series of internal
    /// bounces summed, as Mitsuba's `thindielectric` sums it.
    pub fn reflectance(&self, cos: f32) -> f32 {
        let mut r = fresnel_dielectric(cos.abs(), self.eta).reflectance;
        if r < 1.0 {
            r *= 2.0 / (1.0 + r);
        }
        r
    }
}

impl Scatter for Dielectric {
    fn is_delta(&self) -> bool {
        true
    }

    fn has_delta_lobe(&self) -> bool {
        true
    }

    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, _u: [f32; 2]) -> Option<BsdfSample> {
        let fr = fresnel_dielectric(wo.z, self.eta);
        if u_lobe < fr.reflectance {
            Some(BsdfSample { wi: reflect_local(wo), weight: self.reflect, pdf: 1.0, delta: true, eta: 1.0 })
        } else {
            let wi = refract_local(wo, &fr);
            let scale = 1.0 / (fr.eta_ti * fr.eta_ti);
            Some(BsdfSample { wi, weight: self.transmit * scale, pdf: 1.0, delta: true, eta: fr.eta_ti })
        }
    }

    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }
}

impl Scatter for RoughDielectric {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        eval_rough_dielectric(&self.dist, self.eta, self.reflect, self.transmit, wo, wi)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_rough_dielectric(&self.dist, self.eta, self.reflect, self.transmit, wo, wi)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        sample_rough_dielectric(&self.dist, self.eta, self.reflect, self.transmit, wo, u_lobe, u)
    }

    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }
}

impl Scatter for ThinDielectric {
    fn is_delta(&self) -> bool {
        true
    }

    fn has_delta_lobe(&self) -> bool {
        true
    }

    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, _u: [f32; 2]) -> Option<BsdfSample> {
        if u_lobe < self.reflectance(wo.z) {
            Some(BsdfSample { wi: reflect_local(wo), weight: self.reflect, pdf: 1.0, delta: true, eta: 1.0 })
        } else {
            Some(BsdfSample { wi: -wo, weight: self.transmit, pdf: 1.0, delta: true, eta: 1.0 })
        }
    }

    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }

    fn passage_transmission(&self, wo: Vec3) -> Option<Rgb> {
        Some(self.transmit * (1.0 - self.reflectance(wo.z)))
    }
}

#[derive(Clone, Debug)]
pub struct DielectricMaterial {
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
}

#[derive(Clone, Debug)]
pub struct RoughDielectricMaterial {
    pub dist: RoughnessMap,
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
}

#[derive(Clone, Debug)]
pub struct ThinDielectricMaterial {
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
}

/// The smooth, rough or thin dielectric a description gives (a thin one is always smooth).
pub(crate) fn build(
    eta: f32,
    reflect: Rgb,
    transmit: Rgb,
    roughness: Option<&Roughness>,
    thin: bool,
    textures: &mut TextureCache,
) -> Result<MaterialKind, Error> {
    Ok(match (thin, roughness) {
        (true, _) => MaterialKind::ThinDielectric(ThinDielectricMaterial { eta, reflect, transmit }),
        (false, None) => MaterialKind::Dielectric(DielectricMaterial { eta, reflect, transmit }),
        (false, Some(r)) => MaterialKind::RoughDielectric(RoughDielectricMaterial {
            dist: roughness_map(r, textures)?,
            eta,
            reflect,
            transmit,
        }),
    })
}

impl Shade for DielectricMaterial {
    #[inline]
    fn bsdf_at(&self, _p: &TexturePoint) -> Bsdf {
        Bsdf::Dielectric(Dielectric { eta: self.eta, reflect: self.reflect, transmit: self.transmit })
    }

    fn albedo(&self, _uv: [f32; 2]) -> Rgb {
        self.transmit
    }

    fn is_transmissive(&self) -> bool {
        true
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}

impl Shade for RoughDielectricMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::RoughDielectric(RoughDielectric {
            dist: self.dist.at(p.uv),
            eta: self.eta,
            reflect: self.reflect,
            transmit: self.transmit,
        })
    }

    fn albedo(&self, _uv: [f32; 2]) -> Rgb {
        self.transmit
    }

    fn is_transmissive(&self) -> bool {
        true
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}

impl Shade for ThinDielectricMaterial {
    #[inline]
    fn bsdf_at(&self, _p: &TexturePoint) -> Bsdf {
        Bsdf::ThinDielectric(ThinDielectric { eta: self.eta, reflect: self.reflect, transmit: self.transmit })
    }

    fn albedo(&self, _uv: [f32; 2]) -> Rgb {
        self.transmit
    }

    fn is_transmissive(&self) -> bool {
        true
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
