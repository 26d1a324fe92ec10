//! The path tracer's vertex in SIMD lanes: up to 8 (AVX2) or 16 (AVX-512) paths that scatter
//! off the same kind of BSDF take the arithmetic of their step together, one path per lane.
//!
//! A step splits in three (see `path_batch`): per path, the scalar code reaches the vertex
//! (`PathState::arrive`: interaction, emission, masks), builds the BSDF (`shading`) and draws
//! the light sample and the BSDF's random numbers, in the order `PathState::scatter` draws
//! them; the lanes then evaluate the BSDF towards the light, weight it by MIS, build the
//! shadow ray, sample the BSDF and spawn the next ray; per path again, the results go back
//! into the path (`PathState::go_on`, Russian roulette). Lanes hold structure-of-arrays
//! state in a chunk on the stack: written once, read once, in L1.
//!
//! **Bit identity.** Each lane computes exactly what `PathState::scatter` computes for its
//! path: the same IEEE operations in the same order (Rust never contracts to FMA), the
//! `Lanes` min/max only where the scalar code's `f32::max`/`min` give the same answer (noted
//! at each use), and no libm calls (the concentric disk's sine and cosine are polynomials in
//! both). `tests` below compares each lane with the one-path code on random and special
//! inputs; `tests/wavefront.rs` renders every test scene under every schedule and compares the
//! bits.
//!
//! Covered so far: the Lambertian BSDF without normal or bump maps (`Bsdf::Diffuse`), the
//! BSDF of the Cornell boxes, the bunny and the dragon of `bench/compare-mitsuba`. Every
//! other BSDF steps through `PathState::scatter`, one path at a time.

use super::estimators::{sample_light, PrevEvent};
use super::observe::Unobserved;
use super::path::{PathState, ShadowQuery};
use super::path_batch::CameraSample;
use super::{shading, Counters};
use crate::materials::{Bsdf, DiffuseMaterial, MaterialKind, ShadedBsdf, Texture};
use crate::accel::SimdPath;
use crate::describe::{PathSettings, Strategy};
use crate::lights::LightSample;
use crate::math::lanes::{Lanes, One, MAX_LANES};
#[cfg(target_arch = "x86_64")]
use crate::math::lanes::{Avx2x8, Avx512x16};
use crate::math::{vec3, Frame, Ray, Rgb, Vec3, INV_PI, PI};
use crate::sampling::Sampler;
use crate::world::{Hit, ShapeRef, SurfaceInteraction, World};

/// Which lanes run the kernels: the widest the traversal's choice (`GLINT_SIMD`) allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LaneIsa {
    One,
    #[cfg(target_arch = "x86_64")]
    Avx2,
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl LaneIsa {
    pub fn detect() -> LaneIsa {
        match SimdPath::detect() {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 if Avx512x16::new().is_some() => LaneIsa::Avx512,
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 | SimdPath::Avx2 if Avx2x8::new().is_some() => LaneIsa::Avx2,
            _ => LaneIsa::One,
        }
    }

    /// Paths per kernel call.
    pub fn lanes(self) -> usize {
        match self {
            LaneIsa::One => One::N,
            #[cfg(target_arch = "x86_64")]
            LaneIsa::Avx2 => Avx2x8::N,
            #[cfg(target_arch = "x86_64")]
            LaneIsa::Avx512 => Avx512x16::N,
        }
    }
}

type Column = [f32; MAX_LANES];
type Column3 = [Column; 3];

/// Up to [`MAX_LANES`] diffuse vertices, one per lane: what the scalar code gathered, and what
/// the kernel leaves. Flags are 1.0 (true) or 0.0.
#[derive(Clone, Copy)]
pub(crate) struct DiffuseChunk {
    pub len: usize,
    /// Which path each lane is (the caller's index).
    pub path: [u32; MAX_LANES],
    // In: the vertex.
    dir: Column3,
    p: Column3,
    ng: Column3,
    n: Column3,
    s: Column3,
    t: Column3,
    reflectance: Column3,
    throughput: Column3,
    // In: the light sample (`has_light` 0 where there is none).
    has_light: Column,
    light_wi: Column3,
    light_dist: Column,
    light_radiance: Column3,
    light_pdf: Column,
    light_delta: Column,
    // In: the BSDF's square sample.
    u: [Column; 2],
    // In, for lanes whose interaction the kernel computes (`from_mesh` 1): the hit triangle of
    // an untransformed mesh, its barycentrics, vertex normals and uvs where the mesh has them,
    // and the instance's and material's flags. The kernel then writes `ng`, `n`, `s`, `t`.
    from_mesh: Column,
    corners: [Column3; 3],
    bary: Column3,
    has_normals: Column,
    normals: [Column3; 3],
    has_uvs: Column,
    uvs: [[Column; 2]; 3],
    flip_normals: Column,
    two_sided: Column,
    // Out: the shadow ray (`shadow` 0 where there is none).
    shadow: Column,
    shadow_origin: Column3,
    shadow_dir: Column3,
    shadow_t_max: Column,
    contribution: Column3,
    mis_weight: Column,
    // Out: the next ray (`sampled` 0 where the path ends).
    sampled: Column,
    next_origin: Column3,
    next_dir: Column3,
    pdf: Column,
}

