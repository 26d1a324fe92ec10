//! The path tracer's vertex in SIMD lanes: up to 8 (AVX2) or 16 (AVX-512) paths that scatter
//! off the same kind of BSDF take the arithmetic of their step together, one path per lane.
//!
//! A step splits in three (see `path_batch`): per path, the scalar code reaches the vertex
//! (`PathState::arrive`: interaction, emission, masks), builds the BSDF (`shading`) and draws
//! the light sample and the BSDF's random numbers, in the order `PathState::scatter` draws
//! them; the lanes then evaluate the BSDF towards the light, weight it by MIS, build the
//! shadow ray, sample the BSDF and spawn the next ray; per path again, the results go back
//! into the path (`PathState::go_on`, Russian roulette). Lanes hold structure-of-arrays
//! state in a chunk per BSDF class on the stack (the wave's paths are binned by class as they
//! arrive): written once, read once, in L1. On untransformed meshes of a constant Lambertian
//! material the lanes compute the interaction's normals and frame too ([`MeshHit`]).
//!
//! **Bit identity.** Each lane computes exactly what `PathState::scatter` computes for its
//! path: the same IEEE operations in the same order (Rust never contracts to FMA), the
//! `Lanes` min/max only where the scalar code's `f32::max`/`min` give the same answer (noted
//! at each use), and no libm in vector form: the concentric disk's sine and cosine are
//! polynomials in both, and where the scalar code calls libm (`f32::cos`, `f32::exp`, f64's
//! error function) the lanes make the same scalar call for each lane. `tests` below compares
//! each lane with the one-path code on random and special inputs; `tests/wavefront.rs`
//! renders every test scene under every schedule and compares the bits.
//!
//! Covered so far, without normal or bump maps: the Lambertian BSDF (`diffuse`: the BSDF of
//! the Cornell boxes, the bunny and the dragon of `bench/compare-mitsuba`), the smooth
//! conductor and dielectric (`smooth`), the rough conductor (`rough`: GGX and Beckmann,
//! isotropic or anisotropic, over the lanes' microfacet distribution in `microfacet`, which
//! makes the scalar calls of libm's sine, cosine and exponential and of Beckmann's f64 visible
//! fraction and visible-normal sampling per lane: the same calls, so the same bits), the
//! rough dielectric (`rough_dielectric`: reflection and refraction through the same
//! distribution, from either side of the interface), the smooth plastic (`plastic`: its delta
//! reflection and cosine-sampled base), the rough plastic (`rough_plastic`: its coating's
//! microfacet reflection over the same distribution, and the coating's transmittance table
//! read by the scalar function per lane), and the principled BSDF with all its lobes
//! (`principled`). Every other BSDF steps through `PathState::scatter`, one path at a time.

/// `run(isa, strategy)` for the chunk type `$chunk` whose kernel `$lanes(l, chunk, base, live,
/// light_only)` shades one vector of lanes from `base` (`live`: the lanes that hold vertices,
/// lane i in bit i; the others compute on stale columns and nothing reads their results): the
/// kernel instantiated for each instruction set behind its `#[target_feature]` entry point,
/// the one `LaneIsa::detect` chose run.
macro_rules! lane_kernel {
    ($chunk:ty, $lanes:ident) => {
        impl $chunk {
            /// Runs the kernel over the chunk's lanes on `isa`.
            pub fn run(
                &mut self,
                isa: $crate::integrators::vertex_lanes::LaneIsa,
                strategy: $crate::describe::Strategy,
            ) {
                use $crate::integrators::vertex_lanes::LaneIsa;
                use $crate::math::lanes::Lanes;

                #[inline(always)]
                fn every_vector<L: Lanes>(l: L, c: &mut $chunk, light_only: bool) {
                    let mut base = 0;
                    while base < c.shared.len {
                        let live = (1u32 << (c.shared.len - base).min(L::N)) - 1;
                        $lanes(l, c, base, live, light_only);
                        base += L::N;
                    }
                }

                #[cfg(target_arch = "x86_64")]
                #[target_feature(enable = "avx2,fma")]
                unsafe fn avx2(c: &mut $chunk, light_only: bool) {
                    // SAFETY: this function's contract is that the CPU has AVX2.
                    every_vector(unsafe { $crate::math::lanes::Avx2x8::new_unchecked() }, c, light_only)
                }

                #[cfg(target_arch = "x86_64")]
                #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
                unsafe fn avx512(c: &mut $chunk, light_only: bool) {
                    // SAFETY: this function's contract is that the CPU has AVX-512F.
                    every_vector(unsafe { $crate::math::lanes::Avx512x16::new_unchecked() }, c, light_only)
                }

                let light_only = strategy == $crate::describe::Strategy::Light;
                match isa {
                    LaneIsa::One => every_vector($crate::math::lanes::One, self, light_only),
                    #[cfg(target_arch = "x86_64")]
                    // SAFETY: `LaneIsa::detect` chose AVX2 only where `Avx2x8::new` found it.
                    LaneIsa::Avx2 => unsafe { avx2(self, light_only) },
                    #[cfg(target_arch = "x86_64")]
                    // SAFETY: `LaneIsa::detect` chose AVX-512 only where `Avx512x16::new` found it.
                    LaneIsa::Avx512 => unsafe { avx512(self, light_only) },
                }
            }
        }
    };
}

