//! Triangles in blocks of four, structure-of-arrays, in leaf order: what the wide BVH's
//! leaves point to. A block holds its own copy of the vertices (no index indirection on the
//! hot path) and the original triangle numbers. Unused lanes repeat the block's first
//! triangle (same vertices, same number), so they change no answer (the first of equal
//! lanes wins) and let a block that the ray misses be rejected early.

use super::triangle::ShearedRay;
use crate::math::{Ray, Vec3};

#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Tri4 {
    /// `v[vertex][axis][lane]`.
    pub v: [[[f32; 4]; 3]; 3],
    pub prim: [u32; 4],
}

impl Tri4 {
    pub const EMPTY: Tri4 = Tri4 { v: [[[f32::NAN; 4]; 3]; 3], prim: [u32::MAX; 4] };

    /// Packs up to four triangles.
    pub fn pack(tris: &[(u32, [Vec3; 3])]) -> Tri4 {
        debug_assert!(!tris.is_empty() && tris.len() <= 4);
        let mut b = Tri4::EMPTY;
        for lane in 0..4 {
            let (prim, verts) = &tris[if lane < tris.len() { lane } else { 0 }];
            b.prim[lane] = *prim;
            for (k, p) in verts.iter().enumerate() {
                for axis in 0..3 {
                    b.v[k][axis][lane] = p[axis];
                }
            }
        }
        b
    }

    #[inline(always)]
    pub fn vertex(&self, k: usize, lane: usize) -> Vec3 {
        Vec3 { x: self.v[k][0][lane], y: self.v[k][1][lane], z: self.v[k][2][lane] }
    }
}

/// Per-ray constants of the triangle test: the origin and the shear of [`ShearedRay`].
#[derive(Clone, Copy, Debug)]
pub struct TriRay {
    pub o: [f32; 3],
    pub k: [usize; 3],
    pub s: [f32; 3],
}

impl TriRay {
    #[inline(always)]
    pub fn new(ray: &Ray) -> TriRay {
        let sh = ShearedRay::new(ray.dir);
        TriRay { o: ray.origin.to_array(), k: [sh.kx, sh.ky, sh.kz], s: [sh.sx, sh.sy, sh.sz] }
    }
}

/// Results of a four-triangle test: lanes hit within the interval, and their t, b1, b2.
#[derive(Clone, Copy, Debug)]
pub struct Tri4Hits {
    pub mask: u32,
    pub t: [f32; 4],
    pub b1: [f32; 4],
    pub b2: [f32; 4],
}

impl Tri4Hits {
    /// The nearest lane hit, the first among equals (as testing the lanes in order with a
    /// shrinking interval would find).
    #[inline(always)]
    pub fn nearest(&self) -> Option<usize> {
        let mut m = self.mask;
        let mut best: Option<usize> = None;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            if best.is_none_or(|b| self.t[i] < self.t[b]) {
                best = Some(i);
            }
        }
        best
    }
}

/// One lane of the watertight test, in exactly the operations of `intersect_triangle`:
/// the scalar path, and the fallback of the SIMD paths when an edge function is zero.
#[inline(always)]
pub fn tri_lane(b: &Tri4, lane: usize, r: &TriRay, t_min: f32, t_max: f32) -> Option<(f32, f32, f32)> {
    let [kx, ky, kz] = r.k;
    let rel = |k: usize, axis: usize| b.v[k][axis][lane] - r.o[axis];
    let (a_x, a_y, a_z) = (rel(0, kx), rel(0, ky), rel(0, kz));
    let (b_x, b_y, b_z) = (rel(1, kx), rel(1, ky), rel(1, kz));
    let (c_x, c_y, c_z) = (rel(2, kx), rel(2, ky), rel(2, kz));
    let [sx, sy, sz] = r.s;
    let ax = a_x - sx * a_z;
    let ay = a_y - sy * a_z;
    let bx = b_x - sx * b_z;
    let by = b_y - sy * b_z;
    let cx = c_x - sx * c_z;
    let cy = c_y - sy * c_z;
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
    let az = sz * a_z;
    let bz = sz * b_z;
    let cz = sz * c_z;
    let t_scaled = u * az + v * bz + w * cz;
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    if !(t > t_min && t < t_max) {
        return None;
    }
    Some((t, v * inv, w * inv))
}

/// All four lanes through [`tri_lane`].
#[inline(always)]
pub fn tri4_scalar(b: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
    let mut h = Tri4Hits { mask: 0, t: [0.0; 4], b1: [0.0; 4], b2: [0.0; 4] };
    for lane in 0..4 {
        if let Some((t, b1, b2)) = tri_lane(b, lane, r, t_min, t_max) {
            h.mask |= 1 << lane;
            h.t[lane] = t;
            h.b1[lane] = b1;
            h.b2[lane] = b2;
        }
    }
    h
}