impl Default for DiffuseChunk {
    fn default() -> Self {
        let c = [0.0; MAX_LANES];
        let c3 = [c; 3];
        DiffuseChunk {
            len: 0,
            path: [0; MAX_LANES],
            dir: c3,
            p: c3,
            ng: c3,
            n: c3,
            s: c3,
            t: c3,
            reflectance: c3,
            throughput: c3,
            has_light: c,
            light_wi: c3,
            light_dist: c,
            light_radiance: c3,
            light_pdf: c,
            light_delta: c,
            u: [c; 2],
            from_mesh: c,
            corners: [c3; 3],
            bary: c3,
            has_normals: c,
            normals: [c3; 3],
            has_uvs: c,
            uvs: [[c; 2]; 3],
            flip_normals: c,
            two_sided: c,
            shadow: c,
            shadow_origin: c3,
            shadow_dir: c3,
            shadow_t_max: c,
            contribution: c3,
            mis_weight: c,
            sampled: c,
            next_origin: c3,
            next_dir: c3,
            pdf: c,
        }
    }
}

fn put3(c: &mut Column3, i: usize, v: [f32; 3]) {
    c[0][i] = v[0];
    c[1][i] = v[1];
    c[2][i] = v[2];
}

fn get3(c: &Column3, i: usize) -> Vec3 {
    vec3(c[0][i], c[1][i], c[2][i])
}

fn flag(b: bool) -> f32 {
    if b {
        1.0
    } else {
        0.0
    }
}

impl DiffuseChunk {
    pub fn is_full(&self, lanes: usize) -> bool {
        self.len >= lanes
    }

