//! Ray intersection with round curve segments, in f64 and in the ray's own frame.
//!
//! A segment is the volume swept by a sphere whose centre `c(v)` and radius `r(v)` follow
//! the segment's parameter `v` in [0, 1]. Its surface point of parameter `v` touches the
//! sphere of that `v`, so the normal there is `(p - c(v)) / r(v)`.
//!
//! - Linear: `c` and `r` linear in `v`. The swept volume is the convex hull of the two end
//!   balls (a cone between two spheres), intersected in closed form: the ray's entry is the
//!   nearest of the two sphere entries and the cone's roots (a line enters a convex body once,
//!   and every sphere point lies inside it, so none is nearer than the entry).
//! - Cubic (uniform B-spline): the segment is cut into Bézier spans in the ray's frame (the
//!   ray is the z axis there); a span whose control hull, widened by its largest radius,
//!   misses the axis is dropped, a flat one is approximated by the rounded cone through its
//!   ends, and that cone's entry starts a Newton iteration on the exact equations (the point
//!   lies on the sphere of `v`, and `v` is where it touches the envelope).
//!
//! Only entries are reported (Mitsuba's curves cull back faces): a ray that starts inside a
//! curve does not see its wall, so a reflected ray, started just outside, cannot hit the
//! curve it leaves.

/// A 3-vector in f64.
pub type V3 = [f64; 3];

#[inline(always)]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline(always)]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
fn add_scaled(a: V3, b: V3, s: f64) -> V3 {
    [a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s]
}
#[inline(always)]
fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// A control point (or a point of the centre line): position and radius.
pub type P4 = [f64; 4];

#[inline(always)]
fn xyz(p: P4) -> V3 {
    [p[0], p[1], p[2]]
}

/// The near root of `|o + t d - c|² = r²` (its entry), or `None` when the line misses the
/// sphere. Computed from the closest approach to the centre, which loses no precision
/// when the sphere is small and far.
#[inline]
fn sphere_entry(o: V3, d: V3, c: V3, r: f64) -> Option<f64> {
    let dd = dot(d, d);
    let oc = sub(o, c);
    let b = dot(oc, d);
    let closest = add_scaled(oc, d, -b / dd);
    let disc = dd * (r * r - dot(closest, closest));
    if !(disc >= 0.0) {
        return None;
    }
    let c2 = dot(oc, oc) - r * r;
    let q = -b + if b <= 0.0 { disc.sqrt() } else { -disc.sqrt() };
    // The two roots are c2 / q and q / dd; the near one is the smaller.
    let (t0, t1) = if q == 0.0 { (-b / dd, -b / dd) } else { (c2 / q, q / dd) };
    Some(t0.min(t1))
}

/// Where a line meets the convex hull of two balls: its entry `t` (possibly behind the
/// origin) and the parameter `v` in [0, 1] of the sphere it touches there. `o` and `d` are
/// the line's origin and direction relative to any point (the caller picks one near the
/// segment for precision). `None` when the line misses it or the balls are both points.
pub fn rounded_cone_entry(o: V3, d: V3, a: P4, b: P4) -> Option<(f64, f64)> {
    let (pa, pb) = (xyz(a), xyz(b));
    let axis = sub(pb, pa);
    let l2 = dot(axis, axis);
    let dr = b[3] - a[3];
    if !(a[3].max(b[3]) > 0.0) || !(dot(d, d) > 0.0) {
        return None;
    }
    // One ball inside the other: the hull is the larger ball.
    if dr * dr >= l2 {
        return if a[3] >= b[3] {
            sphere_entry(o, d, pa, a[3]).map(|t| (t, 0.0))
        } else {
            sphere_entry(o, d, pb, b[3]).map(|t| (t, 1.0))
        };
    }
    let mut best: Option<(f64, f64)> = None;
    let mut take = |t: f64, v: f64| {
        if best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, v));
        }
    };
    if let Some(t) = sphere_entry(o, d, pa, a[3]) {
        take(t, 0.0);
    }
    if let Some(t) = sphere_entry(o, d, pb, b[3]) {
        take(t, 1.0);
    }
    // The cone tangent to both spheres. With y the axial coordinate from `pa` (length units),
    // x the distance from the axis and k = dr / L, its points satisfy
    // x² (1 - k²) = (r0 + k y)², r0 + k y >= 0, and touch the sphere at axial position
    // s = (y + k r0) / (1 - k²), which must lie in [0, L].
    let len = l2.sqrt();
    let u = scale(axis, 1.0 / len);
    let k = dr / len;
    let one_k2 = 1.0 - k * k;
    let w0 = sub(o, pa);
    let (yo, yd) = (dot(w0, u), dot(d, u));
    let (op, dp) = (add_scaled(w0, u, -yo), add_scaled(d, u, -yd));
    let g0 = a[3] + k * yo;
    let qa = one_k2 * dot(dp, dp) - k * k * yd * yd;
    let qb = one_k2 * dot(op, dp) - g0 * k * yd;
    let qc = one_k2 * dot(op, op) - g0 * g0;
    let mut cone_root = |t: f64| {
        let y = yo + t * yd;
        let s = (y + k * a[3]) / one_k2;
        if a[3] + k * y >= 0.0 && (0.0..=len).contains(&s) {
            take(t, s / len);
        }
    };
    if qa != 0.0 {
        let disc = qb * qb - qa * qc;
        if disc >= 0.0 {
            let q = -qb - qb.signum() * disc.sqrt();
            if q != 0.0 {
                cone_root(q / qa);
                cone_root(qc / q);
            } else {
                cone_root(-qb / qa);
            }
        }
    } else if qb != 0.0 {
        cone_root(-qc / (2.0 * qb));
    }
    best
}

