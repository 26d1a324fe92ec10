//! Round curves (linear and B-spline) agree with brute force: a dense sampling of the swept
//! sphere (the entry of the ray into each sampled ball), refined around the nearest sample
//! by golden-section search over the curve parameter, for random curves with radii down to
//! near zero and random rays, many aimed at the silhouette (grazing).
//!
//! - Where the reference enters the curve at an angle (|cos| >= 0.05 to the normal), glint
//!   hits too, at the same `t` to within the f32 rounding of a distance (2 ulp).
//! - Wherever glint hits, the point lies on the swept surface, faces the ray, and no
//!   reference entry is nearer.
//! - The BVH, every SIMD path and brute force over the segments give the same bits.
//! - A ray leaving a hit (from the offset origin the integrators use) never hits a convex
//!   curve (one linear segment) again.

use glint::accel::{BvhSplit, SimdPath};
use glint::geometry::{CurveBasis, CurveHit, Curves};
use glint::math::{offset_origin, vec3, Ray, Vec3};
use proptest::prelude::*;

/// Samples of the curve parameter per segment in the reference.
const SAMPLES: usize = 400;
/// Golden-section steps that refine the nearest sample (to far below f32 precision).
const REFINE: usize = 80;
/// Rays per curve.
const RAYS: usize = 48;

type P4 = [f64; 4];

/// Centre and radius of segment `s` (first control point) at `v`, from the basis functions
/// themselves (not glint's Bézier form).
fn centre(basis: CurveBasis, pts: &[[f32; 4]], s: usize, v: f64) -> P4 {
    let p = |i: usize| pts[s + i].map(|c| c as f64);
    match basis {
        CurveBasis::Linear => std::array::from_fn(|c| p(0)[c] * (1.0 - v) + p(1)[c] * v),
        CurveBasis::BSpline => {
            let w = [
                (1.0 - v).powi(3) / 6.0,
                (3.0 * v.powi(3) - 6.0 * v * v + 4.0) / 6.0,
                (-3.0 * v.powi(3) + 3.0 * v * v + 3.0 * v + 1.0) / 6.0,
                v.powi(3) / 6.0,
            ];
            std::array::from_fn(|c| (0..4).map(|i| w[i] * p(i)[c]).sum())
        }
    }
}

/// Entry of the line o + t d into a ball (possibly behind the origin).
fn ball_entry(o: [f64; 3], d: [f64; 3], c: P4) -> Option<f64> {
    let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let b = (oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2]) / dd;
    let q = [oc[0] - b * d[0], oc[1] - b * d[1], oc[2] - b * d[2]];
    let h = c[3] * c[3] - (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    (h >= 0.0).then(|| -b - (h / dd).sqrt())
}

