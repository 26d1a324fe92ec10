//! Per-sample random numbers for the integrators.
//!
//! Two kinds, both keyed only by (seed, pixel, sample index) so that images do not depend on
//! the thread count:
//! - `Independent`: PCG32 numbers.
//! - `Sobol`: padded, Owen-scrambled Sobol points (Burley 2020, "Practical Hash-based Owen
//!   Scrambling"). Every request (1D or 2D) gets its own independently shuffled and
//!   scrambled copy of the first two Sobol dimensions, a (0,2)-sequence, so each 2D decision
//!   (pixel position, lens, light point, BSDF direction) is well stratified across a pixel's
//!   samples. After `SOBOL_DIMENSIONS` requests the sampler continues with PCG32 numbers.
//!   Estimates stay unbiased (Owen scrambling makes each point uniformly distributed).

use super::{mix64, Rng};
use crate::describe::SamplerKind;

/// Requests per sample served by Sobol points; deep path vertices use PCG32 numbers.
const SOBOL_DIMENSIONS: u32 = 64;

pub struct Sampler {
    kind: SamplerKind,
    pixel_seed: u64,
    /// The sample index, bit-reversed: the start of every scrambled pair.
    index_reversed: u32,
    dimension: u32,
    rng: Rng,
}

impl Sampler {
    /// The sampler for sample `index` of pixel `pixel`.
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, index: u32) -> Sampler {
        Sampler {
            kind,
            pixel_seed: mix64(seed ^ mix64(pixel.wrapping_add(0x51_7CC1_B727_220A))),
            dimension: 0,
            index_reversed: index.reverse_bits(),
            rng: Rng::for_key(seed, pixel, index as u64),
        }
    }

    /// A sampler of independent numbers from an existing generator (for tests and tools).
    pub fn from_rng(rng: Rng) -> Sampler {
        Sampler { kind: SamplerKind::Independent, pixel_seed: 0, index_reversed: 0, dimension: 0, rng }
    }

    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        if self.kind == SamplerKind::Independent || self.dimension >= SOBOL_DIMENSIONS {
            return self.rng.next_f32();
        }
        // The pair's first coordinate (inlined, the second is never computed).
        self.sobol_pair()[0]
    }

    #[inline]
    pub fn next_2d(&mut self) -> [f32; 2] {
        if self.kind == SamplerKind::Independent || self.dimension >= SOBOL_DIMENSIONS {
            return self.rng.next_2d();
        }
        self.sobol_pair()
    }

    /// This request's seed and the sample index shuffled for it (itself an Owen scramble).
    #[inline]
    fn next_shuffled_index(&mut self) -> (u64, u32) {
        let dim_seed = mix64(self.pixel_seed ^ (self.dimension as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        self.dimension += 1;
        (dim_seed, laine_karras(self.index_reversed, dim_seed as u32).reverse_bits())
    }

    #[inline]
    fn sobol_pair(&mut self) -> [f32; 2] {
        // Owen scrambling hashes bit-reversed values, and the first Sobol dimension is itself
        // a bit reversal: working in the reversed domain saves four of seven reversals.
        // Equal, bit for bit, to `nested_uniform_scramble` applied step by step (tested).
        let (dim_seed, shuffled) = self.next_shuffled_index();
        let x = laine_karras(shuffled, (dim_seed >> 32) as u32).reverse_bits();
        let y = laine_karras(sobol_dim1_reversed(shuffled), mix64(dim_seed) as u32).reverse_bits();
        [to_unit(x), to_unit(y)]
    }
}

#[inline]
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The second Sobol dimension's generator matrix applied a byte at a time, bit-reversed or
/// not.
const fn sobol_dim1_tables(reversed: bool) -> [[u32; 256]; 4] {
    let mut v = [0u32; 32];
    let mut m: u64 = 1;
    let mut k = 0;
    while k < 32 {
        v[k] = (m << (31 - k)) as u32;
        if reversed {
            v[k] = v[k].reverse_bits();
        }
        m = (m << 1) ^ m;
        k += 1;
    }
    let mut t = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut b = 0;
        while b < 256 {
            let mut r = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if b & (1 << bit) != 0 {
                    r ^= v[byte * 8 + bit];
                }
                bit += 1;
            }
            t[byte][b] = r;
            b += 1;
        }
        byte += 1;
    }
    t
}

#[inline]
fn sobol_dim1_with(t: &[[u32; 256]; 4], i: u32) -> u32 {
    t[0][(i & 0xff) as usize]
        ^ t[1][((i >> 8) & 0xff) as usize]
        ^ t[2][((i >> 16) & 0xff) as usize]
        ^ t[3][(i >> 24) as usize]
}

#[cfg(test)]
fn sobol_dim1(i: u32) -> u32 {
    const TABLES: [[u32; 256]; 4] = sobol_dim1_tables(false);
    sobol_dim1_with(&TABLES, i)
}

/// `sobol_dim1(i).reverse_bits()`.
#[inline]
fn sobol_dim1_reversed(i: u32) -> u32 {
    static TABLES: [[u32; 256]; 4] = sobol_dim1_tables(true);
    sobol_dim1_with(&TABLES, i)
}

/// Laine-Karras style hash of a bit-reversed value: a random permutation in which each bit
/// depends only on the bits below it, which (with the reversal around it) is a nested
/// uniform (Owen) scramble.
#[inline]
fn laine_karras(mut v: u32, seed: u32) -> u32 {
    v = v.wrapping_add(seed);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v
}

