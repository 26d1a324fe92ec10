//! Metals (Mitsuba's `conductor` and `roughconductor`): Fresnel reflection with a complex
//! index of refraction per channel, off a perfect mirror or a microfacet surface.

use super::{fresnel_conductor, reflect_local, BsdfSample, Microfacet, Scatter};
use crate::math::{Rgb, Vec3};

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
