//! The binned SAH split search of the BVH build (Wald 2007): each reference's centre falls
//! into one of `BINS` bins per axis, the bins' boxes and counts are gathered in one pass over
//! the references for all three axes at once, and a sweep over the bin boundaries scores each
//! candidate split with the SAH.
//!
//! The pass is what the build spends its time on, so it is kept lean: a multiply per axis
//! maps a centre to its bin (the reciprocal of the extent is taken once per node), and boxes
//! grow by plain comparisons (`minss`/`maxss`; build boxes are never NaN) instead of the
//! NaN-aware `f32::min`. Large nodes are binned in parallel chunks whose bins are merged.

use super::bvh::{SAH_INTERSECT_COST, SAH_TRAVERSAL_COST};
use crate::math::{Aabb, Vec3};
use rayon::prelude::*;

pub const BINS: usize = 16;
/// References per parallel binning task.
const CHUNK: usize = 16 * 1024;

/// What the split search needs of a build reference.
pub trait Binned: Sync {
    fn bounds(&self) -> &Aabb;
    fn centre(&self) -> Vec3;
}

/// Maps a centre coordinate to its bin on each axis.
#[derive(Clone, Copy, Debug)]
pub struct BinMap {
    lo: [f32; 3],
    scale: [f32; 3],
}

impl BinMap {
    /// Bins spanning the box of the centres; an axis of zero extent puts everything in bin 0.
    pub fn new(centre_bounds: &Aabb) -> BinMap {
        let ext = centre_bounds.extent();
        let mut scale = [0.0; 3];
        for (a, s) in scale.iter_mut().enumerate() {
            if ext[a] > 0.0 {
                *s = BINS as f32 / ext[a];
            }
        }
        BinMap { lo: [centre_bounds.min.x, centre_bounds.min.y, centre_bounds.min.z], scale }
    }

    #[inline(always)]
    pub fn bin(&self, c: f32, axis: usize) -> usize {
        // `as usize` saturates, so rounding below `lo` lands in bin 0.
        (((c - self.lo[axis]) * self.scale[axis]) as usize).min(BINS - 1)
    }
}

/// A split: references whose bin on `axis` is below `bin` go left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Split {
    pub axis: usize,
    pub bin: usize,
    pub cost: f32,
}

#[derive(Clone, Copy)]
struct Bins {
    /// `lo[axis][bin]`, `hi[axis][bin]`: the bin's box corners.
    lo: [[Vec3; BINS]; 3],
    hi: [[Vec3; BINS]; 3],
    count: [[u32; BINS]; 3],
}

impl Bins {
    const EMPTY: Bins = Bins {
        lo: [[Vec3 { x: f32::INFINITY, y: f32::INFINITY, z: f32::INFINITY }; BINS]; 3],
        hi: [[Vec3 { x: f32::NEG_INFINITY, y: f32::NEG_INFINITY, z: f32::NEG_INFINITY }; BINS]; 3],
        count: [[0; BINS]; 3],
    };

    fn gather<R: Binned>(refs: &[R], map: &BinMap) -> Bins {
        let mut bins = Bins::EMPTY;
        for r in refs {
            let (b, c) = (r.bounds(), r.centre());
            for (axis, ca) in [c.x, c.y, c.z].into_iter().enumerate() {
                let i = map.bin(ca, axis);
                lower(&mut bins.lo[axis][i], b.min);
                raise(&mut bins.hi[axis][i], b.max);
                bins.count[axis][i] += 1;
            }
        }
        bins
    }

    fn merge(mut self, o: Bins) -> Bins {
        for axis in 0..3 {
            for i in 0..BINS {
                lower(&mut self.lo[axis][i], o.lo[axis][i]);
                raise(&mut self.hi[axis][i], o.hi[axis][i]);
                self.count[axis][i] += o.count[axis][i];
            }
        }
        self
    }

    fn bin_box(&self, axis: usize, i: usize) -> Aabb {
        Aabb { min: self.lo[axis][i], max: self.hi[axis][i] }
    }
}

/// `a.union(b)` by plain comparisons (for boxes without NaN).
#[inline(always)]
pub fn union(mut a: Aabb, b: &Aabb) -> Aabb {
    lower(&mut a.min, b.min);
    raise(&mut a.max, b.max);
    a
}

/// `a.grow(p)` by plain comparisons (for points without NaN).
#[inline(always)]
pub fn grow(mut a: Aabb, p: Vec3) -> Aabb {
    lower(&mut a.min, p);
    raise(&mut a.max, p);
    a
}

#[inline(always)]
fn lower(a: &mut Vec3, b: Vec3) {
    a.x = if b.x < a.x { b.x } else { a.x };
    a.y = if b.y < a.y { b.y } else { a.y };
    a.z = if b.z < a.z { b.z } else { a.z };
}

