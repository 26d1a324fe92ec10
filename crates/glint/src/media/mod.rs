//! Participating media: what fills the space between surfaces. A ray travelling a distance
//! `t` through a homogeneous medium keeps the fraction exp(-σt t) of its radiance per channel;
//! where it scatters, the phase function picks the new direction.
//!
//! Shapes bound media: each side of a shape may name one (`interior` behind the geometric
//! normal, `exterior` in front), and a ray crossing such a shape enters the medium on the
//! side it goes to. The camera names the medium it starts in.

mod grid;
mod phase;
pub use grid::GridVolume;
pub use phase::{Phase, PhaseSample};

use crate::math::{Ray, Rgb, Vec3};
use std::sync::Arc;

/// A homogeneous medium: constant extinction (per unit length), and an albedo that is
/// constant or varies through space (a grid volume): the scattering coefficient at a point
/// is `sigma_t * albedo(p)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    pub sigma_t: Rgb,
    pub albedo: Albedo,
    pub phase: Phase,
    /// Next-event estimation from scattering points in this medium.
    pub sample_emitters: bool,
}

/// A medium's single-scattering albedo.
#[derive(Clone, Debug, PartialEq)]
pub enum Albedo {
    Constant(Rgb),
    Grid(Arc<GridVolume>),
}

impl Albedo {
    #[inline]
    pub fn at(&self, p: Vec3) -> Rgb {
        match self {
            Albedo::Constant(a) => *a,
            Albedo::Grid(g) => g.eval(p),
        }
    }
}

impl Medium {
    pub fn new(sigma_t: Rgb, albedo: Albedo, phase: Phase, sample_emitters: bool) -> Medium {
        Medium { sigma_t, albedo, phase, sample_emitters }
    }

    /// The scattering coefficient at world point `p`.
    #[inline]
    pub fn sigma_s(&self, p: Vec3) -> Rgb {
        self.sigma_t * self.albedo.at(p)
    }

    /// The fraction of light that crosses a distance `t` unscattered, per channel.
    #[inline]
    pub fn transmittance(&self, t: f32) -> Rgb {
        self.sigma_t.map(|s| exp_neg(s, t))
    }
}

/// exp(-σ t), with a clear medium (σ = 0) transparent even over an infinite distance.
#[inline]
pub fn exp_neg(sigma: f32, t: f32) -> f32 {
    if sigma == 0.0 {
        1.0
    } else {
        (-sigma * t).exp()
    }
}

/// Which media a shape separates (indices into the world's media); both `None` is no
/// medium boundary at all: rays keep the medium they are in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MediumBoundary {
    pub interior: Option<u32>,
    pub exterior: Option<u32>,
}

impl MediumBoundary {
    pub fn is_transition(&self) -> bool {
        self.interior.is_some() || self.exterior.is_some()
    }

    /// The medium a ray leaving the surface along a direction with `cos_n = dir · n_geometric`
    /// travels in, or `current` when the shape bounds no medium.
    #[inline]
    pub fn medium_after(&self, cos_n: f32, current: Option<u32>) -> Option<u32> {
        if !self.is_transition() {
            current
        } else if cos_n > 0.0 {
            self.exterior
        } else {
            self.interior
        }
    }
}

/// One free-flight sample: where the ray scatters (`None`: it reaches the surface first),
/// the path contribution of the segment per channel (`transmittance * sigma_s` at a
/// scattering point, `transmittance` when the surface is reached), and the density with
/// which each channel's own exponential would have produced that outcome (`sigma_t *
/// transmittance`, or the probability `transmittance` of getting past `t_max`).
#[derive(Clone, Copy, Debug)]
pub struct FreeFlight {
    pub t: Option<f32>,
    pub value: Rgb,
    pub density: Rgb,
}

/// Samples a free-flight distance along `ray` from channel `channel`'s exponential (`u`
/// uniform in [0, 1); `t_max` the distance to the next surface); the albedo is looked up
/// where the ray scatters. The volumetric path tracer weights the
/// path by the mean of the channels' path densities (spectral MIS), so that the estimate is
/// unbiased in every channel whichever channel drew the distances.
pub fn sample_distance(m: &Medium, ray: &Ray, t_max: f32, channel: usize, u: f32) -> FreeFlight {
    let sigma = m.sigma_t.channel(channel.min(2));
    let t = if sigma > 0.0 { -(1.0 - u).ln() / sigma } else { f32::INFINITY };
    if t < t_max {
        let tr = m.transmittance(t);
        FreeFlight { t: Some(t), value: tr * m.sigma_s(ray.at(t)), density: m.sigma_t * tr }
    } else {
        let tr = m.transmittance(t_max);
        FreeFlight { t: None, value: tr, density: tr }
    }
}
