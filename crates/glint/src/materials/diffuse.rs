//! `diffuse`: Lambertian reflection of a textured `reflectance` (BSDF: [`Diffuse`]).
//!
//! # The BSDF
//! Lambertian reflection (Mitsuba's `diffuse`).
//!
//! # Differentiable
//! `reflectance`, a constant colour or a bitmap texture per texel. See `docs/differentiable.md`.

use super::{Bsdf, Describe, MaterialKind, Shade, Texture, TextureCache, TexturePoint};
use crate::bsdf::{BsdfSample, Scatter};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::math::{Rgb, Vec3, INV_PI};
use crate::sampling::warp;
use serde::{Deserialize, Serialize};

/// Reflects `reflectance` of the light, evenly in every direction of the upper hemisphere.
#[derive(Clone, Copy, Debug)]
pub struct Diffuse {
    pub reflectance: Rgb,
}

impl Scatter for Diffuse {
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
        self.reflectance * (INV_PI * wi.z)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            0.0
        } else {
            warp::cosine_hemisphere_pdf(wi.z)
        }
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = warp::cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.reflectance,
            pdf: warp::cosine_hemisphere_pdf(wi.z),
            delta: false,
            eta: 1.0,
        })
    }

    fn diffuse_reflectance(&self) -> Rgb {
        self.reflectance
    }
}

/// `diffuse`'s parameters.
///
/// | Parameter | Type | Default (JSON, Mitsuba) | |
/// |---|---|---|---|
/// | `reflectance` | texture | JSON: required; Mitsuba 0.5 | the albedo |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiffuseDesc {
    pub reflectance: TextureDesc,
}

impl Describe for DiffuseDesc {
    type Built = DiffuseMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<DiffuseMaterial, Error> {
        Ok(DiffuseMaterial { reflectance: textures.texture(&self.reflectance)? })
    }

    fn validate(&self) -> Result<(), String> {
        Ok(())
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        vec![&self.reflectance]
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        vec![&mut self.reflectance]
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = Vec::new();
        texture_slot("reflectance", &mut self.reflectance, &mut out);
        out
    }
}

#[derive(Clone, Debug)]
pub struct DiffuseMaterial {
    pub reflectance: Texture,
}

impl Shade for DiffuseMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::Diffuse(Diffuse { reflectance: self.reflectance.eval_at(p) })
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.reflectance.eval(uv)
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
