//! Watertight ray-triangle intersection (Woop, Benthin and Wald 2013): the ray is sheared so
//! that it runs along +z through the origin, and edge functions are evaluated in 2D; edge
//! tests that come out exactly zero are redone in double precision, so a ray through a
//! shared edge or vertex hits exactly one side and never slips through.

use crate::math::{Ray, Vec3};

/// Per-ray constants of the shear, computed once per ray (and per instance).
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    pub kx: usize,
    pub ky: usize,
    pub kz: usize,
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl ShearedRay {
    #[inline]
    pub fn new(dir: Vec3) -> ShearedRay {
        let kz = dir.abs().max_axis();
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        ShearedRay { kx, ky, kz, sx: dir[kx] / dir[kz], sy: dir[ky] / dir[kz], sz: 1.0 / dir[kz] }
    }
}

/// Where a ray met a triangle: distance and the barycentrics of the second and third vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Intersects the ray with triangle (p0, p1, p2) within `(ray.t_min, ray.t_max)`.
#[inline]
pub fn intersect_triangle(ray: &Ray, sh: &ShearedRay, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<TriangleHit> {
    let a = p0 - ray.origin;
    let b = p1 - ray.origin;
    let c = p2 - ray.origin;
    let (kx, ky, kz) = (sh.kx, sh.ky, sh.kz);
    let ax = a[kx] - sh.sx * a[kz];
    let ay = a[ky] - sh.sy * a[kz];
    let bx = b[kx] - sh.sx * b[kz];
    let by = b[ky] - sh.sy * b[kz];
    let cx = c[kx] - sh.sx * c[kz];
    let cy = c[ky] - sh.sy * c[kz];
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
        v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
        w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let az = sh.sz * a[kz];
    let bz = sh.sz * b[kz];
    let cz = sh.sz * c[kz];
    let t_scaled = u * az + v * bz + w * cz;
    // Divide before comparing with the interval: a comparison in the scaled space rounds
    // differently from `t` itself, which would make the closest hit depend on the order in
    // which triangles that meet the ray at (nearly) the same distance are tested.
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    if !(t > ray.t_min && t < ray.t_max) {
        return None;
    }
    Some(TriangleHit { t, b1: v * inv, b2: w * inv })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    #[test]
    fn ray_through_shared_edge_hits_exactly_once_or_twice_never_zero() {
        // Two triangles sharing the diagonal of a unit square; rays aimed exactly at it.
        let p = [vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(0.0, 1.0, 0.0)];
        for i in 0..=1000 {
            let s = i as f32 / 1000.0;
            let target = vec3(s, s, 0.0);
            let origin = vec3(0.3, -0.2, 1.7);
            let ray = Ray::new(origin, target - origin);
            let sh = ShearedRay::new(ray.dir);
            let h1 = intersect_triangle(&ray, &sh, p[0], p[1], p[2]);
            let h2 = intersect_triangle(&ray, &sh, p[0], p[2], p[3]);
            assert!(h1.is_some() || h2.is_some(), "ray slipped through the edge at s={s}");
        }
    }

    #[test]
    fn barycentrics_reconstruct_the_hit_point() {
        let (p0, p1, p2) = (vec3(0.0, 0.0, 2.0), vec3(2.0, 0.0, 2.0), vec3(0.0, 3.0, 2.0));
        let ray = Ray::new(vec3(0.5, 0.5, 0.0), vec3(0.1, 0.2, 1.0));
        let h = intersect_triangle(&ray, &ShearedRay::new(ray.dir), p0, p1, p2).unwrap();
        let q = p0 * (1.0 - h.b1 - h.b2) + p1 * h.b1 + p2 * h.b2;
        assert!((q - ray.at(h.t)).length() < 1e-5);
    }
}
