//! Grid volumes (Mitsuba's `gridvolume`): values stored per cell of a regular grid over the
//! unit cube, placed in the world by a transform and looked up at world points.
//!
//! Conventions (Mitsuba 3's, measured against it): the value of cell (i, j, k) sits at the
//! cell's centre ((i + 0.5) / res_x, (j + 0.5) / res_y, (k + 0.5) / res_z) in the grid's unit
//! cube. Trilinear lookups blend the 8 centres around the point (a point at local x lies
//! between cells floor(x res_x - 0.5) and the next, with weight (x res_x - 0.5) minus that
//! floor on the second); nearest lookups take the cell floor(x res_x). Cell indices outside
//! the grid are brought back by the wrap mode: clamped to the edge, repeated (modulo the
//! resolution) or mirrored (modulo twice the resolution, the second half reversed). Values
//! are not clamped.

use crate::describe::{GridFilter, GridWrap};
use crate::math::{Ray, Rgb, Transform, Vec3};

/// A grid of 1 or 3 channels placed by `to_world` (the unit cube's transform).
#[derive(Clone, Debug, PartialEq)]
pub struct GridVolume {
    resolution: [u32; 3],
    /// 1 (grey) or 3 (RGB).
    channels: u32,
    /// x fastest, then y, then z; the channels of one cell together.
    data: Vec<f32>,
    filter: GridFilter,
    wrap: GridWrap,
    to_world: Transform,
}

impl GridVolume {
    /// A grid from its cells; `None` unless every resolution is at least 1, there are 1 or
    /// 3 channels and `data` holds exactly one value per cell and channel.
    pub fn new(
        resolution: [u32; 3],
        channels: u32,
        data: Vec<f32>,
        filter: GridFilter,
        wrap: GridWrap,
        to_world: Transform,
    ) -> Option<GridVolume> {
        let cells = resolution.iter().try_fold(1usize, |n, &r| n.checked_mul(r as usize))?;
        let ok = resolution.iter().all(|&r| r >= 1)
            && matches!(channels, 1 | 3)
            && cells.checked_mul(channels as usize) == Some(data.len());
        ok.then_some(GridVolume { resolution, channels, data, filter, wrap, to_world })
    }

    /// The largest value in any channel.
    pub fn max_value(&self) -> f32 {
        self.data.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }

    /// Whether world point `p` lies in the grid's box (the unit cube placed by `to_world`).
    pub fn contains(&self, p: Vec3) -> bool {
        let l = self.to_world.inv_point(p);
        [l.x, l.y, l.z].iter().all(|v| (0.0..=1.0).contains(v))
    }