    /// Adds a path's vertex as the next lane, its interaction and frame computed by the scalar
    /// code, drawing its random numbers from `rng` as `PathState::scatter` does (see
    /// [`DiffuseChunk::push_common`]).
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        reflectance: Rgb,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.push_common(path_index, path, si.p, reflectance, light, rng);
        self.from_mesh[i] = 0.0;
        put3(&mut self.ng, i, [si.ng.x, si.ng.y, si.ng.z]);
        put3(&mut self.n, i, [frame.n.x, frame.n.y, frame.n.z]);
        put3(&mut self.s, i, [frame.s.x, frame.s.y, frame.s.z]);
        put3(&mut self.t, i, [frame.t.x, frame.t.y, frame.t.z]);
    }

    /// Adds a path's vertex on an untransformed mesh as the next lane, its interaction and
    /// frame left to the kernel (`p` is the hit point `World::interaction` gives).
    #[allow(clippy::too_many_arguments)]
    pub fn push_mesh(
        &mut self,
        path_index: u32,
        path: &PathState,
        hit: &MeshHit,
        p: Vec3,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.push_common(path_index, path, p, hit.reflectance, light, rng);
        self.from_mesh[i] = 1.0;
        for (k, v) in hit.corners.iter().enumerate() {
            put3(&mut self.corners[k], i, [v.x, v.y, v.z]);
        }
        put3(&mut self.bary, i, hit.bary);
        self.has_normals[i] = flag(hit.normals.is_some());
        for (k, v) in hit.normals.unwrap_or([Vec3::ZERO; 3]).iter().enumerate() {
            put3(&mut self.normals[k], i, [v.x, v.y, v.z]);
        }
        self.has_uvs[i] = flag(hit.uvs.is_some());
        for (k, uv) in hit.uvs.unwrap_or([[0.0; 2]; 3]).iter().enumerate() {
            self.uvs[k][0][i] = uv[0];
            self.uvs[k][1][i] = uv[1];
        }
        self.flip_normals[i] = flag(hit.flip_normals);
        self.two_sided[i] = flag(hit.two_sided);
    }

    /// The lane's path, ray, hit point, reflectance and throughput, its light sample, and the
    /// BSDF's random numbers drawn from `rng` as `PathState::scatter` draws them after the
    /// light sample: the lobe number (unused by a Lambertian BSDF, drawn all the same) and
    /// the square. Returns the lane.
    fn push_common(
        &mut self,
        path_index: u32,
        path: &PathState,
        p: Vec3,
        reflectance: Rgb,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) -> usize {
        let i = self.len;
        self.len += 1;
        self.path[i] = path_index;
        let d = path.ray.dir;
        put3(&mut self.dir, i, [d.x, d.y, d.z]);
        put3(&mut self.p, i, [p.x, p.y, p.z]);
        put3(&mut self.reflectance, i, reflectance.to_array());
        put3(&mut self.throughput, i, path.throughput().to_array());
        match light {
            Some((ls, pick_pmf)) => {
                self.has_light[i] = 1.0;
                put3(&mut self.light_wi, i, [ls.wi.x, ls.wi.y, ls.wi.z]);
                self.light_dist[i] = ls.dist;
                put3(&mut self.light_radiance, i, ls.radiance.to_array());
                self.light_pdf[i] = pick_pmf * ls.pdf;
                self.light_delta[i] = flag(ls.delta);
            }
            None => {
                // Finite values in the unused lanes: nothing is computed from them.
                self.has_light[i] = 0.0;
                put3(&mut self.light_wi, i, [0.0, 0.0, 1.0]);
                self.light_dist[i] = 1.0;
                put3(&mut self.light_radiance, i, [0.0; 3]);
                self.light_pdf[i] = 1.0;
                self.light_delta[i] = 0.0;
            }
        }
        let _u_lobe = rng.next_f32();
        let u = rng.next_2d();
        self.u[0][i] = u[0];
        self.u[1][i] = u[1];
        i
    }

    /// Runs the kernel over the chunk's lanes on `isa`.
    pub fn run(&mut self, isa: LaneIsa, strategy: Strategy) {
        let light_only = strategy == Strategy::Light;
        match isa {
            LaneIsa::One => diffuse_chunk(One, self, light_only),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `LaneIsa::detect` chose AVX2 only where `Avx2x8::new` found it.
            LaneIsa::Avx2 => unsafe { diffuse_chunk_avx2(self, light_only) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `LaneIsa::detect` chose AVX-512 only where `Avx512x16::new` found it.
            LaneIsa::Avx512 => unsafe { diffuse_chunk_avx512(self, light_only) },
        }
    }

    /// Writes lane `i`'s results into its path, as the end of `PathState::scatter` does.
    pub fn finish(&self, i: usize, path: &mut PathState, s: &PathSettings, rng: &mut Sampler, c: &mut Counters) {
        if self.shadow[i] != 0.0 {
            path.leave_shadow_ray(
                ShadowQuery {
                    ray: Ray::segment(get3(&self.shadow_origin, i), get3(&self.shadow_dir, i), self.shadow_t_max[i]),
                    contribution: Rgb::from_array(get3(&self.contribution, i).to_array()),
                    mis_weight: self.mis_weight[i],
                    light_pdf: self.light_pdf[i],
                },
                c,
            );
        }
        if self.sampled[i] == 0.0 {
            return;
        }
        let weight = Rgb::from_array(get3(&self.reflectance, i).to_array());
        let prev = PrevEvent { pdf: self.pdf[i], delta: false, p: get3(&self.p, i) };
        let ray = Ray::new(get3(&self.next_origin, i), get3(&self.next_dir, i));
        path.go_on(s, weight, 1.0, prev, ray, rng);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn diffuse_chunk_avx2(chunk: &mut DiffuseChunk, light_only: bool) {
    // SAFETY: this function's contract is that the CPU has AVX2.
    diffuse_chunk(unsafe { Avx2x8::new_unchecked() }, chunk, light_only)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
unsafe fn diffuse_chunk_avx512(chunk: &mut DiffuseChunk, light_only: bool) {
    // SAFETY: this function's contract is that the CPU has AVX-512F.
    diffuse_chunk(unsafe { Avx512x16::new_unchecked() }, chunk, light_only)
}

/// Every lane of the chunk in vectors of `L::N` (the unused lanes of the last vector compute
/// on whatever their columns hold, and nothing reads their results).
#[inline(always)]
fn diffuse_chunk<L: Lanes>(l: L, c: &mut DiffuseChunk, light_only: bool) {
    let mut base = 0;
    while base < c.len {
        mesh_frames(l, c, base);
        diffuse_lanes(l, c, base, light_only);
        base += L::N;
    }
}

/// Three columns as vectors.
#[derive(Clone, Copy)]
struct V3<F> {
    x: F,
    y: F,
    z: F,
}

#[inline(always)]
fn load3<L: Lanes>(l: L, c: &Column3, base: usize) -> V3<L::F> {
    V3 { x: l.load(&c[0][base..]), y: l.load(&c[1][base..]), z: l.load(&c[2][base..]) }
}

#[inline(always)]
fn store3<L: Lanes>(l: L, v: V3<L::F>, c: &mut Column3, base: usize) {
    l.store(v.x, &mut c[0][base..]);
    l.store(v.y, &mut c[1][base..]);
    l.store(v.z, &mut c[2][base..]);
}

/// `a.dot(b)`, in `Vec3::dot`'s order.
#[inline(always)]
fn dot<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> L::F {
    l.add(l.add(l.mul(a.x, b.x), l.mul(a.y, b.y)), l.mul(a.z, b.z))
}

#[inline(always)]
fn scale<L: Lanes>(l: L, a: V3<L::F>, k: L::F) -> V3<L::F> {
    V3 { x: l.mul(a.x, k), y: l.mul(a.y, k), z: l.mul(a.z, k) }
}

#[inline(always)]
fn add3<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.add(a.x, b.x), y: l.add(a.y, b.y), z: l.add(a.z, b.z) }
}

#[inline(always)]
fn sub3<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.sub(a.x, b.x), y: l.sub(a.y, b.y), z: l.sub(a.z, b.z) }
}

