//! Sampling a rectangular light by solid angle: the rectangle seen from a point is a spherical
//! rectangle, sampled uniformly by Ureña, Fajardo and King's method ("An Area-Preserving
//! Parametrization for Spherical Rectangles", EGSR 2013). Every sample lands on the light and
//! the density is one over the solid angle, so near a large light the estimate no longer
//! suffers the 1/d² spikes of area sampling.
//!
//! Done in f64: the solid angle is a sum of four angles less 2π, which cancels badly in f32.
//! Where area sampling is nearly uniform in solid angle anyway (the light far away compared
//! with its size), where the solid angle is tiny (edge-on) or close to a hemisphere (right on
//! the light), the caller samples by area instead; the choice depends on the point alone, so
//! the density given to a BSDF-sampled direction always matches the sampler's.

use crate::math::{vec3, Vec3};

/// Below this solid angle (sr) area sampling is as good, and the method loses precision.
const MIN_SOLID_ANGLE: f64 = 1e-4;
/// Above this (near the full hemisphere of 2π sr) the point almost touches the light.
const MAX_SOLID_ANGLE: f64 = 6.2;
/// Area sampling's density in solid angle, d³/h (h: the point's height over the light's
/// plane), varies across the light by at most (d_max/d_min)³. Below this bound area sampling
/// is close enough to uniform in solid angle and far cheaper (no trigonometry), so it is kept.
/// At 2 the f64 trigonometry cost 17-18% of the render time on the Cornell boxes of
/// `bench/compare-mitsuba` for 4% less error (equal-error time 15% worse than area sampling,
/// Zen 5, BENCHMARKS.md); at 8 it is used only near large lights, where it pays.
const MIN_AREA_PDF_SPREAD: f64 = 8.0;

/// A rectangular emitter: `corner + s ex + t ey` for s, t in [0, 1], with `ex ⟂ ey`, and
/// `normal` the side its triangles face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rectangle {
    pub corner: Vec3,
    pub ex: Vec3,
    pub ey: Vec3,
    pub normal: Vec3,
    /// The edges' unit vectors and lengths in f64, worked out once: every shading point
    /// needs them to decide how to sample.
    edges: EdgeFrame,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct EdgeFrame {
    x: V,
    y: V,
    z: V,
    lx: f64,
    ly: f64,
    /// The same rounded to f32, for the quick test of `area_sampling_is_clearly_uniform`.
    x32: Vec3,
    y32: Vec3,
    z32: Vec3,
    lx32: f32,
    ly32: f32,
}

impl Rectangle {
    /// The rectangle that two triangles form, if they form one: four distinct corners, right
    /// angles (to 1e-5), both triangles facing the same way.
    pub fn from_triangles(tris: &[[Vec3; 3]]) -> Option<Rectangle> {
        let [t1, t2] = tris else { return None };
        let shared: Vec<Vec3> = t1.iter().copied().filter(|v| t2.contains(v)).collect();
        if shared.len() != 2 {
            return None;
        }
        let lone1 = *t1.iter().find(|v| !shared.contains(v))?;
        let lone2 = *t2.iter().find(|v| !shared.contains(v))?;
        let (ex, ey) = (shared[0] - lone1, shared[1] - lone1);
        let (lx, ly) = (ex.length(), ey.length());
        let tol = 1e-5;
        if !(lx > 0.0 && ly > 0.0)
            || ex.dot(ey).abs() > tol * lx * ly
            || (lone1 + ex + ey - lone2).length() > tol * (lx + ly)
        {
            return None;
        }
        let face = |[a, b, c]: [Vec3; 3]| (b - a).cross(c - a);
        let (n1, n2) = (face(*t1), face(*t2));
        if n1.dot(n2) <= 0.0 {
            return None;
        }
        Some(Rectangle::new(lone1, ex, ey, n1.normalize()))
    }

