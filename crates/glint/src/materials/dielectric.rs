//! `dielectric`, `roughdielectric` and `thindielectric`: glass of relative index `eta`
//! (interior over exterior), its reflection and transmission tinted by `reflect` and
//! `transmit`; smooth, rough with a (textured) microfacet roughness, or an infinitely thin
//! slab (BSDFs: [`Dielectric`], [`RoughDielectric`], [`ThinDielectric`]).
//!
//! # The BSDF
//! Glass (Mitsuba's `dielectric`, `roughdielectric` and `thindielectric`): `eta` is
//! n_inside / n_outside; `reflect` and `transmit` tint the two directions.
//!
//! # Differentiable
//! A rough dielectric's parameters (`alpha`, `eta`, `reflect`, `transmit`), through its BSDF's
//! value (directions are detached). Smooth and thin dielectrics scatter through delta lobes
//! only: asking for their parameters is an error. See `docs/differentiable.md`.

use super::{roughness_map, Bsdf, Describe, MaterialKind, RoughnessMap, Shade, TextureCache, TexturePoint};
use crate::bsdf::{eval_rough_dielectric, pdf_rough_dielectric, sample_rough_dielectric};
use crate::bsdf::{fresnel_dielectric, reflect_local, refract_local, BsdfSample, Microfacet, Scatter};
use crate::describe::slots::{roughness_slots, Slot};
use crate::describe::{checks, Roughness, TextureDesc};
use crate::error::Error;
use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

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

/// `dielectric`'s, `roughdielectric`'s and `thindielectric`'s parameters.
///
/// | Parameter | Type | Default (JSON, Mitsuba) | |
/// |---|---|---|---|
/// | `eta` | float | 1.5 (JSON `ior`; Mitsuba `int_ior` / `ext_ior`) | interior over exterior index |
/// | `reflect`, `transmit` | colour | 1 | tints (Mitsuba's `specular_reflectance`, `specular_transmittance`) |
/// | `roughness` | roughness | none: smooth | distribution and (textured) `alpha`, `alpha_v` |
/// | `thin` | bool | false | an infinitely thin slab (always smooth) |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DielectricDesc {
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
    pub roughness: Option<Roughness>,
    pub thin: bool,
}

impl Describe for DielectricDesc {
    type Built = DielectricMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<DielectricMaterial, Error> {
        let surface = match (self.thin, &self.roughness) {
            (true, _) => DielectricSurface::Thin,
            (false, None) => DielectricSurface::Smooth,
            (false, Some(r)) => DielectricSurface::Rough(roughness_map(r, textures)?),
        };
        Ok(DielectricMaterial { eta: self.eta, reflect: self.reflect, transmit: self.transmit, surface })
    }

    fn validate(&self) -> Result<(), String> {
        checks::eta(self.eta)?;
        checks::color(self.reflect, "specular reflectance")?;
        checks::color(self.transmit, "specular transmittance")?;
        checks::roughness(self.roughness.as_ref())
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        self.roughness.as_ref().map_or(Vec::new(), Roughness::textures)
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        self.roughness.as_mut().map_or(Vec::new(), Roughness::textures_mut)
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = vec![
            ("eta", Slot::Float(&mut self.eta)),
            ("reflect", Slot::Color(&mut self.reflect)),
            ("transmit", Slot::Color(&mut self.transmit)),
        ];
        roughness_slots(&mut self.roughness, &mut out);
        out
    }
}

/// Which dielectric interface a material has.
#[derive(Clone, Debug)]
pub enum DielectricSurface {
    Smooth,
    Rough(RoughnessMap),
    /// An infinitely thin slab.
    Thin,
}

#[derive(Clone, Debug)]
pub struct DielectricMaterial {
    pub eta: f32,
    pub reflect: Rgb,
    pub transmit: Rgb,
    pub surface: DielectricSurface,
}

impl DielectricMaterial {
    /// Smooth glass.
    pub fn smooth(eta: f32, reflect: Rgb, transmit: Rgb) -> DielectricMaterial {
        DielectricMaterial { eta, reflect, transmit, surface: DielectricSurface::Smooth }
    }
}

impl Shade for DielectricMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        let (eta, reflect, transmit) = (self.eta, self.reflect, self.transmit);
        match &self.surface {
            DielectricSurface::Smooth => Bsdf::Dielectric(Dielectric { eta, reflect, transmit }),
            DielectricSurface::Rough(dist) => {
                Bsdf::RoughDielectric(RoughDielectric { dist: dist.at(p.uv), eta, reflect, transmit })
            }
            DielectricSurface::Thin => Bsdf::ThinDielectric(ThinDielectric { eta, reflect, transmit }),
        }
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
