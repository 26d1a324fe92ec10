//! Triangle meshes with their own bottom-level BVH.

use super::MeshAttribute;
use crate::accel::{
    intersect_triangle, BuildOptions, Bvh, BvhSplit, ShearedRay, SimdPath, TriangleHit, TriangleWideBvh, WideStats,
};
use crate::math::{Aabb, Ray, Vec3};

/// Which acceleration structure a mesh traces with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MeshAccel {
    /// The binary BVH alone: the reference.
    Binary,
    Wide4,
    /// 8-wide: the default (faster than 4-wide on the AVX2 machines measured, BENCHMARKS.md).
    #[default]
    Wide8,
}

/// The wide tree a mesh traces, if any.
#[derive(Clone, Debug, Default)]
pub enum WideTris {
    #[default]
    None,
    W4(TriangleWideBvh<4>),
    W8(TriangleWideBvh<8>),
}

/// Size and quality of a mesh's acceleration structure, for `glint bench`.
#[derive(Clone, Debug)]
pub struct AccelStats {
    pub kind: String,
    /// Bytes of what traversal reads: nodes plus (for wide trees) triangle blocks.
    pub bytes: usize,
    /// SAH cost of the traced tree (traversal steps and triangle tests, binary units).
    pub sah_cost: f64,
    /// SAH cost of the binary tree it was built as.
    pub binary_sah_cost: f64,
    pub nodes: usize,
    pub leaves: usize,
}

#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, if the file had them.
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<[u32; 3]>,
    /// The binary BVH: the reference, and the tree the wide one is collapsed from.
    pub bvh: Bvh,
    /// The wide BVH that `intersect` and `occluded` use, when built.
    pub wide: WideTris,
    /// Named per-vertex and per-face attributes (PLY colours and the like), for the
    /// `mesh_attribute` texture; set with [`TriangleMesh::with_attributes`].
    pub attributes: Vec<MeshAttribute>,
}

