//! Round curves (Mitsuba's `linearcurve` and `bsplinecurve`): many curves of control points
//! with a radius each, in world space (the shape's transform moves the points, not the
//! radii, as in Mitsuba), with their own 8-wide BVH over segments.
//!
//! A linear segment joins two control points; its surface is the hull of the two balls, so
//! consecutive segments meet in a round joint and a curve ends in a round cap. A cubic
//! segment is the uniform B-spline span of four consecutive control points, a sphere swept
//! along it; its ends are open (Mitsuba's). Both are intersected in `curve_hit`.
//!
//! The BVH's primitives are whole segments or, where a cubic segment's box is much larger
//! than the boxes of its halves (bent segments), halves or quarters of it.

use super::curve_hit::{self, bezier_eval, bezier_part, bspline_to_bezier, P4, V3};
#[cfg(target_arch = "x86_64")]
use crate::accel::simd::{Avx2, Sse};
use crate::accel::simd::{Isa, Scalar};
use crate::accel::wide::{leaf_ref, FnLeaf, WideBvh};
use crate::accel::{BuildOptions, Bvh, BvhSplit, SimdPath};
use crate::math::{vec3, Aabb, Ray, Vec3};

/// How a curve's control points make its centre line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveBasis {
    /// Straight segments between consecutive points, round joints and caps.
    Linear,
    /// Uniform cubic B-spline, open ends.
    BSpline,
}

impl CurveBasis {
    /// Points a segment spans, less one: a curve of n points has n - degree segments.
    pub fn degree(self) -> usize {
        match self {
            CurveBasis::Linear => 1,
            CurveBasis::BSpline => 3,
        }
    }

    /// Mitsuba's plugin name.
    pub fn plugin(self) -> &'static str {
        match self {
            CurveBasis::Linear => "linearcurve",
            CurveBasis::BSpline => "bsplinecurve",
        }
    }
}

/// Bits of a primitive reference that say which part of its segment it is: 0 the whole,
/// 1 and 2 the halves, 3 to 6 the quarters.
const PART_BITS: u32 = 3;
/// Most control points a curve set may have (the rest of a reference's bits).
pub const MAX_CURVE_POINTS: usize = 1 << (32 - PART_BITS);

/// A segment is cut in two where its halves' boxes have less than this share of its box's
/// surface area (see `Curves::new`).
const SPLIT_GAIN: f32 = 0.45;

/// Leaves of up to 8 primitives, every node of 8 or fewer a leaf: with the meshes' leaves of
/// 4, a million-segment fur ball's BVH took 26 bytes per segment (linear curves: 47 in all,
/// over the 40 aimed at); leaves of 8 halve the nodes.
const CURVE_LEAVES: BuildOptions = BuildOptions { max_leaf: 8, leaf_at_most: 8 };

/// The `v` range of part `code`.
fn part_range(code: u32) -> (f64, f64) {
    let level = 31 - (code + 1).leading_zeros();
    let n = (1u32 << level) as f64;
    let j = (code + 1 - (1 << level)) as f64;
    (j / n, (j + 1.0) / n)
}

/// A set of curves, placed and ready to trace.
#[derive(Clone, Debug)]
pub struct Curves {
    basis: CurveBasis,
    /// Control points in world space: x, y, z and radius.
    points: Vec<[f32; 4]>,
    /// Curve `k` has points `curve_starts[k]..curve_starts[k + 1]`.
    curve_starts: Vec<u32>,
    segment_count: u32,
    /// The BVH's primitives in leaf order: first control point << PART_BITS | part.
    refs: Vec<u32>,
    bvh: WideBvh<8>,
}

/// What shading needs about a point of a curve.
#[derive(Clone, Copy, Debug)]
pub struct CurvePoint {
    pub p: Vec3,
    /// Unit, outward: from the centre of the sphere that touches the surface there.
    pub n: Vec3,
    /// Mitsuba's: u the angle around the curve over 2π, v the segment's parameter spread over
    /// all segments of the shape (segment k covers [k, k + 1] / segments).
    pub uv: [f32; 2],
    pub dpdu: Vec3,
    pub dpdv: Vec3,
}

/// What traversal found: the distance, the segment's first control point and the segment
/// parameter of the hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveHit {
    pub t: f32,
    pub point: u32,
    pub v: f32,
}

/// A ray in f64 with the frame in which it is the +z axis.
struct RayFrame {
    o: V3,
    d: V3,
    /// Length of `d`: the frame's z is `t * len`.
    len: f64,
    /// Rows: the frame's axes (the last is `d / len`).
    axes: [V3; 3],
    t_min: f64,
}