/// Owen scrambling of `x` (Burley 2020).
#[cfg(test)]
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sobol_pairs_are_stratified_in_every_elementary_interval() {
        // A (0,2)-sequence: any 2^m consecutive-from-zero points put exactly one point in
        // each elementary interval of area 2^-m, for every shape. Check m = 6, all shapes.
        let n = 64u32;
        for pixel in 0..4u64 {
            let pts: Vec<[f32; 2]> = (0..n)
                .map(|i| {
                    let mut s = Sampler::new(SamplerKind::Sobol, 9, pixel, i);
                    s.next_2d();
                    s.next_2d()
                })
                .collect();
            for bx in 0..=6 {
                let (nx, ny) = (1usize << bx, 1usize << (6 - bx));
                let mut counts = vec![0; nx * ny];
                for p in &pts {
                    let cx = (p[0] * nx as f32) as usize;
                    let cy = (p[1] * ny as f32) as usize;
                    counts[cy * nx + cx] += 1;
                }
                assert!(counts.iter().all(|&c| c == 1), "pixel {pixel}, {nx}x{ny}: {counts:?}");
            }
        }
    }

    #[test]
    fn table_driven_dimension_matches_bit_by_bit_definition() {
        let mut v = [0u32; 32];
        let mut m: u64 = 1;
        for (k, d) in v.iter_mut().enumerate() {
            *d = (m << (31 - k)) as u32;
            m ^= m << 1;
        }
        let mut rng = Rng::new(1, 1);
        for _ in 0..10_000 {
            let i = rng.next_u32();
            let slow = (0..32).filter(|b| i >> b & 1 == 1).fold(0, |r, b| r ^ v[b]);
            assert_eq!(sobol_dim1(i), slow);
        }
    }

    #[test]
    fn pairs_equal_the_step_by_step_scramble() {
        // The definition: shuffle the index, take Sobol dimensions 0 and 1 of it, scramble
        // each with its own seed.
        for (pixel, index) in [(0u64, 0u32), (5, 1), (77, 1234), (3, u32::MAX), (9, 0x8000_0001)] {
            let mut s = Sampler::new(SamplerKind::Sobol, 42, pixel, index);
            for dimension in 0..8u64 {
                let dim_seed = mix64(s.pixel_seed ^ dimension.wrapping_mul(0x9E37_79B9_7F4A_7C15));
                let shuffled = nested_uniform_scramble(index, dim_seed as u32);
                let x = nested_uniform_scramble(shuffled.reverse_bits(), (dim_seed >> 32) as u32);
                let y = nested_uniform_scramble(sobol_dim1(shuffled), mix64(dim_seed) as u32);
                if dimension % 3 == 2 {
                    assert_eq!(s.next_f32(), to_unit(x));
                } else {
                    assert_eq!(s.next_2d(), [to_unit(x), to_unit(y)]);
                }
            }
        }
    }

    #[test]
    fn deep_requests_integrate_smooth_functions_far_better_than_independent_numbers() {
        // The mean of f(x, y) = x + y over one pixel's N = 16 samples of a late 2D request.
        // Independent points: Var = 2 (1/12) / N. Each coordinate of an Owen-scrambled
        // (0,4,2)-net has one point in each 1/N interval, uniform within it, so the variance
        // of an additive f falls to 2 (1/12) / N^3: N^2 = 256 times less. Over M = 4000
        // pixels the sample variances are known to about sqrt(2/M) = 2.2%; the bars leave a
        // factor 4 for the hash's imperfect scrambling.
        const N: u32 = 16;
        const M: u64 = 4000;
        let variance = |kind: SamplerKind, skip: u32| {
            let means: Vec<f64> = (0..M)
                .map(|pixel| {
                    let sum: f64 = (0..N)
                        .map(|i| {
                            let mut s = Sampler::new(kind, 5, pixel, i);
                            for _ in 0..skip {
                                s.next_2d();
                            }
                            let [x, y] = s.next_2d();
                            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                            (x + y) as f64
                        })
                        .sum();
                    sum / N as f64
                })
                .collect();
            let mean = means.iter().sum::<f64>() / M as f64;
            means.iter().map(|m| (m - mean) * (m - mean)).sum::<f64>() / (M - 1) as f64
        };
        let independent_theory = 2.0 / 12.0 / N as f64;
        let independent = variance(SamplerKind::Independent, 40);
        assert!((independent / independent_theory - 1.0).abs() < 0.2, "{independent} vs {independent_theory}");
        for skip in [40, SOBOL_DIMENSIONS - 1] {
            let sobol = variance(SamplerKind::Sobol, skip);
            let ratio = independent_theory / sobol;
            assert!(
                ratio > (N * N) as f64 / 4.0,
                "request {skip}: variance {sobol}, {ratio:.0}x less than independent"
            );
        }
    }

    #[test]
    fn sobol_numbers_are_uniform_on_average() {
        let mut sum = 0.0f64;
        let n = 1 << 14;
        for i in 0..n {
            let mut s = Sampler::new(SamplerKind::Sobol, 3, (i % 97) as u64, i / 97);
            for _ in 0..8 {
                sum += s.next_f32() as f64;
            }
        }
        let mean = sum / (8 * n) as f64;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }
}
