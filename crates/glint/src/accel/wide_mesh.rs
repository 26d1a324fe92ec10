//! A wide BVH over triangles: the tree plus its leaves' triangles in blocks of four, and
//! the run-time dispatch to the instruction set's kernels.

use super::bvh::Bvh;
use super::huge_pages::PageBuf;
use super::packet::{PacketLeaf, SINGLE_BELOW};
#[cfg(target_arch = "x86_64")]
use super::simd::{Avx2, Avx512, Sse};
use super::simd::{Isa, Scalar, SimdPath};
use super::tri4::{Tri4, TriHits, TriRay};
use super::triangle::TriangleHit;
use super::wide::{leaf_range, leaf_ref, WideBvh, WideStats, LEAF_BIT};
use super::wide::{AnyLeaf, ClosestLeaf};
#[cfg(target_arch = "x86_64")]
use crate::math::lanes::{Avx2x8, Avx512x16};
use crate::math::lanes::{Lanes, One, MAX_LANES};
use crate::math::{Ray, Vec3};
use std::marker::PhantomData;

/// The blocks of leaf `first..first + count`.
///
/// # Safety
/// The range must be a hit leaf's: traversal only passes the ranges of leaf references whose
/// slot was hit; `build` made each with `leaf_ref(start, n)` right after pushing those `n`
/// blocks into `blocks`, so the range is inside it, and empty slots are never hit (see
/// `NodeRay::new`).
#[inline(always)]
unsafe fn leaf_blocks(blocks: &[Tri4], first: u32, count: u32) -> &[Tri4] {
    // SAFETY: the caller's contract.
    unsafe { blocks.get_unchecked(first as usize..(first + count) as usize) }
}

/// Closest hit among leaves' blocks of four, tested two blocks at a time (one AVX2 test;
/// four blocks in one 16-lane AVX-512 test were slower, see BENCHMARKS.md).
///
/// The tie rule ([`ClosestLeaf`]): the hit kept is the smallest `(t, triangle)`. Once there
/// is a best hit at `t`, the ray's `t_max` is the next float above `t`, so the kernels (which
/// accept `t' < t_max`) report exactly the hits at `t' <= t`, and a hit at an equal `t`
/// replaces the best only with a lower triangle number. Testing a pair and taking its
/// smallest `(t, triangle)` lane is then what testing the two blocks in turn gives, and the
/// answer does not depend on the order leaves are visited in.
struct Closest<'a, S> {
    blocks: &'a [Tri4],
    tr: TriRay,
    best: Option<(u32, TriangleHit)>,
    isa: PhantomData<S>,
}

/// The next float above `t`, [`f32::next_up`] with the common case (a positive finite `t`,
/// whose next float is one bit pattern up, `f32::MAX`'s being +inf) first.
#[inline(always)]
pub(crate) fn float_above(t: f32) -> f32 {
    if t > 0.0 && t < f32::INFINITY {
        f32::from_bits(t.to_bits() + 1)
    } else {
        t.next_up()
    }
}

// By hand: a derive would ask `S: Copy`.
impl<S> Clone for Closest<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S> Copy for Closest<'_, S> {}

