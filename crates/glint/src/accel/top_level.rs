//! The scene's top level: a BVH over instances, binary (the reference) and 8-wide (what
//! traversal uses). Leaves are ranges of instance numbers; the caller's closure intersects
//! one instance (itself tracing that mesh's own wide BVH).
//!
//! Mesh instances without a transform (baked into world space, the common case) are not in
//! that tree: their triangles are merged into one flat wide BVH, so that a ray pays for one
//! traversal instead of one per overlapping mesh (the Cornell box's six meshes all overlap
//! the room). Hits in it map back to (instance, triangle) through prefix sums.

use super::bvh::{BuildOptions, Bvh, BvhSplit, BvhStats};
#[cfg(target_arch = "x86_64")]
use super::simd::{Avx2, Sse};
use super::simd::{Isa, Scalar, SimdPath};
use super::triangle::TriangleHit;
use super::wide::{leaf_ref, FnLeaf, WideBvh};
use super::wide_mesh::TriangleWideBvh;
use crate::math::{Aabb, Ray, Vec3};

/// The triangles of one instance merged into the flat BVH (already in world space).
#[derive(Clone, Copy, Debug)]
pub struct FlatMesh<'a> {
    pub instance: u32,
    pub positions: &'a [Vec3],
    pub indices: &'a [[u32; 3]],
}

impl FlatMesh<'_> {
    fn vertices(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[t];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }
}

#[derive(Clone, Debug, Default)]
pub struct TopLevelBvh {
    /// Over the instances of `rest` (its primitive `i` is instance `rest[i]`).
    pub binary: Bvh,
    wide: WideBvh<8>,
    rest: Vec<u32>,
    /// All triangles of the flattened instances; triangle `g` belongs to instance
    /// `flat_instances[k]` where `flat_offsets[k] <= g < flat_offsets[k + 1]`.
    flat: Option<TriangleWideBvh<8>>,
    flat_instances: Vec<u32>,
    flat_offsets: Vec<u32>,
}

impl TopLevelBvh {
    /// A tree over every instance (no flattening).
    pub fn build(bounds: &[Aabb], split: BvhSplit) -> TopLevelBvh {
        TopLevelBvh::build_flattening(bounds, split, &[])
    }

    /// A tree over the instances not in `flat`, plus one merged BVH over the triangles of the
    /// instances in `flat` (instance number, its mesh in world space).
    ///
    /// The merged triangles are numbered in ascending instance order (then the mesh's own
    /// order), so the flat BVH's tie rule, smallest `(t, triangle)`, is the scene's
    /// smallest `(t, instance, triangle)`.
    pub fn build_flattening(bounds: &[Aabb], split: BvhSplit, flat: &[FlatMesh]) -> TopLevelBvh {
        let mut flat = flat.to_vec();
        flat.sort_by_key(|f| f.instance);
        let flat = &flat[..];
        let in_flat: std::collections::HashSet<u32> = flat.iter().map(|f| f.instance).collect();
        let rest: Vec<u32> = (0..bounds.len() as u32).filter(|i| !in_flat.contains(i)).collect();
        let rest_bounds: Vec<Aabb> = rest.iter().map(|&i| bounds[i as usize]).collect();
        let binary = Bvh::build(&rest_bounds, split);
        let wide = WideBvh::collapse(&binary, |first, count| leaf_ref(first as usize, count as usize));
        let mut top = TopLevelBvh { binary, wide, rest, ..Default::default() };
        if flat.is_empty() {
            return top;
        }
        let mut offsets = vec![0u32];
        for m in flat {
            offsets.push(offsets.last().unwrap() + m.indices.len() as u32);
        }
        let locate = |g: u32| -> (usize, usize) {
            let k = offsets.partition_point(|&o| o <= g) - 1;
            (k, (g - offsets[k]) as usize)
        };
        let tri_bounds: Vec<Aabb> = (0..*offsets.last().unwrap())
            .map(|g| {
                let (k, t) = locate(g);
                let [a, b, c] = flat[k].vertices(t);
                // Zero-area triangles cannot be hit: keep them out of the SAH's way.
                if (b - a).cross(c - a).length_squared() == 0.0 {
                    Aabb::EMPTY
                } else {
                    Aabb::from_points(&[a, b, c])
                }
            })
            .collect();
        let bvh = Bvh::build_with(&tri_bounds, split, BuildOptions::WIDE);
        top.flat = Some(TriangleWideBvh::build(&bvh, |g| {
            let (k, t) = locate(g);
            flat[k].vertices(t)
        }));
        top.flat_instances = flat.iter().map(|f| f.instance).collect();
        top.flat_offsets = offsets;
        top
    }