/// The four Bézier control points of the uniform cubic B-spline segment of `p`.
pub fn bspline_to_bezier(p: [P4; 4]) -> [P4; 4] {
    let mix = |w: [f64; 4]| -> P4 {
        std::array::from_fn(|c| (w[0] * p[0][c] + w[1] * p[1][c] + w[2] * p[2][c] + w[3] * p[3][c]) / 6.0)
    };
    [mix([1.0, 4.0, 1.0, 0.0]), mix([0.0, 4.0, 2.0, 0.0]), mix([0.0, 2.0, 4.0, 0.0]), mix([0.0, 1.0, 4.0, 1.0])]
}

/// A cubic's value and first two derivatives at `v` (from its Bézier control points).
pub fn bezier_eval(b: &[P4; 4], v: f64) -> (P4, P4, P4) {
    let s = 1.0 - v;
    let (b0, b1, b2, b3) = (s * s * s, 3.0 * s * s * v, 3.0 * s * v * v, v * v * v);
    let (d0, d1, d2) = (3.0 * s * s, 6.0 * s * v, 3.0 * v * v);
    let (e0, e1) = (6.0 * s, 6.0 * v);
    let p = std::array::from_fn(|c| b0 * b[0][c] + b1 * b[1][c] + b2 * b[2][c] + b3 * b[3][c]);
    let dp = std::array::from_fn(|c| d0 * (b[1][c] - b[0][c]) + d1 * (b[2][c] - b[1][c]) + d2 * (b[3][c] - b[2][c]));
    let ddp =
        std::array::from_fn(|c| e0 * (b[2][c] - 2.0 * b[1][c] + b[0][c]) + e1 * (b[3][c] - 2.0 * b[2][c] + b[1][c]));
    (p, dp, ddp)
}

/// The Bézier control points of the part `[v0, v1]` of a cubic.
pub fn bezier_part(b: &[P4; 4], v0: f64, v1: f64) -> [P4; 4] {
    // Blossoms: the control points of [v0, v1] are f(v0,v0,v0), f(v0,v0,v1), f(v0,v1,v1),
    // f(v1,v1,v1) of the cubic's polar form.
    let blossom = |x: [f64; 3]| -> P4 {
        let lerp = |p: P4, q: P4, t: f64| -> P4 { std::array::from_fn(|c| p[c] + (q[c] - p[c]) * t) };
        let l1 = [lerp(b[0], b[1], x[0]), lerp(b[1], b[2], x[0]), lerp(b[2], b[3], x[0])];
        let l2 = [lerp(l1[0], l1[1], x[1]), lerp(l1[1], l1[2], x[1])];
        lerp(l2[0], l2[1], x[2])
    };
    [blossom([v0, v0, v0]), blossom([v0, v0, v1]), blossom([v0, v1, v1]), blossom([v1, v1, v1])]
}

