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
//! at each use), and no libm calls (the concentric disk's sine and cosine are polynomials in
//! both). `tests` below compares each lane with the one-path code on random and special
//! inputs; `tests/wavefront.rs` renders every test scene under every schedule and compares the
//! bits.
//!
//! Covered so far, without normal or bump maps: the Lambertian BSDF (`diffuse`: the BSDF of
//! the Cornell boxes, the bunny and the dragon of `bench/compare-mitsuba`), the smooth
//! conductor and dielectric (`smooth`), and the smooth plastic (`plastic`: its delta
//! reflection and cosine-sampled base; the rough plastic is not in lanes yet). Every other
//! BSDF steps through `PathState::scatter`, one path at a time.

mod columns;
mod diffuse;
mod lane_math;
mod plastic;
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
use crate::materials::{Bsdf, DiffuseMaterial, MaterialKind, ShadedBsdf, Texture};
#[cfg(target_arch = "x86_64")]
use crate::math::lanes::{Avx2x8, Avx512x16};
use crate::math::lanes::{Lanes, One, MAX_LANES};
use crate::math::{vec3, Rgb, Vec3};
use crate::sampling::Sampler;
use crate::world::{barycentric_point, Hit, ShapeRef, World};
use diffuse::DiffuseChunk;
use plastic::PlasticChunk;
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

/// Steps the paths of a wave as `PathState::step` does, the Lambertian vertices through the
/// lanes: each path reaches its vertex alone, then either scatters alone or waits in the chunk,
/// which runs when full and at [`LaneStepper::flush`].
pub(crate) struct LaneStepper {
    isa: LaneIsa,
    lanes: usize,
    /// One chunk per BSDF class: a chunk's lanes run one kernel.
    chunk: DiffuseChunk,
    smooth: SmoothChunk,
    plastic: PlasticChunk,
}

impl LaneStepper {
    pub fn new(isa: LaneIsa) -> LaneStepper {
        LaneStepper {
            isa,
            lanes: isa.lanes(),
            chunk: DiffuseChunk::default(),
            smooth: SmoothChunk::default(),
            plastic: PlasticChunk::default(),
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
                self.flush_diffuse(s, paths, samples, c);
            }
            return;
        }
        let Some(si) = path.arrive(s, scene, hit, rng, &mut Unobserved) else { return };
        let (bsdf, frame) = shading(scene, &si, -path.ray.dir);
        let smooth = match (&bsdf.bsdf, &bsdf.tilt) {
            (Bsdf::Conductor(m), None) => Some(Smooth::Conductor(*m)),
            (Bsdf::Dielectric(d), None) => Some(Smooth::Dielectric(*d)),
            _ => None,
        };
        if let Some(smooth) = smooth {
            // A delta BSDF: no light sample (`scatter` draws none either).
            self.smooth.push(i as u32, path, &si, &frame, smooth, rng);
            if self.smooth.is_full(self.lanes) {
                self.flush_smooth(s, paths, samples);
            }
            return;
        }
        if let (Bsdf::Plastic(plastic), None) = (&bsdf.bsdf, &bsdf.tilt) {
            // Only the smooth coating: a rough one steps through `scatter` below.
            if plastic.dist.is_none() {
                let light = self.light_sample(s, scene, si.p, rng);
                self.plastic.push(i as u32, path, &si, &frame, plastic, light, rng);
                if self.plastic.is_full(self.lanes) {
                    self.flush_plastic(s, paths, samples, c);
                }
                return;
            }
        }
        let Some(reflectance) = plain_diffuse(&bsdf) else {
            path.scatter(s, scene, &si, &bsdf, &frame, rng, c, &mut Unobserved);
            return;
        };
        let light = self.light_sample(s, scene, si.p, rng);
        self.chunk.push(i as u32, path, &si, &frame, reflectance, light, rng);
        if self.chunk.is_full(self.lanes) {
            self.flush_diffuse(s, paths, samples, c);
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

    /// Runs the waiting vertices of every class and finishes their steps.
    pub fn flush(&mut self, s: &PathSettings, paths: &mut [PathState], samples: &mut [CameraSample], c: &mut Counters) {
        self.flush_diffuse(s, paths, samples, c);
        self.flush_smooth(s, paths, samples);
        self.flush_plastic(s, paths, samples, c);
    }

    fn flush_plastic(
        &mut self,
        s: &PathSettings,
        paths: &mut [PathState],
        samples: &mut [CameraSample],
        c: &mut Counters,
    ) {
        if self.plastic.len == 0 {
            return;
        }
        self.plastic.run(self.isa, s.strategy);
        for lane in 0..self.plastic.len {
            let i = self.plastic.path[lane] as usize;
            self.plastic.finish(lane, &mut paths[i], s, &mut samples[i].sampler, c);
        }
        self.plastic.len = 0;
    }

    fn flush_smooth(&mut self, s: &PathSettings, paths: &mut [PathState], samples: &mut [CameraSample]) {
        if self.smooth.len == 0 {
            return;
        }
        self.smooth.run(self.isa);
        for lane in 0..self.smooth.len {
            let i = self.smooth.path[lane] as usize;
            self.smooth.finish(lane, &mut paths[i], s, &mut samples[i].sampler);
        }
        self.smooth.len = 0;
    }

    fn flush_diffuse(
        &mut self,
        s: &PathSettings,
        paths: &mut [PathState],
        samples: &mut [CameraSample],
        c: &mut Counters,
    ) {
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