#[inline(always)]
fn mul3<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.mul(a.x, b.x), y: l.mul(a.y, b.y), z: l.mul(a.z, b.z) }
}

#[inline(always)]
fn select3<L: Lanes>(l: L, m: L::M, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 { x: l.select(m, a.x, b.x), y: l.select(m, a.y, b.y), z: l.select(m, a.z, b.z) }
}

/// `a.max(b)` as Rust's `f32::max` answers it (the other operand where one is NaN), for
/// operands that are not both zeros of different signs (where `f32::max` leaves the sign
/// unspecified); `Lanes::max` alone gives `b` where `b` is NaN.
#[inline(always)]
fn max_num<L: Lanes>(l: L, a: L::F, b: L::F) -> L::F {
    l.select(l.ne(b, b), a, l.max(a, b))
}

/// `math::offset_origin(p, ng, dir)`: `p` moved off the surface to the side `dir` leaves by.
#[inline(always)]
fn offset_origin<L: Lanes>(l: L, p: V3<L::F>, ng: V3<L::F>, dir: V3<L::F>) -> V3<L::F> {
    // `p.abs().max_component()`: the operands are absolute values, never -0.0.
    let m = max_num(l, max_num(l, l.abs(p.x), l.abs(p.y)), l.abs(p.z));
    let k = l.mul(l.splat(1e-4), l.add(l.splat(1.0), m));
    let back = l.lt(dot(l, ng, dir), l.splat(0.0));
    let n = select3(l, back, V3 { x: l.neg(ng.x), y: l.neg(ng.y), z: l.neg(ng.z) }, ng);
    add3(l, p, scale(l, n, k))
}