/// Golden-section minimum of `f` on [a, b].
fn golden(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..REFINE {
        if f1 <= f2 {
            b = x2;
            (x2, f2) = (x1, f1);
            x1 = b - g * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            (x1, f1) = (x2, f2);
            x2 = a + g * (b - a);
            f2 = f(x2);
        }
    }
    if f1 <= f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

struct Reference {
    t: f64,
    /// The segment's first point and the parameter of the ball entered.
    segment: usize,
    v: f64,
    /// Cosine between the ray and the normal there.
    cos: f64,
}

/// The nearest entry of the ray into the swept balls, over the segments starting at
/// `segments`.
fn reference(basis: CurveBasis, pts: &[[f32; 4]], segments: &[usize], o: [f64; 3], d: [f64; 3]) -> Option<Reference> {
    let entry = |s: usize, v: f64| ball_entry(o, d, centre(basis, pts, s, v)).unwrap_or(f64::INFINITY);
    // How far the line passes outside the ball of v: the balls it meets are the windows of v
    // around the local minima of this (smooth) gap, however thin the curve.
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let gap = |s: usize, v: f64| {
        let c = centre(basis, pts, s, v);
        let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
        let b = (oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2]) / dd;
        let q = [oc[0] - b * d[0], oc[1] - b * d[1], oc[2] - b * d[2]];
        (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() - c[3]
    };
    let h = 1.0 / SAMPLES as f64;
    let mut best: Option<(f64, usize, f64)> = None;
    for &s in segments {
        let gaps: Vec<f64> = (0..=SAMPLES).map(|k| gap(s, k as f64 * h)).collect();
        for k in 0..=SAMPLES {
            let left = if k > 0 { gaps[k - 1] } else { f64::INFINITY };
            let right = if k < SAMPLES { gaps[k + 1] } else { f64::INFINITY };
            if !(gaps[k] <= left && gaps[k] <= right) {
                continue;
            }
            let (vm, gm) = golden((k as f64 * h - h).max(0.0), (k as f64 * h + h).min(1.0), |v| gap(s, v));
            if gm > 0.0 {
                continue;
            }
            // The window's ends: step out until the gap is positive, then bisect.
            let edge = |dir: f64| {
                let mut inside = vm;
                let mut outside = vm;
                loop {
                    let next = (outside + dir * h).clamp(0.0, 1.0);
                    if gap(s, next) > 0.0 {
                        outside = next;
                        break;
                    }
                    inside = next;
                    outside = next;
                    if next == 0.0 || next == 1.0 {
                        return next;
                    }
                }
                for _ in 0..80 {
                    let mid = 0.5 * (inside + outside);
                    if gap(s, mid) <= 0.0 {
                        inside = mid;
                    } else {
                        outside = mid;
                    }
                }
                inside
            };
            let (a, b) = (edge(-1.0), edge(1.0));
            const WINDOW: usize = 64;
            let step = (b - a) / WINDOW as f64;
            let j = (0..=WINDOW)
                .min_by(|&x, &y| entry(s, a + x as f64 * step).total_cmp(&entry(s, a + y as f64 * step)))
                .unwrap();
            let (v, t) =
                golden((a + (j as f64 - 1.0) * step).max(a), (a + (j as f64 + 1.0) * step).min(b), |v| entry(s, v));
            let (v, t) = if entry(s, a + j as f64 * step) < t {
                (a + j as f64 * step, entry(s, a + j as f64 * step))
            } else {
                (v, t)
            };
            if t.is_finite() && best.is_none_or(|bb| t < bb.0) {
                best = Some((t, s, v));
            }
        }
    }
    let (t, s, v) = best?;
    let c = centre(basis, pts, s, v);
    let p = [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
    let n = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    let cos = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2])
        / ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
    Some(Reference { t, segment: s, v, cos })
}

/// Signed distance from `p` to the swept surface (negative inside), refined as above.
fn surface_distance(basis: CurveBasis, pts: &[[f32; 4]], segments: &[usize], p: [f64; 3]) -> f64 {
    let dist = |s: usize, v: f64| {
        let c = centre(basis, pts, s, v);
        ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt() - c[3]
    };
    let h = 1.0 / SAMPLES as f64;
    segments
        .iter()
        .map(|&s| {
            let k = (0..=SAMPLES).min_by(|&a, &b| dist(s, a as f64 * h).total_cmp(&dist(s, b as f64 * h))).unwrap();
            golden((k as f64 * h - h).max(0.0), (k as f64 * h + h).min(1.0), |v| dist(s, v)).1
        })
        .fold(f64::INFINITY, f64::min)
}

fn ulp(x: f32) -> f64 {
    (x.abs().next_up() - x.abs()) as f64
}

