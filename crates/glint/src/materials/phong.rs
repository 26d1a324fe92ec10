//! `phong`: Whitted-style textured diffuse `kd` plus a glossy Phong lobe `ks` of `exponent`
//! (BSDF: [`Phong`]); `ks` may be zero.
//!
//! # The BSDF
//! Diffuse + normalised Phong lobe (Lafortune and Willems 1994): energy-conserving when
//! kd + ks <= 1, so the same material works in the Whitted and the path tracer.

use super::{Bsdf, MaterialKind, Shade, Texture, TextureCache, TexturePoint};
use crate::bsdf::{reflect_local, BsdfSample, Scatter};
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::math::{Frame, Rgb, Vec3, INV_PI, PI};
use crate::sampling::warp;

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

#[derive(Clone, Debug)]
pub struct PhongMaterial {
    pub kd: Texture,
    pub ks: Rgb,
    pub exponent: f32,
}

impl PhongMaterial {
    pub(crate) fn build(
        kd: &TextureDesc,
        ks: Rgb,
        exponent: f32,
        textures: &mut TextureCache,
    ) -> Result<PhongMaterial, Error> {
        Ok(PhongMaterial { kd: textures.texture(kd)?, ks, exponent })
    }
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