    /// The rectangle `corner + s ex + t ey` (s, t in [0, 1]) facing `normal`; `ex` and `ey`
    /// must be perpendicular.
    pub fn new(corner: Vec3, ex: Vec3, ey: Vec3, normal: Vec3) -> Rectangle {
        let (wx, wy) = (wide(ex), wide(ey));
        let (x, y) = (unit(wx), unit(wy));
        let (z, lx, ly) = (cross(x, y), dot(wx, wx).sqrt(), dot(wy, wy).sqrt());
        let narrow = |v: V| vec3(v[0] as f32, v[1] as f32, v[2] as f32);
        let (x32, y32, z32) = (narrow(x), narrow(y), narrow(z));
        let edges = EdgeFrame { x, y, z, lx, ly, x32, y32, z32, lx32: lx as f32, ly32: ly as f32 };
        Rectangle { corner, ex, ey, normal, edges }
    }

    pub fn area(&self) -> f32 {
        self.ex.cross(self.ey).length()
    }
}

type V = [f64; 3];

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn unit(a: V) -> V {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}
fn wide(v: Vec3) -> V {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// The spread test of [`SphericalRectangle::new`] in f32, with a margin: true only where the
/// f64 test also finds area sampling's density varying by less than `min_spread` (so the
/// decision, and the image, are the same), without the conversions and f64 arithmetic. Most
/// shading points are far from the light compared with its size and end here (on the Cornell
/// box, `SphericalRectangle::new` went from 8.4 to 6.6 M instructions in callgrind).
///
/// Why the margin is safe: where this returns true, r = far²/near² < 4 (for the spread of 8;
/// the same argument holds for any moderate spread), so near² > far²/4 >= |d|²/4 (far² is at least |d|², d
/// the corner seen from `p` in the edge frame) and the edges are at most 2 sqrt(far²) long:
/// every term is within a small factor of |d|², and f32 rounding moves r by well under 1e-4
/// relative, far inside the 10% margin on r³. NaN fails the comparison: the f64 test decides.
#[inline]
fn area_sampling_is_clearly_uniform(r: &Rectangle, p: Vec3, min_spread: f64) -> bool {
    let e = &r.edges;
    let d = r.corner - p;
    let (x0, y0, z0) = (d.dot(e.x32), d.dot(e.y32), d.dot(e.z32));
    let (x1, y1) = (x0 + e.lx32, y0 + e.ly32);
    let near2 = x0.max(0.0).min(x1).powi(2) + y0.max(0.0).min(y1).powi(2) + z0 * z0;
    let far2 = x0.abs().max(x1.abs()).powi(2) + y0.abs().max(y1.abs()).powi(2) + z0 * z0;
    let ratio = far2 / near2;
    ratio * ratio * ratio < (0.9 * min_spread * min_spread) as f32
}

/// The rectangle as seen from a point: its coordinates in a frame at the point with axes
/// along the edges and `z` away from the light, and the constants of the parametrization.
pub(super) struct SphericalRectangle {
    origin: V,
    axes: [V; 3],
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    b0: f64,
    b1: f64,
    k: f64,
    solid_angle: f64,
}

impl SphericalRectangle {
    /// `None` where the rectangle should be sampled by area from `p` (see the module doc).
    pub fn new(r: &Rectangle, p: Vec3) -> Option<SphericalRectangle> {
        Self::with_min_spread(r, p, MIN_AREA_PDF_SPREAD)
    }

    /// [`SphericalRectangle::new`] with the area-density spread below which area sampling is
    /// kept as a parameter (tests of the parametrization pass 0: always by solid angle).
    fn with_min_spread(r: &Rectangle, p: Vec3, min_spread: f64) -> Option<SphericalRectangle> {
        if area_sampling_is_clearly_uniform(r, p, min_spread) {
            return None;
        }
        Self::with_min_spread_f64(r, p, min_spread)
    }

    /// The decision and set-up in f64 alone (what the f32 test must never contradict).
    fn with_min_spread_f64(r: &Rectangle, p: Vec3, min_spread: f64) -> Option<SphericalRectangle> {
        let EdgeFrame { x, y, mut z, lx, ly, .. } = r.edges;
        let origin = wide(p);
        let c = wide(r.corner);
        let d = [c[0] - origin[0], c[1] - origin[1], c[2] - origin[2]];
        let mut z0 = dot(d, z);
        if z0 > 0.0 {
            z = [-z[0], -z[1], -z[2]];
            z0 = -z0;
        }
        if !(z0 < 0.0) {
            return None; // in the light's plane, or not a number
        }
        let (x0, y0) = (dot(d, x), dot(d, y));
        let (x1, y1) = (x0 + lx, y0 + ly);
        let near2 = x0.max(0.0).min(x1).powi(2) + y0.max(0.0).min(y1).powi(2) + z0 * z0;
        let far2 = x0.abs().max(x1.abs()).powi(2) + y0.abs().max(y1.abs()).powi(2) + z0 * z0;
        let r = far2 / near2;
        if r * r * r < min_spread * min_spread {
            return None;
        }
        let (v00, v01, v10, v11) = ([x0, y0, z0], [x0, y1, z0], [x1, y0, z0], [x1, y1, z0]);
        let n0 = unit(cross(v00, v10));
        let n1 = unit(cross(v10, v11));
        let n2 = unit(cross(v11, v01));
        let n3 = unit(cross(v01, v00));
        let angle = |a: V, b: V| (-dot(a, b)).clamp(-1.0, 1.0).acos();
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = 2.0 * std::f64::consts::PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        if !(MIN_SOLID_ANGLE..=MAX_SOLID_ANGLE).contains(&solid_angle) {
            return None;
        }
        Some(SphericalRectangle { origin, axes: [x, y, z], x0, x1, y0, y1, z0, b0: n0[2], b1: n2[2], k, solid_angle })
    }

    /// Density in solid angle of every direction towards the rectangle.
    pub fn pdf(&self) -> f32 {
        (1.0 / self.solid_angle) as f32
    }

    /// The point on the rectangle for `u`, uniform in solid angle.
    pub fn sample(&self, u: [f32; 2]) -> Vec3 {
        let (u0, u1) = (u[0] as f64, u[1] as f64);
        // x: invert the solid angle of the sub-rectangle [x0, xu] × [y0, y1].
        let au = u0 * self.solid_angle + self.k;
        let fu = (au.cos() * self.b0 - self.b1) / au.sin();
        let cu = ((fu * fu + self.b0 * self.b0).sqrt().recip() * if fu > 0.0 { 1.0 } else { -1.0 }).clamp(-1.0, 1.0);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).sqrt()).clamp(self.x0, self.x1);
        // y: uniform in the height of the sampled direction's projection.
        let dd = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (dd * dd + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (dd * dd + self.y1 * self.y1).sqrt();
        let hv = h0 + u1 * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 { (hv * dd / (1.0 - hv2).sqrt()).clamp(self.y0, self.y1) } else { self.y1 };
        let [x, y, z] = self.axes;
        let q = |i: usize| self.origin[i] + xu * x[i] + yv * y[i] + self.z0 * z[i];
        vec3(q(0) as f32, q(1) as f32, q(2) as f32)
    }

    /// The solid angle (sr), for tests.
    #[cfg(test)]
    pub fn solid_angle(&self) -> f64 {
        self.solid_angle
    }
}

