//! Signed distance grids (Mitsuba's `sdfgrid`): signed distances sampled at the vertices of
//! a regular grid of `(nx-1)(ny-1)(nz-1)` voxels over the unit cube `[0,1]^3`, placed by an
//! affine object-to-world transform. The surface is the zero level set of the grid's
//! trilinear interpolant (negative inside).
//!
//! Everything is traced in *index space*, where sample `(i, j, k)` sits at the integer point
//! `(i, j, k)` and voxel `(i, j, k)` is the box `[i, i+1] x [j, j+1] x [k, k+1]`; the shape's
//! transform maps index space to world (`to_world · scale(1/(n-1))`). Only the voxels whose
//! eight corner values are not all of one strict sign can hold the surface; each is a
//! primitive of a BVH built once per grid. Per voxel the ray's segment inside the box is
//! intersected with the trilinear function, which is a cubic along the ray: the cubic is split
//! at the roots of its derivative into monotonic pieces, the first piece whose end values
//! bracket zero holds the nearest root, and a safeguarded Newton iteration (at most
//! [`MAX_ITERATIONS`] steps) finds it. Work per ray is thus bounded by the voxel count; NaN or
//! infinite rays fail the box tests and hit nothing.
//!
//! Normals as Mitsuba 3.9.1 computes them: the geometric normal is the gradient of the hit
//! voxel's trilinear interpolant (`analytic` shading uses it too); `smooth` shading blends the
//! normalised gradients of the eight voxels around the nearest grid vertex, each a finite
//! difference of the interpolant across that voxel, trilinearly by the position relative to
//! the voxels' centres (Hansson-Söderlund et al. 2022). The shape has no uv parameterisation.

use crate::accel::{Bvh, BvhSplit};
use crate::math::{vec3, Aabb, Ray, Transform, Vec3};
use std::sync::Arc;

/// Most Newton/bisection steps per voxel.
pub const MAX_ITERATIONS: u32 = 64;

/// How shading normals are computed (Mitsuba's `normals`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdfNormals {
    /// The gradient of the hit voxel's trilinear interpolant (the geometric normal).
    Analytic,
    /// Blended gradients of the neighbouring voxels: continuous across voxel faces.
    Smooth,
}

/// A grid's samples and the BVH over its voxels that can hold the surface (shared by every
/// placement of the grid).
#[derive(Debug)]
pub struct SdfGridData {
    /// Samples along x, y and z (each at least 2).
    res: [u32; 3],
    /// `res[0] * res[1] * res[2]` values, x fastest.
    values: Vec<f32>,
    /// Lower corners of the voxels that can hold the surface (the BVH's primitives).
    voxels: Vec<[u32; 3]>,
    bvh: Bvh,
}

