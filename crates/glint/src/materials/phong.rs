//! `phong`: Whitted-style textured diffuse `kd` plus a glossy Phong lobe `ks` of `exponent`
//! (BSDF: [`Phong`]); `ks` may be zero.
//!
//! # The BSDF
//! Diffuse + normalised Phong lobe (Lafortune and Willems 1994): energy-conserving when
//! kd + ks <= 1, so the same material works in the Whitted and the path tracer.
//!
//! # Differentiable
//! `kd` and `ks` (constant colours, or bitmap textures per texel) and `exponent`. See `docs/differentiable.md`.

use super::{Bsdf, Describe, MaterialKind, Shade, Texture, TextureCache, TexturePoint};
use crate::bsdf::{reflect_local, BsdfSample, Scatter};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::{checks, TextureDesc};
use crate::error::Error;
use crate::math::{Frame, Rgb, Vec3, INV_PI, PI};
use crate::sampling::warp;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug)]
pub struct Phong {
    pub kd: Rgb,
    pub ks: Rgb,
    pub exponent: f32,
}

impl Phong {
    fn specular_probability(&self) -> f32 {
        let d = self.kd.average();
        let s = self.ks.average();
        if d + s <= 0.0 {
            0.0
        } else {
            s / (d + s)
        }
    }

    /// The specular lobe's value without the cosine: (n+2)/(2π) cos^n α.
    pub fn lobe(&self, wo: Vec3, wi: Vec3) -> f32 {
        let cos_alpha = reflect_local(wo).dot(wi);
        if cos_alpha <= 0.0 {
            0.0
        } else {
            (self.exponent + 2.0) * 0.5 * INV_PI * cos_alpha.powf(self.exponent)
        }
    }
}

impl Scatter for Phong {
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
        (self.kd * INV_PI + self.ks * self.lobe(wo, wi)) * wi.z
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability();
        let cos_alpha = reflect_local(wo).dot(wi).max(0.0);
        let spec = (self.exponent + 1.0) * 0.5 * INV_PI * cos_alpha.powf(self.exponent);
        ps * spec + (1.0 - ps) * warp::cosine_hemisphere_pdf(wi.z)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if u_lobe < self.specular_probability() {
            // cos^n lobe around the mirror direction: cos α = u^(1/(n+1)).
            let cos_a = u[0].powf(1.0 / (self.exponent + 1.0));
            let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
            let phi = 2.0 * PI * u[1];
            let local = Vec3 { x: sin_a * phi.cos(), y: sin_a * phi.sin(), z: cos_a };
            Frame::from_normal(reflect_local(wo)).to_world(local)
        } else {
            warp::cosine_hemisphere(u)
        };
        BsdfSample::non_delta(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }

    fn diffuse_reflectance(&self) -> Rgb {
        self.kd
    }
}

/// `phong`'s parameters.
///
/// | Parameter | Type | Default (JSON) | |
/// |---|---|---|---|
/// | `kd` | texture | (required) | diffuse reflectance |
/// | `ks` | colour | 0 | glossy reflectance |
/// | `exponent` | float | 32 | Phong exponent, at least 0 |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhongDesc {
    pub kd: TextureDesc,
    pub ks: Rgb,
    pub exponent: f32,
}

impl Describe for PhongDesc {
    type Built = PhongMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<PhongMaterial, Error> {
        Ok(PhongMaterial { kd: textures.texture(&self.kd)?, ks: self.ks, exponent: self.exponent })
    }

    fn validate(&self) -> Result<(), String> {
        checks::color(self.ks, "ks")?;
        if !(self.exponent >= 0.0 && self.exponent.is_finite()) {
            return Err(format!("Phong exponent {} must be finite and at least 0", self.exponent));
        }
        Ok(())
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        vec![&self.kd]
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        vec![&mut self.kd]
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = Vec::new();
        texture_slot("kd", &mut self.kd, &mut out);
        out.push(("ks", Slot::Color(&mut self.ks)));
        out.push(("exponent", Slot::Float(&mut self.exponent)));
        out
    }
}

#[derive(Clone, Debug)]
pub struct PhongMaterial {
    pub kd: Texture,
    pub ks: Rgb,
    pub exponent: f32,
}

impl Shade for PhongMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::Phong(Phong { kd: self.kd.eval_at(p), ks: self.ks, exponent: self.exponent })
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        (self.kd.eval(uv) + self.ks).map(|v| v.min(1.0))
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
