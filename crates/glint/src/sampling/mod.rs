//! Random numbers, warps from the unit square, and discrete distributions.

mod distribution;
mod filter;
mod rng;
mod sampler;
pub mod warp;

pub use crate::describe::PixelFilter;
pub use crate::describe::SamplerKind;
pub use distribution::{DiscreteSample, Distribution1d, Distribution2d, Sample2d};
pub use rng::{mix64, Rng};
pub use sampler::Sampler;

/// Power heuristic with beta = 2 (Veach 1997), for multiple importance sampling.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let a = pdf_a * pdf_a;
    let b = pdf_b * pdf_b;
    if a.is_infinite() {
        return 1.0;
    }
    if a + b == 0.0 {
        0.0
    } else {
        a / (a + b)
    }
}