impl SdfGridData {
    /// The grid of `values` (x fastest) at `res` samples per axis. Errors: fewer than two
    /// samples along an axis, a value count that does not match, a value that is not finite,
    /// or no voxel that can hold the surface (as Mitsuba refuses such a grid).
    pub fn new(res: [u32; 3], values: Vec<f32>, split: BvhSplit) -> Result<SdfGridData, String> {
        if res.iter().any(|&r| r < 2) {
            return Err(format!(
                "an SDF grid needs at least 2 samples along each axis, got {}x{}x{}",
                res[0], res[1], res[2]
            ));
        }
        let count = res.iter().map(|&r| r as usize).product::<usize>();
        if values.len() != count {
            return Err(format!(
                "an SDF grid of {}x{}x{} needs {count} values, got {}",
                res[0],
                res[1],
                res[2],
                values.len()
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            let (x, y, z) =
                (i % res[0] as usize, i / res[0] as usize % res[1] as usize, i / (res[0] * res[1]) as usize);
            return Err(format!("SDF grid value at ({x}, {y}, {z}) is not finite"));
        }
        let mut grid = SdfGridData { res, values, voxels: Vec::new(), bvh: Bvh::default() };
        let mut boxes = Vec::new();
        for z in 0..res[2] - 1 {
            for y in 0..res[1] - 1 {
                for x in 0..res[0] - 1 {
                    let c = grid.corners([x, y, z]);
                    if c.iter().all(|&v| v > 0.0) || c.iter().all(|&v| v < 0.0) {
                        continue;
                    }
                    grid.voxels.push([x, y, z]);
                    // Padded so that rounding in the f32 box tests loses no ray that the
                    // exact (f64) test in `intersect_voxel` accepts.
                    let lo = vec3(x as f32, y as f32, z as f32);
                    boxes.push(Aabb { min: lo - Vec3::splat(1e-3), max: lo + Vec3::splat(1.0 + 1e-3) });
                }
            }
        }
        if grid.voxels.is_empty() {
            return Err("the SDF grid has no voxel where the distance changes sign (no surface)".into());
        }
        grid.bvh = Bvh::build(&boxes, split);
        Ok(grid)
    }

    pub fn resolution(&self) -> [u32; 3] {
        self.res
    }

    /// How many voxels can hold the surface.
    pub fn voxel_count(&self) -> usize {
        self.voxels.len()
    }

    #[inline]
    fn at(&self, x: u32, y: u32, z: u32) -> f64 {
        let [nx, ny, _] = self.res;
        self.values[(z as usize * ny as usize + y as usize) * nx as usize + x as usize] as f64
    }

    /// The eight corner values of voxel `v`, indexed x + 2y + 4z.
    #[inline]
    fn corners(&self, v: [u32; 3]) -> [f64; 8] {
        std::array::from_fn(|i| self.at(v[0] + (i as u32 & 1), v[1] + (i as u32 >> 1 & 1), v[2] + (i as u32 >> 2)))
    }

    /// The trilinear interpolant of the whole grid at index-space `q`, each coordinate
    /// clamped to the grid (as Mitsuba's clamped texture lookups).
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        let mut base = [0u32; 3];
        let mut w = [0f64; 3];
        for a in 0..3 {
            let hi = (self.res[a] - 1) as f64;
            let c = if q[a].is_nan() { 0.0 } else { q[a].clamp(0.0, hi) };
            let b = (c.floor() as u32).min(self.res[a] - 2);
            base[a] = b;
            w[a] = c - b as f64;
        }
        trilerp(&self.corners(base), w)
    }

    /// Nearest hit of the index-space ray `o + t d` with `t` in `(t_min, t_max)`: its `t`
    /// and the voxel (primitive) index.
    pub fn intersect(&self, o: [f64; 3], d: [f64; 3], t_min: f32, t_max: f32) -> Option<(f32, u32)> {
        let (of, df) = (vec3(o[0] as f32, o[1] as f32, o[2] as f32), vec3(d[0] as f32, d[1] as f32, d[2] as f32));
        if !(of.is_finite() && df.is_finite() && t_min <= t_max) {
            return None;
        }
        let mut ray = Ray { origin: of, dir: df, t_min, t_max };
        let mut best = None;
        self.bvh.traverse(&mut ray, |prim, r| match self.intersect_voxel(prim, o, d, r.t_min, r.t_max) {
            Some(t) => {
                r.t_max = t;
                best = Some((t, prim));
                true
            }
            None => false,
        });
        best
    }

    /// True when the index-space ray meets the surface within `(t_min, t_max)`.
    pub fn occluded(&self, o: [f64; 3], d: [f64; 3], t_min: f32, t_max: f32) -> bool {
        let (of, df) = (vec3(o[0] as f32, o[1] as f32, o[2] as f32), vec3(d[0] as f32, d[1] as f32, d[2] as f32));
        if !(of.is_finite() && df.is_finite() && t_min <= t_max) {
            return false;
        }
        let ray = Ray { origin: of, dir: df, t_min, t_max };
        self.bvh.occluded(&ray, |prim, r| self.intersect_voxel(prim, o, d, r.t_min, r.t_max).is_some())
    }

    /// The nearest root in `(t_min, t_max)` of the trilinear function of voxel `prim` along
    /// the ray, inside the voxel's box.
    pub fn intersect_voxel(&self, prim: u32, o: [f64; 3], d: [f64; 3], t_min: f32, t_max: f32) -> Option<f32> {
        let v = *self.voxels.get(prim as usize)?;
        // The ray in the voxel's own [0,1]^3.
        let lo: [f64; 3] = std::array::from_fn(|a| o[a] - v[a] as f64);
        let (mut t0, mut t1) = (t_min as f64, t_max as f64);
        for a in 0..3 {
            if d[a] == 0.0 {
                // Parallel to the slab (either sign of zero): inside it, the closed interval
                // included, or no hit.
                if !(0.0..=1.0).contains(&lo[a]) {
                    return None;
                }
                continue;
            }
            let (mut ta, mut tb) = (-lo[a] / d[a], (1.0 - lo[a]) / d[a]);
            if ta > tb {
                std::mem::swap(&mut ta, &mut tb);
            }
            t0 = t0.max(ta);
            t1 = t1.min(tb);
        }
        if !(t0 <= t1) || !t0.is_finite() || !t1.is_finite() {
            return None;
        }
        let c = self.corners(v);
        let point = |t: f64| -> [f64; 3] { std::array::from_fn(|a| (lo[a] + d[a] * t).clamp(0.0, 1.0)) };
        // The cubic along the segment, in u ∈ [0, 3] (t = t0 + u (t1 - t0) / 3), from its
        // values at four evenly spaced points (Newton's forward differences).
        let h = (t1 - t0) / 3.0;
        let f: [f64; 4] = std::array::from_fn(|i| trilerp(&c, point(if i == 3 { t1 } else { t0 + h * i as f64 })));
        let d1 = f[1] - f[0];
        let d2 = f[2] - 2.0 * f[1] + f[0];
        let d3 = f[3] - 3.0 * f[2] + 3.0 * f[1] - f[0];
        let k = [f[0], d1 - d2 / 2.0 + d3 / 3.0, d2 / 2.0 - d3 / 2.0, d3 / 6.0];
        let u = solve_first_root(k, f[0], f[3], 3.0)?;
        let t = (t0 + h * u) as f32;
        // The root lies within [t0, t1] ⊂ [t_min, t_max]; the open interval is what counts.
        (t > t_min && t < t_max).then_some(t)
    }

    /// The gradient of voxel `prim`'s trilinear interpolant at index-space `q` (clamped to
    /// the voxel), in index units.
    pub fn voxel_gradient(&self, prim: u32, q: [f64; 3]) -> [f64; 3] {
        let v = self.voxels[prim as usize];
        let c = self.corners(v);
        let w: [f64; 3] = std::array::from_fn(|a| (q[a] - v[a] as f64).clamp(0.0, 1.0));
        trilerp_gradient(&c, w)
    }

    /// Mitsuba's smooth normal at index-space `q`, in object units (not normalised).
    pub fn smooth_normal(&self, q: [f64; 3]) -> [f64; 3] {
        let scale: [f64; 3] = std::array::from_fn(|a| (self.res[a] - 1) as f64);
        let base: [i64; 3] = std::array::from_fn(|a| round_half_away(q[a]) as i64 - 1);
        // The position relative to the centres of the eight voxels around the nearest vertex.
        let mut w: [f64; 3] = std::array::from_fn(|a| q[a] - (base[a] + 1) as f64 + 0.5);
        let valid = |i: usize| (0..3).all(|a| base[a] + ((i >> a) & 1) as i64 >= 0);
        let normals: [[f64; 3]; 8] = std::array::from_fn(|i| {
            if !valid(i) {
                return [0.0; 3];
            }
            let v: [i64; 3] = std::array::from_fn(|a| base[a] + ((i >> a) & 1) as i64);
            // Differences across voxel v along each axis at q's other coordinates.
            let g: [f64; 3] = std::array::from_fn(|a| {
                let (mut q0, mut q1) = (q, q);
                q0[a] = v[a] as f64;
                q1[a] = (v[a] + 1) as f64;
                (self.eval(q1) - self.eval(q0)) * scale[a]
            });
            let len = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            // Mitsuba's normalise of a zero vector gives NaN; a zero weight is the sane reading.
            if len > 0.0 {
                g.map(|x| x / len)
            } else {
                [0.0; 3]
            }
        });
        // An axis whose voxels on one side are all outside the grid gives them no weight.
        for (a, wa) in w.iter_mut().enumerate() {
            let side_invalid = |hi: usize| (0..8).filter(|i| (i >> a) & 1 == hi).all(|i| !valid(i));
            if side_invalid(0) {
                *wa = 1.0;
            }
            if side_invalid(1) {
                *wa = 0.0;
            }
        }
        let mut n = [0.0; 3];
        for (i, ni) in normals.iter().enumerate() {
            let wi: f64 = (0..3).map(|a| if (i >> a) & 1 == 1 { w[a] } else { 1.0 - w[a] }).product();
            for a in 0..3 {
                n[a] += wi * ni[a];
            }
        }
        n
    }
}

/// Rounds halves away from zero (C's `round`, which Mitsuba uses).
fn round_half_away(x: f64) -> f64 {
    x.round()
}

/// The trilinear interpolant of corner values `c` (x + 2y + 4z) at `w` in [0,1]^3.
#[inline]
fn trilerp(c: &[f64; 8], w: [f64; 3]) -> f64 {
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let x0 = lerp(c[0], c[1], w[0]);
    let x1 = lerp(c[2], c[3], w[0]);
    let x2 = lerp(c[4], c[5], w[0]);
    let x3 = lerp(c[6], c[7], w[0]);
    lerp(lerp(x0, x1, w[1]), lerp(x2, x3, w[1]), w[2])
}

/// The gradient of the trilinear interpolant: its partial derivatives are bilinear
/// interpolants of the differences along the four parallel edges.
fn trilerp_gradient(c: &[f64; 8], w: [f64; 3]) -> [f64; 3] {
    let bilerp = |f: [f64; 4], u: f64, v: f64| {
        let a = f[0] + (f[1] - f[0]) * u;
        let b = f[2] + (f[3] - f[2]) * u;
        a + (b - a) * v
    };
    [
        bilerp([c[1] - c[0], c[3] - c[2], c[5] - c[4], c[7] - c[6]], w[1], w[2]),
        bilerp([c[2] - c[0], c[3] - c[1], c[6] - c[4], c[7] - c[5]], w[0], w[2]),
        bilerp([c[4] - c[0], c[5] - c[1], c[6] - c[2], c[7] - c[3]], w[0], w[1]),
    ]
}

/// The smallest root in `[0, end]` of the cubic `k[0] + k[1] u + k[2] u² + k[3] u³`, whose
/// values at 0 and `end` are `f0` and `f_end`: the interval is split at the roots of the
/// derivative into monotonic pieces, the first piece whose end values bracket zero (or
/// touch it) holds the root, and a Newton iteration kept inside the bracket by bisection
/// (at most [`MAX_ITERATIONS`] steps) finds it. `None` when no piece brackets a root.
pub fn solve_first_root(k: [f64; 4], f0: f64, f_end: f64, end: f64) -> Option<f64> {
    let eval = |u: f64| ((k[3] * u + k[2]) * u + k[1]) * u + k[0];
    let deriv = |u: f64| (3.0 * k[3] * u + 2.0 * k[2]) * u + k[1];
    // Roots of the derivative 3 k3 u² + 2 k2 u + k1 inside (0, end), in order.
    let mut splits = [f64::NAN; 2];
    let (a, b, cc) = (3.0 * k[3], 2.0 * k[2], k[1]);
    if a != 0.0 {
        let disc = b * b - 4.0 * a * cc;
        if disc >= 0.0 {
            let q = -0.5 * (b + b.signum() * disc.sqrt());
            let (r0, r1) = (q / a, if q != 0.0 { cc / q } else { q / a });
            splits = if r0 <= r1 { [r0, r1] } else { [r1, r0] };
        }
    } else if b != 0.0 {
        splits[0] = -cc / b;
    }
    let (mut lo, mut f_lo) = (0.0, f0);
    if f_lo == 0.0 {
        return Some(0.0);
    }
    let mut bracket = None;
    for s in splits.into_iter().filter(|s| *s > 0.0 && *s < end) {
        let fs = eval(s);
        if f_lo * fs <= 0.0 {
            bracket = Some((lo, s, f_lo));
            break;
        }
        (lo, f_lo) = (s, fs);
    }
    let (mut lo, mut hi, f_lo) = match bracket {
        Some(b) => b,
        None if f_lo * f_end <= 0.0 => (lo, end, f_lo),
        None => return None,
    };
    // Secant start, then Newton steps that stay inside the bracket, else bisection.
    let f_hi = eval(hi);
    let mut u = if f_hi != f_lo { lo + (hi - lo) * (f_lo / (f_lo - f_hi)) } else { 0.5 * (lo + hi) };
    if !(u >= lo && u <= hi) {
        u = 0.5 * (lo + hi);
    }
    for _ in 0..MAX_ITERATIONS {
        let fu = eval(u);
        if fu == 0.0 {
            return Some(u);
        }
        if fu * f_lo < 0.0 {
            hi = u;
        } else {
            lo = u;
        }
        let next = u - fu / deriv(u);
        let next = if next > lo && next < hi { next } else { 0.5 * (lo + hi) };
        if (next - u).abs() <= 1e-12 * end || hi - lo <= 1e-12 * end {
            return Some(next);
        }
        u = next;
    }
    Some(u)
}

/// A placed SDF grid.
#[derive(Clone, Debug)]
pub struct SdfGrid {
    pub data: Arc<SdfGridData>,
    /// Index space to world: the shape's `to_world` after the scale of [0, n-1] onto [0, 1].
    pub to_world: Transform,
    pub normals: SdfNormals,
}

/// What shading needs about a point of an SDF grid.
#[derive(Clone, Copy, Debug)]
pub struct SdfPoint {
    pub p: Vec3,
    /// Geometric normal: the hit voxel's gradient (unit, world, outward: towards positive).
    pub n: Vec3,
    /// Shading normal (unit, world).
    pub shading_n: Vec3,
}

impl SdfGrid {
    /// `data` placed by `to_world` (which maps the unit cube). `None` when the transform is
    /// not invertible or not finite.
    pub fn new(data: Arc<SdfGridData>, to_world: &Transform, normals: SdfNormals) -> Option<SdfGrid> {
        let r = data.res;
        let scale = Transform::scale(vec3(1.0 / (r[0] - 1) as f32, 1.0 / (r[1] - 1) as f32, 1.0 / (r[2] - 1) as f32))?;
        let to_world = to_world.then_after(&scale);
        to_world.is_finite().then_some(SdfGrid { data, to_world, normals })
    }