impl RayFrame {
    fn new(ray: &Ray) -> Option<RayFrame> {
        let o = [ray.origin.x as f64, ray.origin.y as f64, ray.origin.z as f64];
        let d = [ray.dir.x as f64, ray.dir.y as f64, ray.dir.z as f64];
        let len = curve_hit::dot(d, d).sqrt();
        if !(len > 0.0 && len.is_finite() && o.iter().all(|c| c.is_finite())) {
            return None;
        }
        let z = [d[0] / len, d[1] / len, d[2] / len];
        // Duff et al.'s branchless orthonormal basis.
        let sign = 1f64.copysign(z[2]);
        let a = -1.0 / (sign + z[2]);
        let b = z[0] * z[1] * a;
        let x = [1.0 + sign * z[0] * z[0] * a, sign * b, -sign * z[0]];
        let y = [b, sign + z[1] * z[1] * a, -z[1]];
        Some(RayFrame { o, d, len, axes: [x, y, z], t_min: ray.t_min as f64 })
    }

    /// A control point in the ray's frame.
    fn local(&self, p: [f32; 4]) -> P4 {
        let w = curve_hit::sub([p[0] as f64, p[1] as f64, p[2] as f64], self.o);
        [curve_hit::dot(self.axes[0], w), curve_hit::dot(self.axes[1], w), curve_hit::dot(self.axes[2], w), p[3] as f64]
    }
}

fn p4(p: [f32; 4]) -> P4 {
    p.map(|c| c as f64)
}

fn v3(p: P4) -> Vec3 {
    vec3(p[0] as f32, p[1] as f32, p[2] as f32)
}

impl Curves {
    /// Curves of `basis` through `points` (world space), curve `k` being
    /// `points[starts[k]..starts[k + 1]]`. Fails when a curve has too few points for a
    /// segment, a point is not finite or a radius is negative.
    pub fn new(
        basis: CurveBasis,
        points: Vec<[f32; 4]>,
        curve_starts: Vec<u32>,
        split: BvhSplit,
    ) -> Result<Curves, String> {
        if points.len() >= MAX_CURVE_POINTS {
            return Err(format!("{} control points: at most {} are supported", points.len(), MAX_CURVE_POINTS - 1));
        }
        if curve_starts.first() != Some(&0) || curve_starts.last() != Some(&(points.len() as u32)) {
            return Err("curve starts must run from 0 to the number of points".into());
        }
        if let Some(p) = points.iter().find(|p| !p.iter().all(|c| c.is_finite()) || p[3] < 0.0) {
            return Err(format!("control point {p:?}: positions must be finite and radii finite and not negative"));
        }
        let degree = basis.degree() as u32;
        let mut segments = Vec::new();
        for w in curve_starts.windows(2) {
            if w[1] < w[0] + degree + 1 {
                return Err(format!(
                    "a {} curve needs at least {} control points, one has {}",
                    basis.plugin(),
                    degree + 1,
                    w[1].saturating_sub(w[0])
                ));
            }
            segments.extend(w[0]..w[1] - degree);
        }
        let mut curves = Curves {
            basis,
            points,
            curve_starts,
            segment_count: segments.len() as u32,
            refs: Vec::new(),
            bvh: WideBvh::default(),
        };
        let mut refs = Vec::with_capacity(segments.len());
        let mut boxes = Vec::with_capacity(segments.len());
        for &s in &segments {
            let whole = curves.part_bounds(s, 0.0, 1.0);
            let halves = [curves.part_bounds(s, 0.0, 0.5), curves.part_bounds(s, 0.5, 1.0)];
            // Split where the parts' boxes are much smaller than the whole's (bent cubic
            // segments), as far as quarters. Each part costs a reference and its share of the
            // BVH (about 17 bytes), so a straight segment, whose halves' boxes are about half
            // its own when it runs diagonally, stays whole: splitting those took a fur ball of
            // linear segments from 34 to 58 bytes per segment. Linear segments are tested whole
            // anyway (their hull in closed form), so they are never split.
            let halves_area = halves[0].area() + halves[1].area();
            if basis == CurveBasis::Linear || !(halves_area < SPLIT_GAIN * whole.area()) {
                refs.push(s << PART_BITS);
                boxes.push(whole);
                continue;
            }
            let quarters: [Aabb; 4] =
                std::array::from_fn(|j| curves.part_bounds(s, j as f64 / 4.0, (j + 1) as f64 / 4.0));
            if quarters.iter().map(|b| b.area()).sum::<f32>() < SPLIT_GAIN * halves_area {
                for (j, b) in quarters.into_iter().enumerate() {
                    refs.push(s << PART_BITS | (3 + j as u32));
                    boxes.push(b);
                }
            } else {
                for (j, b) in halves.into_iter().enumerate() {
                    refs.push(s << PART_BITS | (1 + j as u32));
                    boxes.push(b);
                }
            }
        }
        let bvh = Bvh::build_with(&boxes, split, CURVE_LEAVES);
        curves.refs = bvh.prim_indices.iter().map(|&i| refs[i as usize]).collect();
        curves.bvh = WideBvh::collapse(&bvh, |first, count| leaf_ref(first as usize, count as usize));
        Ok(curves)
    }