fn check_curve(basis: CurveBasis, pts: Vec<[f32; 4]>, seeds: &[f32]) -> Result<(), TestCaseError> {
    let n = pts.len() as u32;
    let curves = Curves::new(basis, pts.clone(), vec![0, n], BvhSplit::Sah).unwrap();
    let segments: Vec<usize> = (0..pts.len() - basis.degree()).collect();
    let paths = SimdPath::available();
    let mut r = seeds.iter().copied().cycle();
    let mut next = move || r.next().unwrap();
    let single_linear = basis == CurveBasis::Linear && segments.len() == 1;
    for i in 0..RAYS {
        // Aim at a point near the centre line: inside, on the silhouette (grazing) or just
        // outside it, from a random direction.
        let s = segments[i % segments.len()];
        let c = centre(basis, &pts, s, next() as f64);
        let dir = vec3(next() - 0.5, next() - 0.5, next() - 0.5);
        if dir.length() < 1e-3 {
            continue;
        }
        let dir = dir.normalize();
        let side = vec3(next() - 0.5, next() - 0.5, next() - 0.5);
        let side = (side - dir * side.dot(dir)).normalize();
        let reach = match i % 3 {
            0 => c[3] * next() as f64,
            1 => c[3] * (1.0 + (next() as f64 - 0.5) * 1e-4),
            _ => c[3] * (1.0 + next() as f64 * 0.2),
        } as f32;
        let target = vec3(c[0] as f32, c[1] as f32, c[2] as f32) + side * reach;
        let origin = target - dir * (3.0 + 2.0 * next());
        let ray = Ray::new(origin, dir * (0.5 + next()));
        let hit = curves.intersect_with(&ray, SimdPath::Scalar);
        for &p in &paths {
            prop_assert_eq!(curves.intersect_with(&ray, p), hit, "{:?}", p);
        }
        prop_assert_eq!(curves.intersect_brute_force(&ray), hit);
        // Any-hit occlusion answers as the closest hit does, on every path, also with the
        // ray cut just before or just after the hit.
        let mut cut = ray;
        for t_max in [ray.t_max, hit.map_or(ray.t_max, |h| h.t), hit.map_or(ray.t_max, |h| h.t.next_up())] {
            cut.t_max = t_max;
            let blocked = curves.intersect_with(&cut, SimdPath::Scalar).is_some();
            for &p in &paths {
                prop_assert_eq!(curves.occluded_with(&cut, p), blocked, "{:?} t_max {}", p, t_max);
            }
        }
        let o = [ray.origin.x as f64, ray.origin.y as f64, ray.origin.z as f64];
        let d = [ray.dir.x as f64, ray.dir.y as f64, ray.dir.z as f64];
        let refr = reference(basis, &pts, &segments, o, d);
        check_against_reference(basis, &pts, &segments, &ray, hit, refr.as_ref())?;
        if let Some(h) = hit {
            let q = curves.point(&ray, &h);
            // Leave the surface in a direction on the normal's side; a convex curve is not met
            // again.
            for _ in 0..4 {
                let w = vec3(next() - 0.5, next() - 0.5, next() - 0.5);
                let w = if w.dot(q.n) < 0.0 { -w } else { w };
                if w.length() < 1e-3 {
                    continue;
                }
                let out = Ray::new(offset_origin(q.p, q.n, w), w);
                let again = curves.intersect(&out);
                if single_linear {
                    prop_assert!(again.is_none(), "{:?} re-hit {:?}", out, again);
                }
                let o = [out.origin.x as f64, out.origin.y as f64, out.origin.z as f64];
                let d = [out.dir.x as f64, out.dir.y as f64, out.dir.z as f64];
                let refr = reference(basis, &pts, &segments, o, d);
                check_against_reference(basis, &pts, &segments, &out, again, refr.as_ref())?;
            }
        }
    }
    Ok(())
}