/// One vector of the chunk's lanes, from `base`: `PathState::scatter` for a Lambertian BSDF.
#[inline(always)]
fn diffuse_lanes<L: Lanes>(l: L, c: &mut DiffuseChunk, base: usize, light_only: bool) {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let inv_pi = l.splat(INV_PI);
    let dir = load3(l, &c.dir, base);
    let p = load3(l, &c.p, base);
    let ng = load3(l, &c.ng, base);
    let n = load3(l, &c.n, base);
    let refl = load3(l, &c.reflectance, base);
    let thr = load3(l, &c.throughput, base);
    // `frame.to_local(-ray.dir).z`: the Lambertian BSDF reads only the normal component.
    let wo_z = dot(l, V3 { x: l.neg(dir.x), y: l.neg(dir.y), z: l.neg(dir.z) }, n);
    let wo_below = l.le(wo_z, zero);

    // Next-event estimation: `Diffuse::eval` and `pdf` towards the light, the MIS weight,
    // the contribution and the shadow ray.
    let light_wi = load3(l, &c.light_wi, base);
    let wi_z = dot(l, light_wi, n);
    let black = l.or(wo_below, l.le(wi_z, zero));
    let k = l.mul(inv_pi, wi_z);
    let f = V3 {
        x: l.select(black, zero, l.mul(refl.x, k)),
        y: l.select(black, zero, l.mul(refl.y, k)),
        z: l.select(black, zero, l.mul(refl.z, k)),
    };
    // `cosine_hemisphere_pdf(wi.z)`: `wi.z.max(0.0)`, where `Lanes::max` agrees (0 on NaN).
    let bsdf_pdf = l.select(black, zero, l.mul(l.max(wi_z, zero), inv_pi));
    let f_black = l.and(l.and(l.eq(f.x, zero), l.eq(f.y, zero)), l.eq(f.z, zero));
    let light_pdf = l.load(&c.light_pdf[base..]);
    // `power_heuristic(light_pdf, bsdf_pdf)`.
    let a = l.mul(light_pdf, light_pdf);
    let b = l.mul(bsdf_pdf, bsdf_pdf);
    let sum = l.add(a, b);
    let heuristic = l.select(
        l.eq(a, l.splat(f32::INFINITY)),
        one,
        l.select(l.eq(sum, zero), zero, l.div(a, sum)),
    );
    let delta = l.gt(l.load(&c.light_delta[base..]), zero);
    let mis = if light_only { one } else { l.select(delta, one, heuristic) };
    let has_light = l.gt(l.load(&c.has_light[base..]), zero);
    let shadow = l.and_not(has_light, f_black);
    let radiance = load3(l, &c.light_radiance, base);
    store3(l, mul3(l, mul3(l, thr, f), radiance), &mut c.contribution, base);
    l.store(mis, &mut c.mis_weight[base..]);
    l.store(l.select(shadow, one, zero), &mut c.shadow[base..]);
    // `shadow_ray(si, ls.wi, ls.dist)`.
    let dist = l.load(&c.light_dist[base..]);
    let o = offset_origin(l, p, ng, light_wi);
    let to_target = sub3(l, add3(l, p, scale(l, light_wi, dist)), o);
    let len = l.sqrt(dot(l, to_target, to_target));
    let toward = scale(l, to_target, l.div(one, len));
    let finite = l.lt(l.abs(dist), l.splat(f32::INFINITY));
    store3(l, o, &mut c.shadow_origin, base);
    store3(l, select3(l, finite, toward, light_wi), &mut c.shadow_dir, base);
    let t_max = l.mul(len, l.splat(1.0 - 1e-4));
    l.store(l.select(finite, t_max, l.splat(f32::INFINITY)), &mut c.shadow_t_max[base..]);

    // `Diffuse::sample`: `cosine_hemisphere(u)` by `concentric_disk`, in its operations.
    let u0 = l.load(&c.u[0][base..]);
    let u1 = l.load(&c.u[1][base..]);
    let two = l.splat(2.0);
    let qa = l.sub(l.mul(two, u0), one);
    let qb = l.sub(l.mul(two, u1), one);
    let around_y = l.le(l.abs(qa), l.abs(qb));
    let r = l.select(around_y, qb, qa);
    let q = l.select(around_y, qa, qb);
    let centre = l.eq(r, zero);
    let (sin_t, cos_t) = sin_cos_quarter(l, l.mul(l.splat(PI / 4.0), l.div(q, r)));
    let dx = l.select(centre, zero, l.mul(r, l.select(around_y, sin_t, cos_t)));
    let dy = l.select(centre, zero, l.mul(r, l.select(around_y, cos_t, sin_t)));
    // `(1 - x² - y²).max(0.0)`: never -0.0 nor NaN for a sample in the square, where
    // `Lanes::max` and `f32::max` agree.
    let z = l.sqrt(l.max(l.sub(l.sub(one, l.mul(dx, dx)), l.mul(dy, dy)), zero));
    let refl_black = l.and(l.and(l.eq(refl.x, zero), l.eq(refl.y, zero)), l.eq(refl.z, zero));
    let sampled = l.and_not(l.and_not(l.not(wo_below), l.le(z, zero)), refl_black);
    l.store(l.select(sampled, one, zero), &mut c.sampled[base..]);
    l.store(l.mul(l.max(z, zero), inv_pi), &mut c.pdf[base..]);
    // `frame.to_world(wi)`, then `spawn_ray`.
    let s = load3(l, &c.s, base);
    let t = load3(l, &c.t, base);
    let wi = add3(l, add3(l, scale(l, s, dx), scale(l, t, dy)), scale(l, n, z));
    store3(l, wi, &mut c.next_dir, base);
    store3(l, offset_origin(l, p, ng, wi), &mut c.next_origin, base);
}

