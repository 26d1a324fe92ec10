//! Instruction-set paths for the wide BVH kernels, chosen at run time.
//!
//! The kernels that matter, a ray against the W child boxes of a node and a ray against a
//! block of four triangles (or two blocks at once, where the registers hold eight lanes), are
//! written once per instruction set behind the [`Isa`] trait.
//! Traversal is generic over `Isa` and is instantiated inside `#[target_feature]` entry
//! points (see `wide_mesh.rs`), so the AVX2 path is compiled with AVX2 even though the
//! binary is built for baseline x86-64. Every path computes exactly the same IEEE operations
//! in the same order (no FMA contraction), so all of them return bit-identical hits.

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod scalar;
#[cfg(target_arch = "x86_64")]
mod sse;

#[cfg(target_arch = "x86_64")]
pub use avx2::Avx2;
#[cfg(target_arch = "x86_64")]
pub use avx512::Avx512;
pub use scalar::Scalar;
#[cfg(target_arch = "x86_64")]
pub use sse::Sse;

use super::tri4::{join_hits, Tri4, Tri4Hits, TriHits, TriRay};
use super::wide::{NodeRay, WideNode};
use std::sync::atomic::{AtomicU8, Ordering};

/// Which kernels run. `Avx512` has kernels of its own where the wider registers and mask
/// registers pay (see `avx512.rs`) and the AVX2 ones elsewhere, compiled with AVX-512 on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum SimdPath {
    Scalar,
    Sse,
    Avx2,
    Avx512,
}

impl SimdPath {
    pub const ALL: [SimdPath; 4] = [SimdPath::Scalar, SimdPath::Sse, SimdPath::Avx2, SimdPath::Avx512];

    pub fn is_available(self) -> bool {
        match self {
            SimdPath::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            SimdPath::Sse => true, // SSE2 is part of x86-64
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 => is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"),
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 => {
                SimdPath::Avx2.is_available()
                    && is_x86_feature_detected!("avx512f")
                    && is_x86_feature_detected!("avx512vl")
            }
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }

    /// Every path this CPU can run, slowest first.
    pub fn available() -> Vec<SimdPath> {
        SimdPath::ALL.into_iter().filter(|p| p.is_available()).collect()
    }

    /// The path traversal uses unless told otherwise: `GLINT_SIMD` (scalar, sse, avx2,
    /// avx512) if set and available, else the widest the CPU has. AVX-512's kernels were
    /// 4 to 9% faster than AVX2's on ray sets and 0.98 to 1.05x on renders on a Sapphire
    /// Rapids Xeon (BENCHMARKS.md); they keep to 256-bit registers (no 512-bit clock penalty).
    #[inline]
    pub fn detect() -> SimdPath {
        // Called per ray: a relaxed load once the choice is made.
        match CHOSEN.load(Ordering::Relaxed) {
            u8::MAX => SimdPath::choose(),
            c => SimdPath::ALL[c as usize & 3],
        }
    }

    #[cold]
    fn choose() -> SimdPath {
        let from_env = std::env::var("GLINT_SIMD").ok().and_then(|s| s.parse::<SimdPath>().ok());
        let p = match from_env {
            Some(p) if p.is_available() => p,
            _ => SimdPath::ALL.into_iter().rev().find(|p| p.is_available()).unwrap_or(SimdPath::Scalar),
        };
        CHOSEN.store(p as u8, Ordering::Relaxed);
        p
    }
}

static CHOSEN: AtomicU8 = AtomicU8::new(u8::MAX);

impl std::str::FromStr for SimdPath {
    type Err = String;
    fn from_str(s: &str) -> Result<SimdPath, String> {
        match s {
            "scalar" => Ok(SimdPath::Scalar),
            "sse" => Ok(SimdPath::Sse),
            "avx2" => Ok(SimdPath::Avx2),
            "avx512" => Ok(SimdPath::Avx512),
            _ => Err(format!("unknown SIMD path '{s}' (expected scalar, sse, avx2 or avx512)")),
        }
    }
}

impl std::fmt::Display for SimdPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SimdPath::Scalar => "scalar",
            SimdPath::Sse => "sse",
            SimdPath::Avx2 => "avx2",
            SimdPath::Avx512 => "avx512",
        })
    }
}

