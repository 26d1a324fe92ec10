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
use crate::sampling::Sampler;
use std::sync::Arc;

/// A medium: extinction `sigma_t` per unit length, times a grey density grid where the
/// medium is heterogeneous, and an albedo that is constant or varies through space (a grid
/// volume): the scattering coefficient at a point is `sigma_t(p) * albedo(p)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    pub sigma_t: Rgb,
    pub albedo: Albedo,
    pub phase: Phase,
    /// Next-event estimation from scattering points in this medium.
    pub sample_emitters: bool,
    /// Heterogeneous media: the density (a grey grid) that multiplies `sigma_t` (then grey),
    /// with its majorant `sigma_t * max(density)`.
    pub density: Option<Density>,
    /// Crossed without sampling a distance (a homogeneous medium that scatters nothing:
    /// see [`sample_distance`]).
    pub absorbing_only: bool,
}

/// A heterogeneous medium's density grid and the extinction bound tracking uses. Outside
/// the grid's box the density is 0 (Mitsuba's heterogeneous medium lives in its grid's
/// bounding box), whatever the wrap mode.
#[derive(Clone, Debug, PartialEq)]
pub struct Density {
    pub grid: Arc<GridVolume>,
    /// At least the extinction anywhere: `sigma_t * max(grid)`.
    pub majorant: f32,
}

impl Density {
    /// The density at world point `p`: the grid's value inside its box, 0 outside.
    #[inline]
    pub fn at(&self, p: Vec3) -> f32 {
        if self.grid.contains(p) {
            self.grid.eval(p).r
        } else {
            0.0
        }
    }
}