fn check_against_reference(
    basis: CurveBasis,
    pts: &[[f32; 4]],
    segments: &[usize],
    ray: &Ray,
    hit: Option<CurveHit>,
    refr: Option<&Reference>,
) -> Result<(), TestCaseError> {
    let o = [ray.origin.x as f64, ray.origin.y as f64, ray.origin.z as f64];
    let d = [ray.dir.x as f64, ray.dir.y as f64, ray.dir.z as f64];
    let last = *segments.last().unwrap();
    // B-spline ends are open: the reference's balls there have caps the curve lacks.
    let at_open_end = |r: &Reference| {
        basis == CurveBasis::BSpline && ((r.segment == 0 && r.v < 1e-3) || (r.segment == last && r.v > 1.0 - 1e-3))
    };
    if let Some(r) = refr {
        if r.t > ray.t_min as f64 && r.cos <= -0.05 && !at_open_end(r) {
            let h = hit.ok_or_else(|| {
                TestCaseError::fail(format!(
                    "missed: {ray:?} reference t {} segment {} v {} cos {}",
                    r.t, r.segment, r.v, r.cos
                ))
            })?;
            let tol = 2.0 * ulp(r.t as f32);
            prop_assert!((h.t as f64 - r.t).abs() <= tol, "t {} vs reference {} (tol {tol})", h.t, r.t);
        }
    }
    if let Some(h) = hit {
        let t = h.t as f64;
        let p = [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
        // The distance the f32 rounding of t moves the point, and the f32 control points'.
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let scale = p.iter().fold(1.0f64, |m, c| m.max(c.abs()));
        let tol = 2.0 * ulp(h.t) * len + 1e-6 * scale;
        // Its own sphere passes through the point.
        let c = centre(basis, pts, h.point as usize, h.v as f64);
        let own = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt() - c[3];
        prop_assert!(own.abs() <= tol, "hit {:?} is {own} off its sphere (tol {tol})", h);
        let n = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        prop_assert!(n[0] * d[0] + n[1] * d[1] + n[2] * d[2] < 0.0, "back face {:?}", h);
        // Past an open end's cap (in the reference, not the curve), or from inside it, the
        // point may lie inside the reference's end ball: no more to compare.
        let in_end_ball = |q: [f64; 3]| {
            let inside = |c: P4| ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2) + (q[2] - c[2]).powi(2)).sqrt() < c[3];
            basis == CurveBasis::BSpline
                && (inside(centre(basis, pts, 0, 0.0)) || inside(centre(basis, pts, last, 1.0)))
        };
        let open_ends = in_end_ball(o) || in_end_ball(p);
        // From inside the reference's volume (a ray leaving a hit past an open end, say) there
        // is no entry to compare with either.
        if refr.is_some_and(at_open_end) || open_ends || surface_distance(basis, pts, segments, o) < 0.0 {
            return Ok(());
        }
        let e = surface_distance(basis, pts, segments, p);
        prop_assert!(
            e.abs() <= tol,
            "hit {:?} is {e} off the surface (tol {tol}); reference {:?}",
            h,
            refr.map(|r| (r.t, r.segment, r.v, r.cos))
        );
        if let Some(r) = refr {
            prop_assert!(r.t >= t - tol / len - 2.0 * ulp(h.t) || r.t <= ray.t_min as f64, "nearer {} {}", r.t, t);
        }
    }
    Ok(())
}

/// A random walk of `n` points with radii in [rmin, rmax], its steps 0.4 to 1 long: curves
/// whose radius is small beside their length, as hair is (where a tube is fatter than its
/// segments are long, its envelope degenerates: Embree and Mitsuba assume the same).
fn walk(steps: &[f32], n: usize, rmin: f32, rmax: f32) -> Vec<[f32; 4]> {
    let mut p = Vec3::ZERO;
    let mut out = Vec::new();
    for k in 0..n {
        let s = &steps[4 * k..4 * k + 4];
        let dir = vec3(s[0] - 0.5, s[1] - 0.5, s[2] - 0.5);
        let dir = if dir.length() > 1e-3 { dir.normalize() } else { Vec3::X };
        p += dir * (0.4 + 0.6 * s[3]);
        out.push([p.x, p.y, p.z, rmin + (rmax - rmin) * s[(k + 1) % 4]]);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn linear_curves_agree_with_the_swept_spheres(
        n in 2usize..6,
        steps in prop::collection::vec(0.0f32..1.0, 24),
        thin in prop::bool::ANY,
        seeds in prop::collection::vec(0.0f32..1.0, 64),
    ) {
        let (rmin, rmax) = if thin { (1e-5, 1e-3) } else { (0.02, 0.3) };
        check_curve(CurveBasis::Linear, walk(&steps, n, rmin, rmax), &seeds)?;
    }

    #[test]
    fn bspline_curves_agree_with_the_swept_spheres(
        n in 4usize..7,
        steps in prop::collection::vec(0.0f32..1.0, 28),
        thin in prop::bool::ANY,
        seeds in prop::collection::vec(0.0f32..1.0, 64),
    ) {
        let (rmin, rmax) = if thin { (1e-5, 1e-3) } else { (0.02, 0.1) };
        check_curve(CurveBasis::BSpline, walk(&steps, n, rmin, rmax), &seeds)?;
    }
}
