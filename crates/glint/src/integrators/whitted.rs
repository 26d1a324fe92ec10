//! Whitted-style ray tracing (the paper's section 3.1): direct light from every light with
//! hard shadows (one sample per area light per camera sample), perfect mirror reflection,
//! and refraction weighted by the exact dielectric Fresnel term with total internal
//! reflection, up to a maximum depth. Depth 1 traces camera and shadow rays only. Masked
//! surfaces (cut-outs) let rays through as in the other integrators: a traced ray passes
//! with probability 1 - opacity, a shadow ray carries the product of 1 - opacity.

use super::surface::{passes_mask, transmittance};
use super::{shading, shadow_ray, spawn_ray, Counters};
use crate::bsdf::{fresnel_dielectric, reflect_local, refract_local};
use crate::describe::WhittedSettings;
use crate::materials::{Bsdf, Dielectric};
use crate::math::{Ray, Rgb};
use crate::sampling::Sampler;
use crate::world::{SurfaceInteraction, World};

pub fn li(s: &WhittedSettings, scene: &World, ray: &Ray, rng: &mut Sampler, c: &mut Counters) -> Rgb {
    // The recursion of the paper, run on an explicit stack so that any `max_depth` fits:
    // each frame is a hit waiting for the radiance of a reflected or refracted ray. Rays are
    // traced depth first, reflection before refraction, and every frame adds its children's
    // radiance with the same operations in the same order as the recursive form, so the
    // random numbers and the rounding (and so the image) are those of that form.
    let mut stack: Vec<Frame> = Vec::new();
    let mut ray = *ray;
    let mut budget = MAX_WHITTED_RAYS;
    'trace: loop {
        let depth = stack.len() as u32 + 1;
        budget -= 1;
        let mut value = match shade(s, scene, &ray, rng, c, depth) {
            Node::Done(l) => l,
            // Out of rays: this hit keeps its emission and direct light only.
            Node::Branch(frame, _) if budget == 0 => frame.l,
            Node::Branch(frame, child) => {
                stack.push(frame);
                ray = child;
                continue 'trace;
            }
        };
        // Hand the finished radiance to the frames waiting for it.
        while let Some(frame) = stack.last_mut() {
            match frame.waiting {
                Waiting::Reflection { reflect, reflectance, refraction } => {
                    frame.l += reflect * value * reflectance;
                    if let Some(r) = refraction.filter(|_| budget > 0) {
                        frame.waiting = Waiting::Refraction { transmit: r.transmit, scale: r.scale };
                        ray = r.ray;
                        continue 'trace;
                    }
                }
                Waiting::Refraction { transmit, scale } => frame.l += transmit * value * scale,
                Waiting::Delta { weight } => frame.l += weight * value,
            }
            value = frame.l;
            stack.pop();
        }
        return value;
    }
}

/// The most rays one camera ray may lead to. Glass doubles the rays at every bounce, so a deep
/// `max_depth` would otherwise mean 2^depth rays per pixel; past the budget a hit keeps only
/// its emission and direct light. Depth 13 in glass everywhere fits.
pub const MAX_WHITTED_RAYS: u32 = 1 << 14;

/// A hit whose radiance so far is `l`, waiting for the radiance of a child ray.
struct Frame {
    l: Rgb,
    waiting: Waiting,
}

#[derive(Clone, Copy)]
enum Waiting {
    /// A dielectric's reflected ray, with its refracted ray to follow (unless total
    /// internal reflection).
    Reflection {
        reflect: Rgb,
        reflectance: f32,
        refraction: Option<Refraction>,
    },
    Refraction {
        transmit: Rgb,
        scale: f32,
    },
    /// A mirror's (or other delta BSDF's) sampled ray.
    Delta {
        weight: Rgb,
    },
}

#[derive(Clone, Copy)]
struct Refraction {
    ray: Ray,
    transmit: Rgb,
    scale: f32,
}

enum Node {
    /// The radiance along the ray, with nothing more to trace.
    Done(Rgb),
    /// Emission and direct light so far, and the first child ray to trace.
    Branch(Frame, Ray),
}

