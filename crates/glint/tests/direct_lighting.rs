//! Direct lighting against closed forms. A Lambertian plane of albedo ρ (the only surface
//! that reflects; lights are black behind) is seen through a tiny field of view, so each
//! image shows one point x, whose radiance is exactly ρ/π · E(x):
//! - disk and tilted rectangle lights: E from Lambert's polygon formula (the disk mesh is a
//!   polygon; the formula itself is checked against π L R²/(h² + R²));
//! - sphere lights: E = π L (r/d)² at a point facing the centre;
//! - point light: E = I cos θ / d²; directional light: E = E⊥ cos θ.
//!
//! Area lights are checked with every strategy, delta lights with those that sample lights.

mod common;

use common::analytic::{disk_irradiance, polygon_irradiance, sphere_irradiance};
use common::scenes::{add_quad, add_square, black, camera, diffuse, emission, path, render_with};
use common::stats::{image_estimate, z_critical, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::build::WorldBuilder;
use glint::geometry::disk_mesh;
use glint::integrators::Strategy;
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
    let exact = ALBEDO as f64 / PI as f64 * irradiance;
    for (i, &s) in strategies.iter().enumerate() {
        let out = render_with(scene, &path(s), SPP, 7 + i as u64);
        let e = image_estimate(&out, 0);
        println!("{label} {s:?}: {:.6} ± {:.6}, exact {exact:.6}", e.mean, e.se);
        if (e.mean - exact).abs() > k * e.se + FLOAT_FLOOR * exact {
            failures.push(format!(
                "{label}, {s:?}: {:.6} ± {:.6}, exact {exact:.6} ({:.1} standard errors)",
                e.mean,
                e.se,
                (e.mean - exact) / e.se
            ));
        }
    }
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
    let configs = [(0.5f32, 2.0f32), (0.8, 1.2)];
    let k = z_critical(FALSE_ALARM, configs.len() * AREA_STRATEGIES.len());
    let mut failures = Vec::new();
    for (r, d) in configs {
        let mut b = receiver();
        let m = black(&mut b);
        b.add_sphere(vec3(0.0, d, 0.0), r, &Transform::IDENTITY, m, emission(le), false).unwrap();
        let scene = finish(b);
        let e = sphere_irradiance(le as f64, r as f64, d as f64);
        check(&format!("sphere r={r} d={d}"), &scene, e, &AREA_STRATEGIES, &mut failures, k);
    }
    report(failures);
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