impl TriangleMesh {
    /// Validates indices and builds the BVH. Errors name the first bad triangle.
    pub fn new(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<[f32; 2]>>,
        indices: Vec<[u32; 3]>,
        split: BvhSplit,
    ) -> Result<TriangleMesh, String> {
        let n = positions.len() as u32;
        if let Some((i, t)) = indices.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
            return Err(format!("triangle {i} uses vertex {:?} but the mesh has {n} vertices", t));
        }
        if let Some(ns) = &normals {
            if ns.len() != positions.len() {
                return Err(format!("{} normals for {} vertices", ns.len(), positions.len()));
            }
        }
        if let Some(uv) = &uvs {
            if uv.len() != positions.len() {
                return Err(format!("{} texture coordinates for {} vertices", uv.len(), positions.len()));
            }
        }
        if let Some(p) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {p} is not finite"));
        }
        let mut mesh = TriangleMesh {
            positions,
            normals,
            uvs,
            indices,
            bvh: Bvh::default(),
            wide: WideTris::None,
            attributes: Vec::new(),
        };
        mesh.build_bvh(split);
        Ok(mesh)
    }

    /// The mesh with these attributes; an error names one whose size does not match the
    /// mesh's vertex or face count.
    pub fn with_attributes(mut self, attributes: Vec<MeshAttribute>) -> Result<TriangleMesh, String> {
        for a in &attributes {
            let want = a.expected_len(self.positions.len(), self.indices.len());
            if a.values.len() != want || !(a.dim == 1 || a.dim == 3) {
                return Err(format!("attribute '{}' has {} values, expected {want}", a.name, a.values.len()));
            }
            if let Some(i) = a.values.iter().position(|v| !v.is_finite()) {
                return Err(format!("attribute '{}': value {i} is not finite", a.name));
            }
        }
        self.attributes = attributes;
        Ok(self)
    }

    /// The attribute called `name`, if the mesh has it.
    pub fn attribute(&self, name: &str) -> Option<&MeshAttribute> {
        self.attributes.iter().find(|a| a.name == name)
    }

    pub fn build_bvh(&mut self, split: BvhSplit) {
        self.build_accel(split, MeshAccel::default());
    }

    /// Builds the binary BVH and, unless `accel` is `Binary`, the wide one from it.
    pub fn build_accel(&mut self, split: BvhSplit, accel: MeshAccel) {
        let bounds: Vec<Aabb> = (0..self.indices.len()).map(|i| self.triangle_bounds(i)).collect();
        let opts = if accel == MeshAccel::Binary { BuildOptions::BINARY } else { BuildOptions::WIDE };
        self.bvh = Bvh::build_with(&bounds, split, opts);
        let verts = |i: u32| self.vertices(i as usize);
        self.wide = match accel {
            MeshAccel::Binary => WideTris::None,
            MeshAccel::Wide4 => WideTris::W4(TriangleWideBvh::build(&self.bvh, verts)),
            MeshAccel::Wide8 => WideTris::W8(TriangleWideBvh::build(&self.bvh, verts)),
        };
    }

    pub fn accel_stats(&self) -> AccelStats {
        let b = self.bvh.stats();
        let wide = |kind: &str, s: WideStats, bytes: usize| AccelStats {
            kind: kind.into(),
            bytes,
            sah_cost: s.sah_cost,
            binary_sah_cost: b.sah_cost,
            nodes: s.nodes,
            leaves: s.leaves,
        };
        match &self.wide {
            WideTris::None => AccelStats {
                kind: "binary".into(),
                // What the binary traversal reads: nodes, indices and the indexed vertices.
                bytes: b.bytes + self.indices.len() * 12 + self.positions.len() * 12,
                sah_cost: b.sah_cost,
                binary_sah_cost: b.sah_cost,
                nodes: b.nodes,
                leaves: b.leaves,
            },
            WideTris::W4(w) => wide("wide4", w.stats(), w.bytes()),
            WideTris::W8(w) => wide("wide8", w.stats(), w.bytes()),
        }
    }

    #[inline(always)]
    pub fn vertices(&self, tri: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[tri];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    fn triangle_bounds(&self, tri: usize) -> Aabb {
        let [a, b, c] = self.vertices(tri);
        let bb = Aabb::from_points(&[a, b, c]);
        // A degenerate (zero-area) triangle cannot be hit; keep it out of the way of the SAH.
        if (b - a).cross(c - a).length_squared() == 0.0 {
            Aabb::EMPTY
        } else {
            bb
        }
    }

    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    pub fn triangle_area(&self, tri: usize) -> f32 {
        let [a, b, c] = self.vertices(tri);
        0.5 * (b - a).cross(c - a).length()
    }

    /// Closest hit: (triangle, hit). Shortens `ray.t_max`.
    #[inline]
    pub fn intersect(&self, ray: &mut Ray) -> Option<(u32, TriangleHit)> {
        self.intersect_with(ray, SimdPath::detect())
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_with(ray, SimdPath::detect())
    }

    /// Closest hit through a given SIMD path (all paths give the same answer).
    #[inline]
    pub fn intersect_with(&self, ray: &mut Ray, path: SimdPath) -> Option<(u32, TriangleHit)> {
        match &self.wide {
            WideTris::W8(w) => w.intersect(ray, path),
            WideTris::W4(w) => w.intersect(ray, path),
            WideTris::None => self.intersect_reference(ray),
        }
    }

    #[inline]
    pub fn occluded_with(&self, ray: &Ray, path: SimdPath) -> bool {
        match &self.wide {
            WideTris::W8(w) => w.occluded(ray, path),
            WideTris::W4(w) => w.occluded(ray, path),
            WideTris::None => self.occluded_reference(ray),
        }
    }

    /// Closest hits of many rays at once: `hits[i]` is what `intersect_with(rays[i], path)`
    /// returns, bit for bit (the wide trees trace several rays in flight per thread; the
    /// binary reference goes ray by ray). Panics if the slices differ in length.
    pub fn intersect_batch_with(&self, rays: &[Ray], hits: &mut [Option<(u32, TriangleHit)>], path: SimdPath) {
        match &self.wide {
            WideTris::W8(w) => w.intersect_batch(rays, hits, path),
            WideTris::W4(w) => w.intersect_batch(rays, hits, path),
            WideTris::None => {
                assert_eq!(rays.len(), hits.len(), "intersect_batch: one hit slot per ray");
                for (r, h) in rays.iter().zip(hits) {
                    *h = self.intersect_reference(&mut r.clone());
                }
            }
        }
    }

    /// Occlusion of many rays at once: `blocked[i]` is `occluded_with(rays[i], path)`.
    /// Panics if the slices differ in length.
    pub fn occluded_batch_with(&self, rays: &[Ray], blocked: &mut [bool], path: SimdPath) {
        match &self.wide {
            WideTris::W8(w) => w.occluded_batch(rays, blocked, path),
            WideTris::W4(w) => w.occluded_batch(rays, blocked, path),
            WideTris::None => {
                assert_eq!(rays.len(), blocked.len(), "occluded_batch: one answer per ray");
                for (r, b) in rays.iter().zip(blocked) {
                    *b = self.occluded_reference(r);
                }
            }
        }
    }

    /// Occlusion of many rays in packets (`TriangleWideBvh::occluded_packets`): `blocked[i]`
    /// is `occluded_with(rays[i], path)`; rays leave a packet where fewer than `single_below`
    /// are active. Panics if the slices differ in length.
    pub fn occluded_packets_with(&self, rays: &[Ray], blocked: &mut [bool], path: SimdPath, single_below: u32) {
        match &self.wide {
            WideTris::W8(w) => w.occluded_packets_split(rays, blocked, path, single_below),
            WideTris::W4(w) => w.occluded_packets_split(rays, blocked, path, single_below),
            WideTris::None => self.occluded_batch_with(rays, blocked, path),
        }
    }

    /// Closest hits of many rays in packets (`TriangleWideBvh::intersect_packets`): `hits[i]`
    /// is `intersect_with(rays[i], path)`, bit for bit; rays leave a packet where fewer than
    /// `single_below` are active. Panics if the slices differ in length.
    pub fn intersect_packets_with(
        &self,
        rays: &[Ray],
        hits: &mut [Option<(u32, TriangleHit)>],
        path: SimdPath,
        single_below: u32,
    ) {
        match &self.wide {
            WideTris::W8(w) => w.intersect_packets_split(rays, hits, path, single_below),
            WideTris::W4(w) => w.intersect_packets_split(rays, hits, path, single_below),
            WideTris::None => self.intersect_batch_with(rays, hits, path),
        }
    }

    /// Closest hit through the binary BVH: the reference implementation. Of hits at equal
    /// `t`, the lowest triangle number (the tie rule, see `accel::wide::ClosestLeaf`).
    #[inline]
    pub fn intersect_reference(&self, ray: &mut Ray) -> Option<(u32, TriangleHit)> {
        let sh = ShearedRay::new(ray.dir);
        let mut best: Option<(u32, TriangleHit)> = None;
        self.bvh.traverse(ray, |tri, r| {
            let [a, b, c] = self.vertices(tri as usize);
            match intersect_triangle(r, &sh, a, b, c) {
                // `r.t_max` is just above the best `t` (below), so `h.t <= best t` here.
                Some(h) if best.is_none_or(|(bt, bh)| h.t < bh.t || (h.t == bh.t && tri < bt)) => {
                    // `h.t < r.t_max` (the test's interval), so the interval only shrinks.
                    r.t_max = h.t.next_up();
                    best = Some((tri, h));
                    true
                }
                _ => false,
            }
        });
        if let Some((_, h)) = &best {
            ray.t_max = h.t;
        }
        best
    }

    #[inline]
    pub fn occluded_reference(&self, ray: &Ray) -> bool {
        let sh = ShearedRay::new(ray.dir);
        self.bvh.occluded(ray, |tri, r| {
            let [a, b, c] = self.vertices(tri as usize);
            intersect_triangle(r, &sh, a, b, c).is_some()
        })
    }

    /// Closest hit by testing every triangle: the reference that the BVH must agree with.
    /// Triangles are tested in ascending order and a later one must be strictly nearer, so
    /// the answer is the smallest `(t, triangle)` (the tie rule of every kernel).
    pub fn intersect_brute_force(&self, ray: &Ray) -> Option<(u32, TriangleHit)> {
        let sh = ShearedRay::new(ray.dir);
        let mut r = *ray;
        let mut best = None;
        for tri in 0..self.indices.len() {
            let [a, b, c] = self.vertices(tri);
            if let Some(h) = intersect_triangle(&r, &sh, a, b, c) {
                r.t_max = h.t;
                best = Some((tri as u32, h));
            }
        }
        best
    }

    pub fn memory_bytes(&self) -> usize {
        self.positions.len() * 12
            + self.normals.as_ref().map_or(0, |n| n.len() * 12)
            + self.uvs.as_ref().map_or(0, |n| n.len() * 8)
            + self.indices.len() * 12
    }
}