/// The solid angle of a rectangle seen from `p` by another route (two triangles, Van
/// Oosterom and Strackee's formula), to check the parametrization's constants.
#[cfg(test)]
fn solid_angle_of_triangles(r: &Rectangle, p: Vec3) -> f64 {
    let tri = |a: V, b: V, c: V| {
        let (la, lb, lc) = (dot(a, a).sqrt(), dot(b, b).sqrt(), dot(c, c).sqrt());
        let num = dot(a, cross(b, c)).abs();
        let den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
        2.0 * num.atan2(den)
    };
    let rel = |v: Vec3| wide(v - p);
    let (a, b, c, d) = (rel(r.corner), rel(r.corner + r.ex), rel(r.corner + r.ex + r.ey), rel(r.corner + r.ey));
    tri(a, b, c) + tri(a, c, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> Rectangle {
        Rectangle::new(vec3(-0.5, 1.0, -0.3), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.2, 0.6), Vec3::ZERO)
    }

    #[test]
    fn solid_angle_matches_the_triangle_formula() {
        for p in [vec3(0.0, 0.0, 0.0), vec3(2.0, -1.0, 3.0), vec3(0.1, 1.05, 0.0), vec3(-3.0, 4.0, 1.0)] {
            let s = SphericalRectangle::with_min_spread(&rect(), p, 0.0).unwrap();
            let other = solid_angle_of_triangles(&rect(), p);
            // The corners are summed in f32 for the triangles: agreement to f32 rounding.
            assert!((s.solid_angle() / other - 1.0).abs() < 1e-6, "{p:?}: {} vs {other}", s.solid_angle());
        }
    }

    #[test]
    fn quick_f32_test_never_contradicts_the_f64_one() {
        let mut rng = crate::sampling::Rng::new(3, 9);
        let mut f = |scale: f32| (rng.next_f32() * 2.0 - 1.0) * scale;
        let (mut f64_rejects, mut caught) = (0, 0);
        for i in 0..200_000 {
            // Rectangles of all sizes and orientations, points near and far, some on the plane.
            let size = [0.01, 1.0, 300.0][i % 3];
            let ex = vec3(f(size), f(size), f(size));
            let ey = ex.cross(vec3(f(1.0), f(1.0), f(1.0))).normalize() * (size * (0.1 + f(1.0).abs()));
            let rect = Rectangle::new(vec3(f(500.0), f(500.0), f(500.0)), ex, ey, ex.cross(ey).normalize());
            let reach = [0.001, 1.0, 10.0, 1000.0][i % 4] * size;
            let mut p = rect.corner + ex * f(1.5) + ey * f(1.5) + rect.normal * f(reach);
            if i % 50 == 0 {
                p = rect.corner + ex * f(1.0); // in the plane
            }
            let quick = area_sampling_is_clearly_uniform(&rect, p, MIN_AREA_PDF_SPREAD);
            let f64_rejects_spread = SphericalRectangle::with_min_spread_f64(&rect, p, MIN_AREA_PDF_SPREAD).is_none()
                && SphericalRectangle::with_min_spread_f64(&rect, p, 0.0).is_some();
            if quick {
                assert!(
                    SphericalRectangle::with_min_spread_f64(&rect, p, MIN_AREA_PDF_SPREAD).is_none(),
                    "f32 test says uniform, f64 samples by solid angle: {rect:?} from {p:?}"
                );
            }
            f64_rejects += f64_rejects_spread as u32;
            caught += (f64_rejects_spread && quick) as u32;
        }
        // It must also be worth having: most points the spread test sends to area sampling.
        assert!(f64_rejects > 10_000 && caught as f64 > 0.9 * f64_rejects as f64, "{caught} of {f64_rejects}");
    }

    #[test]
    fn samples_lie_on_the_rectangle() {
        let r = rect();
        let n = r.ex.cross(r.ey).normalize();
        let s = SphericalRectangle::with_min_spread(&r, vec3(0.3, -0.2, 0.4), 0.0).unwrap();
        for i in 0..32 {
            for j in 0..32 {
                let u = [(i as f32 + 0.5) / 32.0, (j as f32 + 0.5) / 32.0];
                let q = s.sample(u) - r.corner;
                let (a, b) = (q.dot(r.ex) / r.ex.length_squared(), q.dot(r.ey) / r.ey.length_squared());
                assert!(q.dot(n).abs() < 1e-5, "{u:?}: off the plane by {}", q.dot(n));
                assert!((-1e-5..=1.0 + 1e-5).contains(&a) && (-1e-5..=1.0 + 1e-5).contains(&b), "{u:?}: {a} {b}");
            }
        }
    }

    #[test]
    fn two_triangles_of_a_quad_are_a_rectangle_and_a_skewed_pair_is_not() {
        let (a, b, c, d) = (vec3(0.0, 0.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(2.0, 1.0, 0.0), vec3(0.0, 1.0, 0.0));
        let r = Rectangle::from_triangles(&[[a, b, c], [a, c, d]]).unwrap();
        assert!((r.area() - 2.0).abs() < 1e-6);
        assert_eq!(r.normal, Vec3::Z);
        assert!(Rectangle::from_triangles(&[[a, b, c], [a, d, c]]).is_none(), "triangles facing apart");
        let skew = vec3(0.3, 1.0, 0.0);
        assert!(
            Rectangle::from_triangles(&[[a, b, c + vec3(0.3, 0.0, 0.0)], [a, c + vec3(0.3, 0.0, 0.0), skew]]).is_none()
        );
        assert!(Rectangle::from_triangles(&[[a, b, c]]).is_none());
    }
}
