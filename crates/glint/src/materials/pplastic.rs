//! `pplastic` as Mitsuba's unpolarized variants render it: a rough specular lobe over a
//! textured diffuse base attenuated by Fresnel transmission in and out (BSDF:
//! [`PPlasticParams`]); the specular lobe's sampling probability is fixed per material.
//!
//! # The BSDF
//! Mitsuba's `pplastic` as its unpolarized variants (`scalar_rgb`) render it: a rough
//! dielectric specular lobe over a diffuse base seen through two Fresnel transmissions,
//! (1 - F(cos θo)) ρ/π (1 - F(cos θi)), with no internal-scattering series and no 1/η²
//! (unlike `roughplastic`). The lobes are chosen with a fixed probability, the specular
//! reflectance's share of the two albedos.
//!
//! # Differentiable
//! `diffuse` (a constant or a bitmap texture per texel), `specular`, `eta`, `alpha` and
//! `alpha_v`. See `docs/differentiable.md`.

use super::{roughness_map, Bsdf, Describe, MaterialKind, RoughnessMap, Shade, Texture, TextureCache, TexturePoint};
use crate::bsdf::{fresnel_dielectric, BsdfSample, Microfacet, Scatter};
use crate::describe::slots::{roughness_value_slots, texture_slot, Slot};
use crate::describe::{checks, Roughness, TextureDesc};
use crate::error::Error;
use crate::math::{Rgb, Vec3, INV_PI};
use crate::sampling::warp;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug)]
pub struct PPlasticParams {
    pub diffuse: Rgb,
    pub specular: Rgb,
    /// n_inside / n_outside of the coating.
    pub eta: f32,
    pub dist: Microfacet,
    /// Probability of sampling the specular lobe: mean specular over mean diffuse plus
    /// mean specular, from the textures' means (fixed for the material, as in Mitsuba).
    pub specular_probability: f32,
}

impl Scatter for PPlasticParams {
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
        let f = fresnel_dielectric(wo.dot(h), self.eta).reflectance;
        let specular = self.specular * (f * self.dist.d(h) * self.dist.g(wo, wi, h) / (4.0 * wo.z));
        let (fo, fi) = (fresnel_dielectric(wo.z, self.eta).reflectance, fresnel_dielectric(wi.z, self.eta).reflectance);
        specular + self.diffuse * ((1.0 - fo) * (1.0 - fi) * INV_PI * wi.z)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        let ps = self.specular_probability;
        let specular =
            if wo.dot(h) > 0.0 && wi.dot(h) > 0.0 { self.dist.pdf_wm(wo, h) / (4.0 * wo.dot(h)) } else { 0.0 };
        ps * specular + (1.0 - ps) * warp::cosine_hemisphere_pdf(wi.z)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if u_lobe < self.specular_probability {
            let h = self.dist.sample_wm(wo, u);
            h * (2.0 * wo.dot(h)) - wo
        } else {
            warp::cosine_hemisphere(u)
        };
        BsdfSample::non_delta(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }

    fn diffuse_reflectance(&self) -> Rgb {
        self.diffuse
    }
}

/// `pplastic`'s parameters.
///
/// | Parameter | Type | Default (JSON, Mitsuba) | |
/// |---|---|---|---|
/// | `diffuse` | texture | (JSON: required; Mitsuba 0.5) | the base's albedo |
/// | `specular` | colour | 1 | the specular lobe's tint |
/// | `eta` | float | 1.49 (JSON `ior`) | the coating's index |
/// | `roughness` | roughness | Beckmann, alpha 0.1 | (textured) `alpha`, `alpha_v` |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PPlasticDesc {
    pub diffuse: TextureDesc,
    pub specular: Rgb,
    pub eta: f32,
    pub roughness: Roughness,
}

impl Describe for PPlasticDesc {
    type Built = PPlasticMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<PPlasticMaterial, Error> {
        let diffuse = textures.texture(&self.diffuse)?;
        let (d, s) = (diffuse.mean().average(), self.specular.average());
        let specular_probability = if d + s > 0.0 { s / (d + s) } else { 0.5 };
        let dist = roughness_map(&self.roughness, textures)?;
        Ok(PPlasticMaterial { diffuse, specular: self.specular, eta: self.eta, dist, specular_probability })
    }

    fn validate(&self) -> Result<(), String> {
        checks::eta(self.eta)?;
        checks::color(self.specular, "specular reflectance")?;
        checks::roughness(Some(&self.roughness))
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        [vec![&self.diffuse], self.roughness.textures()].concat()
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        let mut textures = vec![&mut self.diffuse];
        textures.extend(self.roughness.textures_mut());
        textures
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = Vec::new();
        texture_slot("diffuse", &mut self.diffuse, &mut out);
        out.push(("specular", Slot::Color(&mut self.specular)));
        out.push(("eta", Slot::Float(&mut self.eta)));
        roughness_value_slots(&mut self.roughness, &mut out);
        out
    }
}

#[derive(Clone, Debug)]
pub struct PPlasticMaterial {
    pub diffuse: Texture,
    pub specular: Rgb,
    pub eta: f32,
    pub dist: RoughnessMap,
    pub specular_probability: f32,
}

impl Shade for PPlasticMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::PPlastic(PPlasticParams {
            diffuse: self.diffuse.eval_at(p),
            specular: self.specular,
            eta: self.eta,
            dist: self.dist.at(p.uv),
            specular_probability: self.specular_probability,
        })
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.diffuse.eval(uv)
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