/// Quad (p0, p1, p2, p3 in order) as a two-triangle mesh with uv (0,0)..(1,1).
pub fn quad_mesh(p: [Vec3; 4], split: BvhSplit) -> TriangleMesh {
    let uvs = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    TriangleMesh::new(p.to_vec(), None, Some(uvs), vec![[0, 1, 2], [0, 2, 3]], split).expect("valid quad")
}

/// Axis-aligned cube [-1, 1]^3 with outward faces: Mitsuba's `cube`, vertex for vertex (24
/// vertices, four per face, each face with its own uv square laid out as Mitsuba lays it, so
/// that a texture on a cube lands where Mitsuba puts it).
pub fn cube_mesh(split: BvhSplit) -> TriangleMesh {
    // Face s has the vertices 4s..4s+3 at these corners, corner c at (+-1, +-1, +-1) with
    // bit k of c the sign of axis k, and uv (0, 1), (1, 1), (1, 0), (0, 0) in that order.
    const CORNER: [u32; 24] = [1, 5, 4, 0, 3, 2, 6, 7, 1, 3, 7, 5, 5, 7, 6, 4, 4, 6, 2, 0, 3, 1, 0, 2];
    const UV: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    let sign = |c: u32, k: u32| if c & (1 << k) != 0 { 1.0 } else { -1.0 };
    let positions = CORNER.iter().map(|&c| Vec3 { x: sign(c, 0), y: sign(c, 1), z: sign(c, 2) }).collect();
    let uvs = (0..24).map(|i| UV[i % 4]).collect();
    let indices = (0..6u32).flat_map(|s| [[4 * s, 4 * s + 1, 4 * s + 2], [4 * s + 3, 4 * s, 4 * s + 2]]).collect();
    TriangleMesh::new(positions, None, Some(uvs), indices, split).expect("valid cube")
}

