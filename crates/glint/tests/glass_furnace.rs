//! Lossless specular objects in a uniform environment Le are invisible: smooth glass
//! (η = 1.5, a sphere and a slab), thin glass, and a perfect mirror (conductor with η = 0,
//! k = 1, reflectance 1) render Le everywhere. For glass this needs the radiance scaling
//! 1/η² on refraction, which cancels on entering and leaving; a camera inside glass sees
//! the scaled radiance itself, η² Le (radiance / η² is what is conserved).
//! Without Russian roulette every path's weight is exactly 1 (up to f32 rounding), so each
//! pixel must match; with roulette the image and block means must match statistically.

mod common;

use common::scenes::{camera, render_with};
use common::stats::{check_constant_image, constant_image_comparisons, z_critical, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::geometry::cube_mesh;
use glint::integrators::{Integrator, PathSettings, Strategy};
use glint::lights::LightSelection;
use glint::materials::{ConductorMaterial, DielectricMaterial, DielectricSurface, Material, MaterialKind};
use glint::math::{vec3, Rgb, Transform, Vec3};
use glint::world::World;
use std::sync::Arc;

const LE: f32 = 0.7;
const ETA: f32 = 1.5;
const SIZE: u32 = 16;
const BLOCK: usize = 4;
/// Relative error of f32 path weights that multiply to one: a few ulps (6e-8) per bounce
/// over at most a few dozen bounces.
const FLOAT_TOLERANCE: f32 = 1e-5;

fn glass() -> MaterialKind {
    MaterialKind::Dielectric(DielectricMaterial::smooth(ETA, Rgb::WHITE, Rgb::WHITE))
}

fn scene_with(kind: MaterialKind, eye: Vec3) -> World {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let m = b.add_material(Material::new("specular", kind, false));
    b.add_sphere(vec3(0.0, 0.0, 0.0), 1.0, &Transform::IDENTITY, m, None, false).unwrap();
    // A slab beside it: flat faces and edges, where total internal reflection happens.
    let slab = Transform::translate(vec3(1.3, -0.6, 0.8))
        .then_after(&Transform::rotate(vec3(0.3, 1.0, 0.2), 35.0))
        .then_after(&Transform::scale(vec3(0.8, 0.15, 0.6)).unwrap());
    b.add_mesh_instance(&Arc::new(cube_mesh(BvhSplit::Sah)), &slab, false, m, None, false).unwrap();
    b.add_constant_environment(Rgb::splat(LE));
    b.finish(camera(eye, vec3(0.4, -0.2, 0.3), Vec3::Y, 60.0, SIZE, SIZE), LightSelection::Power).unwrap()
}

const OUTSIDE: Vec3 = Vec3 { x: 0.5, y: 1.5, z: -3.5 };

fn without_roulette(strategy: Strategy) -> Integrator {
    Integrator::Path(PathSettings { strategy, rr_depth: u32::MAX, ..Default::default() })
}

/// Every pixel equal to `exact` (no roulette), then image and block means (roulette on),
/// for every strategy.
fn check(label: &str, scene: &World, exact: f32) {
    let strategies = [Strategy::Mis, Strategy::Light, Strategy::Bsdf];
    let mut failures = Vec::new();
    for s in strategies {
        let out = render_with(scene, &without_roulette(s), 16, 1);
        let worst = out.image.pixels.iter().map(|p| (p.r - exact).abs() / exact).fold(0.0f32, f32::max);
        if worst > FLOAT_TOLERANCE {
            failures.push(format!("{label}, {s:?}, no roulette: a pixel is off by {worst:.2e} (relative)"));
        }
    }
    let k = z_critical(FALSE_ALARM, strategies.len() * constant_image_comparisons(SIZE as usize, SIZE as usize, BLOCK));
    for (i, s) in strategies.into_iter().enumerate() {
        let integrator = Integrator::Path(PathSettings { strategy: s, rr_depth: 1, ..Default::default() });
        let out = render_with(scene, &integrator, 256, 10 + i as u64);
        failures.extend(check_constant_image(&format!("{label}, {s:?}, roulette"), &out, exact as f64, BLOCK, k));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn glass_in_a_furnace_is_invisible() {
    check("glass", &scene_with(glass(), OUTSIDE), LE);
}

#[test]
fn thin_glass_in_a_furnace_is_invisible() {
    let thin = MaterialKind::Dielectric(DielectricMaterial {
        surface: DielectricSurface::Thin,
        ..DielectricMaterial::smooth(ETA, Rgb::WHITE, Rgb::WHITE)
    });
    check("thin glass", &scene_with(thin, OUTSIDE), LE);
}

#[test]
fn perfect_mirror_in_a_furnace_is_invisible() {
    let mirror = MaterialKind::Conductor(ConductorMaterial {
        eta: Rgb::BLACK,
        k: Rgb::WHITE,
        specular: Rgb::WHITE,
        roughness: None,
    });
    check("mirror", &scene_with(mirror, OUTSIDE), LE);
}

#[test]
fn inside_glass_the_furnace_radiance_is_eta_squared_le() {
    // The camera sits inside the sphere and sees only its inner surface.
    let scene = scene_with(glass(), vec3(0.1, 0.2, -0.3));
    check("inside glass", &scene, ETA * ETA * LE);
}

/// Russian roulette must judge a path by its throughput without the 1/η² radiance scaling
/// of refraction (pbrt's and Mitsuba's "eta scale"): that factor is undone when the path
/// leaves the glass. Judged by the scaled throughput, a path inside glass survives with
/// probability 1/η² instead of 0.95 (the cap), and each survivor's weight grows by η²: one
/// such roulette alone gives a single sample a relative variance of η² − 1. With the eta
/// scale every roulette in this furnace survives with 0.95, so even ten of them on one path
/// give less than 0.95^-10 − 1 = 0.67. The test takes the pixels that see the sphere and
/// requires their mean relative variance per sample below half of η² − 1.
#[test]
fn russian_roulette_ignores_the_radiance_scaling_of_refraction() {
    let scene = scene_with(glass(), OUTSIDE);
    let integrator = Integrator::Path(PathSettings { strategy: Strategy::Bsdf, rr_depth: 1, ..Default::default() });
    let spp = 256;
    let out = render_with(&scene, &integrator, spp, 3);
    let variance = out.variance.as_ref().unwrap();
    let cam = scene.camera();
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for y in 0..SIZE as usize {
        for x in 0..SIZE as usize {
            let ray = cam.generate_ray(x as f32 + 0.5, y as f32 + 0.5, [0.5, 0.5]);
            let sees_sphere = scene
                .intersect(&ray)
                .is_some_and(|h| scene.instances()[h.instance as usize].shape == glint::world::ShapeRef::Sphere(0));
            if sees_sphere {
                // Variance of one sample = variance of the mean × samples.
                sum += variance.get(x, y).r as f64 * spp as f64 / (LE as f64 * LE as f64);
                n += 1;
            }
        }
    }
    assert!(n >= 20, "the sphere covers only {n} pixels");
    let mean = sum / n as f64;
    let bound = 0.5 * (ETA as f64 * ETA as f64 - 1.0);
    assert!(mean < bound, "relative variance per sample {mean:.3} on the sphere; roulette inside glass must not count 1/eta^2 (bound {bound:.3})");
}
