//! Unidirectional path tracing with next-event estimation and multiple importance
//! sampling (power heuristic), Russian roulette on the path throughput, and unbounded depth
//! by default. Depth counts path segments, as Mitsuba's `max_depth` does: 1 shows emitters
//! seen directly, 2 adds direct lighting, and so on.

use super::surface::{opacity, transmittance, MAX_MASK_PASSES};
use super::{camera_hit, shading, shadow_ray, spawn_ray, Counters};
use crate::describe::{PathSettings, Strategy};

/// The longest path, in segments, even when `max_depth` is unbounded: a hard ceiling so that
/// a path trapped between mirrors with a Russian roulette probability of 1 still ends. Light
/// carried by longer paths is lost (a bias below throughput^4096).
pub const MAX_PATH_DEPTH: u32 = 4096;
use crate::math::{Ray, Rgb};
use crate::sampling::{power_heuristic, Sampler};
use crate::world::World;

pub fn li(s: &PathSettings, scene: &World, camera_ray: &Ray, rng: &mut Sampler, c: &mut Counters) -> Rgb {
    let max_depth = s.max_depth.unwrap_or(MAX_PATH_DEPTH).min(MAX_PATH_DEPTH);
    if max_depth == 0 {
        return Rgb::BLACK;
    }
    let mut l = Rgb::BLACK;
    let mut throughput = Rgb::WHITE;
    // The product of eta^2 over the refractions so far: it undoes the 1/eta^2 radiance
    // scaling in `throughput` for Russian roulette, as pbrt and Mitsuba do, so that paths
    // inside glass are not killed for a scale factor that leaving the glass undoes.
    let mut eta_scale = 1.0f32;
    let mut ray = *camera_ray;
    // Density of the BSDF sample that produced `ray` (solid angle) and whether it was delta;
    // the camera ray behaves like a delta sample (nothing else could have produced it).
    let mut prev_pdf = 1.0f32;
    let mut prev_delta = true;
    let mut prev_p = ray.origin;
    let mut depth = 0u32; // segments traced so far
    let mut mask_passes = 0u32;

    loop {
        let hit = if depth == 0 {
            // Hidden emitters are looked through by the camera ray (and not counted as depth).
            camera_hit(scene, &ray, s.hide_emitters, c).map(|(r, h)| {
                ray = r;
                h
            })
        } else {
            c.rays += 1;
            scene.intersect(&ray)
        };
        depth += 1;
        let Some(hit) = hit else {
            if !(depth == 1 && s.hide_emitters) {
                for &li_idx in &scene.environment_lights {
                    let light = &scene.lights[li_idx as usize];
                    let le = light.environment(ray.dir);
                    if le.is_black() {
                        continue;
                    }
                    let w = emitter_weight(s.strategy, prev_delta, prev_pdf, || {
                        scene.light_pmf(li_idx) * light.pdf_li(prev_p, ray.dir, ray.origin, ray.dir)
                    });
                    l += throughput * le * w;
                }
            }
            break;
        };
        let si = scene.interaction(&ray, &hit);

        if let Some(li_idx) = si.light {
            if !(depth == 1 && s.hide_emitters) {
                let light = &scene.lights[li_idx as usize];
                let le = scene.emitted(&si, ray.dir);
                if !le.is_black() {
                    let w = emitter_weight(s.strategy, prev_delta, prev_pdf, || {
                        scene.light_pmf(li_idx) * light.pdf_li(prev_p, ray.dir, si.p, si.ng)
                    });
                    l += throughput * le * w;
                }
            }
        }
        // A masked surface lets the path through unscattered with probability 1 - opacity.
        // Passing is not a bounce: depth, the MIS state and the previous vertex stay as
        // they were (shadow rays from that vertex crossed the surface the same way).
        if scene.has_masks && mask_passes < MAX_MASK_PASSES {
            let o = opacity(scene, &si);
            if o < 1.0 && rng.next_f32() >= o {
                mask_passes += 1;
                depth -= 1;
                ray = spawn_ray(&si, ray.dir);
                continue;
            }
        }
        if depth >= max_depth {
            break;
        }

        let wo_world = -ray.dir;
        let (bsdf, frame) = shading(scene, &si, wo_world);
        let wo = frame.to_local(wo_world);

        // Next-event estimation: one light, chosen by the scene's light distribution.
        if s.strategy != Strategy::Bsdf && !bsdf.is_delta() {
            if let Some(dist) = &scene.light_distribution {
                // One 2D point picks the light (its first coordinate, rescaled) and the point
                // on it, as Mitsuba does: the sampler's 2D stratification then holds within
                // each light's share of the samples.
                let u = rng.next_2d();
                let pick = dist.sample(u[0]);
                let light = &scene.lights[pick.index];
                if let Some(ls) = light.sample_li(si.p, [pick.remapped, u[1]]) {
                    if ls.pdf > 0.0 && !ls.radiance.is_black() {
                        let wi = frame.to_local(ls.wi);
                        let f = bsdf.eval(wo, wi);
                        if !f.is_black() {
                            c.shadow_rays += 1;
                            let visible = transmittance(scene, &shadow_ray(&si, ls.wi, ls.dist), c);
                            if visible > 0.0 {
                                let light_pdf = pick.pmf * ls.pdf;
                                let w = if ls.delta || s.strategy == Strategy::Light {
                                    1.0
                                } else {
                                    power_heuristic(light_pdf, bsdf.pdf(wo, wi))
                                };
                                l += throughput * f * ls.radiance * (w * visible / light_pdf);
                            }
                        }
                    }
                }
            }
        }

        // Continue the path by sampling the BSDF.
        let u_lobe = rng.next_f32();
        let u = rng.next_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            break;
        };
        if bs.weight.is_black() {
            break;
        }
        throughput *= bs.weight;
        eta_scale *= bs.eta * bs.eta;
        let wi_world = frame.to_world(bs.wi);
        prev_pdf = bs.pdf;
        prev_delta = bs.delta;
        prev_p = si.p;
        ray = spawn_ray(&si, wi_world);

        if depth >= s.rr_depth {
            let q = match s.rr_probability {
                Some(p) => p,
                None => (throughput.max_component() * eta_scale).min(0.95),
            };
            if q <= 0.0 || rng.next_f32() >= q {
                break;
            }
            throughput = throughput / q;
        }
    }
    l
}

/// MIS weight of an emitter reached by a BSDF-sampled ray. `light_pdf` is only evaluated
/// when needed (it costs a distribution lookup).
#[inline]
fn emitter_weight(strategy: Strategy, prev_delta: bool, prev_pdf: f32, light_pdf: impl FnOnce() -> f32) -> f32 {
    if prev_delta {
        return 1.0;
    }
    match strategy {
        Strategy::Bsdf => 1.0,
        Strategy::Light => 0.0,
        Strategy::Mis => power_heuristic(prev_pdf, light_pdf()),
    }
}