mod columns;
mod diffuse;
mod lane_math;
mod microfacet;
mod plastic;
mod principled;
mod rough;
mod rough_dielectric;
mod rough_plastic;
mod smooth;
mod warp;

use super::estimators::sample_light;
use super::observe::Unobserved;
use super::path::PathState;
use super::path_batch::CameraSample;
use super::{shading, Counters};
use crate::accel::SimdPath;
use crate::describe::{PathSettings, Strategy};
use crate::lights::LightSample;
use crate::materials::{Bsdf, DiffuseMaterial, MaterialKind, Texture};
#[cfg(target_arch = "x86_64")]
use crate::math::lanes::{Avx2x8, Avx512x16};
use crate::math::lanes::{Lanes, One, MAX_LANES};
use crate::math::{vec3, Rgb, Vec3};
use crate::sampling::Sampler;
use crate::world::{barycentric_point, Hit, ShapeRef, World};
use diffuse::DiffuseChunk;
use plastic::PlasticChunk;
use principled::PrincipledChunk;
use rough::RoughChunk;
use rough_dielectric::RoughDielectricChunk;
use rough_plastic::RoughPlasticChunk;
use smooth::{Smooth, SmoothChunk};

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

/// One value per lane, and three.
type Column = [f32; MAX_LANES];
type Column3 = [Column; 3];
pub(super) fn put3(c: &mut Column3, i: usize, v: [f32; 3]) {
    c[0][i] = v[0];
    c[1][i] = v[1];
    c[2][i] = v[2];
}

pub(super) fn get3(c: &Column3, i: usize) -> Vec3 {
    vec3(c[0][i], c[1][i], c[2][i])
}