impl<'a, S: Isa> Closest<'a, S> {
    #[inline(always)]
    fn new(blocks: &'a [Tri4], ray: &Ray) -> Closest<'a, S> {
        Closest { blocks, tr: TriRay::new(ray), best: None, isa: PhantomData }
    }

    #[inline(always)]
    fn take<const N: usize>(&mut self, h: &TriHits<N>, prim: impl Fn(usize) -> u32, r: &mut Ray) -> bool {
        let Some(lane) = h.nearest(&prim) else { return false };
        let t = h.t[lane];
        if let Some((bp, bh)) = &self.best {
            // `t <= bh.t` by the kernels' bound; an equal `t` wins with a lower number only.
            if !(t < bh.t || (t == bh.t && prim(lane) < *bp)) {
                return false;
            }
        }
        let p = prim(lane);
        // The kernels accept only `t > t_min && t < t_max`, so `t` is finite and below
        // `r.t_max`: its next float up is at most `r.t_max`, and the interval only shrinks.
        r.t_max = float_above(t);
        self.best = Some((p, TriangleHit { t, b1: h.b1[lane], b2: h.b2[lane] }));
        true
    }

    /// Tests `blocks` in pairs, the first paired with `pending` (a block left over from an
    /// earlier leaf) if there is one; leaves the last unpaired block in `pending`.
    #[inline(always)]
    fn feed(&mut self, pending: &mut Option<&'a Tri4>, blocks: &'a [Tri4], r: &mut Ray) -> bool {
        let mut hit = false;
        for b in blocks {
            let Some(a) = pending.take() else {
                *pending = Some(b);
                continue;
            };
            // SAFETY: `S` is available (the only callers are `intersect_generic`'s and
            // `intersect_batch_generic`'s and `intersect_packets_generic`'s, which require
            // it); the kernel reads only `a`, `b`
            // and `self.tr`.
            let h = unsafe { S::tri8(a, b, &self.tr, r.t_min, r.t_max) };
            hit |= self.take(&h, |lane| if lane < 4 { a.prim[lane] } else { b.prim[lane - 4] }, r);
        }
        hit
    }

    /// Tests the block left unpaired, if any.
    #[inline(always)]
    fn finish(&mut self, pending: Option<&'a Tri4>, r: &mut Ray) -> bool {
        let Some(a) = pending else { return false };
        // SAFETY: as in `feed`.
        let h = unsafe { S::tri4(a, &self.tr, r.t_min, r.t_max) };
        self.take(&h, |lane| a.prim[lane], r)
    }
}

impl<S: Isa> ClosestLeaf for Closest<'_, S> {
    #[inline(always)]
    fn test(&mut self, first: u32, count: u32, r: &mut Ray) -> bool {
        let mut pending = None;
        // SAFETY: traversal passes only hit leaves' ranges (see `leaf_blocks`).
        let hit = self.feed(&mut pending, unsafe { leaf_blocks(self.blocks, first, count) }, r);
        hit | self.finish(pending, r)
    }

    #[inline(always)]
    fn test_leaves<const W: usize>(&mut self, children: &[u32; W], mask: u32, r: &mut Ray) -> bool {
        let mut pending = None;
        let mut hit = false;
        let mut m = mask;
        while m != 0 {
            let (first, count) = leaf_range(children[m.trailing_zeros() as usize]);
            m &= m - 1;
            // SAFETY: the set bits of `mask` are hit leaf children (see `leaf_blocks`).
            hit |= self.feed(&mut pending, unsafe { leaf_blocks(self.blocks, first, count) }, r);
        }
        hit | self.finish(pending, r)
    }
}

/// Any hit among a leaf's blocks of four, one block at a time: pairing blocks as `Closest`
/// does cost more instructions here (callgrind, bunny diffuse rays: 3% more), since a pair
/// tests its second block even when the first already blocks the ray.
struct Any<'a, S> {
    blocks: &'a [Tri4],
    tr: TriRay,
    isa: PhantomData<S>,
}

impl<S: Isa> AnyLeaf for Any<'_, S> {
    #[inline(always)]
    fn test(&mut self, first: u32, count: u32, r: &Ray) -> bool {
        // SAFETY: as for `Closest`: hit leaf ranges lie inside `blocks`.
        let blocks = unsafe { leaf_blocks(self.blocks, first, count) };
        // A plain loop: `Iter::any` was compiled as a separate function, called per leaf
        // from outside the AVX2 entry point (perf showed it apart from the traversal).
        for b in blocks {
            // SAFETY: `S` is available (see `Closest::feed`).
            if unsafe { S::tri4(b, &self.tr, r.t_min, r.t_max) }.mask != 0 {
                return true;
            }
        }
        false
    }
}