    /// The box of the placed unit cube (as Mitsuba's).
    pub fn bounds(&self) -> Aabb {
        let hi = self.data.res.map(|r| (r - 1) as f32);
        self.to_world.aabb(&Aabb { min: Vec3::ZERO, max: vec3(hi[0], hi[1], hi[2]) })
    }

    /// The ray in index space, in f64 (its `t` is unchanged).
    fn local(&self, ray: &Ray) -> ([f64; 3], [f64; 3]) {
        let inv = &self.to_world.inv.0;
        let (o, d) = (ray.origin, ray.dir);
        let row = |r: &[f64; 4], v: Vec3, w: f64| r[0] * v.x as f64 + r[1] * v.y as f64 + r[2] * v.z as f64 + r[3] * w;
        (std::array::from_fn(|a| row(&inv[a], o, 1.0)), std::array::from_fn(|a| row(&inv[a], d, 0.0)))
    }

    /// Nearest hit in `(t_min, t_max)`: its `t` and the voxel (primitive) hit.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, u32)> {
        let (o, d) = self.local(ray);
        self.data.intersect(o, d, ray.t_min, ray.t_max)
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        let (o, d) = self.local(ray);
        self.data.occluded(o, d, ray.t_min, ray.t_max)
    }

    /// The surface point of a hit at `t` in voxel `prim`.
    pub fn point(&self, ray: &Ray, t: f32, prim: u32) -> SdfPoint {
        let (o, d) = self.local(ray);
        let q: [f64; 3] = std::array::from_fn(|a| o[a] + d[a] * t as f64);
        let g = self.data.voxel_gradient(prim, q);
        let mut n = self.to_world.normal(vec3(g[0] as f32, g[1] as f32, g[2] as f32)).normalize();
        if !n.is_finite() {
            // A flat spot of the interpolant (zero gradient): face the ray.
            n = -ray.dir.normalize();
        }
        let shading_n = match self.normals {
            SdfNormals::Analytic => n,
            SdfNormals::Smooth => {
                // An object-space normal: back to index units, then as a normal to world.
                let s = self.data.smooth_normal(q);
                let r = self.data.res.map(|r| (r - 1) as f64);
                let ns = self
                    .to_world
                    .normal(vec3((s[0] / r[0]) as f32, (s[1] / r[1]) as f32, (s[2] / r[2]) as f32))
                    .normalize();
                if ns.is_finite() {
                    ns
                } else {
                    n
                }
            }
        };
        SdfPoint { p: ray.at(t), n, shading_n }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// The signed distance to a sphere of radius `r` around `c`, sampled at n^3 vertices of
    /// the unit cube.
    pub(crate) fn sphere_grid(n: u32, c: Vec3, r: f32) -> SdfGridData {
        let mut values = Vec::new();
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let p = vec3(x as f32, y as f32, z as f32) / (n - 1) as f32;
                    values.push((p - c).length() - r);
                }
            }
        }
        SdfGridData::new([n; 3], values, BvhSplit::Sah).unwrap()
    }

    const C: Vec3 = vec3(0.5, 0.45, 0.55);
    const R: f32 = 0.3;

    fn placed(normals: SdfNormals) -> SdfGrid {
        // Scaled by 2 and moved: the sphere is then of radius 0.6 around to_world(C).
        let xf = Transform::translate(vec3(1.0, -2.0, 0.5)).then_after(&Transform::scale(Vec3::splat(2.0)).unwrap());
        SdfGrid::new(Arc::new(sphere_grid(33, C, R)), &xf, normals).unwrap()
    }

    /// The true sphere's hit along `ray` (world), radius and centre after the placement.
    fn true_hit(ray: &Ray) -> Option<f32> {
        let (c, r) = (C * 2.0 + vec3(1.0, -2.0, 0.5), R * 2.0);
        let oc = ray.origin - c;
        let (a, b, cc) = (ray.dir.dot(ray.dir), 2.0 * oc.dot(ray.dir), oc.dot(oc) - r * r);
        let disc = b * b - 4.0 * a * cc;
        if disc < 0.0 {
            return None;
        }
        let t0 = (-b - disc.sqrt()) / (2.0 * a);
        let t1 = (-b + disc.sqrt()) / (2.0 * a);
        [t0, t1].into_iter().find(|&t| t > 0.0)
    }

    #[test]
    fn hits_and_normals_match_the_sampled_sphere() {
        let centre = C * 2.0 + vec3(1.0, -2.0, 0.5);
        // World cell size: 2 / 32.
        let h = 2.0 / 32.0;
        for normals in [SdfNormals::Analytic, SdfNormals::Smooth] {
            let g = placed(normals);
            let mut rng = Rng::new(3, 0);
            let mut hits = 0;
            for _ in 0..4000 {
                let dir = vec3(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5).normalize();
                // From 3 away, aimed at a point within 0.5 of the centre: a hit when the
                // ray passes inside the sphere.
                let target = centre + vec3(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * 1.2;
                let ray = Ray::new(target - dir * 3.0, dir);
                let expect = true_hit(&ray);
                let got = g.intersect(&ray);
                match (expect, got) {
                    (Some(te), Some((t, prim))) => {
                        hits += 1;
                        let p = g.point(&ray, t, prim);
                        let true_n = (ray.at(te) - centre).normalize();
                        // The surface lies within a small part of a cell of the sphere; along
                        // the ray that error grows as the ray turns tangent.
                        let cos = true_n.dot(dir).abs();
                        assert!((t - te).abs() * cos < 0.05 * h, "t {t} vs {te} (cos {cos})");
                        assert!((p.n.length() - 1.0).abs() < 1e-5 && (p.shading_n.length() - 1.0).abs() < 1e-5);
                        assert!(p.n.dot(true_n) > 0.99, "{:?} vs {true_n:?}", p.n);
                        assert!(p.shading_n.dot(true_n) > 0.99, "{:?} vs {true_n:?}", p.shading_n);
                    }
                    (None, None) => {}
                    // Grazing rays may fall either way within a sliver of the silhouette.
                    (e, got) => {
                        let closest = (centre - ray.origin).cross(dir).length();
                        assert!((closest - 2.0 * R).abs() < 0.25 * h, "{e:?} vs {got:?}, closest {closest}");
                    }
                }
            }
            assert!(hits > 1000, "{hits}");
        }
    }

    #[test]
    fn misses_grazes_and_starts_inside() {
        let g = placed(SdfNormals::Smooth);
        let centre = C * 2.0 + vec3(1.0, -2.0, 0.5);
        // Passing well beside the sphere, or pointing away from it.
        assert!(g.intersect(&Ray::new(centre + vec3(-5.0, 0.8, 0.0), Vec3::X)).is_none());
        assert!(g.intersect(&Ray::new(centre + vec3(-5.0, 0.0, 0.0), -Vec3::X)).is_none());
        // A segment that stops short of the surface.
        assert!(g.intersect(&Ray::segment(centre + vec3(-5.0, 0.0, 0.0), Vec3::X, 4.0)).is_none());
        // Grazing exactly: either way, nothing panics; a hit lies near the tangent point.
        let r = Ray::new(centre + vec3(-5.0, 2.0 * R, 0.0), Vec3::X);
        if let Some((t, _)) = g.intersect(&r) {
            assert!((r.at(t) - (centre + vec3(0.0, 2.0 * R, 0.0))).length() < 0.3);
        }
        // From the centre (inside, negative): the exit point, its outward normal along the ray.
        let r = Ray::new(centre, vec3(0.3, 0.8, -0.2).normalize());
        let (t, prim) = g.intersect(&r).unwrap();
        assert!((t - 2.0 * R).abs() < 0.01, "{t}");
        assert!(g.point(&r, t, prim).n.dot(r.dir) > 0.99);
        assert!(g.occluded(&r) && !g.occluded(&Ray::segment(centre, r.dir, 0.5)));
    }

    #[test]
    fn bad_rays_hit_nothing_and_end() {
        let g = placed(SdfNormals::Analytic);
        let o = vec3(1.5, -1.5, 1.0);
        for (o, d) in [
            (o, vec3(f32::NAN, 0.0, 1.0)),
            (o, Vec3::ZERO),
            (o, vec3(f32::INFINITY, 1.0, 0.0)),
            (vec3(f32::NAN, 0.0, 0.0), Vec3::X),
            (vec3(f32::INFINITY, 0.0, 0.0), -Vec3::X),
        ] {
            assert!(g.intersect(&Ray::new(o, d)).is_none());
            assert!(!g.occluded(&Ray::new(o, d)));
        }
        let mut r = Ray::new(vec3(-3.0, -1.5, 1.0), Vec3::X);
        r.t_max = f32::NAN;
        assert!(g.intersect(&r).is_none());
        // Along grid planes exactly (zero direction components of either sign, the origin
        // on voxel faces).
        for d in [vec3(1.0, 0.0, 0.0), vec3(1.0, -0.0, -0.0), vec3(-1.0, -0.0, 0.0)] {
            let start = if d.x > 0.0 { -3.0 } else { 35.0 };
            let r = Ray::new(g.to_world.point(vec3(start, 16.0, 16.0)), d);
            assert!(g.intersect(&r).is_some(), "{d:?}");
        }
    }

    #[test]
    fn bad_grids_are_refused() {
        let s = BvhSplit::Sah;
        assert!(SdfGridData::new([1, 2, 2], vec![0.0; 4], s).unwrap_err().contains("at least 2"));
        assert!(SdfGridData::new([2, 2, 2], vec![0.0; 7], s).unwrap_err().contains("needs 8 values"));
        let mut v = vec![1.0; 8];
        v[5] = f32::NAN;
        assert!(SdfGridData::new([2, 2, 2], v, s).unwrap_err().contains("(1, 0, 1) is not finite"));
        assert!(SdfGridData::new([2, 2, 2], vec![1.0; 8], s).unwrap_err().contains("no surface"));
        // A zero corner is a voxel that can hold the surface (as in Mitsuba).
        let mut v = vec![1.0; 8];
        v[0] = 0.0;
        assert_eq!(SdfGridData::new([2, 2, 2], v, s).unwrap().voxel_count(), 1);
    }

    #[test]
    fn the_cubic_solver_finds_the_first_root() {
        // (u - 0.5)(u - 1.5)(u - 2.5) on [0, 3]: three roots, the first one wins.
        let k = [-1.875, 5.75, -4.5, 1.0];
        let f = |u: f64| ((k[3] * u + k[2]) * u + k[1]) * u + k[0];
        let u = solve_first_root(k, f(0.0), f(3.0), 3.0).unwrap();
        assert!((u - 0.5).abs() < 1e-9, "{u}");
        // Same signs at both ends, two roots between: still found through the split.
        let k = [1.0, -4.0, 2.0, 0.0]; // 2u² - 4u + 1: roots 0.29, 1.71
        let u = solve_first_root(k, 1.0, 2.0 * 9.0 - 12.0 + 1.0, 3.0).unwrap();
        assert!((u - (1.0 - 0.5f64.sqrt())).abs() < 1e-9, "{u}");
        // No root: a positive cubic.
        assert!(solve_first_root([1.0, 0.0, 1.0, 0.0], 1.0, 10.0, 3.0).is_none());
        // NaN coefficients: no root, no hang.
        assert!(solve_first_root([f64::NAN; 4], f64::NAN, f64::NAN, 3.0).is_none());
    }
}
