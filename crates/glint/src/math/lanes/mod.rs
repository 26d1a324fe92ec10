//! Lanes: one operation on N independent values at once (one per ray or path), with the
//! same bits in every lane as the one-lane code gives.
//!
//! A [`Lanes`] value is a token: it exists only where its instruction set does, so its
//! vectors can be operated on by safe methods. Three implementations: [`One`] (plain `f32`,
//! the reference and the baseline fallback), [`Avx2x8`] (eight lanes, AVX2) and
//! [`Avx512x16`] (sixteen lanes, AVX-512F). Code over lanes is generic and
//! `#[inline(always)]` all the way down, and is instantiated inside a
//! `#[target_feature]` entry point (see `accel::packet`), as the wide BVH's kernels are.
//!
//! Why in-house: `std::simd` is nightly-only; the `wide` crate fixes the instruction set at
//! compile time (glint ships one baseline x86-64 binary and picks at run time), and both it
//! and `pulp` define min/max with IEEE `minNum` semantics or leave NaN unspecified, where the
//! bit-identity contract needs the one rule the traversal kernels already use (x86's `maxps`:
//! the second operand when either is NaN, and on ±0).
//!
//! Every operation here is IEEE-exact (no approximate reciprocals, no fused multiply-add), so
//! a lane computes exactly what [`One`] computes for the same inputs; the tests below check
//! each operation on each instruction set the CPU has, on random and special values.

mod one;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use one::One;
#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2x8, Avx512x16};

/// Most lanes any implementation has (sizes per-lane arrays in generic code).
pub const MAX_LANES: usize = 16;

/// N lanes of `f32` and their masks.
///
/// # Safety
/// Implementors must be constructible only where the CPU has their instructions (a value of
/// the token is the proof), and every method must compute, per lane, exactly what the
/// documented scalar operation gives on [`One`].
pub unsafe trait Lanes: Copy + Send + Sync + 'static {
    /// Lanes per vector (at most [`MAX_LANES`]).
    const N: usize;
    /// N values.
    type F: Copy;
    /// N booleans.
    type M: Copy;

    fn splat(self, x: f32) -> Self::F;
    /// Lanes from `a[0..N]`. Panics if `a` is shorter.
    fn load(self, a: &[f32]) -> Self::F;
    /// Writes the lanes to `out[0..N]`. Panics if `out` is shorter.
    fn store(self, v: Self::F, out: &mut [f32]);
    fn add(self, a: Self::F, b: Self::F) -> Self::F;
    fn sub(self, a: Self::F, b: Self::F) -> Self::F;
    fn mul(self, a: Self::F, b: Self::F) -> Self::F;
    fn div(self, a: Self::F, b: Self::F) -> Self::F;
    fn sqrt(self, a: Self::F) -> Self::F;
    /// `-a`: the sign bit flipped (NaNs included), as Rust's unary minus.
    fn neg(self, a: Self::F) -> Self::F;
    /// `a.abs()`: the sign bit cleared.
    fn abs(self, a: Self::F) -> Self::F;
    /// `if a > b { a } else { b }`: `b` when either is NaN and when both are zeros (x86's
    /// `maxps`, the rule of every traversal kernel).
    fn max(self, a: Self::F, b: Self::F) -> Self::F;
    /// `if a < b { a } else { b }` (x86's `minps`).
    fn min(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a < b` (false where either is NaN); likewise `le`, `gt`, `ge`, `eq`.
    fn lt(self, a: Self::F, b: Self::F) -> Self::M;
    fn le(self, a: Self::F, b: Self::F) -> Self::M;
    fn gt(self, a: Self::F, b: Self::F) -> Self::M;
    fn ge(self, a: Self::F, b: Self::F) -> Self::M;
    fn eq(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a != b` (true where either is NaN).
    fn ne(self, a: Self::F, b: Self::F) -> Self::M;
    /// Whether the sign bit is set (-0.0 and negative NaNs included).
    fn sign(self, a: Self::F) -> Self::M;
    fn and(self, a: Self::M, b: Self::M) -> Self::M;
    fn or(self, a: Self::M, b: Self::M) -> Self::M;
    /// `a && !b`.
    fn and_not(self, a: Self::M, b: Self::M) -> Self::M;
    /// `!a`.
    fn not(self, a: Self::M) -> Self::M;
    /// `if m { a } else { b }`, lane by lane.
    fn select(self, m: Self::M, a: Self::F, b: Self::F) -> Self::F;
    /// Lane i's boolean in bit i.
    fn bits(self, m: Self::M) -> u32;
}

#[cfg(test)]
mod tests;