/// A packet's leaf tests: each lane's ray through [`Any`], with its triangle-test constants
/// made once per packet.
struct AnyPacket<'a, S> {
    blocks: &'a [Tri4],
    trs: [TriRay; MAX_LANES],
    isa: PhantomData<S>,
}

impl<'a, S: Isa> AnyPacket<'a, S> {
    #[inline(always)]
    fn new(blocks: &'a [Tri4], rays: &[Ray]) -> AnyPacket<'a, S> {
        let mut trs = [TriRay::new(&rays[0]); MAX_LANES];
        for (tr, ray) in trs.iter_mut().zip(rays).skip(1) {
            *tr = TriRay::new(ray);
        }
        AnyPacket { blocks, trs, isa: PhantomData }
    }
}

impl<'a, S: Isa> PacketLeaf for AnyPacket<'a, S> {
    type Single = Any<'a, S>;
    #[inline(always)]
    fn single(&self, lane: usize) -> Any<'a, S> {
        Any { blocks: self.blocks, tr: self.trs[lane], isa: PhantomData }
    }
}

/// Rays per packet of [`TriangleWideBvh::occluded_packets`] on `path`: the lanes of the
/// implementation its dispatch picks.
pub fn packet_lanes(path: SimdPath) -> usize {
    match path {
        #[cfg(target_arch = "x86_64")]
        SimdPath::Avx512 => Avx512x16::N,
        #[cfg(target_arch = "x86_64")]
        SimdPath::Avx2 => Avx2x8::N,
        _ => One::N,
    }
}

#[derive(Clone, Debug, Default)]
pub struct TriangleWideBvh<const W: usize> {
    /// Private: traversal relies on leaf ranges being in range of `blocks`.
    tree: WideBvh<W>,
    blocks: PageBuf<Tri4>,
}

impl<const W: usize> TriangleWideBvh<W> {
    /// Collapses `bvh` (built over the triangles) and packs each leaf's triangles, in leaf
    /// order, into blocks of four. `vertices(i)` gives triangle `i`'s corners.
    pub fn build(bvh: &Bvh, vertices: impl Fn(u32) -> [Vec3; 3]) -> TriangleWideBvh<W> {
        let mut blocks = Vec::with_capacity(bvh.prim_indices.len() / 3 + 1);
        let tree = WideBvh::<W>::collapse(bvh, |first, count| {
            let start = blocks.len();
            let prims = &bvh.prim_indices[first as usize..(first + count) as usize];
            for chunk in prims.chunks(4) {
                let tris: Vec<(u32, [Vec3; 3])> = chunk.iter().map(|&p| (p, vertices(p))).collect();
                blocks.push(Tri4::pack(&tris));
            }
            leaf_ref(start, blocks.len() - start)
        });
        TriangleWideBvh { tree, blocks: PageBuf::new(blocks) }
    }

    pub fn tree(&self) -> &WideBvh<W> {
        &self.tree
    }

    pub fn blocks(&self) -> &[Tri4] {
        &self.blocks
    }

