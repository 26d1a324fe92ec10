//! Acceleration structures: the binary SAH BVH (the reference), the wide SIMD BVH collapsed
//! from it, and triangle intersection.

mod batch;
mod binning;
mod build;
mod bvh;
mod huge_pages;
mod packet;
pub mod simd;
mod top_level;
pub mod tri4;
mod triangle;
pub mod wide;
mod wide_mesh;

pub use batch::LANES as BATCH_LANES;
pub use bvh::{
    BuildOptions, Bvh, BvhNode, BvhSplit, BvhStats, TraversalVisits, MAX_DEPTH, SAH_DEPTH_LIMIT, SAH_INTERSECT_COST,
    SAH_TRAVERSAL_COST,
};
pub use packet::SINGLE_BELOW;
pub use simd::SimdPath;
pub use top_level::{FlatMesh, TopLevelBvh};
pub use triangle::{intersect_triangle, ShearedRay, TriangleHit};
pub use wide::{WideBvh, WideStats};
pub use wide_mesh::{packet_lanes, TriangleWideBvh};

/// Asks the CPU to start loading the cache line that holds `value`, so that a later read of
/// it waits less. Changes nothing else.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    prefetch_address((value as *const T).cast());
}

/// [`prefetch`] of any address, valid or not; a no-op off x86-64.
#[inline(always)]
pub(crate) fn prefetch_address(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch never faults and writes nothing, whatever the address (null,
        // dangling, unmapped). SSE is part of the x86-64 baseline.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
