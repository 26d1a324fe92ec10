//! Pixel reconstruction filters. Camera samples are placed uniformly in their pixel; the box
//! keeps each sample in its own pixel, and the others are splatted by the film
//! (`render::splat`) over every pixel within their radius, weighted as Mitsuba weights them,
//! each pixel dividing by the weights it received.

use crate::describe::PixelFilter;

impl PixelFilter {
    /// Whether samples are splatted over neighbouring pixels (every filter but the box,
    /// whose reach is the sample's own pixel).
    pub fn splats(&self) -> bool {
        !matches!(self, PixelFilter::Box)
    }

    /// Reach in pixels from a sample to the centres of the pixels it contributes to.
    pub fn radius(&self) -> f32 {
        match *self {
            PixelFilter::Box => 0.5,
            PixelFilter::Tent { radius } => radius,
            PixelFilter::Gaussian { stddev } => 4.0 * stddev,
        }
    }

    /// The 1D weight at offset `x` (pixels) from the sample, as Mitsuba's filters: the tent
    /// `max(0, 1 - |x| / r)`, and the gaussian `exp(-x^2 / 2s^2)` less its value at the
    /// radius (so that it reaches zero there), clamped at zero. Not normalised: pixels divide
    /// by their summed weights.
    pub fn eval(&self, x: f32) -> f32 {
        match *self {
            PixelFilter::Box => {
                if x.abs() <= 0.5 {
                    1.0
                } else {
                    0.0
                }
            }
            PixelFilter::Tent { radius } => (1.0 - x.abs() / radius).max(0.0),
            PixelFilter::Gaussian { stddev } => {
                let alpha = -1.0 / (2.0 * stddev * stddev);
                let r = 4.0 * stddev;
                ((alpha * x * x).exp() - (alpha * r * r).exp()).max(0.0)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_peak_at_zero_and_vanish_at_the_radius() {
        for f in [PixelFilter::Tent { radius: 1.5 }, PixelFilter::Gaussian { stddev: 0.5 }] {
            let r = f.radius();
            assert!(f.eval(0.0) > 0.9 && f.eval(0.0) <= 1.0, "{f:?}");
            assert!(f.eval(r).abs() < 1e-6 && f.eval(r * 1.01) == 0.0 && f.eval(-r * 1.5) == 0.0, "{f:?}");
            assert_eq!(f.eval(0.3), f.eval(-0.3));
            assert!(f.eval(0.2) > f.eval(0.6));
            assert_eq!(f.eval(f32::NAN).max(0.0), 0.0);
        }
    }
}
