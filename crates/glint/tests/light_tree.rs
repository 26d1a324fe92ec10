//! The light BVH (`LightSelection::Tree`): at random shading points of a scene with many
//! lights of every bounded kind (spheres, rectangles, one-sided and two-sided meshes, disks
//! whose triangles are leaves of their own, cylinders, point and spot lights) and infinite ones beside them,
//! - the probabilities of all lights sum to one, and each light the tree samples is given
//!   exactly the probability `light_pmf_at` recomputes for it (what MIS uses when a
//!   BSDF-sampled ray hits that light), and the lights are drawn with those probabilities
//!   (a chi-square test);
//! - the direct integrator with emitter samples only, BSDF samples only and both agree
//!   within Šidák-corrected standard errors on image and block means (area lights only:
//!   BSDF samples never reach delta lights), so no light that reaches a point is ever given
//!   probability zero there.

mod common;

use common::bsdf_check::chi2_test;
use common::scenes::{add_quad, camera, diffuse, render_with};
use common::stats::{block_estimates, image_estimate, sidak, z_critical, Estimate, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::integrators::{DirectSettings, Integrator};
use glint::lights::{by_triangle, AreaEmission, Light, LightSelection};
use glint::materials::{Bitmap, Texture};
use glint::math::{rgb, vec3, Frame, Rgb, Transform, Vec3};
use glint::sampling::Rng;
use glint::world::World;

fn lit(radiance: Rgb, two_sided: bool) -> Option<AreaEmission> {
    Some(AreaEmission { radiance: Texture::Constant(radiance), two_sided })
}

/// A floor under a grid of small lights of every bounded kind with powers over 3 orders of
/// magnitude, some facing away, and (with `sky`) a dim constant environment. Without
/// `deltas`, spheres stand where the point and spot lights would (BSDF samples never reach
/// those).
fn many_lights(sky: bool, deltas: bool) -> World {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let floor = diffuse(&mut b, "floor", Rgb::splat(0.7));
    let lamp = b.black_material();
    let a = 4.0;
    add_quad(&mut b, [vec3(-a, 0.0, a), vec3(a, 0.0, a), vec3(a, 0.0, -a), vec3(-a, 0.0, -a)], floor, None);
    let mut rng = Rng::new(42, 7);
    for i in 0..6 {
        for j in 0..6 {
            let (x, z) = (-3.0 + 1.2 * i as f32, -3.0 + 1.2 * j as f32);
            let y = 0.6 + 1.5 * rng.next_f32();
            let power = 10f32.powf(3.0 * rng.next_f32() - 1.0);
            let c = rgb(power, power * (0.5 + rng.next_f32()), power * 0.7);
            match (i * 6 + j) % 7 {
                0 => b.add_sphere(vec3(x, y, z), 0.08, &Transform::IDENTITY, lamp, lit(c, false), false).unwrap(),
                // Facing down, facing up (away from the floor), and two-sided.
                k @ 1..=3 => {
                    let s = 0.12;
                    let mut q =
                        [vec3(x - s, y, z - s), vec3(x + s, y, z - s), vec3(x + s, y, z + s), vec3(x - s, y, z + s)];
                    if k == 2 {
                        q.reverse();
                    }
                    let tilt = vec3(0.0, 0.05 * (k as f32 - 2.0), 0.0);
                    q[0] += tilt;
                    q[1] += tilt;
                    let quad = glint::geometry::quad_mesh(q, BvhSplit::Sah);
                    b.add_mesh_instance(
                        &std::sync::Arc::new(quad),
                        &Transform::IDENTITY,
                        false,
                        lamp,
                        lit(c, k == 3),
                        false,
                    )
                    .unwrap();
                }
                4 => b
                    .add_cylinder(
                        vec3(x, y, z),
                        vec3(x + 0.2, y, z),
                        0.04,
                        &Transform::IDENTITY,
                        lamp,
                        lit(c, false),
                        false,
                    )
                    .unwrap(),
                5 | 6 if !deltas => {
                    b.add_sphere(vec3(x, y, z), 0.05, &Transform::IDENTITY, lamp, lit(c, false), false).unwrap()
                }
                5 => b.add_light(Light::Point { position: vec3(x, y, z), intensity: c * 0.05 }),
                _ => {
                    let dir = vec3(0.3 * rng.next_f32(), -1.0, 0.2);
                    b.add_light(Light::Spot {
                        position: vec3(x, y, z),
                        frame: Frame::from_normal(dir.normalize()),
                        intensity: c * 0.2,
                        cutoff: 0.5,
                        beam: 0.35,
                        gltf_falloff: false,
                    })
                }
            }
        }
    }
    // Two disks (triangle fans: the tree holds each triangle as a leaf), one facing down,
    // one tilted and two-sided.
    let disk = std::sync::Arc::new(glint::geometry::disk_mesh(BvhSplit::Sah));
    let down = Transform::translate(vec3(-1.0, 2.2, 0.5))
        .then_after(&Transform::rotate(Vec3::X, 90.0))
        .then_after(&Transform::scale(vec3(0.4, 0.4, 0.4)).unwrap());
    b.add_mesh_instance(&disk, &down, false, lamp, lit(rgb(3.0, 2.5, 2.0), false), false).unwrap();
    let tilted = Transform::translate(vec3(1.5, 1.4, -0.8))
        .then_after(&Transform::rotate(vec3(1.0, 0.0, 1.0), 60.0))
        .then_after(&Transform::scale(vec3(0.3, 0.3, 0.3)).unwrap());
    // Textured, in a checker of 150x contrast: the tree weighs each triangle by the texture
    // read over it (a floor keeps every triangle's probability above zero).
    let checker = Texture::Checkerboard {
        color0: rgb(0.02, 0.04, 0.06),
        color1: rgb(3.0, 2.0, 1.0),
        uv_scale: [3.0, 3.0],
        uv_offset: [0.0, 0.0],
    };
    let textured = Some(AreaEmission { radiance: checker, two_sided: true });
    b.add_mesh_instance(&disk, &tilted, false, lamp, textured, false).unwrap();
    if sky {
        b.add_constant_environment(Rgb::splat(0.05));
    }
    let cam = camera(vec3(0.0, 5.0, 5.5), vec3(0.0, 0.0, 0.0), Vec3::Y, 60.0, 32, 32);
    b.finish(cam, LightSelection::Tree).unwrap()
}

/// `LightSelection::Auto` is the tree on a textured emitting mesh split by triangle and with
/// many lights, and power otherwise.
#[test]
fn auto_selection_is_the_tree_where_it_has_something_to_choose_by() {
    let disk = std::sync::Arc::new(glint::geometry::disk_mesh(BvhSplit::Sah));
    let world = |lights: &[&str]| {
        let mut b = WorldBuilder::new(BvhSplit::Sah);
        let lamp = b.black_material();
        for (k, which) in lights.iter().enumerate() {
            let at = Transform::translate(vec3(k as f32, 1.0, 0.0));
            match *which {
                "sphere" => {
                    b.add_sphere(
                        vec3(k as f32, 1.0, 0.0),
                        0.1,
                        &Transform::IDENTITY,
                        lamp,
                        lit(Rgb::WHITE, false),
                        false,
                    )
                    .unwrap();
                }
                "disk" => {
                    b.add_mesh_instance(&disk, &at, false, lamp, lit(Rgb::WHITE, false), false).unwrap();
                }
                "textured disk" => {
                    let radiance = Texture::Checkerboard {
                        color0: Rgb::WHITE,
                        color1: Rgb::splat(2.0),
                        uv_scale: [1.0, 1.0],
                        uv_offset: [0.0, 0.0],
                    };
                    let emission = Some(AreaEmission { radiance, two_sided: false });
                    b.add_mesh_instance(&disk, &at, false, lamp, emission, false).unwrap();
                }
                "bitmap disk" => {
                    let pixels = (0..8).map(|k| Rgb::splat(if k == 5 { 30.0 } else { 0.5 })).collect();
                    let image = std::sync::Arc::new(Bitmap { width: 4, height: 2, pixels });
                    let radiance = Texture::Bitmap { image, uv_scale: [1.0, 1.0], uv_offset: [0.0, 0.0] };
                    let emission = Some(AreaEmission { radiance, two_sided: false });
                    b.add_mesh_instance(&disk, &at, false, lamp, emission, false).unwrap();
                }
                "sky" => b.add_constant_environment(Rgb::splat(0.1)),
                other => panic!("no such light {other}"),
            }
        }
        let cam = camera(vec3(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 4, 4);
        b.finish(cam, LightSelection::Auto).unwrap().light_selection()
    };
    assert_eq!(world(&["disk"]), LightSelection::Power);
    assert_eq!(world(&["sphere", "sky"]), LightSelection::Power);
    assert_eq!(world(&["sphere", "sphere", "disk"]), LightSelection::Power);
    let many = vec!["sphere"; World::AUTO_TREE_LIGHTS];
    assert_eq!(world(&many), LightSelection::Tree);
    assert_eq!(world(&many[1..]), LightSelection::Power);
    assert_eq!(world(&["textured disk"]), LightSelection::Tree);
    // A bitmap on a disk is sampled by its texels, the disk one leaf: nothing to choose by.
    assert_eq!(world(&["bitmap disk"]), LightSelection::Power);
}

#[test]
fn tree_probabilities_sum_to_one_and_match_what_mis_recomputes() {
    let world = many_lights(true, true);
    let n = world.lights().len() as u32;
    let mut rng = Rng::new(5, 5);
    let points = 40;
    let alpha = sidak(FALSE_ALARM, points);
    let mut failures = Vec::new();
    for k in 0..points {
        let p = vec3(8.0 * rng.next_f32() - 4.0, 2.5 * rng.next_f32(), 8.0 * rng.next_f32() - 4.0);
        // Every choice: a light, or one triangle of a mesh the tree splits.
        let choices: Vec<(u32, u32)> = (0..n)
            .flat_map(|i| match &world.lights()[i as usize] {
                l @ Light::Mesh { emitter, .. } if by_triangle(l) => {
                    (0..emitter.triangles.len() as u32).map(|t| (i, t)).collect()
                }
                _ => vec![(i, 0)],
            })
            .collect();
        assert!(choices.len() > n as usize + 10, "the disks' triangles are not leaves of their own");
        let pmfs: Vec<f32> = choices.iter().map(|&(i, t)| world.light_pmf_at(p, i, t)).collect();
        let sum: f64 = pmfs.iter().map(|&x| x as f64).sum();
        if (sum - 1.0).abs() > 1e-5 {
            failures.push(format!("{p:?}: the probabilities sum to {sum}"));
        }
        let draws = 20_000u64;
        let mut counts = vec![0u64; choices.len() + 1];
        for d in 0..draws {
            let u = (d as f32 + rng.next_f32()) / draws as f32;
            match world.choose_light(p, u) {
                Some(c) => {
                    let key = (c.index as u32, c.triangle.unwrap_or(0));
                    let k = choices.iter().position(|&x| x == key).expect("a choice that exists");
                    counts[k] += 1;
                    // The same product of the same choices: equal to f32 rounding of an f64 product.
                    if (c.pmf / pmfs[k] - 1.0).abs() > 1e-6 || !(0.0..1.0).contains(&c.remapped) {
                        failures.push(format!("{p:?}: {key:?} drawn with {}, recomputed {}", c.pmf, pmfs[k]));
                    }
                }
                None => counts[choices.len()] += 1,
            }
        }
        let mut expected: Vec<f64> = pmfs.iter().map(|&x| x as f64 * draws as f64).collect();
        expected.push(((1.0 - sum) * draws as f64).max(1e-9));
        match chi2_test(&counts, &expected) {
            Ok(o) if o.p_value >= alpha => {}
            Ok(o) => failures
                .push(format!("point {k}: chi-square {:.1} on {} dof, p = {:.1e}", o.statistic, o.dof, o.p_value)),
            Err(e) => failures.push(format!("point {k}: {e}")),
        }
    }
    failures.truncate(10);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn light_and_bsdf_sampling_agree_under_the_tree() {
    let scene = many_lights(false, false);
    let strategies = [("emitter", 1, 0), ("bsdf", 0, 1), ("mis", 1, 1)];
    const SPP: u32 = 512;
    let estimates: Vec<(&str, Vec<Estimate>)> = strategies
        .iter()
        .enumerate()
        .map(|(i, &(name, emitter_samples, bsdf_samples))| {
            let integrator = Integrator::Direct(DirectSettings { emitter_samples, bsdf_samples, hide_emitters: true });
            let out = render_with(&scene, &integrator, SPP, 300 + i as u64);
            // Luminance-like: the green channel, the image and its 8 × 8 blocks.
            (name, std::iter::once(image_estimate(&out, 1)).chain(block_estimates(&out, 1, 8)).collect())
        })
        .collect();
    let k = z_critical(FALSE_ALARM, 3 * estimates[0].1.len());
    let mut failures = Vec::new();
    for i in 0..3 {
        for j in i + 1..3 {
            for (r, (x, y)) in estimates[i].1.iter().zip(&estimates[j].1).enumerate() {
                let z = x.z_against(y);
                if r == 0 {
                    println!(
                        "{} vs {}: {:.5} ± {:.5} vs {:.5} ± {:.5}",
                        estimates[i].0, estimates[j].0, x.mean, x.se, y.mean, y.se
                    );
                }
                if !(z.abs() <= k) {
                    failures.push(format!(
                        "{} vs {}, region {r}: {:.5} ± {:.5} vs {:.5} ± {:.5} (z = {z:.1})",
                        estimates[i].0, estimates[j].0, x.mean, x.se, y.mean, y.se
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
