//! The scene's top level: a BVH over instances, binary (the reference) and 8-wide (what
//! traversal uses). Leaves are ranges of instance numbers; the caller's closure intersects
//! one instance (itself tracing that mesh's own wide BVH).

use super::bvh::{Bvh, BvhSplit, BvhStats};
#[cfg(target_arch = "x86_64")]
use super::simd::{Avx2, Sse};
use super::simd::{Isa, Scalar, SimdPath};
use super::wide::{leaf_ref, FnLeaf, WideBvh};
use crate::math::{Aabb, Ray};

#[derive(Clone, Debug, Default)]
pub struct TopLevelBvh {
    pub binary: Bvh,
    wide: WideBvh<8>,
}

impl TopLevelBvh {
    pub fn build(bounds: &[Aabb], split: BvhSplit) -> TopLevelBvh {
        let binary = Bvh::build(bounds, split);
        let wide = WideBvh::collapse(&binary, |first, count| leaf_ref(first as usize, count as usize));
        TopLevelBvh { binary, wide }
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
        let mut leaf = FnLeaf(|first: u32, count: u32, r: &mut Ray| {
            let mut hit = false;
            for &p in &prims[first as usize..(first + count) as usize] {
                hit |= hit_prim(p, r);
            }
            hit
        });
        self.wide.traverse::<S>(ray, &mut leaf)
    }

    #[inline(always)]
    unsafe fn occluded_generic<S: Isa, F: FnMut(u32, &Ray) -> bool>(&self, ray: &Ray, mut hit_prim: F) -> bool {
        let prims = &self.binary.prim_indices;
        let mut leaf = FnLeaf(|first: u32, count: u32, r: &Ray| {
            prims[first as usize..(first + count) as usize].iter().any(|&p| hit_prim(p, r))
        });
        self.wide.occluded::<S>(ray, &mut leaf)
    }
}
