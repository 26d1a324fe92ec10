//! Direct lighting against closed forms. A Lambertian plane of albedo ρ (the only surface
//! that reflects; lights are black behind) is seen through a tiny field of view, so each
//! image shows one point x, whose radiance is exactly ρ/π · E(x):
//! - disk and tilted rectangle lights: E from Lambert's polygon formula (the disk mesh is a
//!   polygon; the formula itself is checked against π L R²/(h² + R²));
//! - sphere lights: E = π L (r/d)² at a point facing the centre;
//! - point light: E = I cos θ / d²; directional light: E = E⊥ cos θ.
//!
//! Area lights are checked with every strategy, delta lights with those that sample lights;
//! the direct integrator with light samples only, BSDF samples only, and both.

mod common;

use common::analytic::{disk_irradiance, polygon_irradiance, sphere_irradiance};
use common::scenes::{add_quad, add_square, black, camera, diffuse, emission, path, render_with};
use common::stats::{image_estimate, z_critical, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::geometry::disk_mesh;
use glint::integrators::{DirectSettings, Integrator, Strategy};
use glint::lights::Light;
use glint::lights::LightSelection;
use glint::math::{vec3, Rgb, Transform, Vec3, PI};
use glint::world::World;
use std::sync::Arc;

const ALBEDO: f32 = 0.8;
const SPP: u32 = 16384;
/// Estimates with (almost) no variance, as under delta lights, can only be as exact as f32
/// arithmetic: ~100 roundings of 6e-8 along the path stay under this relative bound.
const FLOAT_FLOOR: f64 = 2e-5;
const AREA_STRATEGIES: [Strategy; 3] = [Strategy::Mis, Strategy::Light, Strategy::Bsdf];
const DELTA_STRATEGIES: [Strategy; 2] = [Strategy::Mis, Strategy::Light];

/// A builder holding the receiving plane y = 0 (normal +y); the camera looks at the origin.
fn receiver() -> WorldBuilder {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let plane = diffuse(&mut b, "plane", Rgb::splat(ALBEDO));
    add_square(&mut b, Vec3::ZERO, 1, 1.0, 50.0, plane, None);
    b
}

fn finish(b: WorldBuilder) -> World {
    // 0.001° across 4 pixels: the pixels see the plane within ~1e-4 of the origin.
    let cam = camera(vec3(2.5, 0.6, 1.2), Vec3::ZERO, Vec3::Y, 0.001, 4, 4);
    b.finish(cam, LightSelection::Power).unwrap()
}

/// Renders `scene` with each strategy and compares the mean radiance with ρ/π · E.
fn check(label: &str, scene: &World, irradiance: f64, strategies: &[Strategy], failures: &mut Vec<String>, k: f64) {
    let integrators: Vec<(String, Integrator)> = strategies.iter().map(|&s| (format!("{s:?}"), path(s))).collect();
    check_with(label, scene, irradiance, &integrators, failures, k);
}

fn check_with(
    label: &str,
    scene: &World,
    irradiance: f64,
    integrators: &[(String, Integrator)],
    failures: &mut Vec<String>,
    k: f64,
) {
    let exact = ALBEDO as f64 / PI as f64 * irradiance;
    for (i, (name, integrator)) in integrators.iter().enumerate() {
        let out = render_with(scene, integrator, SPP, 7 + i as u64);
        let e = image_estimate(&out, 0);
        println!("{label} {name}: {:.6e} ± {:.2e}, exact {exact:.6e}", e.mean, e.se);
        if (e.mean - exact).abs() > k * e.se + FLOAT_FLOOR * exact {
            failures.push(format!(
                "{label}, {name}: {:.6} ± {:.6}, exact {exact:.6} ({:.1} standard errors)",
                e.mean,
                e.se,
                (e.mean - exact) / e.se
            ));
        }
    }
}

/// The direct integrator with (emitter_samples, bsdf_samples) of light sampling only, BSDF
/// sampling only, and uneven counts of both.
fn direct_integrators() -> Vec<(String, Integrator)> {
    [(4, 0), (0, 4), (1, 3), (3, 1)]
        .into_iter()
        .map(|(emitter_samples, bsdf_samples)| {
            let s = DirectSettings { emitter_samples, bsdf_samples, hide_emitters: false };
            (format!("direct {emitter_samples}/{bsdf_samples}"), Integrator::Direct(s))
        })
        .collect()
}

fn report(failures: Vec<String>) {
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn polygon_formula_matches_the_disk_closed_form() {
    let (r, h) = (0.5f32, 1.0f32);
    let n = 4096;
    let ring: Vec<Vec3> = (0..n)
        .map(|i| {
            let phi = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
            vec3(r * phi.cos() as f32, h, r * phi.sin() as f32)
        })
        .collect();
    let polygon = polygon_irradiance(Vec3::ZERO, Vec3::Y, &ring, 1.0);
    let disk = disk_irradiance(1.0, r as f64, h as f64);
    // A 4096-gon has (2π/n)²/6 ≈ 4e-7 less area than the disk; the rest is f32 input.
    assert!((polygon / disk - 1.0).abs() < 2e-6, "{polygon} vs {disk}");
}

#[test]
fn disk_light_above_the_point() {
    let (le, r, h) = (3.0f32, 0.5f32, 1.0f32);
    let mut b = receiver();
    let m = black(&mut b);
    // The unit disk faces +z; turned to face down, scaled and lifted.
    let xf = Transform::translate(vec3(0.0, h, 0.0))
        .then_after(&Transform::rotate(Vec3::X, 90.0))
        .then_after(&Transform::scale(Vec3::splat(r)).unwrap());
    let disk = disk_mesh(BvhSplit::Sah);
    // Triangle i of the fan is (centre, rim i, rim i + 1): the rim in order.
    let ring: Vec<Vec3> = disk.positions.iter().skip(1).step_by(3).map(|&p| xf.point(p)).collect();
    assert!(xf.vector(Vec3::Z).y < 0.0, "the disk must face the plane");
    b.add_mesh_instance(&Arc::new(disk), &xf, false, m, emission(le), false).unwrap();
    let scene = finish(b);
    let e = polygon_irradiance(Vec3::ZERO, Vec3::Y, &ring, le as f64);
    // The polygon is within 0.2% of the disk (a check that the set-up is what it claims).
    assert!((e / disk_irradiance(le as f64, r as f64, h as f64) - 1.0).abs() < 2e-3);
    let mut failures = Vec::new();
    check("disk", &scene, e, &AREA_STRATEGIES, &mut failures, z_critical(FALSE_ALARM, AREA_STRATEGIES.len()));
    report(failures);
}

#[test]
fn tilted_rectangle_light_off_axis() {
    let le = 2.0f32;
    let c = vec3(-0.6, 0.9, 0.3);
    let (e1, e2) = (vec3(0.5, 0.0, 0.1), vec3(0.1, 0.3, 0.4));
    let mut corners = [c - e1 - e2, c + e1 - e2, c + e1 + e2, c - e1 + e2];
    // Emission leaves along (p1 - p0) × (p2 - p0): make it face the origin.
    if (corners[1] - corners[0]).cross(corners[2] - corners[0]).dot(-c) < 0.0 {
        corners.reverse();
    }
    assert!(corners.iter().all(|p| p.y > 0.0), "the light must be above the plane");
    let mut b = receiver();
    let m = black(&mut b);
    add_quad(&mut b, corners, m, emission(le));
    let scene = finish(b);
    let e = polygon_irradiance(Vec3::ZERO, Vec3::Y, &corners, le as f64);
    let mut failures = Vec::new();
    check("rectangle", &scene, e, &AREA_STRATEGIES, &mut failures, z_critical(FALSE_ALARM, AREA_STRATEGIES.len()));
    report(failures);
}

#[test]
fn sphere_lights_facing_the_point() {
    let le = 4.0f32;
    // The last is 1e-7 sr across: 1 - cos θmax cancels to nothing in f32 there (and BSDF
    // sampling all but never hits it, so it is checked with the strategies that sample lights).
    let configs =
        [(0.5f32, 2.0f32, &AREA_STRATEGIES[..]), (0.8, 1.2, &AREA_STRATEGIES[..]), (0.01, 50.0, &DELTA_STRATEGIES[..])];
    let k = z_critical(FALSE_ALARM, configs.iter().map(|c| c.2.len()).sum());
    let mut failures = Vec::new();
    for (r, d, strategies) in configs {
        let mut b = receiver();
        let m = black(&mut b);
        b.add_sphere(vec3(0.0, d, 0.0), r, &Transform::IDENTITY, m, emission(le), false).unwrap();
        let scene = finish(b);
        let e = sphere_irradiance(le as f64, r as f64, d as f64);
        check(&format!("sphere r={r} d={d}"), &scene, e, strategies, &mut failures, k);
    }
    report(failures);
}

/// A large rectangle just above the point: sampled by solid angle, where area sampling has
/// its 1/d² spikes.
#[test]
fn rectangle_light_close_overhead() {
    let le = 1.5f32;
    let (x0, x1, z0, z1, h) = (-0.7f32, 1.1f32, -0.4f32, 0.9f32, 0.3f32);
    // Facing down: (p1 - p0) × (p2 - p0) = -y.
    let corners = [vec3(x0, h, z0), vec3(x1, h, z0), vec3(x1, h, z1), vec3(x0, h, z1)];
    let mut b = receiver();
    let m = black(&mut b);
    add_quad(&mut b, corners, m, emission(le));
    let scene = finish(b);
    let e = polygon_irradiance(Vec3::ZERO, Vec3::Y, &corners, le as f64);
    let mut failures = Vec::new();
    check(
        "close rectangle",
        &scene,
        e,
        &AREA_STRATEGIES,
        &mut failures,
        z_critical(FALSE_ALARM, AREA_STRATEGIES.len()),
    );
    report(failures);
}

/// The direct integrator's sample counts change the noise, never the mean: a sphere and a
/// rectangle light, each with four (emitter_samples, bsdf_samples) settings.
#[test]
fn direct_integrator_sample_counts_are_unbiased() {
    let direct = direct_integrators();
    let k = z_critical(FALSE_ALARM, 2 * direct.len());
    let mut failures = Vec::new();
    let (le, r, d) = (4.0f32, 0.5f32, 1.5f32);
    let mut b = receiver();
    let m = black(&mut b);
    b.add_sphere(vec3(0.0, d, 0.0), r, &Transform::IDENTITY, m, emission(le), false).unwrap();
    check_with("sphere", &finish(b), sphere_irradiance(le as f64, r as f64, d as f64), &direct, &mut failures, k);
    let corners = [vec3(-0.5, 0.8, -0.2), vec3(0.4, 0.8, -0.2), vec3(0.4, 0.8, 0.6), vec3(-0.5, 0.8, 0.6)];
    let mut b = receiver();
    let m = black(&mut b);
    add_quad(&mut b, corners, m, emission(le));
    let e = polygon_irradiance(Vec3::ZERO, Vec3::Y, &corners, le as f64);
    check_with("rectangle", &finish(b), e, &direct, &mut failures, k);
    report(failures);
}

/// With hide_emitters, a camera ray looks through an area light (as Mitsuba's does) and sees
/// the wall behind it, lit by a point light; without, it sees the light.
#[test]
fn hidden_emitters_are_looked_through() {
    let (le, intensity) = (5.0f32, 2.0f32);
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let wall = diffuse(&mut b, "wall", Rgb::splat(ALBEDO));
    add_square(&mut b, vec3(0.0, 0.0, -2.0), 2, 1.0, 10.0, wall, None);
    let m = black(&mut b);
    // One-sided, facing the camera: nothing of it reaches the wall.
    add_square(&mut b, Vec3::ZERO, 2, 1.0, 0.5, m, emission(le));
    let light = vec3(0.5, 0.0, -1.0);
    b.add_light(Light::Point { position: light, intensity: Rgb::splat(intensity) });
    let scene = b.finish(camera(vec3(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 0.001, 4, 4), LightSelection::Power).unwrap();
    let to_light = light - vec3(0.0, 0.0, -2.0);
    let wall_radiance = ALBEDO as f64 / PI as f64 * intensity as f64 * (to_light.z / to_light.length()) as f64
        / to_light.length_squared() as f64;
    let direct = |hide_emitters| Integrator::Direct(DirectSettings { hide_emitters, ..DirectSettings::default() });
    let path_tracer =
        |hide_emitters| Integrator::Path(glint::integrators::PathSettings { hide_emitters, ..Default::default() });
    let cases = [
        ("direct, hidden", direct(true), wall_radiance),
        ("path, hidden", path_tracer(true), wall_radiance),
        ("direct, shown", direct(false), le as f64),
        ("path, shown", path_tracer(false), le as f64),
    ];
    let k = z_critical(FALSE_ALARM, cases.len());
    for (name, integrator, expected) in cases {
        // The only noise is which of the two lights is picked for the wall.
        let e = image_estimate(&render_with(&scene, &integrator, 1024, 1), 0);
        assert!(
            (e.mean - expected).abs() <= k * e.se + FLOAT_FLOOR * expected,
            "{name}: {} ± {} instead of {expected}",
            e.mean,
            e.se
        );
    }
}

#[test]
fn point_light() {
    let intensity = 2.0f32;
    let p = vec3(0.4, 1.1, -0.3);
    let mut b = receiver();
    b.add_light(Light::Point { position: p, intensity: Rgb::splat(intensity) });
    let scene = finish(b);
    let d = p.length() as f64;
    let e = intensity as f64 * (p.y as f64 / d) / (d * d);
    let mut failures = Vec::new();
    check("point", &scene, e, &DELTA_STRATEGIES, &mut failures, z_critical(FALSE_ALARM, DELTA_STRATEGIES.len()));
    report(failures);
}

#[test]
fn directional_light() {
    let irradiance = 1.5f32;
    let dir = vec3(0.3, -1.0, 0.2).normalize();
    let mut b = receiver();
    b.add_directional(dir, Rgb::splat(irradiance));
    let scene = finish(b);
    let e = irradiance as f64 * -dir.y as f64;
    let mut failures = Vec::new();
    check("directional", &scene, e, &DELTA_STRATEGIES, &mut failures, z_critical(FALSE_ALARM, DELTA_STRATEGIES.len()));
    report(failures);
}
