//! Sampling a spherical light. Seen from outside, the sphere fills a cone of directions,
//! sampled uniformly in solid angle (as pbrt-v4 and Mitsuba 3 do): every sample hits the
//! light, and the density is one over the cone's solid angle. From inside (or on) the sphere,
//! where there is no cone, points are sampled uniformly over its area.
//!
//! The cone is described by `1 - cos θmax`, computed as `sin²θmax / (1 + cos θmax)`: the plain
//! `1 - cos θmax` cancels to nothing for small or distant spheres in f32 (a sphere subtending
//! sin²θmax < 6e-8 would get an infinite density and vanish).

use super::LightSample;
use crate::geometry::Sphere;
use crate::math::{vec3, Frame, Rgb, Vec3, PI};
use crate::sampling::warp;

/// Relative margin on the squared radius within which a point counts as inside (or on) the
/// sphere, where the cone degenerates; points on the sphere's own surface land here.
const INSIDE_MARGIN: f32 = 1.0001;

/// The cone a sphere subtends from a point outside it.
struct Cone {
    /// Unit direction from the point to the centre.
    axis: Vec3,
    /// Distance from the point to the centre.
    dc: f32,
    cos_max: f32,
    /// 1 - cos θmax, without cancellation.
    one_minus_cos_max: f32,
}

/// The cone `s` subtends from `p`; `None` when `p` is inside (or on) the sphere.
fn cone(s: &Sphere, p: Vec3) -> Option<Cone> {
    let to_c = s.center - p;
    let dc2 = to_c.length_squared();
    let r2 = s.radius * s.radius;
    if dc2 <= r2 * INSIDE_MARGIN {
        return None;
    }
    let dc = dc2.sqrt();
    let sin2_max = r2 / dc2;
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    Some(Cone { axis: to_c / dc, dc, cos_max, one_minus_cos_max: sin2_max / (1.0 + cos_max) })
}

/// A direction towards a sphere that emits `radiance` on one side (`inward`: the inside
/// only). `None` when nothing reaches `p` from that side, or for a degenerate sample.
pub(super) fn sample(s: &Sphere, radiance: Rgb, inward: bool, p: Vec3, u: [f32; 2]) -> Option<LightSample> {
    match cone(s, p) {
        Some(c) if !inward => Some(sample_cone(s, &c, radiance, u)),
        None if inward => sample_area(s, radiance, p, u),
        _ => None,
    }
}

/// Solid-angle density of `sample` producing the direction `wi` from `p` that meets the
/// sphere at `q` (normal `n`).
pub(super) fn pdf(s: &Sphere, p: Vec3, q: Vec3, n: Vec3, wi: Vec3) -> f32 {
    match cone(s, p) {
        Some(c) => 1.0 / (2.0 * PI * c.one_minus_cos_max),
        None => {
            let cos_l = n.dot(wi).abs();
            if cos_l == 0.0 {
                return 0.0;
            }
            (q - p).length_squared() / (cos_l * s.area())
        }
    }
}

fn sample_cone(s: &Sphere, c: &Cone, radiance: Rgb, u: [f32; 2]) -> LightSample {
    // 1 - cos θ uniform in [0, 1 - cos θmax]: uniform in solid angle over the cone.
    let x = u[0] * c.one_minus_cos_max;
    let cos_t = 1.0 - x;
    let sin_t = (x * (2.0 - x)).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    let frame = Frame::from_normal(c.axis);
    let wi = frame.to_world(vec3(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)).normalize();
    // Distance to the near intersection: dc cos θ - sqrt(r² - dc² sin²θ), where
    // dc² sin²θ / r² = sin²θ / sin²θmax = u (2 - x) / (1 + cos θmax) avoids the
    // cancellation of r² - dc² sin²θ for a distant sphere.
    let ratio = u[0] * (2.0 - x) / (1.0 + c.cos_max);
    let dist = (c.dc * cos_t - s.radius * (1.0 - ratio).max(0.0).sqrt()).max(0.0);
    LightSample { wi, radiance, pdf: 1.0 / (2.0 * PI * c.one_minus_cos_max), dist, delta: false }
}

fn sample_area(s: &Sphere, radiance: Rgb, p: Vec3, u: [f32; 2]) -> Option<LightSample> {
    let n = warp::uniform_sphere(u);
    let q = s.center + n * s.radius;
    let d = q - p;
    let dist2 = d.length_squared();
    if dist2 == 0.0 {
        return None;
    }
    let dist = dist2.sqrt();
    let wi = d / dist;
    let cos_l = n.dot(wi).abs();
    if cos_l == 0.0 {
        return None;
    }
    Some(LightSample { wi, radiance, pdf: dist2 / (cos_l * s.area()), dist, delta: false })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_distant_small_sphere_keeps_its_cone() {
        // sin²θmax = 1e-10: the plain 1 - cos θmax is 0 in f32.
        let s = Sphere::new(vec3(0.0, 0.0, 1e5), 1.0);
        let c = cone(&s, Vec3::ZERO).unwrap();
        let exact = 1e-10f64 / (1.0 + (1.0 - 1e-10f64).sqrt());
        assert!((c.one_minus_cos_max as f64 / exact - 1.0).abs() < 1e-6, "{}", c.one_minus_cos_max);
        let ls = sample_cone(&s, &c, Rgb::WHITE, [0.3, 0.7]);
        assert!(ls.pdf.is_finite() && ls.pdf > 0.0);
        // The sampled ray meets the sphere at the distance it reports.
        let q = ls.wi * ls.dist;
        assert!(((q - s.center).length() - 1.0).abs() < 0.05, "{}", (q - s.center).length());
    }
}