    /// Closest hit among the flattened instances: (instance, triangle, hit), the smallest
    /// `(t, instance, triangle)`; shortens `ray.t_max`.
    #[inline]
    pub fn intersect_flat(&self, ray: &mut Ray) -> Option<(u32, u32, TriangleHit)> {
        let (g, h) = self.flat.as_ref()?.intersect(ray, SimdPath::detect())?;
        let k = self.flat_offsets.partition_point(|&o| o <= g) - 1;
        Some((self.flat_instances[k], g - self.flat_offsets[k], h))
    }

    /// Whether anything among the flattened instances blocks the ray.
    #[inline]
    pub fn occluded_flat(&self, ray: &Ray) -> bool {
        self.flat.as_ref().is_some_and(|f| f.occluded(ray, SimdPath::detect()))
    }

    /// [`TopLevelBvh::intersect_flat`] of many rays at once (several traversals in flight per
    /// thread, bit-identical answers); `hits[i]` is for `rays[i]`, which are not shortened.
    ///
    /// Panics if the slices differ in length.
    pub fn intersect_flat_batch(&self, rays: &[Ray], hits: &mut [Option<(u32, u32, TriangleHit)>]) {
        assert_eq!(rays.len(), hits.len(), "intersect_flat_batch: one hit slot per ray");
        let Some(flat) = &self.flat else {
            hits.fill(None);
            return;
        };
        let mut global = vec![None; rays.len()];
        flat.intersect_batch(rays, &mut global, SimdPath::detect());
        for (out, g) in hits.iter_mut().zip(global) {
            *out = g.map(|(g, h)| {
                let k = self.flat_offsets.partition_point(|&o| o <= g) - 1;
                (self.flat_instances[k], g - self.flat_offsets[k], h)
            });
        }
    }

    /// [`TopLevelBvh::intersect_flat`] of many rays, in packets
    /// (`TriangleWideBvh::intersect_packets`, bit-identical answers); `hits[i]` is for
    /// `rays[i]`, which are not shortened.
    ///
    /// Panics if the slices differ in length.
    pub fn intersect_flat_packets(&self, rays: &[Ray], hits: &mut [Option<(u32, u32, TriangleHit)>]) {
        assert_eq!(rays.len(), hits.len(), "intersect_flat_packets: one hit slot per ray");
        let Some(flat) = &self.flat else {
            hits.fill(None);
            return;
        };
        let mut global = vec![None; rays.len()];
        flat.intersect_packets(rays, &mut global, SimdPath::detect());
        for (out, g) in hits.iter_mut().zip(global) {
            *out = g.map(|(g, h)| {
                let k = self.flat_offsets.partition_point(|&o| o <= g) - 1;
                (self.flat_instances[k], g - self.flat_offsets[k], h)
            });
        }
    }

    /// [`TopLevelBvh::occluded_flat`] of many rays, in packets (`TriangleWideBvh::occluded_packets`).
    ///
    /// Panics if the slices differ in length.
    pub fn occluded_flat_packets(&self, rays: &[Ray], blocked: &mut [bool]) {
        assert_eq!(rays.len(), blocked.len(), "occluded_flat_packets: one answer per ray");
        match &self.flat {
            Some(flat) => flat.occluded_packets(rays, blocked, SimdPath::detect()),
            None => blocked.fill(false),
        }
    }