/// The most tentative collisions one delta- or ratio-tracking walk takes; a walk that
/// reaches it (a majorant far above the extinction over a long distance) stops there.
pub const MAX_TRACKING_STEPS: u32 = 1 << 20;

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
        Medium { sigma_t, albedo, phase, sample_emitters, density: None, absorbing_only: false }
    }

    /// A heterogeneous medium: grey extinction `sigma_t * density(p)`.
    pub fn heterogeneous(
        sigma_t: f32,
        density: Arc<GridVolume>,
        albedo: Albedo,
        phase: Phase,
        sample_emitters: bool,
    ) -> Medium {
        let majorant = sigma_t * density.max_value().max(0.0);
        Medium {
            sigma_t: Rgb::splat(sigma_t),
            albedo,
            phase,
            sample_emitters,
            density: Some(Density { grid: density, majorant }),
            absorbing_only: false,
        }
    }

    /// The extinction at world point `p` (grey in heterogeneous media).
    #[inline]
    pub fn sigma_t_at(&self, p: Vec3) -> Rgb {
        match &self.density {
            None => self.sigma_t,
            Some(d) => self.sigma_t * d.at(p),
        }
    }

    /// The fraction of light that crosses the first `t` of `ray` unscattered: exact in
    /// homogeneous media, an unbiased ratio-tracking estimate in heterogeneous ones (the
    /// product of 1 - sigma_t / majorant over tentative collisions drawn at the majorant's
    /// rate).
    pub fn transmittance_along(&self, ray: &Ray, t: f32, rng: &mut Sampler) -> Rgb {
        let Some(d) = &self.density else { return self.transmittance(t) };
        if !(d.majorant > 0.0) {
            return Rgb::WHITE;
        }
        // Only the part of the ray inside the grid's box has any extinction.
        let Some((t0, t1)) = d.grid.clip(ray, t) else { return Rgb::WHITE };
        let mut tr = 1.0f32;
        let mut s = t0;
        for _ in 0..MAX_TRACKING_STEPS {
            let next = s - (1.0 - rng.next_f32()).ln() / d.majorant;
            if !(next < t1) || next <= s {
                break;
            }
            s = next;
            tr *= 1.0 - (self.sigma_t.r * d.at(ray.at(s)) / d.majorant).clamp(0.0, 1.0);
            if tr <= 0.0 {
                break;
            }
        }
        Rgb::splat(tr)
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
///
/// In a heterogeneous medium the distance comes from delta tracking: tentative collisions
/// at the majorant's rate, each real with probability sigma_t(p) / majorant; the extinction
/// being grey, every channel has the same density and the outcome weighs the albedo at a
/// scattering point, 1 at the surface.
///
/// A medium marked `absorbing_only` (homogeneous, albedo 0) is crossed without a distance
/// drawn: a collision there could only end the path, so every channel's strategy is given the
/// same certain outcome (density 1) and the path carries the transmittance to the surface,
/// the same expectation with no variance. Other media that happen to have albedo 0 keep
/// free-flight sampling.
pub fn sample_distance(m: &Medium, ray: &Ray, t_max: f32, channel: usize, rng: &mut Sampler) -> FreeFlight {
    if let Some(d) = &m.density {
        return delta_tracking(m, d, ray, t_max, rng);
    }
    if m.absorbing_only {
        return FreeFlight { t: None, value: m.transmittance(t_max), density: Rgb::WHITE };
    }
    let u = rng.next_f32();
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

fn delta_tracking(m: &Medium, d: &Density, ray: &Ray, t_max: f32, rng: &mut Sampler) -> FreeFlight {
    let passed = FreeFlight { t: None, value: Rgb::WHITE, density: Rgb::WHITE };
    if !(d.majorant > 0.0) {
        return passed;
    }
    let Some((t0, t1)) = d.grid.clip(ray, t_max) else { return passed };
    let mut s = t0;
    for _ in 0..MAX_TRACKING_STEPS {
        let next = s - (1.0 - rng.next_f32()).ln() / d.majorant;
        if !(next < t1) || next <= s {
            return passed;
        }
        s = next;
        let p = ray.at(s);
        let sigma = m.sigma_t.r * d.at(p);
        if rng.next_f32() * d.majorant < sigma {
            return FreeFlight { t: Some(s), value: m.albedo.at(p), density: Rgb::WHITE };
        }
    }
    passed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::describe::{GridFilter, GridWrap};
    use crate::math::{rgb, vec3, Transform};
    use crate::sampling::SamplerKind;

    /// A slab along x over [0, 1): two cells (nearest) of density 0.5 and 1, sigma_t 2:
    /// optical depth along x from 0 to 1 is 2 (0.5 * 0.5 + 1 * 0.5) = 1.5.
    fn slab() -> Medium {
        let grid =
            GridVolume::new([2, 1, 1], 1, vec![0.5, 1.0], GridFilter::Nearest, GridWrap::Clamp, Transform::IDENTITY)
                .unwrap();
        Medium::heterogeneous(2.0, Arc::new(grid), Albedo::Constant(Rgb::splat(0.8)), Phase::Isotropic, true)
    }

    const N: usize = 40_000;

    #[test]
    fn an_absorbing_only_medium_is_crossed_carrying_its_transmittance() {
        let sigma = rgb(0.5, 1.0, 2.0);
        let mut m = Medium::new(sigma, Albedo::Constant(Rgb::BLACK), Phase::Isotropic, false);
        let ray = Ray::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0));
        let mut rng = Sampler::new(SamplerKind::Independent, 3, 0, 0);
        // Marked: the surface is always reached, the path weighed by exp(-sigma t) per channel
        // and every channel's density 1 (the same outcome for all). No random number is used.
        m.absorbing_only = true;
        for channel in 0..3 {
            let f = sample_distance(&m, &ray, 1.5, channel, &mut rng);
            assert!(f.t.is_none());
            assert_eq!(f.value, m.transmittance(1.5));
            assert_eq!(f.density, Rgb::WHITE);
        }
        // Unmarked, the same medium samples distances: some paths are absorbed.
        m.absorbing_only = false;
        let absorbed = (0..1000).filter(|_| sample_distance(&m, &ray, 1.5, 2, &mut rng).t.is_some()).count();
        // exp(-2 x 1.5) = 0.05 pass: about 950 of 1000 collide.
        assert!((900..1000).contains(&absorbed), "{absorbed}");
    }

    #[test]
    fn ratio_tracking_through_a_slab_averages_exp_minus_tau() {
        let m = slab();
        let ray = Ray::new(vec3(0.0, 0.5, 0.5), vec3(1.0, 0.0, 0.0));
        let mut rng = Sampler::new(SamplerKind::Independent, 7, 0, 0);
        // Beyond x = 1 the ray has left the grid's box: no more extinction (t = 3).
        for (t, tau) in [(1.0f32, 1.5f64), (0.5, 0.5), (0.75, 1.0), (3.0, 1.5)] {
            let xs: Vec<f64> = (0..N).map(|_| m.transmittance_along(&ray, t, &mut rng).r as f64).collect();
            let mean = xs.iter().sum::<f64>() / N as f64;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (N - 1) as f64;
            let se = (var / N as f64).sqrt();
            let exact = (-tau).exp();
            // 4.5 standard errors: a false alarm about once in 150,000 runs.
            assert!((mean - exact).abs() <= 4.5 * se, "t {t}: {mean} ± {se}, exact {exact}");
        }
    }

    #[test]
    fn delta_tracking_passes_a_slab_with_probability_exp_minus_tau_and_weighs_the_albedo() {
        let m = slab();
        let ray = Ray::new(vec3(0.0, 0.5, 0.5), vec3(1.0, 0.0, 0.0));
        let mut rng = Sampler::new(SamplerKind::Independent, 9, 0, 0);
        let mut passed = 0usize;
        let mut in_first_half = 0usize;
        for _ in 0..N {
            let f = sample_distance(&m, &ray, 1.0, 0, &mut rng);
            match f.t {
                None => {
                    passed += 1;
                    assert_eq!((f.value, f.density), (Rgb::WHITE, Rgb::WHITE));
                }
                Some(t) => {
                    assert!((0.0..1.0).contains(&t));
                    assert_eq!((f.value, f.density), (Rgb::splat(0.8), Rgb::WHITE));
                    in_first_half += usize::from(t < 0.5);
                }
            }
        }
        for (count, p) in [(passed, (-1.5f64).exp()), (in_first_half, 1.0 - (-0.5f64).exp())] {
            let freq = count as f64 / N as f64;
            let se = (p * (1.0 - p) / N as f64).sqrt();
            assert!((freq - p).abs() <= 4.5 * se, "{freq} vs {p} ± {se}");
        }
    }

    #[test]
    fn a_constant_density_samples_distances_as_the_homogeneous_medium() {
        // Density 1 in a box around the ray, sigma_t 1.3: the heterogeneous medium's
        // distances and transmittances follow exp(-1.3 t) as the homogeneous one's do.
        let to_world = Transform::translate(vec3(-50.0, -50.0, -50.0))
            .then_after(&Transform::scale(vec3(100.0, 100.0, 100.0)).unwrap());
        let grid = GridVolume::new([1, 1, 1], 1, vec![1.0], GridFilter::Trilinear, GridWrap::Clamp, to_world).unwrap();
        let het = Medium::heterogeneous(1.3, Arc::new(grid), Albedo::Constant(Rgb::WHITE), Phase::Isotropic, true);
        let ray = Ray::new(vec3(-3.0, 0.2, 0.9), vec3(0.6, 0.0, 0.8));
        let mut rng = Sampler::new(SamplerKind::Independent, 11, 0, 0);
        let t_max = 1.0;
        let mut sum_t = 0.0f64;
        let mut scattered = 0usize;
        for _ in 0..N {
            if let Some(t) = sample_distance(&het, &ray, t_max, 0, &mut rng).t {
                sum_t += t as f64;
                scattered += 1;
            }
            // With the majorant equal to the extinction, ratio tracking is 0 or 1 (up to the
            // rounding of the trilinear weights).
            let tr = het.transmittance_along(&ray, 0.4, &mut rng).r;
            assert!(tr < 1e-5 || tr == 1.0, "{tr}");
        }
        let s = 1.3f64;
        let p = 1.0 - (-s * t_max as f64).exp();
        let freq = scattered as f64 / N as f64;
        assert!((freq - p).abs() <= 4.5 * (p * (1.0 - p) / N as f64).sqrt(), "{freq} vs {p}");
        // Mean distance of a scattering event, given one before t_max: 1/s - t_max e^{-s t_max} / p.
        let exact = 1.0 / s - t_max as f64 * (-s * t_max as f64).exp() / p;
        let mean = sum_t / scattered as f64;
        // Standard deviation of a truncated exponential is below t_max / 2.
        assert!((mean - exact).abs() <= 4.5 * 0.5 / (scattered as f64).sqrt(), "{mean} vs {exact}");
    }
}