    pub fn stats(&self) -> WideStats {
        // SAH in triangle tests: a block of four costs one test on the SIMD paths.
        self.tree.stats(|leaf| super::wide::leaf_range(leaf).1 as f64)
    }

    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.tree.nodes()) + self.blocks.len() * std::mem::size_of::<Tri4>()
    }

    /// Closest hit with the given path: (triangle, hit); shortens `ray.t_max`.
    #[inline]
    pub fn intersect(&self, ray: &mut Ray, path: SimdPath) -> Option<(u32, TriangleHit)> {
        // SAFETY (every arm): each path runs only where the CPU has it.
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 if path.is_available() => unsafe { self.intersect_avx2(ray) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 if path.is_available() => unsafe { self.intersect_avx512(ray) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.intersect_generic::<Sse>(ray) },
            _ => unsafe { self.intersect_generic::<Scalar>(ray) },
        }
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray, path: SimdPath) -> bool {
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 if path.is_available() => unsafe { self.occluded_avx2(ray) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 if path.is_available() => unsafe { self.occluded_avx512(ray) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.occluded_generic::<Sse>(ray) },
            _ => unsafe { self.occluded_generic::<Scalar>(ray) },
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn intersect_avx2(&self, ray: &mut Ray) -> Option<(u32, TriangleHit)> {
        self.intersect_generic::<Avx2>(ray)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    unsafe fn intersect_avx512(&self, ray: &mut Ray) -> Option<(u32, TriangleHit)> {
        self.intersect_generic::<Avx512>(ray)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_avx2(&self, ray: &Ray) -> bool {
        self.occluded_generic::<Avx2>(ray)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    unsafe fn occluded_avx512(&self, ray: &Ray) -> bool {
        self.occluded_generic::<Avx512>(ray)
    }

    #[inline(always)]
    unsafe fn intersect_generic<S: Isa>(&self, ray: &mut Ray) -> Option<(u32, TriangleHit)> {
        let mut leaf = Closest::<S> { blocks: &self.blocks, tr: TriRay::new(ray), best: None, isa: PhantomData };
        self.tree.traverse::<S>(ray, &mut leaf);
        // Traversal left `t_max` just above the hit (see `Closest`): shortened to the hit, as
        // callers expect.
        if let Some((_, h)) = &leaf.best {
            ray.t_max = h.t;
        }
        leaf.best
    }

    #[inline(always)]
    unsafe fn occluded_generic<S: Isa>(&self, ray: &Ray) -> bool {
        let mut leaf = Any::<S> { blocks: &self.blocks, tr: TriRay::new(ray), isa: PhantomData };
        self.tree.occluded::<S>(ray, &mut leaf)
    }

    /// Closest hits of many rays: `hits[i]` is what [`TriangleWideBvh::intersect`] returns
    /// for `rays[i]`, bit for bit, but several rays are traced at once per thread (see
    /// `batch.rs`), which hides memory latency.
    ///
    /// Panics if the slices differ in length.
    pub fn intersect_batch(&self, rays: &[Ray], hits: &mut [Option<(u32, TriangleHit)>], path: SimdPath) {
        assert_eq!(rays.len(), hits.len(), "intersect_batch: one hit slot per ray");
        // SAFETY (every arm): each path runs only where the CPU has it.
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 if path.is_available() => unsafe { self.intersect_batch_avx2(rays, hits) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 if path.is_available() => unsafe { self.intersect_batch_avx512(rays, hits) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.intersect_batch_generic::<Sse>(rays, hits) },
            _ => unsafe { self.intersect_batch_generic::<Scalar>(rays, hits) },
        }
    }

    /// Occlusion of many rays: `blocked[i]` is [`TriangleWideBvh::occluded`] of `rays[i]`.
    ///
    /// Panics if the slices differ in length.
    pub fn occluded_batch(&self, rays: &[Ray], blocked: &mut [bool], path: SimdPath) {
        assert_eq!(rays.len(), blocked.len(), "occluded_batch: one answer per ray");
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 if path.is_available() => unsafe { self.occluded_batch_avx2(rays, blocked) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 if path.is_available() => unsafe { self.occluded_batch_avx512(rays, blocked) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.occluded_batch_generic::<Sse>(rays, blocked) },
            _ => unsafe { self.occluded_batch_generic::<Scalar>(rays, blocked) },
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn intersect_batch_avx2(&self, rays: &[Ray], hits: &mut [Option<(u32, TriangleHit)>]) {
        self.intersect_batch_generic::<Avx2>(rays, hits)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    unsafe fn intersect_batch_avx512(&self, rays: &[Ray], hits: &mut [Option<(u32, TriangleHit)>]) {
        self.intersect_batch_generic::<Avx512>(rays, hits)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_batch_avx2(&self, rays: &[Ray], blocked: &mut [bool]) {
        self.occluded_batch_generic::<Avx2>(rays, blocked)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    unsafe fn occluded_batch_avx512(&self, rays: &[Ray], blocked: &mut [bool]) {
        self.occluded_batch_generic::<Avx512>(rays, blocked)
    }

    #[inline(always)]
    unsafe fn intersect_batch_generic<S: Isa>(&self, rays: &[Ray], hits: &mut [Option<(u32, TriangleHit)>]) {
        let blocks: &[Tri4] = &self.blocks;
        self.tree.traverse_batch::<S, Closest<S>>(
            rays,
            |r| Closest { blocks, tr: TriRay::new(r), best: None, isa: PhantomData },
            |i, _, leaf| hits[i] = leaf.best,
        );
    }

    #[inline(always)]
    unsafe fn occluded_batch_generic<S: Isa>(&self, rays: &[Ray], blocked: &mut [bool]) {
        let blocks: &[Tri4] = &self.blocks;
        self.tree.occluded_batch::<S, Any<S>>(
            rays,
            |r| Any { blocks, tr: TriRay::new(r), isa: PhantomData },
            |i, b| blocked[i] = b,
        );
    }

    /// Occlusion of many rays in packets (see `packet.rs`): `blocked[i]` is
    /// [`TriangleWideBvh::occluded`] of `rays[i]`, bit for bit; sixteen rays per packet on
    /// the AVX-512 path, eight on AVX2, one (the single-ray traversal in the packet's
    /// form) on the others.
    ///
    /// Panics if the slices differ in length.
    pub fn occluded_packets(&self, rays: &[Ray], blocked: &mut [bool], path: SimdPath) {
        self.occluded_packets_split(rays, blocked, path, SINGLE_BELOW);
    }

    /// [`TriangleWideBvh::occluded_packets`] with rays leaving the packet where fewer than
    /// `single_below` are active at a node (0: never), for tests and measurements; the
    /// answers are the same for every value.
    pub fn occluded_packets_split(&self, rays: &[Ray], blocked: &mut [bool], path: SimdPath, single_below: u32) {
        assert_eq!(rays.len(), blocked.len(), "occluded_packets: one answer per ray");
        let s = single_below;
        // SAFETY (every arm): each path runs only where the CPU has it.
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 if path.is_available() => unsafe { self.occluded_packets_avx2(rays, blocked, s) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 if path.is_available() => unsafe { self.occluded_packets_avx512(rays, blocked, s) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.occluded_packets_generic::<Sse, One>(One, rays, blocked, s) },
            _ => unsafe { self.occluded_packets_generic::<Scalar, One>(One, rays, blocked, s) },
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn occluded_packets_avx2(&self, rays: &[Ray], blocked: &mut [bool], single_below: u32) {
        // SAFETY: this path runs only where AVX2 is available (`occluded_packets`).
        let l = unsafe { Avx2x8::new_unchecked() };
        self.occluded_packets_generic::<Avx2, Avx2x8>(l, rays, blocked, single_below)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    unsafe fn occluded_packets_avx512(&self, rays: &[Ray], blocked: &mut [bool], single_below: u32) {
        // SAFETY: the AVX-512 path requires AVX-512F (`SimdPath::is_available`).
        let l = unsafe { Avx512x16::new_unchecked() };
        self.occluded_packets_generic::<Avx512, Avx512x16>(l, rays, blocked, single_below)
    }

    #[inline(always)]
    unsafe fn occluded_packets_generic<S: Isa, L: Lanes>(
        &self,
        l: L,
        rays: &[Ray],
        blocked: &mut [bool],
        single_below: u32,
    ) {
        for (r, b) in rays.chunks(L::N).zip(blocked.chunks_mut(L::N)) {
            let leaf = AnyPacket::<S>::new(&self.blocks, r);
            // SAFETY: `S` is available (this function's callers).
            let bits = unsafe { self.tree.occluded_packet::<S, L, _>(l, r, &leaf, single_below) };
            for (i, b) in b.iter_mut().enumerate() {
                *b = bits >> i & 1 == 1;
            }
        }
    }

    /// Closest hits of many rays in packets (see `packet.rs`): `hits[i]` is
    /// [`TriangleWideBvh::intersect`] of `rays[i]`, bit for bit (the tie rule makes the
    /// answer independent of the packet's visit order); sixteen rays per packet on the
    /// AVX-512 path, eight on AVX2, one on the others. The rays are not shortened.
    ///
    /// Panics if the slices differ in length.
    pub fn intersect_packets(&self, rays: &[Ray], hits: &mut [Option<(u32, TriangleHit)>], path: SimdPath) {
        self.intersect_packets_split(rays, hits, path, SINGLE_BELOW);
    }

    /// [`TriangleWideBvh::intersect_packets`] with rays leaving the packet where fewer than
    /// `single_below` are active at a node (0: never), for tests and measurements; the
    /// answers are the same for every value.
    pub fn intersect_packets_split(
        &self,
        rays: &[Ray],
        hits: &mut [Option<(u32, TriangleHit)>],
        path: SimdPath,
        single_below: u32,
    ) {
        assert_eq!(rays.len(), hits.len(), "intersect_packets: one hit slot per ray");
        let s = single_below;
        // SAFETY (every arm): each path runs only where the CPU has it.
        match path {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 if path.is_available() => unsafe { self.intersect_packets_avx2(rays, hits, s) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 if path.is_available() => unsafe { self.intersect_packets_avx512(rays, hits, s) },
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => unsafe { self.intersect_packets_generic::<Sse, One>(One, rays, hits, s) },
            _ => unsafe { self.intersect_packets_generic::<Scalar, One>(One, rays, hits, s) },
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn intersect_packets_avx2(&self, rays: &[Ray], hits: &mut [Option<(u32, TriangleHit)>], single_below: u32) {
        // SAFETY: this path runs only where AVX2 is available (`intersect_packets`).
        let l = unsafe { Avx2x8::new_unchecked() };
        self.intersect_packets_generic::<Avx2, Avx2x8>(l, rays, hits, single_below)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    unsafe fn intersect_packets_avx512(
        &self,
        rays: &[Ray],
        hits: &mut [Option<(u32, TriangleHit)>],
        single_below: u32,
    ) {
        // SAFETY: the AVX-512 path requires AVX-512F (`SimdPath::is_available`).
        let l = unsafe { Avx512x16::new_unchecked() };
        self.intersect_packets_generic::<Avx512, Avx512x16>(l, rays, hits, single_below)
    }

    #[inline(always)]
    unsafe fn intersect_packets_generic<S: Isa, L: Lanes>(
        &self,
        l: L,
        rays: &[Ray],
        hits: &mut [Option<(u32, TriangleHit)>],
        single_below: u32,
    ) {
        let blocks: &[Tri4] = &self.blocks;
        for (r, h) in rays.chunks(L::N).zip(hits.chunks_mut(L::N)) {
            let mut local = [r[0]; MAX_LANES];
            local[..r.len()].copy_from_slice(r);
            let mut leaves = [Closest::<S>::new(blocks, &r[0]); MAX_LANES];
            for (leaf, ray) in leaves.iter_mut().zip(r).skip(1) {
                *leaf = Closest::new(blocks, ray);
            }
            // SAFETY: `S` is available (this function's callers).
            unsafe { self.tree.intersect_packet::<S, L, _>(l, &mut local[..r.len()], &mut leaves, single_below) };
            for (h, leaf) in h.iter_mut().zip(&leaves) {
                *h = leaf.best;
            }
        }
    }

    /// Whether the tree is a single leaf (tiny meshes).
    pub fn is_single_leaf(&self) -> bool {
        self.tree.root() & LEAF_BIT != 0
    }
}
