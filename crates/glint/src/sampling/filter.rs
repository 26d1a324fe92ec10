//! Pixel reconstruction filters, applied by filter importance sampling: each camera sample's
//! offset from the pixel centre is drawn from the filter itself, and every sample has weight
//! one. The expected pixel value is the filtered image, and pixels stay independent, which
//! keeps rendering deterministic and free of splatting races.

use crate::math::PI;

#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub enum PixelFilter {
    /// Uniform over the pixel.
    #[default]
    Box,
    /// Triangle of the given radius (pixels).
    Tent { radius: f32 },
    /// Gaussian of the given standard deviation (pixels), truncated at 4 sigma... as
    /// Mitsuba does (its radius is 4 stddev).
    Gaussian { stddev: f32 },
}

impl PixelFilter {
    /// Offset from the pixel centre, in pixels, for uniform `u`.
    pub fn sample(&self, u: [f32; 2]) -> [f32; 2] {
        match *self {
            PixelFilter::Box => [u[0] - 0.5, u[1] - 0.5],
            PixelFilter::Tent { radius } => [sample_tent(u[0]) * radius, sample_tent(u[1]) * radius],
            PixelFilter::Gaussian { stddev } => {
                // Box-Muller, rejected beyond the 4-sigma support by folding back into it.
                let r = (-2.0 * (1.0 - u[0]).max(1e-12).ln()).sqrt();
                let phi = 2.0 * PI * u[1];
                let lim = 4.0;
                let clamp = |v: f32| if v.abs() > lim { v % lim } else { v };
                [clamp(r * phi.cos()) * stddev, clamp(r * phi.sin()) * stddev]
            }
        }
    }
}

/// Inverse CDF of the unit tent on [-1, 1].
fn sample_tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).sqrt()
    }
}