/// The square [-1, 1]^2 in the z = 0 plane facing +z (Mitsuba's `rectangle`).
pub fn rectangle_mesh(split: BvhSplit) -> TriangleMesh {
    quad_mesh(
        [
            Vec3 { x: -1.0, y: -1.0, z: 0.0 },
            Vec3 { x: 1.0, y: -1.0, z: 0.0 },
            Vec3 { x: 1.0, y: 1.0, z: 0.0 },
            Vec3 { x: -1.0, y: 1.0, z: 0.0 },
        ],
        split,
    )
}

/// Triangles in the fan of a disk: every format's disk is this one mesh.
pub const DISK_SEGMENTS: u32 = 256;

/// Unit disk in the z = 0 plane facing +z, as a fan of [`DISK_SEGMENTS`] triangles, with
/// Mitsuba's polar uv: u the radius, v the azimuth over 2 pi (0 along +x, growing towards
/// +y). Each triangle has its own three vertices, so that v does not wrap across the seam
/// and the centre's v is the middle of its segment.
pub fn disk_mesh(split: BvhSplit) -> TriangleMesh {
    let segments = DISK_SEGMENTS;
    let rim = |i: u32| {
        let phi = 2.0 * std::f32::consts::PI * i as f32 / segments as f32;
        Vec3 { x: phi.cos(), y: phi.sin(), z: 0.0 }
    };
    let mut positions = Vec::with_capacity(3 * segments as usize);
    let mut uvs = Vec::with_capacity(3 * segments as usize);
    for i in 0..segments {
        let v = |k: f32| k / segments as f32;
        positions.extend([Vec3::ZERO, rim(i), rim((i + 1) % segments)]);
        uvs.extend([[0.0, v(i as f32 + 0.5)], [1.0, v(i as f32)], [1.0, v(i as f32 + 1.0)]]);
    }
    let indices = (0..segments).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    TriangleMesh::new(positions, None, Some(uvs), indices, split).expect("valid disk")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    #[test]
    fn cube_faces_point_outwards() {
        let cube = cube_mesh(BvhSplit::Sah);
        for t in 0..cube.indices.len() {
            let [a, b, c] = cube.vertices(t);
            let n = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            assert!(n.dot(centre) > 0.0, "face {t} points inwards");
        }
    }

    #[test]
    fn out_of_range_index_is_an_error() {
        let e = TriangleMesh::new(vec![Vec3::ZERO; 3], None, None, vec![[0, 1, 3]], BvhSplit::Sah);
        assert!(e.unwrap_err().contains("vertex"));
    }

    #[test]
    fn quad_is_hit_in_the_middle() {
        let q = quad_mesh(
            [vec3(-1.0, -1.0, 0.0), vec3(1.0, -1.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(-1.0, 1.0, 0.0)],
            BvhSplit::Sah,
        );
        let mut r = Ray::new(vec3(0.0, 0.0, 5.0), vec3(0.0, 0.0, -1.0));
        let (_, h) = q.intersect(&mut r).unwrap();
        assert!((h.t - 5.0).abs() < 1e-6);
    }
}