/// `Frame::from_normal(n)` (Duff et al.'s basis), in its operations.
#[inline(always)]
fn frame_from_normal<L: Lanes>(l: L, n: V3<L::F>) -> (V3<L::F>, V3<L::F>) {
    let one = l.splat(1.0);
    // `1.0f32.copysign(n.z)`.
    let sign = l.select(l.sign(n.z), l.splat(-1.0), one);
    let a = l.div(l.splat(-1.0), l.add(sign, n.z));
    let b = l.mul(l.mul(n.x, n.y), a);
    let s = V3 {
        x: l.add(one, l.mul(l.mul(l.mul(sign, n.x), n.x), a)),
        y: l.mul(sign, b),
        z: l.mul(l.neg(sign), n.x),
    };
    let t = V3 { x: b, y: l.add(sign, l.mul(l.mul(n.y, n.y), a)), z: l.neg(n.y) };
    (s, t)
}

/// Whether every component is finite (`Vec3::is_finite`).
#[inline(always)]
fn finite3<L: Lanes>(l: L, v: V3<L::F>) -> L::M {
    let inf = l.splat(f32::INFINITY);
    l.and(l.and(l.lt(l.abs(v.x), inf), l.lt(l.abs(v.y), inf)), l.lt(l.abs(v.z), inf))
}

#[inline(always)]
fn cross<L: Lanes>(l: L, a: V3<L::F>, b: V3<L::F>) -> V3<L::F> {
    V3 {
        x: l.sub(l.mul(a.y, b.z), l.mul(a.z, b.y)),
        y: l.sub(l.mul(a.z, b.x), l.mul(a.x, b.z)),
        z: l.sub(l.mul(a.x, b.y), l.mul(a.y, b.x)),
    }
}

#[inline(always)]
fn neg3<L: Lanes>(l: L, a: V3<L::F>) -> V3<L::F> {
    V3 { x: l.neg(a.x), y: l.neg(a.y), z: l.neg(a.z) }
}

/// `v.normalize()`: `v * (1 / |v|)`.
#[inline(always)]
fn normalize<L: Lanes>(l: L, v: V3<L::F>) -> V3<L::F> {
    scale(l, v, l.div(l.splat(1.0), l.sqrt(dot(l, v, v))))
}

/// For the lanes of untransformed meshes: `World::interaction`'s geometric normal and
/// shading frame (interpolated normals, dp/du from the uvs), then `shading`'s turn of a
/// two-sided material's frame towards the viewer, written to the `ng`, `n`, `s`, `t` columns;
/// the other lanes keep theirs.
#[inline(always)]
fn mesh_frames<L: Lanes>(l: L, c: &mut DiffuseChunk, base: usize) {
    let zero = l.splat(0.0);
    let yes = |col: &Column| l.gt(l.load(&col[base..]), zero);
    let from_mesh = yes(&c.from_mesh);
    if l.bits(from_mesh) == 0 {
        return;
    }
    let [a, b, cc] = c.corners.each_ref().map(|k| load3(l, k, base));
    let [b0, b1, b2] = [0, 1, 2].map(|k| l.load(&c.bary[k][base..]));
    let e1 = sub3(l, b, a);
    let e2 = sub3(l, cc, a);
    let ng_obj = cross(l, e1, e2);
    // dp/du: from the uvs (`triangle_dpduv`), else the edge b - a.
    let [t0, t1, t2] = c.uvs.each_ref().map(|uv| (l.load(&uv[0][base..]), l.load(&uv[1][base..])));
    let (du0, dv0) = (l.sub(t1.0, t0.0), l.sub(t1.1, t0.1));
    let (du1, dv1) = (l.sub(t2.0, t0.0), l.sub(t2.1, t0.1));
    let det = l.sub(l.mul(du0, dv1), l.mul(dv0, du1));
    let inv = l.div(l.splat(1.0), det);
    let dpdu_uv = scale(l, sub3(l, scale(l, e1, dv1), scale(l, e2, dv0)), inv);
    let dpdv_uv = scale(l, sub3(l, scale(l, e2, du0), scale(l, e1, du1)), inv);
    let uv_ok = l.and(l.ne(det, zero), l.and(finite3(l, dpdu_uv), finite3(l, dpdv_uv)));
    let (fallback_s, _) = frame_from_normal(l, normalize(l, ng_obj));
    let dpdu_mesh = select3(l, uv_ok, dpdu_uv, fallback_s);
    let dpdu = select3(l, yes(&c.has_uvs), dpdu_mesh, e1);
    // The geometric normal, and the shading normal: the interpolated one where the mesh
    // has normals and it is not zero, else the geometric one; the geometric one again where
    // that is not finite.
    let flip = yes(&c.flip_normals);
    let ng_unit = normalize(l, ng_obj);
    let ng = select3(l, flip, neg3(l, ng_unit), ng_unit);
    let [n0, n1, n2] = c.normals.each_ref().map(|k| load3(l, k, base));
    let ns = add3(l, add3(l, scale(l, n0, b0), scale(l, n1, b1)), scale(l, n2, b2));
    let ns_unit = normalize(l, ns);
    let ns_unit = select3(l, flip, neg3(l, ns_unit), ns_unit);
    let use_ns = l.and(yes(&c.has_normals), l.gt(dot(l, ns, ns), zero));
    let n_shading = select3(l, use_ns, ns_unit, ng);
    let n_shading = select3(l, finite3(l, n_shading), n_shading, ng);
    // `Frame::from_normal_tangent(n_shading, dpdu)`.
    let s_raw = sub3(l, dpdu, scale(l, n_shading, dot(l, n_shading, dpdu)));
    let len2 = dot(l, s_raw, s_raw);
    let tangent_ok = l.and(
        l.gt(len2, l.mul(l.splat(1e-20), dot(l, dpdu, dpdu))),
        l.lt(l.abs(len2), l.splat(f32::INFINITY)),
    );
    let s_unit = scale(l, s_raw, l.div(l.splat(1.0), l.sqrt(len2)));
    let (basis_s, basis_t) = frame_from_normal(l, n_shading);
    let s = select3(l, tangent_ok, s_unit, basis_s);
    let t = select3(l, tangent_ok, cross(l, n_shading, s_unit), basis_t);
    // `shading`: a two-sided material's frame faces the viewer (`-ray.dir`).
    let dir = load3(l, &c.dir, base);
    let facing_away = l.lt(dot(l, n_shading, neg3(l, dir)), zero);
    let turn = l.and(yes(&c.two_sided), facing_away);
    let n = select3(l, turn, neg3(l, n_shading), n_shading);
    let keep = |new: V3<L::F>, col: &Column3| select3(l, from_mesh, new, load3(l, col, base));
    let (ng, n, s, t) = (keep(ng, &c.ng), keep(n, &c.n), keep(s, &c.s), keep(t, &c.t));
    store3(l, ng, &mut c.ng, base);
    store3(l, n, &mut c.n, base);
    store3(l, s, &mut c.s, base);
    store3(l, t, &mut c.t, base);
}