    /// [`TopLevelBvh::occluded_flat`] of many rays at once.
    ///
    /// Panics if the slices differ in length.
    pub fn occluded_flat_batch(&self, rays: &[Ray], blocked: &mut [bool]) {
        assert_eq!(rays.len(), blocked.len(), "occluded_flat_batch: one answer per ray");
        match &self.flat {
            Some(flat) => flat.occluded_batch(rays, blocked, SimdPath::detect()),
            None => blocked.fill(false),
        }
    }

    /// Whether any instance is outside the flat BVH (in the tree the closures visit).
    pub fn has_unflattened(&self) -> bool {
        !self.rest.is_empty()
    }

    pub fn stats(&self) -> BvhStats {
        self.binary.stats()
    }

    pub fn bounds(&self) -> Aabb {
        self.binary.bounds()
    }

    /// Closest hit: `hit_prim(instance, ray)` intersects one instance and, on a hit,
    /// shortens `ray.t_max` and returns true.
    #[inline]
    pub fn traverse<F: FnMut(u32, &mut Ray) -> bool>(&self, ray: &mut Ray, hit_prim: F) -> bool {
        // The AVX-512 path keeps the AVX2 kernels here: with AVX-512's (and the instances'
        // code inlined into them compiled for AVX-512) `scenes/balls-100.json` rendered 4 to
        // 6% slower (BENCHMARKS.md, 2026-12-03; the cause was not traced).
        // SAFETY (every arm): each path runs only where the CPU has it.
        match SimdPath::detect() {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 | SimdPath::Avx512 => unsafe { self.traverse_avx2(ray, hit_prim) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.traverse_generic::<Sse, F>(ray, hit_prim) },
            _ => unsafe { self.traverse_generic::<Scalar, F>(ray, hit_prim) },
        }
    }

    /// Any hit: stops at the first instance `hit_prim` reports blocking.
    #[inline]
    pub fn occluded<F: FnMut(u32, &Ray) -> bool>(&self, ray: &Ray, hit_prim: F) -> bool {
        match SimdPath::detect() {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 | SimdPath::Avx512 => unsafe { self.occluded_avx2(ray, hit_prim) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.occluded_generic::<Sse, F>(ray, hit_prim) },
            _ => unsafe { self.occluded_generic::<Scalar, F>(ray, hit_prim) },
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn traverse_avx2<F: FnMut(u32, &mut Ray) -> bool>(&self, ray: &mut Ray, hit_prim: F) -> bool {
        self.traverse_generic::<Avx2, F>(ray, hit_prim)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_avx2<F: FnMut(u32, &Ray) -> bool>(&self, ray: &Ray, hit_prim: F) -> bool {
        self.occluded_generic::<Avx2, F>(ray, hit_prim)
    }

    #[inline(always)]
    unsafe fn traverse_generic<S: Isa, F: FnMut(u32, &mut Ray) -> bool>(&self, ray: &mut Ray, mut hit_prim: F) -> bool {
        let prims = &self.binary.prim_indices;
        let rest = &self.rest;
        let mut leaf = FnLeaf(|first: u32, count: u32, r: &mut Ray| {
            let mut hit = false;
            for &p in &prims[first as usize..(first + count) as usize] {
                hit |= hit_prim(rest[p as usize], r);
            }
            hit
        });
        self.wide.traverse::<S>(ray, &mut leaf)
    }

    #[inline(always)]
    unsafe fn occluded_generic<S: Isa, F: FnMut(u32, &Ray) -> bool>(&self, ray: &Ray, mut hit_prim: F) -> bool {
        let prims = &self.binary.prim_indices;
        let rest = &self.rest;
        let mut leaf = FnLeaf(|first: u32, count: u32, r: &Ray| {
            prims[first as usize..(first + count) as usize].iter().any(|&p| hit_prim(rest[p as usize], r))
        });
        self.wide.occluded::<S>(ray, &mut leaf)
    }
}