#[inline(always)]
fn raise(a: &mut Vec3, b: Vec3) {
    a.x = if b.x > a.x { b.x } else { a.x };
    a.y = if b.y > a.y { b.y } else { a.y };
    a.z = if b.z > a.z { b.z } else { a.z };
}

/// The cheapest split over all axes of non-zero extent (the first among equal costs, in
/// axis then bin order), or `None` when no axis separates anything.
pub fn best_split<R: Binned>(refs: &[R], map: &BinMap, parent_area: f32, parallel: bool) -> Option<Split> {
    let bins = if parallel && refs.len() > CHUNK {
        refs.par_chunks(CHUNK).map(|c| Bins::gather(c, map)).reduce(|| Bins::EMPTY, Bins::merge)
    } else {
        Bins::gather(refs, map)
    };
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        if map.scale[axis] == 0.0 {
            continue;
        }
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0u32; BINS];
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in (1..BINS).rev() {
            acc = union(acc, &bins.bin_box(axis, i));
            cnt += bins.count[axis][i];
            right_area[i] = acc.area();
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in 1..BINS {
            acc = union(acc, &bins.bin_box(axis, i - 1));
            cnt += bins.count[axis][i - 1];
            if cnt == 0 || right_count[i] == 0 {
                continue;
            }
            let cost = SAH_TRAVERSAL_COST
                + SAH_INTERSECT_COST * (acc.area() * cnt as f32 + right_area[i] * right_count[i] as f32)
                    / parent_area.max(f32::MIN_POSITIVE);
            if best.is_none_or(|b| cost < b.cost) {
                best = Some(Split { axis, bin: i, cost });
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    struct R(Aabb);
    impl Binned for R {
        fn bounds(&self) -> &Aabb {
            &self.0
        }
        fn centre(&self) -> Vec3 {
            (self.0.min + self.0.max) * 0.5
        }
    }

    fn refs(n: usize) -> Vec<R> {
        (0..n)
            .map(|i| {
                let p = vec3((i * 37 % 101) as f32, (i * 11 % 53) as f32 * 0.5, (i % 7) as f32);
                R(Aabb { min: p, max: p + Vec3::splat(0.25 + (i % 5) as f32) })
            })
            .collect()
    }

    /// `n` references, their bin map and the area of their box.
    fn setup(n: usize) -> (Vec<R>, BinMap, f32) {
        let rs = refs(n);
        let map = BinMap::new(&rs.iter().fold(Aabb::EMPTY, |b, r| b.grow(r.centre())));
        let area = rs.iter().fold(Aabb::EMPTY, |b, r| b.union(r.0)).area();
        (rs, map, area)
    }

    /// The one-pass search scores every candidate exactly as the definition does: for each
    /// axis and boundary, the SAH of the two sides' boxes and counts, found here by brute force.
    #[test]
    fn best_split_is_the_brute_force_minimum() {
        let (rs, map, area) = setup(3000);
        let mut want: Option<Split> = None;
        for axis in 0..3 {
            for bin in 1..BINS {
                let side = |left: bool| {
                    rs.iter()
                        .filter(|r| (map.bin(r.centre()[axis], axis) < bin) == left)
                        .fold((Aabb::EMPTY, 0u32), |(b, n), r| (b.union(r.0), n + 1))
                };
                let ((lb, ln), (rb, rn)) = (side(true), side(false));
                if ln == 0 || rn == 0 {
                    continue;
                }
                let cost =
                    SAH_TRAVERSAL_COST + SAH_INTERSECT_COST * (lb.area() * ln as f32 + rb.area() * rn as f32) / area;
                if want.is_none_or(|w| cost < w.cost) {
                    want = Some(Split { axis, bin, cost });
                }
            }
        }
        let got = best_split(&rs, &map, area, false).unwrap();
        let want = want.unwrap();
        assert_eq!((got.axis, got.bin), (want.axis, want.bin));
        assert!((got.cost - want.cost).abs() <= 1e-5 * want.cost, "{got:?} vs {want:?}");
    }

    #[test]
    fn parallel_chunks_give_the_same_split() {
        let (rs, map, area) = setup(100_000);
        assert_eq!(best_split(&rs, &map, area, true), best_split(&rs, &map, area, false));
    }

    #[test]
    fn every_centre_lands_in_a_bin_and_extremes_in_the_end_bins() {
        let cb = Aabb { min: vec3(-1.0, 2.0, 5.0), max: vec3(3.0, 2.0, 5.5) };
        let map = BinMap::new(&cb);
        assert_eq!(map.bin(-1.0, 0), 0);
        assert_eq!(map.bin(3.0, 0), BINS - 1);
        assert_eq!(map.bin(2.0, 1), 0, "zero extent: one bin");
        assert_eq!(map.bin(5.5, 2), BINS - 1);
    }
}