/// Spans shorter than this (in `v`) are not cut further.
const MAX_SPLIT_DEPTH: u32 = 7;
/// A span is flat enough for its rounded cone to start Newton's iteration when its inner
/// control points lie within this fraction of its smallest radius from its chord.
const FLATNESS: f64 = 0.1;
const NEWTON_STEPS: u32 = 12;

/// The entry `(t, v)` of a ray into the swept sphere of a cubic with Bézier control points
/// `b`, among the points of parameter `v` in `[v0, v1]` (and in [0, 1]: the segment's ends
/// are open), with `t` in `(t_min, t_max]`. The control points are in the ray's frame: the
/// ray starts at the origin and runs along +z at unit speed (`t` is then the distance).
pub fn cubic_entry(b: &[P4; 4], v0: f64, v1: f64, t_min: f64, t_max: f64) -> Option<(f64, f64)> {
    let mut best: Option<(f64, f64)> = None;
    let mut stack: Vec<(f64, f64, u32)> = Vec::new();
    stack.push((v0, v1, 0));
    while let Some((a, c, depth)) = stack.pop() {
        let span = bezier_part(b, a, c);
        let rmax = span.iter().fold(0.0f64, |m, p| m.max(p[3]));
        let far = best.map_or(t_max, |(t, _)| t);
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &span {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        // Every point of the span lies within `rmax` of its control hull.
        if lo[0] > rmax || hi[0] < -rmax || lo[1] > rmax || hi[1] < -rmax || hi[2] + rmax < t_min || lo[2] - rmax > far
        {
            continue;
        }
        if !(rmax > 0.0) {
            continue;
        }
        // How far the span strays from the rounded cone through its ends: its inner control
        // points' distance from the chord and their radii's from the ends' interpolation.
        let chord = sub(xyz(span[3]), xyz(span[0]));
        let cl2 = dot(chord, chord);
        let deviation = |p: P4, along: f64| {
            let w = sub(xyz(p), xyz(span[0]));
            let proj = if cl2 > 0.0 { dot(w, chord) / cl2 } else { 0.0 };
            let off = add_scaled(w, chord, -proj);
            dot(off, off).sqrt() + (p[3] - (span[0][3] + (span[3][3] - span[0][3]) * along)).abs()
        };
        let stray = deviation(span[1], 1.0 / 3.0).max(deviation(span[2], 2.0 / 3.0));
        let rmin = span.iter().fold(f64::INFINITY, |m, p| m.min(p[3])).max(0.0);
        if depth < MAX_SPLIT_DEPTH && stray > FLATNESS * rmin.max(rmax * 0.25) {
            let m = 0.5 * (a + c);
            // Nearer half (by its middle's depth) on top.
            let (za, zc) = (bezier_eval(b, 0.5 * (a + m)).0[2], bezier_eval(b, 0.5 * (m + c)).0[2]);
            if za <= zc {
                stack.push((m, c, depth + 1));
                stack.push((a, m, depth + 1));
            } else {
                stack.push((a, m, depth + 1));
                stack.push((m, c, depth + 1));
            }
            continue;
        }
        // The cone widened by the stray holds the span (the control hull lies within `stray`
        // of the chord): its entry, if any, starts Newton's iteration just before the surface.
        let widen = |p: P4| -> P4 { [p[0], p[1], p[2], p[3] + stray] };
        let cone = rounded_cone_entry([0.0; 3], [0.0, 0.0, 1.0], widen(span[0]), widen(span[3]));
        let Some((t0, s)) = cone else {
            continue;
        };
        // Newton's iteration from the cone's entry converges fast where the ray meets the
        // curve at an angle; where it does not (grazing rays), a bracketing search finds the
        // entry. A root that lands outside the span is still a point of the surface: kept.
        let fast = newton(b, t0, a + s * (c - a)).filter(|(_, v)| (0.0..=1.0).contains(v));
        let Some((t, v)) = fast.or_else(|| bracketed_entry(b, a, c)) else { continue };
        if t > t_min && t <= far && best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, v));
        }
    }
    best
}

/// Steps of the golden-section and bisection searches of [`bracketed_entry`]: each shrinks
/// its interval 1.6 or 2 times, so 90 take a span of [0, 1] below f64 resolution.
const SEARCH_STEPS: u32 = 90;

