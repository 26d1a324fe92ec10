//! Many paths advanced together (wavefront style): every live path's ray is traced in one
//! batch, every path then takes one step, the shadow rays those steps leave are traced in a
//! second batch, and the paths that ended drop out. The batches go through the single-ray
//! kernels one ray after another or through the world's interleaved batch traversal (several
//! rays in flight per thread), as the caller asks.
//!
//! Each path runs the steps of the one-path tracer ([`super::path::li`]) with the same
//! sampler in the same order, and each batch query answers as the single-ray query does, so
//! every path's radiance is the same bits either way (tests/wavefront.rs checks this).

use super::path::PathState;
use super::surface::transmittance_if_blocked;
use super::vertex_lanes::{LaneIsa, LaneStepper};
use super::Counters;
use crate::describe::PathSettings;
use crate::math::{Ray, Rgb};
use crate::sampling::Sampler;
use crate::world::{BatchTraversal, Hit, World};

/// A camera ray and the sampler of its pixel sample (already past the camera's dimensions).
pub struct CameraSample {
    pub ray: Ray,
    pub sampler: Sampler,
}

/// The radiance of every sample's path: `out[i]` is `path::li` of `samples[i]`, bit for bit.
///
/// Panics if the slices differ in length.
pub fn li_batch(
    s: &PathSettings,
    scene: &World,
    traversal: BatchTraversal,
    shading: PathShading,
    samples: &mut [CameraSample],
    out: &mut [Rgb],
    c: &mut Counters,
) {
    assert_eq!(samples.len(), out.len(), "li_batch: one radiance per sample");
    // Positions go in the low 32 bits of the grouping keys.
    assert!(samples.len() <= u32::MAX as usize, "li_batch: at most 2^32 - 1 samples at once");
    let mut paths: Vec<PathState> = samples.iter().map(|cs| PathState::new(s, &cs.ray)).collect();
    let mut live: Vec<usize> = (0..paths.len()).filter(|&i| paths[i].tracing).collect();
    let mut rays: Vec<Ray> = Vec::with_capacity(live.len());
    let mut hits: Vec<Option<Hit>> = Vec::with_capacity(live.len());
    let mut shadowed: Vec<usize> = Vec::with_capacity(live.len());
    let mut blocked: Vec<bool> = Vec::with_capacity(live.len());
    let mut stepping: Vec<Stepping> = Vec::with_capacity(live.len());
    let mut order: Vec<u64> = Vec::with_capacity(live.len());
    // Closest hits in packets for the camera rays only (the first wave): they are coherent;
    // later waves' rays scatter, and go through the single-ray kernels (same bits either way).
    let mut closest = traversal;
    // The BSDF classes' chunks (tens of KiB): made once, each emptied by every wave's flush.
    let mut stepper = (shading == PathShading::Lanes).then(|| LaneStepper::new(LaneIsa::detect()));
    while !live.is_empty() {
        // Camera rays that look through hidden emitters are traced one at a time (below).
        rays.clear();
        rays.extend(live.iter().map(|&i| &paths[i]).filter(|p| !p.traces_hidden_emitters(s)).map(|p| p.ray));
        hits.clear();
        hits.resize(rays.len(), None);
        scene.intersect_many(&rays, &mut hits, closest);
        if closest == BatchTraversal::Packets {
            closest = BatchTraversal::OneByOne;
        }
        c.rays += rays.len() as u64;

        // Paths step grouped by the instance they hit, so that consecutive steps run the same
        // material and light code (paths are independent: the order changes no path's bits).
        let mut batched = hits.iter();
        stepping.clear();
        order.clear();
        for &i in &live {
            let hit = if paths[i].traces_hidden_emitters(s) {
                paths[i].trace(s, scene, c)
            } else {
                *batched.next().expect("one batched hit per path traced in the batch")
            };
            // The instance hit (misses last) above the position: sorting plain integers costs
            // less than sorting the steps by a key (callgrind, Cornell box: 3.9 M instructions
            // against 5.0 M).
            order.push((hit.map_or(u32::MAX, |h| h.instance) as u64) << 32 | stepping.len() as u64);
            stepping.push(Stepping { path: i, hit });
        }
        order.sort_unstable();
        if let Some(stepper) = stepper.as_mut() {
            // The same loop, the covered BSDFs' arithmetic in lanes (`vertex_lanes`).
            for (k, &o) in order.iter().enumerate() {
                if scene.prefetch_hits {
                    prefetch_ahead(scene, &stepping, &order, k);
                }
                let st = &stepping[o as u32 as usize];
                stepper.step(s, scene, &mut paths, samples, st.path, st.hit, c);
            }
            stepper.flush(s, &mut paths, samples, c);
        } else if scene.prefetch_hits {
            for (k, &o) in order.iter().enumerate() {
                prefetch_ahead(scene, &stepping, &order, k);
                let st = &stepping[o as u32 as usize];
                paths[st.path].step(s, scene, st.hit, &mut samples[st.path].sampler, c);
            }
        } else {
            // A loop of its own: the check inside the loop above cost 2% on the Cornell box.
            for &o in &order {
                let st = &stepping[o as u32 as usize];
                paths[st.path].step(s, scene, st.hit, &mut samples[st.path].sampler, c);
            }
        }

        shadowed.clear();
        rays.clear();
        for &o in &order {
            let path = stepping[o as u32 as usize].path;
            if let Some(q) = &paths[path].shadow {
                shadowed.push(path);
                rays.push(q.ray);
            }
        }
        blocked.clear();
        blocked.resize(rays.len(), false);
        scene.occluded_many(&rays, &mut blocked, traversal);
        for (&i, &b) in shadowed.iter().zip(&blocked) {
            let path = &mut paths[i];
            if let Some(q) = path.shadow.take() {
                let visible = transmittance_if_blocked(scene, &q.ray, b, c);
                path.resolve_shadow(&q, visible);
            }
        }
        live.retain(|&i| paths[i].tracing);
    }
    for (o, p) in out.iter_mut().zip(&paths) {
        *o = p.l;
    }
}

/// Starts loading the hit data of the paths one and two places after the `k`-th in `order`:
/// the hit data of the paths a step or two ahead is fetched while this one steps (on large
/// meshes the vertices a hit reads are cache misses; no bits change).
#[inline]
fn prefetch_ahead(scene: &World, stepping: &[Stepping], order: &[u64], k: usize) {
    let ahead = |k: usize| order.get(k).and_then(|&o| stepping[o as u32 as usize].hit.as_ref());
    if let Some(h) = ahead(k + 2) {
        scene.prefetch_hit_indices(h);
    }
    if let Some(h) = ahead(k + 1) {
        scene.prefetch_hit_vertices(h);
    }
}

/// How a wave's paths take their steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathShading {
    /// One path after another through `PathState::step`.
    OneByOne,
    /// The vertices `vertex_lanes` covers in SIMD lanes (8 on AVX2, 16 on AVX-512, as
    /// `GLINT_SIMD` and the CPU allow), the others one by one.
    Lanes,
}

/// A path about to take its step, and the hit it takes it at.
struct Stepping {
    path: usize,
    hit: Option<Hit>,
}
