//! Phase functions: the angular distribution of light scattered in a medium.
//!
//! Directions follow the BSDF convention: `wo` points back towards the previous vertex
//! (against the travel of the incoming light path), `wi` is the new direction. The angle
//! that matters is the one between the travel direction `-wo` and `wi`: cos θ = -wo·wi, so
//! θ = 0 is straight on. Every phase function here is sampled exactly by its density, so a
//! sample's weight is 1 and `eval` is the pdf.

use crate::math::{Frame, Vec3, PI};
use crate::sampling::warp;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// 1 / 4π in every direction.
    Isotropic,
    /// Henyey-Greenstein with mean cosine `g` in (-1, 1).
    HenyeyGreenstein { g: f32 },
}

/// Below this |g| Henyey-Greenstein is evaluated and sampled as isotropic (its inversion
/// divides by g; in f64 it is exact well below this).
const ISOTROPIC_G: f32 = 1e-6;

/// A sampled direction and its solid-angle density (which is also the phase value).
#[derive(Clone, Copy, Debug)]
pub struct PhaseSample {
    pub wi: Vec3,
    pub pdf: f32,
}

impl Phase {
    /// The phase function's value (and density) for scattering from `wo` into `wi`.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        match *self {
            Phase::Isotropic => warp::UNIFORM_SPHERE_PDF,
            Phase::HenyeyGreenstein { g } if g.abs() < ISOTROPIC_G => warp::UNIFORM_SPHERE_PDF,
            Phase::HenyeyGreenstein { g } => hg(g, -wo.dot(wi)),
        }
    }

    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> PhaseSample {
        match *self {
            Phase::Isotropic => PhaseSample { wi: warp::uniform_sphere(u), pdf: warp::UNIFORM_SPHERE_PDF },
            Phase::HenyeyGreenstein { g } if g.abs() < ISOTROPIC_G => Phase::Isotropic.sample(wo, u),
            Phase::HenyeyGreenstein { g } => {
                // Inverse of the CDF of cos θ, in f64: near |g| = 1 and g = 0 the terms cancel.
                let (g64, u0) = (g as f64, u[0] as f64);
                let s = (1.0 - g64 * g64) / (1.0 - g64 + 2.0 * g64 * u0);
                let cos_t = ((1.0 + g64 * g64 - s * s) / (2.0 * g64)).clamp(-1.0, 1.0) as f32;
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = 2.0 * PI * u[1];
                let local = Vec3 { x: sin_t * phi.cos(), y: sin_t * phi.sin(), z: cos_t };
                let wi = Frame::from_normal(-wo).to_world(local).normalize();
                PhaseSample { wi, pdf: hg(g, cos_t) }
            }
        }
    }
}

/// The Henyey-Greenstein density at cos θ from the travel direction (in f64: near |g| = 1
/// the denominator cancels to (1 - |g|)² at the peak).
fn hg(g: f32, cos_t: f32) -> f32 {
    let (g, c) = (g as f64, cos_t as f64);
    let denom = (1.0 + g * g - 2.0 * g * c).max(0.0);
    ((1.0 - g * g) / (4.0 * std::f64::consts::PI * denom * denom.sqrt())) as f32
}
