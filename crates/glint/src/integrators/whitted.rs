//! Whitted-style ray tracing (the paper's section 3.1): direct light from every light with
//! hard shadows (one sample per area light per camera sample), perfect mirror reflection,
//! and refraction weighted by the exact dielectric Fresnel term with total internal
//! reflection, up to a maximum depth. Depth 1 traces camera and shadow rays only.

use super::{shading, shadow_ray, spawn_ray, Counters};
use crate::bsdf::{fresnel_dielectric, reflect_local, refract_local, Bsdf};
use crate::describe::WhittedSettings;
use crate::math::{Ray, Rgb};
use crate::sampling::Sampler;
use crate::world::World;

pub fn li(s: &WhittedSettings, scene: &World, ray: &Ray, rng: &mut Sampler, c: &mut Counters) -> Rgb {
    trace(s, scene, ray, rng, c, 1)
}

fn trace(s: &WhittedSettings, scene: &World, ray: &Ray, rng: &mut Sampler, c: &mut Counters, depth: u32) -> Rgb {
    c.rays += 1;
    let Some(hit) = scene.intersect(ray) else {
        if scene.environment_lights.is_empty() {
            return Rgb::from_array(s.background);
        }
        return scene
            .environment_lights
            .iter()
            .fold(Rgb::BLACK, |a, &i| a + scene.lights[i as usize].environment(ray.dir));
    };
    let si = scene.interaction(ray, &hit);
    let wo_world = -ray.dir;
    let mut l = Rgb::BLACK;
    if let Some(li) = si.light {
        l += scene.lights[li as usize].emitted(si.ng, ray.dir);
    }
    let (bsdf, frame) = shading(scene, &si, wo_world);
    let wo = frame.to_local(wo_world);
    let can_recurse = depth < s.max_depth;

    match bsdf {
        Bsdf::Dielectric { eta, reflect, transmit } => {
            if can_recurse {
                let fr = fresnel_dielectric(wo.z, eta);
                let r_dir = frame.to_world(reflect_local(wo));
                l += reflect * trace(s, scene, &spawn_ray(&si, r_dir), rng, c, depth + 1) * fr.reflectance;
                if fr.reflectance < 1.0 {
                    let t_dir = frame.to_world(refract_local(wo, &fr));
                    let scale = (1.0 - fr.reflectance) / (fr.eta_ti * fr.eta_ti);
                    l += transmit * trace(s, scene, &spawn_ray(&si, t_dir), rng, c, depth + 1) * scale;
                }
            }
        }
        _ if bsdf.is_delta() => {
            // Mirrors (and other delta BSDFs): follow the sampled delta direction.
            if can_recurse {
                if let Some(bs) = bsdf.sample(wo, rng.next_f32(), rng.next_2d()) {
                    let dir = frame.to_world(bs.wi);
                    l += bs.weight * trace(s, scene, &spawn_ray(&si, dir), rng, c, depth + 1);
                }
            }
        }
        _ => {
            // Diffuse and glossy: direct light only, one sample per light.
            for light in &scene.lights {
                let Some(ls) = light.sample_li(si.p, rng.next_2d()) else {
                    continue;
                };
                if ls.pdf <= 0.0 || ls.radiance.is_black() {
                    continue;
                }
                let f = bsdf.eval(wo, frame.to_local(ls.wi));
                if f.is_black() {
                    continue;
                }
                c.shadow_rays += 1;
                if !scene.occluded(&shadow_ray(&si, ls.wi, ls.dist)) {
                    l += f * ls.radiance / ls.pdf;
                }
            }
        }
    }
    l
}
