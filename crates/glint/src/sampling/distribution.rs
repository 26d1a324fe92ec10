/// A discrete distribution over `n` items proportional to non-negative weights, sampled by
/// binary search over the cumulative sums.
#[derive(Clone, Debug)]
pub struct Distribution1d {
    cdf: Vec<f64>,
    total: f64,
}

/// The item chosen and the probability of choosing it.
#[derive(Clone, Copy, Debug)]
pub struct DiscreteSample {
    pub index: usize,
    pub pmf: f32,
    /// The random number rescaled to [0, 1) within the chosen item, for reuse.
    pub remapped: f32,
}

impl Distribution1d {
    /// `None` when there are no items or all weights are zero.
    pub fn new(weights: &[f32]) -> Option<Distribution1d> {
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for &w in weights {
            acc += w.max(0.0) as f64;
            cdf.push(acc);
        }
        if acc <= 0.0 || !acc.is_finite() {
            return None;
        }
        Some(Distribution1d { cdf, total: acc })
    }
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    pub fn total(&self) -> f64 {
        self.total
    }
    pub fn pmf(&self, i: usize) -> f32 {
        ((self.cdf[i + 1] - self.cdf[i]) / self.total) as f32
    }
    pub fn sample(&self, u: f32) -> DiscreteSample {
        let target = u as f64 * self.total;
        // First index whose upper cumulative value exceeds target, skipping zero-weight items.
        let mut lo = 0usize;
        let mut hi = self.len() - 1;
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.cdf[mid + 1] <= target {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let w = self.cdf[lo + 1] - self.cdf[lo];
        let remapped = if w > 0.0 { ((target - self.cdf[lo]) / w).clamp(0.0, 0.999_999_94) as f32 } else { 0.0 };
        DiscreteSample { index: lo, pmf: (w / self.total) as f32, remapped }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_weights_are_never_chosen() {
        let d = Distribution1d::new(&[0.0, 1.0, 0.0, 3.0, 0.0]).unwrap();
        for i in 0..1000 {
            let s = d.sample(i as f32 / 1000.0);
            assert!(s.index == 1 || s.index == 3, "{}", s.index);
        }
        assert!((d.pmf(3) - 0.75).abs() < 1e-6);
    }

    #[test]
    fn all_zero_is_none() {
        assert!(Distribution1d::new(&[0.0, 0.0]).is_none());
        assert!(Distribution1d::new(&[]).is_none());
    }
}
