//! White furnace tests: scenes whose radiance is known everywhere.
//! - Albedo-1 diffuse objects (an open box with a ball in it) inside a uniform environment
//!   Le reflect exactly what they receive, so every pixel is Le.
//! - Inside a closed enclosure whose walls (and a box within) all emit Le and reflect with
//!   albedo a, radiance is Le + a·L everywhere, so L = Le / (1 - a).
//!
//! Every path strategy and Russian roulette setting must agree with the exact value, each
//! whole-image and 4×4-block mean within a critical number of standard errors.

mod common;

use common::scenes::{add_square, camera, diffuse, emission, render_with};
use common::stats::{check_constant_image, constant_image_comparisons, z_critical, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::geometry::cube_mesh;
use glint::integrators::{Integrator, PathSettings, Strategy};
use glint::lights::LightSelection;
use glint::materials::{DiffuseMaterial, Material, MaterialKind, Texture};
use glint::math::{vec3, Rgb, Transform, Vec3};
use glint::world::World;
use std::sync::Arc;

const SIZE: u32 = 16;
const BLOCK: usize = 4;
const SPP: u32 = 256;
/// For the `#[ignore]`d long runs, 32 times the samples: 5.7 times smaller errors.
const LONG_SPP: u32 = 8192;

/// Every strategy, each with three kinds of Russian roulette: the default (throughput-based
/// from depth 5), throughput-based from the first bounce, and a fixed survival probability
/// `p` from the first bounce. A path's weight then grows as (albedo/p)^bounces, so `p` must be
/// at least the albedo for the variance (and so the standard error) to be finite.
fn integrators(p: f32) -> Vec<(String, Integrator)> {
    let mut v = Vec::new();
    for strategy in [Strategy::Mis, Strategy::Light, Strategy::Bsdf] {
        let base = PathSettings { strategy, ..Default::default() };
        v.push((format!("{strategy:?}, default roulette"), Integrator::Path(base.clone())));
        v.push((
            format!("{strategy:?}, roulette from depth 1"),
            Integrator::Path(PathSettings { rr_depth: 1, ..base.clone() }),
        ));
        v.push((
            format!("{strategy:?}, roulette p={p} from depth 1"),
            Integrator::Path(PathSettings { rr_depth: 1, rr_probability: Some(p), ..base }),
        ));
    }
    v
}

fn check_all(scene: &World, exact: f64, roulette_p: f32, spp: u32) {
    let integrators = integrators(roulette_p);
    let k =
        z_critical(FALSE_ALARM, integrators.len() * constant_image_comparisons(SIZE as usize, SIZE as usize, BLOCK));
    let mut failures = Vec::new();
    for (i, (name, integrator)) in integrators.iter().enumerate() {
        let out = render_with(scene, integrator, spp, 100 + i as u64);
        failures.extend(check_constant_image(name, &out, exact, BLOCK, k));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Radiance of the environment around the open box.
const ENV: f32 = 0.5;

fn open_box_in_environment() -> World {
    let le = ENV;
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let white = diffuse(&mut b, "white", Rgb::WHITE);
    // A box open at the top (paths bounce many times inside) with a ball in it.
    add_square(&mut b, vec3(0.0, -1.0, 0.0), 1, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(0.0, 0.0, -1.0), 2, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(0.0, 0.0, 1.0), 2, -1.0, 1.0, white, None);
    add_square(&mut b, vec3(-1.0, 0.0, 0.0), 0, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(1.0, 0.0, 0.0), 0, -1.0, 1.0, white, None);
    b.add_sphere(vec3(0.2, -0.5, 0.1), 0.5, &Transform::IDENTITY, white, None, false).unwrap();
    b.add_constant_environment(Rgb::splat(le));
    let cam = camera(vec3(0.5, 3.0, 2.5), vec3(0.0, -0.4, 0.0), Vec3::Y, 45.0, SIZE, SIZE);
    b.finish(cam, LightSelection::Power).unwrap()
}

/// The open box with a ball and a free-standing sheet of Mitsuba's `principledthin` made a
/// white Lambertian transmitter (`diff_trans` 2, no specular transmission: the one setting
/// of the model that keeps all energy): light crosses them from either face.
fn open_box_with_thin_transmitters() -> World {
    use glint::materials::PrincipledThinRates;
    use glint::materials::{PrincipledThinMaterial, ScalarTexture};
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let white = diffuse(&mut b, "white", Rgb::WHITE);
    let c = ScalarTexture::Constant;
    let sheet = b.add_material(Material::new(
        "sheet",
        MaterialKind::PrincipledThin(PrincipledThinMaterial {
            base_color: Texture::Constant(Rgb::WHITE),
            roughness: c(0.5),
            anisotropic: c(0.0),
            spec_trans: c(0.0),
            eta: c(1.5),
            spec_tint: c(0.0),
            sheen: c(0.0),
            sheen_tint: c(0.0),
            flatness: c(0.0),
            diff_trans: c(2.0),
            rates: PrincipledThinRates::default(),
        }),
        true,
    ));
    add_square(&mut b, vec3(0.0, -1.0, 0.0), 1, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(0.0, 0.0, -1.0), 2, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(-1.0, 0.0, 0.0), 0, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(1.0, 0.0, 0.0), 0, -1.0, 1.0, sheet, None);
    add_square(&mut b, vec3(0.0, -0.3, 0.4), 2, 1.0, 0.5, sheet, None);
    b.add_sphere(vec3(-0.3, -0.5, -0.3), 0.4, &Transform::IDENTITY, sheet, None, false).unwrap();
    b.add_constant_environment(Rgb::splat(ENV));
    let cam = camera(vec3(0.5, 3.0, 2.5), vec3(0.0, -0.4, 0.0), Vec3::Y, 45.0, SIZE, SIZE);
    b.finish(cam, LightSelection::Power).unwrap()
}

/// Emission and albedo of the enclosure.
const LE: f32 = 1.0;
const ALBEDO: f32 = 0.5;

fn emitting_enclosure() -> World {
    let (le, a) = (LE, ALBEDO);
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    // One-sided, so that a wrongly oriented surface would show up black.
    let wall = b.add_material(Material::new(
        "wall",
        MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(a)) }),
        false,
    ));
    // A sphere facing inwards around a box: two lights of different kinds, so light
    // selection matters. No concave edges: there, sampling lights alone has infinite
    // variance (the 1/d² of two surfaces meeting) and standard errors would mean nothing.
    b.add_sphere(Vec3::ZERO, 2.5, &Transform::IDENTITY, wall, emission(le), true).unwrap();
    let xf = Transform::translate(vec3(0.3, -0.4, 0.2))
        .then_after(&Transform::rotate(vec3(1.0, 2.0, 0.5), 30.0))
        .then_after(&Transform::scale(Vec3::splat(0.6)).unwrap());
    b.add_mesh_instance(&Arc::new(cube_mesh(BvhSplit::Sah)), &xf, false, wall, emission(le), false).unwrap();
    let cam = camera(vec3(-0.8, 0.8, -1.8), vec3(0.2, -0.3, 0.0), Vec3::Y, 70.0, SIZE, SIZE);
    let scene = b.finish(cam, LightSelection::Power).unwrap();
    assert_eq!(scene.lights().len(), 2);
    scene
}

#[test]
fn albedo_one_objects_in_a_uniform_environment_look_like_the_environment() {
    check_all(&open_box_in_environment(), ENV as f64, 0.95, SPP);
}

#[test]
fn thin_white_transmitters_in_a_uniform_environment_look_like_the_environment() {
    check_all(&open_box_with_thin_transmitters(), ENV as f64, 0.95, SPP);
}

#[test]
fn emitting_enclosure_of_albedo_a_has_radiance_le_over_one_minus_a() {
    check_all(&emitting_enclosure(), (LE / (1.0 - ALBEDO)) as f64, 0.6, SPP);
}

#[test]
#[ignore = "long: run with `cargo test -- --ignored`"]
fn furnaces_hold_with_many_samples() {
    check_all(&open_box_in_environment(), ENV as f64, 0.95, LONG_SPP);
    check_all(&emitting_enclosure(), (LE / (1.0 - ALBEDO)) as f64, 0.6, LONG_SPP);
}