    pub fn basis(&self) -> CurveBasis {
        self.basis
    }

    pub fn segment_count(&self) -> usize {
        self.segment_count as usize
    }

    pub fn curve_count(&self) -> usize {
        self.curve_starts.len() - 1
    }

    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Bytes of everything tracing keeps: points, curve starts, primitive references, BVH.
    pub fn memory_bytes(&self) -> usize {
        self.points.len() * 16 + self.curve_starts.len() * 4 + self.refs.len() * 4 + self.bvh.stats(|_| 1.0).node_bytes
    }

    /// BVH primitives (segments or their parts).
    pub fn primitive_count(&self) -> usize {
        self.refs.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds
    }

    /// The segment's centre line as Bézier control points (position and radius).
    fn bezier(&self, point: u32) -> [P4; 4] {
        let i = point as usize;
        match self.basis {
            CurveBasis::Linear => {
                let (a, b) = (p4(self.points[i]), p4(self.points[i + 1]));
                let lerp = |t: f64| -> P4 { std::array::from_fn(|c| a[c] + (b[c] - a[c]) * t) };
                [a, lerp(1.0 / 3.0), lerp(2.0 / 3.0), b]
            }
            CurveBasis::BSpline => bspline_to_bezier(std::array::from_fn(|k| p4(self.points[i + k]))),
        }
    }

    /// A box around the part `[v0, v1]` of the segment starting at `point`: its Bézier
    /// hull widened by its largest radius (a linear segment's hull is its two end balls).
    fn part_bounds(&self, point: u32, v0: f64, v1: f64) -> Aabb {
        let span = bezier_part(&self.bezier(point), v0, v1);
        let (span, r) = match self.basis {
            CurveBasis::Linear => ([span[0], span[3]].to_vec(), span[0][3].max(span[3][3])),
            CurveBasis::BSpline => (span.to_vec(), span.iter().fold(0.0f64, |m, p| m.max(p[3]))),
        };
        let mut b = Aabb::EMPTY;
        for p in &span {
            let (lo, hi) = (
                vec3((p[0] - r) as f32, (p[1] - r) as f32, (p[2] - r) as f32),
                vec3((p[0] + r) as f32, (p[1] + r) as f32, (p[2] + r) as f32),
            );
            // Rounded outwards: the f32 box must hold the f64 one.
            b = b.grow(vec3(lo.x.next_down(), lo.y.next_down(), lo.z.next_down())).grow(vec3(
                hi.x.next_up(),
                hi.y.next_up(),
                hi.z.next_up(),
            ));
        }
        b
    }

    /// The entry of `ray` into primitive `r`, as (t in the ray's units, v).
    #[inline]
    fn test_ref(&self, rf: &RayFrame, r: u32, t_max: f64) -> Option<(f64, f64)> {
        let point = r >> PART_BITS;
        let i = point as usize;
        match self.basis {
            CurveBasis::Linear => {
                // Relative to the first point, for precision.
                let (a, b) = (p4(self.points[i]), p4(self.points[i + 1]));
                let o = curve_hit::sub(rf.o, [a[0], a[1], a[2]]);
                let rel = |p: P4| -> P4 { [p[0] - a[0], p[1] - a[1], p[2] - a[2], p[3]] };
                let (t, v) = curve_hit::rounded_cone_entry(o, rf.d, rel(a), rel(b))?;
                (t > rf.t_min && t <= t_max).then_some((t, v))
            }
            CurveBasis::BSpline => {
                let (v0, v1) = part_range(r & ((1 << PART_BITS) - 1));
                let local: [P4; 4] = std::array::from_fn(|k| rf.local(self.points[i + k]));
                let b = bspline_to_bezier(local);
                let (z, v) = curve_hit::cubic_entry(&b, v0, v1, rf.t_min * rf.len, t_max * rf.len)?;
                Some((z / rf.len, v))
            }
        }
    }