    /// The part [t0, t1] of `ray` within [0, t_max] that lies in the grid's box, `None` when
    /// the ray misses it there.
    pub fn clip(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        let o = self.to_world.inv_point(ray.origin);
        let d = self.to_world.inv_vector(ray.dir);
        let (mut t0, mut t1) = (0.0f32, t_max);
        for (o, d) in [(o.x, d.x), (o.y, d.y), (o.z, d.z)] {
            if d == 0.0 || !d.is_finite() {
                if !(0.0..=1.0).contains(&o) {
                    return None;
                }
                continue;
            }
            let (a, b) = ((0.0 - o) / d, (1.0 - o) / d);
            let (near, far) = if a <= b { (a, b) } else { (b, a) };
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// The value at world point `p` (grey grids in all three channels).
    pub fn eval(&self, p: Vec3) -> Rgb {
        let local = self.to_world.inv_point(p);
        let local = [local.x, local.y, local.z];
        match self.filter {
            GridFilter::Nearest => {
                let mut cell = [0u32; 3];
                for a in 0..3 {
                    let x = finite_or_zero(local[a] * self.resolution[a] as f32);
                    cell[a] = self.wrap_index(x.floor() as i64, self.resolution[a]);
                }
                self.cell(cell)
            }
            GridFilter::Trilinear => {
                // Per axis: the two cells around the point and the second one's weight.
                let mut lo = [0u32; 3];
                let mut hi = [0u32; 3];
                let mut w = [0f32; 3];
                for a in 0..3 {
                    let x = finite_or_zero(local[a] * self.resolution[a] as f32 - 0.5);
                    let f = x.floor();
                    let i = f as i64;
                    lo[a] = self.wrap_index(i, self.resolution[a]);
                    hi[a] = self.wrap_index(i.saturating_add(1), self.resolution[a]);
                    w[a] = (x - f).clamp(0.0, 1.0);
                }
                let mut sum = Rgb::BLACK;
                for corner in 0..8 {
                    let mut weight = 1.0;
                    let mut cell = [0u32; 3];
                    for a in 0..3 {
                        if corner >> a & 1 == 1 {
                            cell[a] = hi[a];
                            weight *= w[a];
                        } else {
                            cell[a] = lo[a];
                            weight *= 1.0 - w[a];
                        }
                    }
                    if weight > 0.0 {
                        sum += self.cell(cell) * weight;
                    }
                }
                sum
            }
        }
    }

    /// The cell index `i` (any integer) brought into [0, n) by the wrap mode.
    fn wrap_index(&self, i: i64, n: u32) -> u32 {
        let n = n as i64;
        let j = match self.wrap {
            GridWrap::Clamp => i.clamp(0, n - 1),
            GridWrap::Repeat => i.rem_euclid(n),
            GridWrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
        };
        j as u32
    }

    fn cell(&self, [x, y, z]: [u32; 3]) -> Rgb {
        let [rx, ry, _] = self.resolution;
        let i = ((z as usize * ry as usize + y as usize) * rx as usize + x as usize) * self.channels as usize;
        if self.channels == 1 {
            Rgb::splat(self.data[i])
        } else {
            Rgb { r: self.data[i], g: self.data[i + 1], b: self.data[i + 2] }
        }
    }
}

/// `x`, or 0 for NaN and infinities (a lookup at a non-finite point reads some cell rather
/// than producing NaN weights).
fn finite_or_zero(x: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    /// A 4x3x2 grid of 3 channels whose values are their own flat index (the green channel
    /// negated), placed by translate(0.1, 0, 0) * scale(2, 1, 1). The expected values below
    /// are what Mitsuba 3.9.1's gridvolume returns for this grid at these points.
    fn grid(filter: GridFilter, wrap: GridWrap) -> GridVolume {
        let data: Vec<f32> = (0..2 * 3 * 4 * 3).map(|i| if i % 3 == 1 { -(i as f32) } else { i as f32 }).collect();
        let to_world =
            Transform::translate(vec3(0.1, 0.0, 0.0)).then_after(&Transform::scale(vec3(2.0, 1.0, 1.0)).unwrap());
        GridVolume::new([4, 3, 2], 3, data, filter, wrap, to_world).unwrap()
    }

    const POINTS: [[f32; 3]; 5] =
        [[0.1, 0.5, 0.5], [0.35, 1.0 / 6.0, 0.25], [0.7, 0.4, 0.8], [-0.1, 1.1, -0.3], [3.5, -0.6, 1.3]];

    fn check(filter: GridFilter, wrap: GridWrap, expected: [[f32; 3]; 5]) {
        let g = grid(filter, wrap);
        // The first point lies on a cell boundary in z (local z 0.5, 2 cells): the nearest
        // cell there depends on the last bit of the inverse transform (Mitsuba's rounds
        // down), so nearest lookups are checked from the second point on.
        let skip = usize::from(filter == GridFilter::Nearest);
        for (p, e) in POINTS.iter().zip(expected).skip(skip) {
            let v = g.eval(vec3(p[0], p[1], p[2]));
            for (got, want) in v.to_array().into_iter().zip(e) {
                assert!((got - want).abs() < 1e-3, "{filter:?} {wrap:?} at {p:?}: {v:?}, expected {e:?}");
            }
        }
    }

    #[test]
    fn trilinear_lookups_blend_cell_centres_as_mitsuba_does() {
        use GridWrap::*;
        let t = GridFilter::Trilinear;
        check(
            t,
            Clamp,
            [[30.0, -31.0, 32.0], [0.0, -1.0, 2.0], [46.5, -47.5, 48.5], [24.0, -25.0, 26.0], [45.0, -46.0, 47.0]],
        );
        check(
            t,
            Repeat,
            [[34.5, -35.5, 36.5], [0.0, -1.0, 2.0], [42.9, -43.9, 44.9], [45.3, -46.3, 47.3], [18.9, -19.9, 20.9]],
        );
        check(
            t,
            Mirror,
            [[30.0, -31.0, 32.0], [0.0, -1.0, 2.0], [46.5, -47.5, 48.5], [27.6, -28.6, 29.6], [50.1, -51.1, 52.1]],
        );
    }

    #[test]
    fn nearest_lookups_take_the_cell_the_point_is_in() {
        use GridWrap::*;
        let n = GridFilter::Nearest;
        check(
            n,
            Clamp,
            [[12.0, -13.0, 14.0], [0.0, -1.0, 2.0], [51.0, -52.0, 53.0], [24.0, -25.0, 26.0], [45.0, -46.0, 47.0]],
        );
        check(
            n,
            Repeat,
            [[12.0, -13.0, 14.0], [0.0, -1.0, 2.0], [51.0, -52.0, 53.0], [45.0, -46.0, 47.0], [18.0, -19.0, 20.0]],
        );
        check(
            n,
            Mirror,
            [[12.0, -13.0, 14.0], [0.0, -1.0, 2.0], [51.0, -52.0, 53.0], [24.0, -25.0, 26.0], [51.0, -52.0, 53.0]],
        );
    }

    #[test]
    fn a_cell_centre_gives_the_cell_value_and_midway_the_mean() {
        // 2 cells along x, grey: centres at x = 0.25 and 0.75 of the unit cube. A node-centred
        // convention (x (res - 1)) would give 0.25 at x = 0.25 and 1 only at x = 1.
        let g =
            GridVolume::new([2, 1, 1], 1, vec![0.0, 1.0], GridFilter::Trilinear, GridWrap::Clamp, Transform::IDENTITY)
                .unwrap();
        let at = |x: f32| g.eval(vec3(x, 0.5, 0.5)).r;
        assert!((at(0.25) - 0.0).abs() < 1e-6);
        assert!((at(0.75) - 1.0).abs() < 1e-6);
        assert!((at(0.5) - 0.5).abs() < 1e-6);
        assert!((at(0.375) - 0.25).abs() < 1e-6);
        assert!((at(0.0) - 0.0).abs() < 1e-6 && (at(1.0) - 1.0).abs() < 1e-6);
        let repeat =
            GridVolume::new([2, 1, 1], 1, vec![0.0, 1.0], GridFilter::Trilinear, GridWrap::Repeat, Transform::IDENTITY)
                .unwrap();
        // Repeated, x = 0 lies midway between the last cell's centre (-0.25) and the first's.
        assert!((repeat.eval(vec3(0.0, 0.5, 0.5)).r - 0.5).abs() < 1e-6);
        assert!(g.eval(vec3(f32::NAN, f32::INFINITY, -f32::INFINITY)).r.is_finite());
    }

    #[test]
    fn nearest_takes_floor_of_position_times_resolution() {
        // 4 cells along x holding 0..3 (Mitsuba 3.9.1 gives these): cell i covers
        // [i / 4, (i + 1) / 4); a half-cell shift (floor(x res - 0.5)) would give 0 at 0.26.
        let g = |wrap| {
            GridVolume::new([4, 1, 1], 1, vec![0.0, 1.0, 2.0, 3.0], GridFilter::Nearest, wrap, Transform::IDENTITY)
                .unwrap()
        };
        let (clamp, repeat) = (g(GridWrap::Clamp), g(GridWrap::Repeat));
        for (x, c, r) in [
            (0.1, 0.0, 0.0),
            (0.26, 1.0, 1.0),
            (0.6, 2.0, 2.0),
            (0.9, 3.0, 3.0),
            (1.0, 3.0, 0.0),
            (-0.25, 0.0, 3.0),
            (1.25, 3.0, 1.0),
        ] {
            assert_eq!(clamp.eval(vec3(x, 0.5, 0.5)).r, c, "clamp at {x}");
            assert_eq!(repeat.eval(vec3(x, 0.5, 0.5)).r, r, "repeat at {x}");
        }
    }

    #[test]
    fn rays_are_clipped_to_the_grid_box() {
        let g = grid(GridFilter::Trilinear, GridWrap::Clamp); // box [0.1, 2.1] x [0, 1] x [0, 1]
        let r = Ray::new(vec3(-0.9, 0.5, 0.5), vec3(1.0, 0.0, 0.0));
        let (t0, t1) = g.clip(&r, 100.0).unwrap();
        assert!((t0 - 1.0).abs() < 1e-5 && (t1 - 3.0).abs() < 1e-5, "{t0} {t1}");
        assert_eq!(g.clip(&r, 0.5), None);
        let (t0, t1) = g.clip(&r, 2.0).unwrap();
        assert!((t0 - 1.0).abs() < 1e-5 && t1 == 2.0);
        assert_eq!(g.clip(&Ray::new(vec3(-0.9, 1.5, 0.5), vec3(1.0, 0.0, 0.0)), 100.0), None);
        let inside = Ray::new(vec3(1.0, 0.5, 0.5), vec3(0.0, 0.0, -1.0));
        let (t0, t1) = g.clip(&inside, f32::INFINITY).unwrap();
        assert!(t0 == 0.0 && (t1 - 0.5).abs() < 1e-6);
    }

    #[test]
    fn grids_with_wrong_shapes_are_refused() {
        let f = (GridFilter::Trilinear, GridWrap::Clamp, Transform::IDENTITY);
        assert!(GridVolume::new([2, 1, 1], 2, vec![0.0; 4], f.0, f.1, f.2).is_none());
        assert!(GridVolume::new([2, 1, 1], 1, vec![0.0; 3], f.0, f.1, f.2).is_none());
        assert!(GridVolume::new([0, 1, 1], 1, vec![], f.0, f.1, f.2).is_none());
    }
}