/// Golden-section minimum of `f` over `[lo, hi]`.
fn golden_min(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..SEARCH_STEPS {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    if f1 <= f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

/// The entry of the ray (the z axis) into the spheres of parameters `[a, c]` of a cubic, by
/// search rather than Newton: the spheres it meets are those of the window of `v` where its
/// distance from the centre is at most the radius (around the minimum of the difference, which
/// is unimodal on a flat span), and the entry is the minimum over that window of the
/// spheres' near roots. `None` when the ray misses, or when the minimum is at the span's
/// ends (then it is the neighbour's, or an open end).
fn bracketed_entry(b: &[P4; 4], a: f64, c: f64) -> Option<(f64, f64)> {
    let gap = |v: f64| {
        let (p, _, _) = bezier_eval(b, v);
        (p[0] * p[0] + p[1] * p[1]).sqrt() - p[3]
    };
    let (v_min, g_min) = golden_min(a, c, gap);
    if g_min > 0.0 {
        return None;
    }
    let edge = |outer: f64| {
        if gap(outer) <= 0.0 {
            return outer;
        }
        let (mut inside, mut outside) = (v_min, outer);
        for _ in 0..SEARCH_STEPS {
            let mid = 0.5 * (inside + outside);
            if gap(mid) <= 0.0 {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        inside
    };
    let (lo, hi) = (edge(a), edge(c));
    let near = |v: f64| {
        let (p, _, _) = bezier_eval(b, v);
        let h = p[3] * p[3] - (p[0] * p[0] + p[1] * p[1]);
        if h >= 0.0 {
            p[2] - h.sqrt()
        } else {
            f64::INFINITY
        }
    };
    let (v, t) = golden_min(lo, hi, near);
    let end = 1e-9 * (c - a);
    (t.is_finite() && v > a + end && v < c - end).then_some((t, v))
}

/// Newton's iteration for the point `(0, 0, t)` of the ray on the envelope of the spheres
/// of a cubic: F1 = (p - c)·c' + r r' = 0 (it touches the envelope), F2 = |p - c|² - r² = 0.
/// Each round starts from the ray's entry into the sphere of the current `v` (when it meets
/// it); a round that lands on an exit (a grazing ray converges there as readily) starts the
/// next from the entry of that sphere. Returns the converged `(t, v)` of an entry, or `None`.
fn newton(b: &[P4; 4], mut t: f64, mut v: f64) -> Option<(f64, f64)> {
    for _round in 0..3 {
        let (c, _, _) = bezier_eval(b, v);
        let miss2 = c[0] * c[0] + c[1] * c[1];
        if c[3] * c[3] >= miss2 {
            t = c[2] - (c[3] * c[3] - miss2).sqrt();
        }
        (t, v) = newton_round(b, t, v)?;
        let (c, dc, ddc) = bezier_eval(b, v);
        let w = [-c[0], -c[1], t - c[2]];
        if w[2] >= 0.0 {
            continue; // an exit: try from the entry of this sphere
        }
        // On the envelope's outer sheet |p - c(v)|² - r(v)² is at a minimum over v (where the
        // curve bends more tightly than its radius, the inner sheet lies inside the volume).
        let (dc3, ddc3) = (xyz(dc), xyz(ddc));
        let g2 = dot(dc3, dc3) - dot(w, ddc3) - dc[3] * dc[3] - c[3] * ddc[3];
        return (g2 >= 0.0).then_some((t, v));
    }
    None
}

fn newton_round(b: &[P4; 4], mut t: f64, mut v: f64) -> Option<(f64, f64)> {
    for step in 0..NEWTON_STEPS {
        let (c, dc, ddc) = bezier_eval(b, v);
        let w = [-c[0], -c[1], t - c[2]];
        let (r, dr, ddr) = (c[3], dc[3], ddc[3]);
        let (dc3, ddc3) = (xyz(dc), xyz(ddc));
        let f1 = dot(w, dc3) + r * dr;
        let f2 = dot(w, w) - r * r;
        let j11 = dc3[2];
        let j12 = -dot(dc3, dc3) + dot(w, ddc3) + dr * dr + r * ddr;
        let j21 = 2.0 * w[2];
        let j22 = -2.0 * f1;
        let det = j11 * j22 - j12 * j21;
        if !(det != 0.0) || !det.is_finite() {
            return None;
        }
        let dt = -(f1 * j22 - j12 * f2) / det;
        let dv = -(j11 * f2 - j21 * f1) / det;
        t += dt;
        v += dv;
        if !(t.is_finite() && v.is_finite() && (-0.5..=1.5).contains(&v)) {
            return None;
        }
        let scale = t.abs().max(r.abs()).max(1e-30);
        if dt.abs() <= 1e-12 * scale && dv.abs() <= 1e-12 && step > 0 {
            return Some((t, v));
        }
        if step == NEWTON_STEPS - 1 && !(dt.abs() <= 1e-7 * scale && dv.abs() <= 1e-7) {
            return None;
        }
    }
    Some((t, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounded_cone_of_equal_radii_is_a_capsule() {
        // A capsule along x of radius 0.5 from 0 to 2, hit from above at x = 1: t = 4.5.
        let (t, v) =
            rounded_cone_entry([1.0, 5.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 0.5], [2.0, 0.0, 0.0, 0.5]).unwrap();
        assert!((t - 4.5).abs() < 1e-12 && (v - 0.5).abs() < 1e-12, "{t} {v}");
        // Along the axis, the cap of the first sphere: t = 4.5 from x = -5.
        let (t, v) =
            rounded_cone_entry([-5.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.5], [2.0, 0.0, 0.0, 0.5]).unwrap();
        assert!((t - 4.5).abs() < 1e-12 && v == 0.0);
        // Beyond the cap, past the end: a miss.
        assert!(
            rounded_cone_entry([3.0, 5.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 0.5], [2.0, 0.0, 0.0, 0.5]).is_none()
        );
    }

    #[test]
    fn tapered_cone_touches_the_sphere_of_its_parameter() {
        let (a, b) = ([0.0, 0.0, 0.0, 1.0], [4.0, 0.0, 0.0, 0.25]);
        let o = [1.7, 6.0, 0.1];
        let d = [0.1, -1.0, 0.02];
        let (t, v) = rounded_cone_entry(o, d, a, b).unwrap();
        let p = add_scaled(o, d, t);
        let c = [4.0 * v, 0.0, 0.0];
        let r = 1.0 + (0.25 - 1.0) * v;
        assert!((dot(sub(p, c), sub(p, c)).sqrt() - r).abs() < 1e-12);
        // Tangency: |p - c(v)|² - r(v)² is stationary in v, (p - c)·c' + r r' = 0.
        let f1 = dot(sub(p, c), [4.0, 0.0, 0.0]) + r * (0.25 - 1.0);
        assert!(f1.abs() < 1e-9, "{f1}");
    }

    #[test]
    fn straight_cubic_agrees_with_the_capsule_inside_its_span() {
        // A B-spline with collinear, evenly spaced points is the straight line at unit speed.
        let p = [[-1.0, 0.0, 5.0, 0.2], [0.0, 0.0, 5.0, 0.2], [1.0, 0.0, 5.0, 0.2], [2.0, 0.0, 5.0, 0.2]];
        let b = bspline_to_bezier(p);
        let (t, v) = cubic_entry(&b, 0.0, 1.0, 0.0, f64::INFINITY).unwrap();
        // The ray is the z axis: x = 0 is the segment's start (v = 0, c = p1).
        assert!((t - 4.8).abs() < 1e-12 && v.abs() < 1e-9, "{t} {v}");
        let shifted: [P4; 4] = p.map(|q| [q[0] - 0.5, q[1], q[2], q[3]]);
        let (t, v) = cubic_entry(&bspline_to_bezier(shifted), 0.0, 1.0, 0.0, f64::INFINITY).unwrap();
        assert!((t - 4.8).abs() < 1e-12 && (v - 0.5).abs() < 1e-9, "{t} {v}");
        // Past the open end (x = 1.0 + 0.1 beyond v = 1): the cap is not there.
        let shifted: [P4; 4] = p.map(|q| [q[0] - 1.1, q[1], q[2], q[3]]);
        assert!(cubic_entry(&bspline_to_bezier(shifted), 0.0, 1.0, 0.0, f64::INFINITY).is_none());
    }
}