/// Everything the recursive form did at one hit before (and without) recursing.
fn shade(s: &WhittedSettings, scene: &World, ray: &Ray, rng: &mut Sampler, c: &mut Counters, depth: u32) -> Node {
    let mut l = Rgb::BLACK;
    let Some(si) = scattering_hit(scene, ray, rng, c, &mut l) else {
        return Node::Done(escaped(s, scene, ray, l));
    };
    let wo_world = -ray.dir;
    let (bsdf, frame) = shading(scene, &si, wo_world);
    let wo = frame.to_local(wo_world);
    let can_recurse = depth < s.max_depth;

    if let Bsdf::Dielectric(Dielectric { eta, reflect, transmit }) = bsdf.bsdf {
        if can_recurse {
            let fr = fresnel_dielectric(wo.z, eta);
            let r_dir = frame.to_world(reflect_local(wo));
            let refraction = (fr.reflectance < 1.0).then(|| Refraction {
                ray: spawn_ray(&si, frame.to_world(refract_local(wo, &fr))),
                transmit,
                scale: (1.0 - fr.reflectance) / (fr.eta_ti * fr.eta_ti),
            });
            let waiting = Waiting::Reflection { reflect, reflectance: fr.reflectance, refraction };
            return Node::Branch(Frame { l, waiting }, spawn_ray(&si, r_dir));
        }
    } else if bsdf.is_delta() {
        // Mirrors (and other delta BSDFs): follow the sampled delta direction.
        if can_recurse {
            if let Some(bs) = bsdf.sample(wo, rng.next_f32(), rng.next_2d()) {
                let dir = frame.to_world(bs.wi);
                let waiting = Waiting::Delta { weight: bs.weight };
                return Node::Branch(Frame { l, waiting }, spawn_ray(&si, dir));
            }
        }
    } else {
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
            // Exactly 0 or 1 where no mask is on the way, and times 1 keeps the bits.
            let visible = transmittance(scene, &shadow_ray(&si, ls.wi, ls.dist), c);
            if visible > 0.0 {
                l += f * ls.radiance / ls.pdf * visible;
            }
        }
    }
    Node::Done(l)
}

/// The first surface along `ray` that scatters it, after adding to `l` what the surfaces on
/// the way emit: a masked surface lets the ray through unscattered with probability
/// 1 - opacity (one random number per masked surface met; passing is not a bounce). `None`
/// when the ray escapes.
fn scattering_hit(
    scene: &World,
    ray: &Ray,
    rng: &mut Sampler,
    c: &mut Counters,
    l: &mut Rgb,
) -> Option<SurfaceInteraction> {
    let mut ray = *ray;
    let mut passes = 0;
    loop {
        c.rays += 1;
        let hit = scene.intersect(&ray)?;
        let si = scene.interaction(&ray, &hit);
        *l += scene.emitted(&si, ray.dir);
        if passes_mask(scene, &si, ray.dir, passes, rng) {
            passes += 1;
            ray = spawn_ray(&si, ray.dir);
            continue;
        }
        return Some(si);
    }
}