    /// Nearest entry in `(t_min, t_max)`; of equal distances, the segment that starts at the
    /// lower point (so the answer does not depend on the order of the tests).
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<CurveHit> {
        self.intersect_with(ray, SimdPath::detect())
    }

    /// [`Curves::intersect`] with the BVH traversed by the given SIMD path (same answers).
    pub fn intersect_with(&self, ray: &Ray, path: SimdPath) -> Option<CurveHit> {
        let path = if path.is_available() { path } else { SimdPath::Scalar };
        // SAFETY (every arm): each path runs only where the CPU has it (checked above).
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 | SimdPath::Avx512 => unsafe { self.intersect_avx2(ray) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.intersect_generic::<Sse>(ray) },
            _ => unsafe { self.intersect_generic::<Scalar>(ray) },
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn intersect_avx2(&self, ray: &Ray) -> Option<CurveHit> {
        // SAFETY: the caller checked that AVX2 and FMA are available.
        unsafe { self.intersect_generic::<Avx2>(ray) }
    }

    /// # Safety
    /// `S` must be available on this CPU.
    #[inline(always)]
    unsafe fn intersect_generic<S: Isa>(&self, ray: &Ray) -> Option<CurveHit> {
        let rf = RayFrame::new(ray)?;
        let mut best: Option<CurveHit> = None;
        let mut r = *ray;
        let mut leaf = FnLeaf(|first: u32, count: u32, r: &mut Ray| {
            let mut found = false;
            for &pr in &self.refs[first as usize..(first + count) as usize] {
                let point = pr >> PART_BITS;
                let Some((t, v)) = self.test_ref(&rf, pr, r.t_max as f64 * (1.0 + 1e-6)) else { continue };
                let tf = t as f32;
                let better = match best {
                    None => tf < r.t_max,
                    Some(b) => tf < b.t || (tf == b.t && point < b.point),
                };
                if better && tf > ray.t_min {
                    best = Some(CurveHit { t: tf, point, v: v.clamp(0.0, 1.0) as f32 });
                    r.t_max = tf;
                    found = true;
                }
            }
            found
        });
        // SAFETY: the caller guarantees `S` is available.
        unsafe { self.bvh.traverse::<S>(&mut r, &mut leaf) };
        best
    }

    /// Whether anything blocks the ray in `(t_min, t_max)`: the same answer as
    /// `intersect(ray).is_some()`, ending at the first hit found.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_with(ray, SimdPath::detect())
    }