pub(super) fn flag(b: bool) -> f32 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// A hit on an untransformed triangle mesh that neither emits nor may be passed, of a
/// Lambertian material with a constant reflectance: the lanes compute its interaction.
pub(crate) struct MeshHit {
    pub(super) corners: [Vec3; 3],
    pub(super) bary: [f32; 3],
    pub(super) normals: Option<[Vec3; 3]>,
    pub(super) uvs: Option<[[f32; 2]; 3]>,
    pub(super) reflectance: Rgb,
    pub(super) flip_normals: bool,
    pub(super) two_sided: bool,
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
        let (p, b0) = barycentric_point([a, b, c], hit.b1, hit.b2);
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

/// What the stepper asks of each class's chunk.
trait Chunk {
    /// The vertices waiting.
    fn waiting(&self) -> usize;
    /// Runs the class's kernel over the waiting vertices.
    fn kernel(&mut self, isa: LaneIsa, strategy: Strategy);
    /// Writes lane `lane`'s results into its path, as the end of `PathState::scatter` does.
    fn finish_lane(
        &self,
        lane: usize,
        paths: &mut [PathState],
        samples: &mut [CameraSample],
        s: &PathSettings,
        c: &mut Counters,
    );
    /// Empties the chunk.
    fn clear(&mut self);
}

/// The chunks keep their bookkeeping in `SharedColumns` and their kernel in `run`.
macro_rules! chunks {
    ($($chunk:ty),+) => {$(
        impl Chunk for $chunk {
            fn waiting(&self) -> usize {
                self.shared.len
            }
            fn kernel(&mut self, isa: LaneIsa, strategy: Strategy) {
                self.run(isa, strategy);
            }
            fn finish_lane(&self, lane: usize, paths: &mut [PathState], samples: &mut [CameraSample], s: &PathSettings, c: &mut Counters) {
                let i = self.shared.path[lane] as usize;
                self.shared.finish(lane, &mut paths[i], s, &mut samples[i].sampler, c);
            }
            fn clear(&mut self) {
                self.shared.len = 0;
            }
        }
    )+};
}

chunks!(DiffuseChunk, SmoothChunk, PlasticChunk, RoughPlasticChunk, RoughChunk, RoughDielectricChunk, PrincipledChunk);

/// Runs `chunk`'s waiting vertices and finishes their steps.
fn flush_chunk<C: Chunk>(
    chunk: &mut C,
    isa: LaneIsa,
    s: &PathSettings,
    paths: &mut [PathState],
    samples: &mut [CameraSample],
    c: &mut Counters,
) {
    if chunk.waiting() == 0 {
        return;
    }
    chunk.kernel(isa, s.strategy);
    for lane in 0..chunk.waiting() {
        chunk.finish_lane(lane, paths, samples, s, c);
    }
    chunk.clear();
}

/// Steps the paths of a wave as `PathState::step` does, the vertices of the classes above
/// through the lanes: each path reaches its vertex alone, then either scatters alone or waits
/// in its class's chunk, which runs when full and at [`LaneStepper::flush`].
pub(crate) struct LaneStepper {
    isa: LaneIsa,
    lanes: usize,
    /// One chunk per BSDF class: a chunk's lanes run one kernel.
    diffuse: DiffuseChunk,
    smooth: SmoothChunk,
    plastic: PlasticChunk,
    rough_plastic: RoughPlasticChunk,
    rough: RoughChunk,
    rough_dielectric: RoughDielectricChunk,
    principled: PrincipledChunk,
}

impl LaneStepper {
    pub fn new(isa: LaneIsa) -> LaneStepper {
        LaneStepper {
            isa,
            lanes: isa.lanes(),
            diffuse: DiffuseChunk::default(),
            smooth: SmoothChunk::default(),
            plastic: PlasticChunk::default(),
            rough_plastic: RoughPlasticChunk::default(),
            rough: RoughChunk::default(),
            rough_dielectric: RoughDielectricChunk::default(),
            principled: PrincipledChunk::default(),
        }
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
        let (isa, lanes) = (self.isa, self.lanes);
        let path = &mut paths[i];
        let rng = &mut samples[i].sampler;
        let index = i as u32;
        if let Some((mesh_hit, p)) = hit.as_ref().and_then(|h| MeshHit::of(scene, h)) {
            // What `arrive` does at a surface that neither emits nor may be passed.
            if !path.arrive_opaque() {
                return;
            }
            let light = light_sample(s, scene, p, rng);
            self.diffuse.push_mesh(index, path, &mesh_hit, p, light, rng);
            if self.diffuse.shared.len >= lanes {
                flush_chunk(&mut self.diffuse, isa, s, paths, samples, c);
            }
            return;
        }
        let Some(si) = path.arrive(s, scene, hit, rng, &mut Unobserved) else { return };
        let (bsdf, frame) = shading(scene, &si, -path.ray.dir);
        // A normal or bump map (`tilt`) leaves the vertex to `scatter`.
        if bsdf.tilt.is_some() {
            path.scatter(s, scene, &si, &bsdf, &frame, rng, c, &mut Unobserved);
            return;
        }
        // Each class's vertex waits in its chunk with its light sample (delta BSDFs draw none,
        // as in `scatter`) and its BSDF's random numbers. Every BSDF is named, so that a new
        // one is placed here on purpose.
        let (class, waiting) = match &bsdf.bsdf {
            Bsdf::Diffuse(d) => {
                let light = light_sample(s, scene, si.p, rng);
                self.diffuse.push(index, path, &si, &frame, d.reflectance, light, rng);
                (Class::Diffuse, self.diffuse.shared.len)
            }
            Bsdf::Conductor(m) => {
                self.smooth.push(index, path, &si, &frame, Smooth::Conductor(*m), rng);
                (Class::Smooth, self.smooth.shared.len)
            }
            Bsdf::Dielectric(d) => {
                self.smooth.push(index, path, &si, &frame, Smooth::Dielectric(*d), rng);
                (Class::Smooth, self.smooth.shared.len)
            }
            // The smooth kernel's coating transmits 1 - F: a smooth coating with a table (only
            // a hand-built plastic has one) steps through `scatter` below.
            Bsdf::Plastic(p) if p.dist.is_some() || p.transmittance.is_none() => {
                let light = light_sample(s, scene, si.p, rng);
                match &p.dist {
                    None => {
                        self.plastic.push(index, path, &si, &frame, p, light, rng);
                        (Class::Plastic, self.plastic.shared.len)
                    }
                    Some(dist) => {
                        self.rough_plastic.push(index, path, &si, &frame, p, dist, light, rng);
                        (Class::RoughPlastic, self.rough_plastic.shared.len)
                    }
                }
            }
            Bsdf::RoughConductor(m) => {
                let light = light_sample(s, scene, si.p, rng);
                self.rough.push(index, path, &si, &frame, m, light, rng);
                (Class::Rough, self.rough.shared.len)
            }
            Bsdf::RoughDielectric(d) => {
                let light = light_sample(s, scene, si.p, rng);
                self.rough_dielectric.push(index, path, &si, &frame, d, light, rng);
                (Class::RoughDielectric, self.rough_dielectric.shared.len)
            }
            Bsdf::Principled(b) => {
                let light = light_sample(s, scene, si.p, rng);
                self.principled.push(index, path, &si, &frame, b, light, rng);
                (Class::Principled, self.principled.shared.len)
            }
            // Not in lanes yet.
            Bsdf::Plastic(_)
            | Bsdf::Phong(_)
            | Bsdf::ThinDielectric(_)
            | Bsdf::Black(_)
            | Bsdf::Null(_)
            | Bsdf::PrincipledThin(_)
            | Bsdf::Blend(_)
            | Bsdf::PPlastic(_)
            | Bsdf::Hair(_)
            | Bsdf::GltfPbr(_)
            | Bsdf::CoatedDiffuse(_) => {
                path.scatter(s, scene, &si, &bsdf, &frame, rng, c, &mut Unobserved);
                return;
            }
        };
        if waiting >= lanes {
            self.flush_class(class, s, paths, samples, c);
        }
    }