/// `warp::sin_cos_quarter`, in its operations and constants.
#[inline(always)]
fn sin_cos_quarter<L: Lanes>(l: L, t: L::F) -> (L::F, L::F) {
    let c = |x: f32| l.splat(x);
    let t2 = l.mul(t, t);
    let sin_poly = l.add(c(1.0 / 120.0), l.mul(t2, l.add(c(-1.0 / 5040.0), l.mul(t2, c(1.0 / 362_880.0)))));
    let sin = l.mul(t, l.add(c(1.0), l.mul(t2, l.add(c(-1.0 / 6.0), l.mul(t2, sin_poly)))));
    let cos_inner = l.add(c(1.0 / 40_320.0), l.mul(t2, c(-1.0 / 3_628_800.0)));
    let cos_mid = l.add(c(1.0 / 24.0), l.mul(t2, l.add(c(-1.0 / 720.0), l.mul(t2, cos_inner))));
    let cos = l.add(c(1.0), l.mul(t2, l.add(c(-0.5), l.mul(t2, cos_mid))));
    (sin, cos)
}

/// A hit on an untransformed triangle mesh that neither emits nor may be passed, of a
/// Lambertian material with a constant reflectance: the lanes compute its interaction.
pub(crate) struct MeshHit {
    corners: [Vec3; 3],
    bary: [f32; 3],
    normals: Option<[Vec3; 3]>,
    uvs: Option<[[f32; 2]; 3]>,
    reflectance: Rgb,
    flip_normals: bool,
    two_sided: bool,
}