    /// [`Curves::occluded`] with the BVH traversed by the given SIMD path (same answers).
    pub fn occluded_with(&self, ray: &Ray, path: SimdPath) -> bool {
        let path = if path.is_available() { path } else { SimdPath::Scalar };
        // SAFETY (every arm): each path runs only where the CPU has it (checked above).
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 | SimdPath::Avx512 => unsafe { self.occluded_avx2(ray) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.occluded_generic::<Sse>(ray) },
            _ => unsafe { self.occluded_generic::<Scalar>(ray) },
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_avx2(&self, ray: &Ray) -> bool {
        // SAFETY: the caller checked that AVX2 and FMA are available.
        unsafe { self.occluded_generic::<Avx2>(ray) }
    }

    /// # Safety
    /// `S` must be available on this CPU.
    #[inline(always)]
    unsafe fn occluded_generic<S: Isa>(&self, ray: &Ray) -> bool {
        let Some(rf) = RayFrame::new(ray) else { return false };
        // The test and the acceptance of `intersect` with nothing found yet: a reference
        // counts when its entry lies in (t_min, t_max), so the answers are the same.
        let bound = ray.t_max as f64 * (1.0 + 1e-6);
        let mut leaf = FnLeaf(|first: u32, count: u32, _: &Ray| {
            self.refs[first as usize..(first + count) as usize].iter().any(|&pr| {
                self.test_ref(&rf, pr, bound).is_some_and(|(t, _)| {
                    let tf = t as f32;
                    tf < ray.t_max && tf > ray.t_min
                })
            })
        });
        // SAFETY: the caller guarantees `S` is available.
        unsafe { self.bvh.occluded::<S>(ray, &mut leaf) }
    }

    /// Every primitive, without the BVH (for tests).
    pub fn intersect_brute_force(&self, ray: &Ray) -> Option<CurveHit> {
        let rf = RayFrame::new(ray)?;
        let mut best: Option<CurveHit> = None;
        for &pr in &self.refs {
            let point = pr >> PART_BITS;
            let Some((t, v)) = self.test_ref(&rf, pr, ray.t_max as f64 * (1.0 + 1e-6)) else { continue };
            let tf = t as f32;
            let better = match best {
                None => tf < ray.t_max,
                Some(b) => tf < b.t || (tf == b.t && point < b.point),
            };
            if better && tf > ray.t_min {
                best = Some(CurveHit { t: tf, point, v: v.clamp(0.0, 1.0) as f32 });
            }
        }
        best
    }

    /// The segment number (Mitsuba's primitive index) of the segment starting at `point`.
    pub fn segment_index(&self, point: u32) -> u32 {
        let curve = self.curve_starts.partition_point(|&s| s <= point) - 1;
        point - curve as u32 * self.basis.degree() as u32
    }

    /// The centre, its derivatives and the radius's at parameter `v` of a segment.
    fn centre(&self, point: u32, v: f64) -> (P4, P4, P4) {
        bezier_eval(&self.bezier(point), v)
    }

    /// The surface point of a hit, re-projected onto the sphere that touches it there.
    pub fn point(&self, ray: &Ray, hit: &CurveHit) -> CurvePoint {
        let v = hit.v as f64;
        let (c, dc, ddc) = self.centre(hit.point, v);
        let o = [ray.origin.x as f64, ray.origin.y as f64, ray.origin.z as f64];
        let d = [ray.dir.x as f64, ray.dir.y as f64, ray.dir.z as f64];
        let p = [o[0] + d[0] * hit.t as f64, o[1] + d[1] * hit.t as f64, o[2] + d[2] * hit.t as f64];
        let centre = [c[0], c[1], c[2]];
        let mut rad = curve_hit::sub(p, centre);
        let len = curve_hit::dot(rad, rad).sqrt();
        if len > 0.0 {
            rad = rad.map(|x| x / len);
        } else {
            rad = [-d[0], -d[1], -d[2]];
            let l = curve_hit::dot(rad, rad).sqrt();
            rad = rad.map(|x| x / l);
        }
        let radius = c[3].max(0.0);
        let p = [centre[0] + rad[0] * radius, centre[1] + rad[1] * radius, centre[2] + rad[2] * radius];
        let tangent = [dc[0], dc[1], dc[2]];
        let speed2 = curve_hit::dot(tangent, tangent);
        let axis = if speed2 > 0.0 { tangent.map(|x| x / speed2.sqrt()) } else { [0.0, 0.0, 1.0] };
        let (u_rot, u_rad) = local_frame(axis);
        let mut u = curve_hit::dot(u_rot, rad).atan2(curve_hit::dot(u_rad, rad));
        if u < 0.0 {
            u += 2.0 * std::f64::consts::PI;
        }
        let n_seg = self.segment_count as f64;
        let seg = self.segment_index(hit.point) as f64;
        // dp/du: around the curve; dp/dv: along it (the centre's motion, the radius's change
        // and the turn of the cross-section with the curve), over all segments.
        let dpdu = cross(axis, curve_hit::sub(p, centre)).map(|x| x * 2.0 * std::f64::consts::PI);
        let turn = if speed2 > 0.0 { -radius * curve_hit::dot(rad, [ddc[0], ddc[1], ddc[2]]) / speed2 } else { 0.0 };
        let dpdv: V3 = std::array::from_fn(|k| n_seg * (tangent[k] + dc[3] * rad[k] + turn * tangent[k]));
        CurvePoint {
            p: v3([p[0], p[1], p[2], 0.0]),
            n: v3([rad[0], rad[1], rad[2], 0.0]),
            uv: [(u / (2.0 * std::f64::consts::PI)) as f32, ((v + seg) / n_seg) as f32],
            dpdu: v3([dpdu[0], dpdu[1], dpdu[2], 0.0]),
            dpdv: v3([dpdv[0], dpdv[1], dpdv[2], 0.0]),
        }
    }
}

fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Mitsuba's frame around a curve's unit tangent: `u_rot` is +z made orthogonal to it (+y
/// where the tangent is ±z), `u_rad = u_rot × tangent`; u = 0 lies along `u_rad`.
fn local_frame(axis: V3) -> (V3, V3) {
    let guide = [0.0, 0.0, 1.0];
    let along = curve_hit::dot(axis, guide);
    let mut rot = [guide[0] - axis[0] * along, guide[1] - axis[1] * along, guide[2] - axis[2] * along];
    let l = curve_hit::dot(rot, rot).sqrt();
    if along.abs() >= 1.0 || !(l > 0.0) {
        rot = [0.0, 1.0, 0.0];
    } else {
        rot = rot.map(|x| x / l);
    }
    (rot, cross(rot, axis))
}
