//! Triangles in blocks of four, structure-of-arrays, in leaf order: what the wide BVH's
//! leaves point to. A block holds its own copy of the vertices (no index indirection on the
//! hot path) and the original triangle numbers. Unused lanes repeat the block's first
//! triangle (same vertices, same number), so they change no answer (a lane equal in both t
//! and triangle number to another is the same hit) and let a block that the ray misses be
//! rejected early.

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

/// Results of a test of N triangle lanes (one block of four, or two blocks side by side):
/// lanes hit within the interval, and their t, b1, b2.
#[derive(Clone, Copy, Debug)]
pub struct TriHits<const N: usize> {
    pub mask: u32,
    pub t: [f32; N],
    pub b1: [f32; N],
    pub b2: [f32; N],
}

/// Results of a four-triangle test.
pub type Tri4Hits = TriHits<4>;

impl<const N: usize> TriHits<N> {
    pub const NONE: TriHits<N> = TriHits { mask: 0, t: [0.0; N], b1: [0.0; N], b2: [0.0; N] };

    /// The lane hit with the smallest `(t, prim(lane))`: the nearest, and of equal distances
    /// the lowest triangle number (the tie rule of every closest-hit kernel, see
    /// `accel::wide::ClosestLeaf`), whatever order the lanes are in.
    #[inline(always)]
    pub fn nearest(&self, prim: impl Fn(usize) -> u32) -> Option<usize> {
        let mut m = self.mask;
        if m == 0 {
            return None;
        }
        let mut best = m.trailing_zeros() as usize;
        m &= m - 1;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            // Triangle numbers are looked up on exact ties only (rare).
            if self.t[i] < self.t[best] || (self.t[i] == self.t[best] && prim(i) < prim(best)) {
                best = i;
            }
        }
        Some(best)
    }
}

/// Two blocks' results side by side: `lo`'s lanes first, as one test of both would give.
#[inline(always)]
pub fn join_hits(lo: &Tri4Hits, hi: &Tri4Hits) -> TriHits<8> {
    let mut h = TriHits::<8> { mask: lo.mask | (hi.mask << 4), ..TriHits::NONE };
    h.t[..4].copy_from_slice(&lo.t);
    h.t[4..].copy_from_slice(&hi.t);
    h.b1[..4].copy_from_slice(&lo.b1);
    h.b1[4..].copy_from_slice(&hi.b1);
    h.b2[..4].copy_from_slice(&lo.b2);
    h.b2[4..].copy_from_slice(&hi.b2);
    h
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

/// Whether lane `lane` has an edge function that is exactly zero in single precision (the
/// case `tri_lane` redoes in double precision); for tests of the SIMD paths' fallback.
#[cfg(test)]
pub fn tri_lane_has_zero_edge(b: &Tri4, lane: usize, r: &TriRay) -> bool {
    let [kx, ky, kz] = r.k;
    let rel = |k: usize, axis: usize| b.v[k][axis][lane] - r.o[axis];
    let [sx, sy, _] = r.s;
    let (ax, ay) = (rel(0, kx) - sx * rel(0, kz), rel(0, ky) - sy * rel(0, kz));
    let (bx, by) = (rel(1, kx) - sx * rel(1, kz), rel(1, ky) - sy * rel(1, kz));
    let (cx, cy) = (rel(2, kx) - sx * rel(2, kz), rel(2, ky) - sy * rel(2, kz));
    cx * by - cy * bx == 0.0 || ax * cy - ay * cx == 0.0 || bx * ay - by * ax == 0.0
}

/// All four lanes through [`tri_lane`].
#[inline(always)]
pub fn tri4_scalar(b: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits {
    let mut h = Tri4Hits::NONE;
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