impl MeshHit {
    /// The hit, where the lanes cover it, and its point as `World::interaction` computes it.
    #[inline]
    fn of(scene: &World, hit: &Hit) -> Option<(MeshHit, Vec3)> {
        let inst = scene.instances.get(hit.instance as usize)?;
        let ShapeRef::Mesh(m) = inst.shape else { return None };
        if inst.light.is_some() || inst.to_world.is_some() {
            return None;
        }
        let mat = scene.materials.get(inst.material as usize)?;
        // A plain `Diffuse` kind has no mask, normal or bump map (those wrap it).
        let MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(reflectance) }) = &mat.kind else {
            return None;
        };
        if mat.cull_back_faces {
            return None;
        }
        let mesh = scene.meshes.get(m as usize)?;
        let tri = hit.prim as usize;
        let [i0, i1, i2] = *mesh.indices.get(tri)?;
        let [a, b, c] = mesh.vertices(tri);
        let b0 = 1.0 - hit.b1 - hit.b2;
        let p = a * b0 + b * hit.b1 + c * hit.b2;
        let (i0, i1, i2) = (i0 as usize, i1 as usize, i2 as usize);
        let at = MeshHit {
            corners: [a, b, c],
            bary: [b0, hit.b1, hit.b2],
            normals: mesh.normals.as_ref().map(|n| [n[i0], n[i1], n[i2]]),
            uvs: mesh.uvs.as_ref().map(|t| [t[i0], t[i1], t[i2]]),
            reflectance: *reflectance,
            flip_normals: inst.flip_normals,
            two_sided: mat.two_sided,
        };
        Some((at, p))
    }
}

/// Steps the paths of a wave as `PathState::step` does, the Lambertian vertices through the
/// lanes: each path reaches its vertex alone, then either scatters alone or waits in the chunk,
/// which runs when full and at [`LaneStepper::flush`].
pub(crate) struct LaneStepper {
    isa: LaneIsa,
    lanes: usize,
    chunk: DiffuseChunk,
}

impl LaneStepper {
    pub fn new(isa: LaneIsa) -> LaneStepper {
        LaneStepper { isa, lanes: isa.lanes(), chunk: DiffuseChunk::default() }
    }

    /// Path `i`'s step at `hit`; its results may wait until the chunk runs (at the latest at
    /// [`LaneStepper::flush`], which must come before its shadow ray is traced).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn step(
        &mut self,
        s: &PathSettings,
        scene: &World,
        paths: &mut [PathState],
        samples: &mut [CameraSample],
        i: usize,
        hit: Option<Hit>,
        c: &mut Counters,
    ) {
        let path = &mut paths[i];
        let rng = &mut samples[i].sampler;
        if let Some((mesh_hit, p)) = hit.as_ref().and_then(|h| MeshHit::of(scene, h)) {
            // What `arrive` does at a surface that neither emits nor may be passed.
            if !path.arrive_opaque() {
                return;
            }
            let light = self.light_sample(s, scene, p, rng);
            self.chunk.push_mesh(i as u32, path, &mesh_hit, p, light, rng);
            if self.chunk.is_full(self.lanes) {
                self.flush(s, paths, samples, c);
            }
            return;
        }
        let Some(si) = path.arrive(s, scene, hit, rng, &mut Unobserved) else { return };
        let (bsdf, frame) = shading(scene, &si, -path.ray.dir);
        let Some(reflectance) = plain_diffuse(&bsdf) else {
            path.scatter(s, scene, &si, &bsdf, &frame, rng, c, &mut Unobserved);
            return;
        };
        let light = self.light_sample(s, scene, si.p, rng);
        self.chunk.push(i as u32, path, &si, &frame, reflectance, light, rng);
        if self.chunk.is_full(self.lanes) {
            self.flush(s, paths, samples, c);
        }
    }

    /// Next-event estimation's light sample at `p` and the light's probability, as
    /// `PathState::scatter` draws it for a BSDF that is not delta.
    #[inline]
    fn light_sample(&self, s: &PathSettings, scene: &World, p: Vec3, rng: &mut Sampler) -> Option<(LightSample, f32)> {
        if s.strategy == Strategy::Bsdf {
            return None;
        }
        sample_light(scene, p, rng).map(|(ls, pick_pmf, _)| (ls, pick_pmf))
    }

    /// Runs the waiting vertices and finishes their steps.
    pub fn flush(&mut self, s: &PathSettings, paths: &mut [PathState], samples: &mut [CameraSample], c: &mut Counters) {
        if self.chunk.len == 0 {
            return;
        }
        self.chunk.run(self.isa, s.strategy);
        for lane in 0..self.chunk.len {
            let i = self.chunk.path[lane] as usize;
            self.chunk.finish(lane, &mut paths[i], s, &mut samples[i].sampler, c);
        }
        self.chunk.len = 0;
    }
}

/// The reflectance of a Lambertian BSDF with no normal or bump map: what the lanes cover.
#[inline]
fn plain_diffuse(bsdf: &ShadedBsdf) -> Option<Rgb> {
    match (&bsdf.bsdf, &bsdf.tilt) {
        (Bsdf::Diffuse(d), None) => Some(d.reflectance),
        _ => None,
    }
}

#[cfg(test)]
mod tests;
