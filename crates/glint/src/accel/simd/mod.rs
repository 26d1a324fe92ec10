//! Instruction-set paths for the wide BVH kernels, chosen at run time.
//!
//! The two kernels that matter, a ray against the W child boxes of a node and a ray against a
//! block of four triangles, are written once per instruction set behind the [`Isa`] trait.
//! Traversal is generic over `Isa` and is instantiated inside `#[target_feature]` entry
//! points (see `wide_mesh.rs`), so the AVX2 path is compiled with AVX2 even though the
//! binary is built for baseline x86-64. Every path computes exactly the same IEEE operations
//! in the same order (no FMA contraction), so all of them return bit-identical hits.

#[cfg(target_arch = "x86_64")]
mod avx2;
mod scalar;
#[cfg(target_arch = "x86_64")]
mod sse;

#[cfg(target_arch = "x86_64")]
pub use avx2::Avx2;
pub use scalar::Scalar;
#[cfg(target_arch = "x86_64")]
pub use sse::Sse;

use super::tri4::{Tri4, Tri4Hits, TriRay};
use super::wide::{NodeRay, WideNode};
use std::sync::atomic::{AtomicU8, Ordering};

/// Which kernels run. `Avx512` runs the AVX2 kernels compiled with AVX-512 enabled (the
/// compiler may use its masks and wider register file); the 8-wide node test fits AVX2.
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
    /// avx512) if set and available, else AVX2 when present. AVX-512 is not the default: on
    /// the machines measured it was no faster (see BENCHMARKS.md) and it can lower clocks.
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
            _ => [SimdPath::Avx2, SimdPath::Sse, SimdPath::Scalar].into_iter().find(|p| p.is_available()).unwrap(),
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
}
