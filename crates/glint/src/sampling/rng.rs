//! PCG32 (O'Neill 2014): small state, good statistics, and cheap to seed per pixel, which
//! is what makes images independent of the thread count.

#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

const MULT: u64 = 6364136223846793005;

impl Rng {
    /// A generator for stream `stream` with seed `seed`; distinct streams are independent.
    pub fn new(seed: u64, stream: u64) -> Rng {
        let mut r = Rng { state: 0, inc: (stream << 1) | 1 };
        r.next_u32();
        r.state = r.state.wrapping_add(seed);
        r.next_u32();
        r
    }

    /// A generator keyed by several integers (seed, pixel, pass...), mixed by a hash so that
    /// neighbouring keys give unrelated sequences.
    pub fn for_key(seed: u64, a: u64, b: u64) -> Rng {
        Rng::new(mix64(seed ^ mix64(a.wrapping_add(0x9E37_79B9_7F4A_7C15))), mix64(b ^ 0xD1B5_4A32_D192_ED03))
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1), never 1.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    #[inline]
    pub fn next_2d(&mut self) -> [f32; 2] {
        [self.next_f32(), self.next_f32()]
    }

    /// Uniform in [0, 1) with 53 bits, for tests that need it.
    pub fn next_f64(&mut self) -> f64 {
        let hi = (self.next_u32() as u64) << 21;
        let lo = (self.next_u32() >> 11) as u64;
        (hi | lo) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// SplitMix64 finaliser.
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_are_in_unit_interval_with_right_mean() {
        let mut r = Rng::new(7, 3);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = r.next_f32();
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        // Mean of U(0,1) has std 1/sqrt(12 n); allow 5 sigma.
        let tol = 5.0 / (12.0 * n as f64).sqrt();
        assert!((sum / n as f64 - 0.5).abs() < tol);
    }

    #[test]
    fn streams_differ() {
        let a: Vec<u32> = (0..8).scan(Rng::for_key(1, 2, 3), |r, _| Some(r.next_u32())).collect();
        let b: Vec<u32> = (0..8).scan(Rng::for_key(1, 2, 4), |r, _| Some(r.next_u32())).collect();
        assert_ne!(a, b);
    }
}
