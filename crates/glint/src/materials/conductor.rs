//! `conductor` and `roughconductor`: metal with a complex index of refraction `eta` + i`k`
//! per channel, tinted by `specular`; smooth, or rough with a (textured) microfacet
//! roughness (BSDFs: [`Conductor`], [`RoughConductor`]).
//!
//! # The BSDF
//! Metals (Mitsuba's `conductor` and `roughconductor`): Fresnel reflection with a complex
//! index of refraction per channel, off a perfect mirror or a microfacet surface.
//!
//! # Differentiable
//! A rough conductor's parameters: `alpha` (and `alpha_v`), `eta`, `k`, `specular`. A smooth
//! conductor reflects through a delta lobe, which has no value to differentiate: asking for
//! its parameters is an error. See `docs/differentiable.md`.

use super::{roughness_map, Bsdf, Describe, MaterialKind, RoughnessMap, Shade, TextureCache, TexturePoint};
use crate::bsdf::{fresnel_conductor, reflect_local, BsdfSample, Microfacet, Scatter};
use crate::describe::slots::{roughness_slots, Slot};
use crate::describe::{checks, Roughness, TextureDesc};
use crate::error::Error;
use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

/// Perfectly smooth metal.
#[derive(Clone, Copy, Debug)]
pub struct Conductor {
    pub eta: Rgb,
    pub k: Rgb,
    pub specular: Rgb,
}

/// Microfacet metal (GGX or Beckmann).
#[derive(Clone, Copy, Debug)]
pub struct RoughConductor {
    pub dist: Microfacet,
    pub eta: Rgb,
    pub k: Rgb,
    pub specular: Rgb,
}

impl Scatter for Conductor {
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

    fn sample(&self, wo: Vec3, _u_lobe: f32, _u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = reflect_local(wo);
        Some(BsdfSample {
            wi,
            weight: self.specular * fresnel_conductor(wo.z, self.eta, self.k),
            pdf: 1.0,
            delta: true,
            eta: 1.0,
        })
    }

    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }
}

impl Scatter for RoughConductor {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let h = (wo + wi).normalize();
        let d = self.dist.d(h);
        if d == 0.0 {
            return Rgb::BLACK;
        }
        let f = fresnel_conductor(wi.dot(h), self.eta, self.k);
        let g = self.dist.g(wo, wi, h);
        self.specular * f * (d * g / (4.0 * wo.z))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        self.dist.pdf_wm(wo, h) / (4.0 * wo.dot(h))
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let h = self.dist.sample_wm(wo, u);
        let wi = (h * (2.0 * wo.dot(h)) - wo).normalize();
        BsdfSample::non_delta(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }

    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }
}

/// `conductor`'s and `roughconductor`'s parameters.
///
/// | Parameter | Type | Default (JSON, Mitsuba) | |
/// |---|---|---|---|
/// | `eta`, `k` | colour | a perfect mirror (0, 1); JSON `metal` and Mitsuba `material` name presets | complex index of refraction |
/// | `specular` | colour | 1 | tint (Mitsuba's `specular_reflectance`) |
/// | `roughness` | roughness | none: smooth | distribution and (textured) `alpha`, `alpha_v` |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConductorDesc {
    pub eta: Rgb,
    pub k: Rgb,
    pub specular: Rgb,
    pub roughness: Option<Roughness>,
}

impl Describe for ConductorDesc {
    type Built = ConductorMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<ConductorMaterial, Error> {
        let roughness = self.roughness.as_ref().map(|r| roughness_map(r, textures)).transpose()?;
        Ok(ConductorMaterial { eta: self.eta, k: self.k, specular: self.specular, roughness })
    }

    fn validate(&self) -> Result<(), String> {
        checks::color(self.eta, "eta")?;
        checks::color(self.k, "k")?;
        checks::color(self.specular, "specular reflectance")?;
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
            ("eta", Slot::Color(&mut self.eta)),
            ("k", Slot::Color(&mut self.k)),
            ("specular", Slot::Color(&mut self.specular)),
        ];
        roughness_slots(&mut self.roughness, &mut out);
        out
    }
}

/// A smooth metal, or a rough one where `roughness` is given.
#[derive(Clone, Debug)]
pub struct ConductorMaterial {
    pub eta: Rgb,
    pub k: Rgb,
    pub specular: Rgb,
    pub roughness: Option<RoughnessMap>,
}

impl Shade for ConductorMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        let (eta, k, specular) = (self.eta, self.k, self.specular);
        match &self.roughness {
            None => Bsdf::Conductor(Conductor { eta, k, specular }),
            Some(dist) => Bsdf::RoughConductor(RoughConductor { dist: dist.at(p.uv), eta, k, specular }),
        }
    }

    fn albedo(&self, _uv: [f32; 2]) -> Rgb {
        self.specular
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