/// What an escaping ray brings, added to `l`: the environment lights, or the background.
fn escaped(s: &WhittedSettings, scene: &World, ray: &Ray, l: Rgb) -> Rgb {
    if scene.environment_lights.is_empty() {
        return l + Rgb::from_array(s.background);
    }
    scene.environment_lights.iter().fold(l, |a, &i| a + scene.lights[i as usize].environment(ray.dir))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::BvhSplit;
    use crate::assemble::WorldBuilder;
    use crate::camera::{Camera, FovAxis};
    use crate::geometry::quad_mesh;
    use crate::lights::AreaEmission;
    use crate::lights::LightSelection;
    use crate::materials::{
        ConductorMaterial, DielectricMaterial, DiffuseMaterial, MaskMaterial, Material, MaterialKind, Texture,
    };
    use crate::math::{vec3, Transform, Vec3};
    use crate::sampling::SamplerKind;
    use std::sync::Arc;

    /// The recursive form this module had before it was made iterative: the reference.
    fn li_recursive(s: &WhittedSettings, scene: &World, ray: &Ray, rng: &mut Sampler, c: &mut Counters) -> Rgb {
        trace(s, scene, ray, rng, c, 1)
    }

    fn trace(s: &WhittedSettings, scene: &World, ray: &Ray, rng: &mut Sampler, c: &mut Counters, depth: u32) -> Rgb {
        let mut l = Rgb::BLACK;
        let Some(si) = scattering_hit(scene, ray, rng, c, &mut l) else {
            return escaped(s, scene, ray, l);
        };
        let wo_world = -ray.dir;
        let (bsdf, frame) = shading(scene, &si, wo_world);
        let wo = frame.to_local(wo_world);
        let can_recurse = depth < s.max_depth;

        if let Bsdf::Dielectric(Dielectric { eta, reflect, transmit }) = bsdf.bsdf {
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
        } else if bsdf.is_delta() {
            // Mirrors (and other delta BSDFs): follow the sampled delta direction.
            if can_recurse {
                if let Some(bs) = bsdf.sample(wo, rng.next_f32(), rng.next_2d()) {
                    let dir = frame.to_world(bs.wi);
                    l += bs.weight * trace(s, scene, &spawn_ray(&si, dir), rng, c, depth + 1);
                }
            }
        } else {
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
                let visible = transmittance(scene, &shadow_ray(&si, ls.wi, ls.dist), c);
                if visible > 0.0 {
                    l += f * ls.radiance / ls.pdf * visible;
                }
            }
        }
        l
    }

    /// A room with a glass ball, a mirror ball, a mirror wall and an area light.
    fn scene(width: u32, height: u32) -> World {
        let mut b = WorldBuilder::new(BvhSplit::Sah);
        let white = b.add_material(Material::new(
            "white",
            MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(0.7)) }),
            true,
        ));
        let mirror = b.add_material(Material::new(
            "mirror",
            MaterialKind::Conductor(ConductorMaterial {
                eta: Rgb::BLACK,
                k: Rgb::WHITE,
                specular: Rgb::splat(0.9),
                roughness: None,
            }),
            true,
        ));
        let glass = b.add_material(Material::new(
            "glass",
            MaterialKind::Dielectric(DielectricMaterial::smooth(1.5, Rgb::WHITE, Rgb::WHITE)),
            false,
        ));
        let quad = |b: &mut WorldBuilder, p: [Vec3; 4], m: u32, e: Option<AreaEmission>| {
            let mesh = Arc::new(quad_mesh(p, BvhSplit::Sah));
            b.add_mesh_instance(&mesh, &Transform::IDENTITY, false, m, e, false).unwrap();
        };
        let (a, z) = (2.0, -2.0);
        quad(&mut b, [vec3(-a, 0.0, a), vec3(a, 0.0, a), vec3(a, 0.0, z), vec3(-a, 0.0, z)], white, None);
        quad(&mut b, [vec3(-a, 0.0, z), vec3(a, 0.0, z), vec3(a, 3.0, z), vec3(-a, 3.0, z)], mirror, None);
        let light = b.black_material();
        let e = Some(AreaEmission::constant(Rgb::splat(10.0)));
        quad(
            &mut b,
            [vec3(-0.5, 2.9, -0.5), vec3(-0.5, 2.9, 0.5), vec3(0.5, 2.9, 0.5), vec3(0.5, 2.9, -0.5)],
            light,
            e,
        );
        b.add_sphere(vec3(-0.6, 0.6, 0.0), 0.6, &Transform::IDENTITY, glass, None, false).unwrap();
        b.add_sphere(vec3(0.8, 0.5, -0.5), 0.5, &Transform::IDENTITY, mirror, None, false).unwrap();
        let to_world = Transform::look_at(vec3(0.0, 1.5, 4.0), vec3(0.0, 0.8, 0.0), Vec3::Y).unwrap();
        b.finish(Camera::new(to_world, width, height, 45.0, FovAxis::Y), LightSelection::Power).unwrap()
    }

    fn radiance(
        f: fn(&WhittedSettings, &World, &Ray, &mut Sampler, &mut Counters) -> Rgb,
        s: &WhittedSettings,
        scene: &World,
    ) -> (Vec<u32>, u64) {
        let mut c = Counters::default();
        let mut bits = Vec::new();
        for y in 0..scene.camera.height {
            for x in 0..scene.camera.width {
                let pixel = (y * scene.camera.width + x) as u64;
                for sample in 0..2 {
                    let mut rng = Sampler::new(SamplerKind::Independent, 7, pixel, sample);
                    let ray = scene.camera.generate_ray(x as f32 + rng.next_f32(), y as f32 + rng.next_f32(), [0.5; 2]);
                    bits.extend(f(s, scene, &ray, &mut rng, &mut c).to_array().map(f32::to_bits));
                }
            }
        }
        (bits, c.rays + c.shadow_rays)
    }

    #[test]
    fn iterative_form_is_bit_identical_to_the_recursive_one() {
        let scene = scene(40, 30);
        for max_depth in [1, 2, 5, 12] {
            let s = WhittedSettings { max_depth, background: [0.1, 0.2, 0.3] };
            let (iterative, rays_i) = radiance(li, &s, &scene);
            let (recursive, rays_r) = radiance(li_recursive, &s, &scene);
            assert_eq!(rays_i, rays_r, "depth {max_depth}: different ray counts");
            assert!(iterative == recursive, "depth {max_depth}: images differ");
            assert!(iterative.iter().any(|&b| b != 0), "depth {max_depth}: black image");
        }
    }

    /// A diffuse floor at z = 0 lit by a small downward light at `light_z`, a black sheet of
    /// opacity 0.5 at `sheet_z` (if any), seen from `eye_z` straight above.
    fn sheet_scene(sheet_z: Option<f32>, eye_z: f32, light_z: f32) -> World {
        let mut b = WorldBuilder::new(BvhSplit::Sah);
        let floor = b.add_material(Material::new(
            "floor",
            MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(0.5)) }),
            true,
        ));
        // Counter-clockwise from above (normal +z), the light's the other way round.
        let quad = |b: &mut WorldBuilder, a: f32, z: f32, m: u32, e: Option<AreaEmission>| {
            let mut p = [vec3(-a, -a, z), vec3(a, -a, z), vec3(a, a, z), vec3(-a, a, z)];
            if e.is_some() {
                p.reverse();
            }
            let mesh = Arc::new(quad_mesh(p, BvhSplit::Sah));
            b.add_mesh_instance(&mesh, &Transform::IDENTITY, false, m, e, false).unwrap();
        };
        quad(&mut b, 20.0, 0.0, floor, None);
        let light = b.black_material();
        quad(&mut b, 0.3, light_z, light, Some(AreaEmission::constant(Rgb::splat(20.0))));
        if let Some(z) = sheet_z {
            let black = MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::BLACK) });
            let sheet = b.add_material(Material::new(
                "sheet",
                MaterialKind::Mask(MaskMaterial {
                    opacity: Texture::Constant(Rgb::splat(0.5)),
                    nested: Box::new(black),
                }),
                true,
            ));
            quad(&mut b, 20.0, z, sheet, None);
        }
        let to_world = Transform::look_at(vec3(0.0, 0.0, eye_z), vec3(0.0, 0.01, 0.0), Vec3::Y).unwrap();
        b.finish(Camera::new(to_world, 12, 12, 30.0, FovAxis::Y), LightSelection::Power).unwrap()
    }

    /// Every sample's radiance (mean of the channels), `spp` samples per pixel.
    fn samples(scene: &World, spp: u32) -> Vec<f64> {
        let s = WhittedSettings { max_depth: 4, background: [0.0; 3] };
        let mut c = Counters::default();
        let mut out = Vec::new();
        for y in 0..scene.camera.height {
            for x in 0..scene.camera.width {
                let pixel = (y * scene.camera.width + x) as u64;
                for sample in 0..spp {
                    let mut rng = Sampler::new(SamplerKind::Independent, 3, pixel, sample);
                    let ray = scene.camera.generate_ray(x as f32 + 0.5, y as f32 + 0.5, [0.5; 2]);
                    let l = li(&s, scene, &ray, &mut rng, &mut c);
                    out.push(l.to_array().iter().map(|&v| v as f64).sum::<f64>() / 3.0);
                }
            }
        }
        out
    }

    fn mean_and_error(v: &[f64]) -> (f64, f64) {
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    }

    #[test]
    fn a_half_opaque_sheet_halves_the_light_its_shadow_rays_cross() {
        // The camera under the sheet: shadow rays from the floor cross it and carry its
        // transmittance 0.5, so every sample is exactly half (the same light points are
        // sampled with and without the sheet).
        let plain = samples(&sheet_scene(None, 0.5, 2.0), 4);
        let masked = samples(&sheet_scene(Some(1.0), 0.5, 2.0), 4);
        assert!(plain.iter().any(|&v| v > 0.01), "the floor is lit");
        for (p, q) in plain.iter().zip(&masked) {
            assert!((q - 0.5 * p).abs() <= 1e-6 * p.abs() + 1e-9, "{q} is not half of {p}");
        }
    }

    #[test]
    fn a_half_opaque_sheet_halves_what_the_camera_sees_through_it() {
        // The light under the sheet, the camera above: camera rays pass with probability 0.5
        // and the black sheet returns nothing when they do not. Before masks were read here
        // the sheet was opaque and the image black.
        let (a, ea) = mean_and_error(&samples(&sheet_scene(None, 3.0, 0.8), 64));
        let (b, eb) = mean_and_error(&samples(&sheet_scene(Some(1.5), 3.0, 0.8), 64));
        assert!(a > 0.01, "the floor is lit: {a}");
        let tol = 4.0 * (eb * eb + 0.25 * ea * ea).sqrt();
        assert!((b - 0.5 * a).abs() < tol, "{b} vs half of {a} (tolerance {tol})");
    }

    #[test]
    fn very_deep_recursion_fits_a_small_thread_stack() {
        // Two facing mirrors with the camera between them: the ray bounces until max_depth.
        let mut b = WorldBuilder::new(BvhSplit::Sah);
        let mirror = b.add_material(Material::new(
            "mirror",
            MaterialKind::Conductor(ConductorMaterial {
                eta: Rgb::BLACK,
                k: Rgb::WHITE,
                specular: Rgb::WHITE,
                roughness: None,
            }),
            true,
        ));
        for z in [-1.0f32, 1.0] {
            let p = [vec3(-5.0, -5.0, z), vec3(5.0, -5.0, z), vec3(5.0, 5.0, z), vec3(-5.0, 5.0, z)];
            let mesh = Arc::new(quad_mesh(p, BvhSplit::Sah));
            b.add_mesh_instance(&mesh, &Transform::IDENTITY, false, mirror, None, false).unwrap();
        }
        let to_world = Transform::look_at(Vec3::ZERO, vec3(0.0, 0.0, 1.0), Vec3::Y).unwrap();
        let scene = b.finish(Camera::new(to_world, 1, 1, 10.0, FovAxis::Y), LightSelection::Power).unwrap();
        let s = WhittedSettings { max_depth: 3000, background: [0.0; 3] };
        let rays = std::thread::Builder::new()
            .stack_size(64 * 1024)
            .spawn(move || {
                let mut c = Counters::default();
                let mut rng = Sampler::new(SamplerKind::Independent, 1, 0, 0);
                let ray = scene.camera.generate_ray(0.5, 0.5, [0.5; 2]);
                let _ = li(&s, &scene, &ray, &mut rng, &mut c);
                c.rays
            })
            .unwrap()
            .join()
            .expect("no stack overflow");
        assert_eq!(rays, 3000);
    }
}