    /// Runs the chunk of one class.
    fn flush_class(
        &mut self,
        class: Class,
        s: &PathSettings,
        paths: &mut [PathState],
        samples: &mut [CameraSample],
        c: &mut Counters,
    ) {
        let isa = self.isa;
        match class {
            Class::Diffuse => flush_chunk(&mut self.diffuse, isa, s, paths, samples, c),
            Class::Smooth => flush_chunk(&mut self.smooth, isa, s, paths, samples, c),
            Class::Plastic => flush_chunk(&mut self.plastic, isa, s, paths, samples, c),
            Class::RoughPlastic => flush_chunk(&mut self.rough_plastic, isa, s, paths, samples, c),
            Class::Rough => flush_chunk(&mut self.rough, isa, s, paths, samples, c),
            Class::RoughDielectric => flush_chunk(&mut self.rough_dielectric, isa, s, paths, samples, c),
            Class::Principled => flush_chunk(&mut self.principled, isa, s, paths, samples, c),
        }
    }

    /// Runs the waiting vertices of every class and finishes their steps.
    pub fn flush(&mut self, s: &PathSettings, paths: &mut [PathState], samples: &mut [CameraSample], c: &mut Counters) {
        let isa = self.isa;
        flush_chunk(&mut self.diffuse, isa, s, paths, samples, c);
        flush_chunk(&mut self.smooth, isa, s, paths, samples, c);
        flush_chunk(&mut self.plastic, isa, s, paths, samples, c);
        flush_chunk(&mut self.rough_plastic, isa, s, paths, samples, c);
        flush_chunk(&mut self.rough, isa, s, paths, samples, c);
        flush_chunk(&mut self.rough_dielectric, isa, s, paths, samples, c);
        flush_chunk(&mut self.principled, isa, s, paths, samples, c);
    }
}

/// Next-event estimation's light sample at `p` and the light's probability, as
/// `PathState::scatter` draws it for a BSDF that is not delta.
#[inline]
fn light_sample(s: &PathSettings, scene: &World, p: Vec3, rng: &mut Sampler) -> Option<(LightSample, f32)> {
    if s.strategy == Strategy::Bsdf {
        return None;
    }
    sample_light(scene, p, rng).map(|(ls, pick_pmf, _)| (ls, pick_pmf))
}

/// The BSDF classes the lanes cover, one chunk each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    Diffuse,
    /// The smooth conductor and dielectric.
    Smooth,
    /// The smooth plastic.
    Plastic,
    /// The rough plastic.
    RoughPlastic,
    /// The rough conductor.
    Rough,
    /// The rough dielectric.
    RoughDielectric,
    Principled,
}

#[cfg(test)]
mod tests;