/// The two kernels of one instruction set.
///
/// # Safety
/// Implementations may use instructions that the CPU lacks; callers must only use an `Isa`
/// whose [`SimdPath`] is available, from code compiled with its target features.
pub unsafe trait Isa {
    /// Slab test of the ray against the node's W child boxes within `(r.t_min, t_max)`.
    /// Returns the mask of children hit and writes each child's entry distance to `dist`.
    ///
    /// # Safety
    /// The CPU must have this instruction set (see the trait), and `r.near`, `r.far` must
    /// be rows below 6, as [`NodeRay::new`] makes them. Then memory is safe for every float
    /// input: the kernel reads only `node` and `r`, and writes only `dist`.
    unsafe fn node<const W: usize>(node: &WideNode<W>, r: &NodeRay, t_max: f32, dist: &mut [f32; W]) -> u32;
    /// Watertight test of four triangles, bit-identical to `intersect_triangle`.
    ///
    /// # Safety
    /// As for [`Isa::node`]; `r.k` must hold axes below 3, which `TriRay::new` ensures.
    unsafe fn tri4(block: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> Tri4Hits;
    /// Two blocks in one test: lanes 0..4 are `lo`'s, 4..8 `hi`'s, each exactly as
    /// [`Isa::tri4`] finds it. Paths with eight lanes per instruction do both at once.
    ///
    /// # Safety
    /// As for [`Isa::tri4`].
    #[inline(always)]
    unsafe fn tri8(lo: &Tri4, hi: &Tri4, r: &TriRay, t_min: f32, t_max: f32) -> TriHits<8> {
        join_hits(&Self::tri4(lo, r, t_min, t_max), &Self::tri4(hi, r, t_min, t_max))
    }

    /// Writes the references `children[i]` for the set bits `i` of `mask` (bits below W),
    /// lowest first, to `out[0..n]` and returns n, the number of set bits. `out[n..W]` may be
    /// overwritten with anything (the AVX-512 path stores all W lanes of a compress).
    ///
    /// # Safety
    /// As for [`Isa::node`], and `out` must be valid for writes of W `u32`s.
    #[inline(always)]
    unsafe fn compress_refs<const W: usize>(children: &[u32; W], mask: u32, out: *mut u32) -> usize {
        let (mut n, mut m) = (0, mask & (u32::MAX >> (32 - W)));
        while m != 0 {
            // SAFETY: n < W (one write per set bit below W); the caller's contract.
            unsafe { out.add(n).write(children[m.trailing_zeros() as usize]) };
            n += 1;
            m &= m - 1;
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::tri4::tri4_scalar;
    use crate::math::{vec3, Ray, Vec3};
    use crate::sampling::Rng;

    /// `S::tri8` on two blocks against the scalar test of each: the same lanes hit, with the
    /// same t and barycentrics, bit for bit.
    fn check_tri8<S: Isa>(path: SimdPath) {
        assert!(path.is_available());
        let mut rng = Rng::new(5, 8);
        // Vertices on a coarse grid, so that rays aimed at grid points often pass exactly
        // through vertices and edges (zero edge functions: the double-precision fallback).
        let grid = |rng: &mut Rng| (rng.next_u32() % 5) as f32 - 2.0;
        let point = |rng: &mut Rng| vec3(grid(rng), grid(rng), grid(rng));
        let block = |rng: &mut Rng| {
            let n = 1 + (rng.next_u32() % 4) as usize;
            let tris: Vec<(u32, [Vec3; 3])> =
                (0..n).map(|i| (rng.next_u32() % 1000 + i as u32, [point(rng), point(rng), point(rng)])).collect();
            Tri4::pack(&tris)
        };
        let (mut hits, mut fallbacks) = (0, 0);
        for i in 0..20_000 {
            let blocks = [block(&mut rng), block(&mut rng)];
            let origin = vec3(grid(&mut rng) * 1.5, grid(&mut rng) * 1.5, 4.0 + grid(&mut rng));
            let aimed = &blocks[(i / 3) % 2];
            let target = match i % 3 {
                0 => aimed.vertex((i / 3) % 3, 0),
                1 => (aimed.vertex(0, 1) + aimed.vertex(1, 1)) * 0.5,
                _ => vec3(rng.next_f32() * 4.0 - 2.0, rng.next_f32() * 4.0 - 2.0, rng.next_f32() * 4.0 - 2.0),
            };
            let mut ray = Ray::new(origin, target - origin);
            if i % 7 == 0 {
                ray.t_max = rng.next_f32() * 2.0;
            }
            let r = TriRay::new(&ray);
            let want = join_hits(
                &tri4_scalar(&blocks[0], &r, ray.t_min, ray.t_max),
                &tri4_scalar(&blocks[1], &r, ray.t_min, ray.t_max),
            );
            // SAFETY: the path is available (asserted above).
            let got = unsafe { S::tri8(&blocks[0], &blocks[1], &r, ray.t_min, ray.t_max) };
            same_hits(&got, &want, path, &ray);
            hits += want.mask.count_ones();
            fallbacks +=
                blocks.iter().any(|blk| (0..4).any(|l| crate::accel::tri4::tri_lane_has_zero_edge(blk, l, &r))) as u32;
        }
        // The cases that matter were exercised: hits, and zero edge functions.
        assert!(hits > 1000 && fallbacks > 100, "{path}: {hits} hits, {fallbacks} pairs with a zero edge");
    }

    fn same_hits<const N: usize>(got: &TriHits<N>, want: &TriHits<N>, path: SimdPath, ray: &Ray) {
        assert_eq!(got.mask, want.mask, "{path}: lanes hit of {N}, ray {ray:?}");
        for lane in (0..N).filter(|l| want.mask >> l & 1 == 1) {
            let bits = |h: &TriHits<N>| [h.t[lane].to_bits(), h.b1[lane].to_bits(), h.b2[lane].to_bits()];
            assert_eq!(bits(got), bits(want), "{path}: lane {lane} of {N}, ray {ray:?}");
        }
    }

    #[test]
    fn tri8_is_two_tri4_tests_on_every_path() {
        check_tri8::<Scalar>(SimdPath::Scalar);
        #[cfg(target_arch = "x86_64")]
        {
            check_tri8::<Sse>(SimdPath::Sse);
            if SimdPath::Avx2.is_available() {
                check_tri8::<Avx2>(SimdPath::Avx2);
            }
            if SimdPath::Avx512.is_available() {
                check_tri8::<Avx512>(SimdPath::Avx512);
            } else {
                eprintln!("no AVX-512 on this CPU: its kernels are not tested here");
            }
        }
    }

    /// `compress_refs` on every path and every mask of an 8-wide node: the set children,
    /// lowest first.
    #[test]
    fn compress_refs_keeps_the_set_children_in_order() {
        fn check<S: Isa>(path: SimdPath) {
            let children: [u32; 8] = std::array::from_fn(|i| 100 + i as u32 * 7);
            for mask in 0..=255u32 {
                let mut out = [u32::MAX; 8];
                // SAFETY: the path is available; `out` holds eight `u32`s.
                let n = unsafe { S::compress_refs(&children, mask, out.as_mut_ptr()) };
                let want: Vec<u32> = (0..8).filter(|i| mask >> i & 1 == 1).map(|i| children[i]).collect();
                assert_eq!(&out[..n], &want[..], "{path}: mask {mask:#x}");
            }
        }
        check::<Scalar>(SimdPath::Scalar);
        #[cfg(target_arch = "x86_64")]
        {
            check::<Sse>(SimdPath::Sse);
            if SimdPath::Avx512.is_available() {
                check::<Avx512>(SimdPath::Avx512);
            }
        }
    }
}
