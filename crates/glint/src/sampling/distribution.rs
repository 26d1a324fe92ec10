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

/// A discrete distribution over the cells of a `width` × `height` grid, proportional to
/// non-negative weights: a row by the rows' sums (with `u[1]`), then a column within it
/// (with `u[0]`). Shared by the environment map and textured area lights.
#[derive(Clone, Debug)]
pub struct Distribution2d {
    rows: Distribution1d,
    cols: Vec<Distribution1d>,
}

/// The cell chosen, its probability, and the random numbers rescaled within it.
#[derive(Clone, Copy, Debug)]
pub struct Sample2d {
    pub x: usize,
    pub y: usize,
    pub pmf: f32,
    pub remapped: [f32; 2],
}

impl Distribution2d {
    /// `weights` row by row (`weights[y * width + x]`); `None` when they are all zero.
    pub fn new(weights: &[f32], width: usize, height: usize) -> Option<Distribution2d> {
        if width == 0 || weights.len() != width * height {
            return None;
        }
        let mut cols = Vec::with_capacity(height);
        let mut row_weights = Vec::with_capacity(height);
        for row in weights.chunks(width) {
            row_weights.push(row.iter().map(|w| w.max(0.0)).sum::<f32>());
            // A black row is never chosen, but keep a valid distribution for it.
            cols.push(Distribution1d::new(row).unwrap_or_else(|| Distribution1d::new(&vec![1.0; width]).unwrap()));
        }
        let rows = Distribution1d::new(&row_weights)?;
        Some(Distribution2d { rows, cols })
    }

    pub fn width(&self) -> usize {
        self.cols[0].len()
    }

    pub fn height(&self) -> usize {
        self.rows.len()
    }

    /// The probability of cell (x, y).
    pub fn pmf(&self, x: usize, y: usize) -> f32 {
        self.rows.pmf(y) * self.cols[y].pmf(x)
    }

    pub fn sample(&self, u: [f32; 2]) -> Sample2d {
        let row = self.rows.sample(u[1]);
        let col = self.cols[row.index].sample(u[0]);
        Sample2d { x: col.index, y: row.index, pmf: row.pmf * col.pmf, remapped: [col.remapped, row.remapped] }
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

    #[test]
    fn grid_cells_are_chosen_by_weight_and_pmfs_sum_to_one() {
        let w = [1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 2.0, 2.0, 0.0];
        let d = Distribution2d::new(&w, 3, 3).unwrap();
        let total: f32 = (0..3).flat_map(|y| (0..3).map(move |x| (x, y))).map(|(x, y)| d.pmf(x, y)).sum();
        assert!((total - 1.0).abs() < 1e-6);
        let n = 400;
        let mut counts = [0u32; 9];
        for i in 0..n {
            for j in 0..n {
                let s = d.sample([(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32]);
                assert_eq!(s.pmf, d.pmf(s.x, s.y));
                counts[s.y * 3 + s.x] += 1;
            }
        }
        // A stratified grid of u lands in each cell in proportion to its weight (to one row
        // or column of strata).
        for (k, &c) in counts.iter().enumerate() {
            let expected = w[k] / 8.0 * (n * n) as f32;
            assert!((c as f32 - expected).abs() <= 2.0 * n as f32, "cell {k}: {c} vs {expected}");
        }
        assert!(Distribution2d::new(&[0.0; 4], 2, 2).is_none());
    }
}
