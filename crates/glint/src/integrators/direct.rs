//! Direct illumination only, as Mitsuba 3's `direct` integrator: emitters seen along the
//! camera ray, plus at its first hit `emitter_samples` light samples and `bsdf_samples` BSDF
//! samples, combined by the power heuristic with the sample counts (Veach's multi-sample
//! form: a strategy's density is weighted by how many samples it takes). A strategy given no
//! samples gets weight zero, so 0 light samples is pure BSDF sampling and 0 BSDF samples pure
//! light sampling.
//!
//! One deliberate difference: Mitsuba 3.9.1 gives each of its `emitter_samples` samples of a
//! delta light (point, spot, directional) the weight 1 instead of 1/emitter_samples, so such
//! lights come out emitter_samples times too bright there; here every light sample counts
//! 1/emitter_samples.

use super::surface::{opacity, passes_mask, transmittance, MAX_MASK_PASSES};
use super::{camera_hit, shading, shadow_ray, spawn_ray, Counters};
use crate::describe::DirectSettings;
use crate::math::{Ray, Rgb};
use crate::sampling::{power_heuristic, Sampler};
use crate::world::World;

pub fn li(s: &DirectSettings, scene: &World, camera_ray: &Ray, rng: &mut Sampler, c: &mut Counters) -> Rgb {
    let mut l = Rgb::BLACK;
    let mut camera_ray = *camera_ray;
    let mut passes = 0;
    // The camera ray passes a masked surface with probability 1 - opacity (adding what the
    // surface emits), as the path tracer does.
    let (ray, si) = loop {
        let Some((ray, hit)) = camera_hit(scene, &camera_ray, s.hide_emitters, c) else {
            if s.hide_emitters {
                return l;
            }
            return scene
                .environment_lights
                .iter()
                .fold(l, |l, &i| l + scene.lights[i as usize].environment(camera_ray.dir));
        };
        let si = scene.interaction(&ray, &hit);
        // Only reached when emitters are shown (`camera_hit` looks through them otherwise).
        l += scene.emitted(&si, ray.dir);
        if passes_mask(scene, &si, ray.dir, passes, rng) {
            passes += 1;
            camera_ray = spawn_ray(&si, ray.dir);
            continue;
        }
        break (ray, si);
    };
    let wo_world = -ray.dir;
    let (bsdf, frame) = shading(scene, &si, wo_world);
    let wo = frame.to_local(wo_world);
    let (n_e, n_b) = (s.emitter_samples as f32, s.bsdf_samples as f32);

    // Light sampling (not for BSDFs that only reflect in delta directions).
    if !bsdf.is_delta() && scene.can_choose_lights() {
        for _ in 0..s.emitter_samples {
            // The light and the point on it from one 2D point (see path.rs).
            let u = rng.next_2d();
            let Some(choice) = scene.choose_light(si.p, u[0]) else {
                continue;
            };
            let pick_pmf = choice.pmf;
            let Some(ls) = scene.sample_chosen(&choice, si.p, u[1]) else {
                continue;
            };
            if !(ls.pdf > 0.0) || ls.radiance.is_black() {
                continue;
            }
            let wi = frame.to_local(ls.wi);
            let f = bsdf.eval(wo, wi);
            if f.is_black() {
                continue;
            }
            c.shadow_rays += 1;
            let visible = transmittance(scene, &shadow_ray(&si, ls.wi, ls.dist), c);
            if !(visible > 0.0) {
                continue;
            }
            let light_pdf = pick_pmf * ls.pdf;
            let w = if ls.delta { 1.0 } else { power_heuristic(n_e * light_pdf, n_b * bsdf.pdf(wo, wi)) };
            l += f * ls.radiance * (w * visible / (n_e * light_pdf));
        }
    }

    // BSDF sampling: the emitter (or sky) each sampled ray reaches.
    for _ in 0..s.bsdf_samples {
        let u_lobe = rng.next_f32();
        let Some(bs) = bsdf.sample(wo, u_lobe, rng.next_2d()) else {
            continue;
        };
        if bs.weight.is_black() {
            continue;
        }
        let wi_world = frame.to_world(bs.wi);
        let ray = spawn_ray(&si, wi_world);
        c.rays += 1;
        // The weight of a light reached with light density `light_pdf` (zero after a delta
        // sample, which light sampling cannot produce).
        let weight = |light_pdf: f32| {
            let w = if bs.delta { 1.0 } else { power_heuristic(n_b * bs.pdf, n_e * light_pdf) };
            bs.weight * (w / n_b)
        };
        // Masked surfaces on the way pass a fraction 1 - opacity of what lies behind them.
        let (mut ray, mut through) = (ray, 1.0f32);
        for _ in 0..=MAX_MASK_PASSES {
            match scene.intersect(&ray) {
                Some(hit) => {
                    let sj = scene.interaction(&ray, &hit);
                    if let Some(li_idx) = sj.light {
                        let le = scene.emitted(&sj, ray.dir);
                        if !le.is_black() {
                            let light_pdf = scene.light_pdf(si.p, li_idx, sj.prim, ray.dir, sj.p, sj.ng);
                            l += weight(light_pdf) * le * through;
                        }
                    }
                    through *= 1.0 - if scene.has_masks { opacity(scene, &sj, ray.dir) } else { 1.0 };
                    if !(through > 0.0) {
                        break;
                    }
                    ray = spawn_ray(&sj, ray.dir);
                }
                None => {
                    for &li_idx in &scene.environment_lights {
                        let light = &scene.lights[li_idx as usize];
                        let le = light.environment(ray.dir);
                        if le.is_black() {
                            continue;
                        }
                        let light_pdf = scene.light_pdf(si.p, li_idx, 0, ray.dir, ray.origin, ray.dir);
                        l += weight(light_pdf) * le * through;
                    }
                    break;
                }
            }
        }
    }
    l
}
