//! Light sampling, BSDF sampling and their MIS combination are three estimators of the same
//! image: on a scene with glossy (GGX α = 0.2, and an anisotropic 0.1 × 0.4 ball) and diffuse surfaces lit by a small and a
//! large quad light and a small sphere light, their image means and 8×8-block means must
//! agree pairwise within Šidák-corrected standard errors (independent seeds).

mod common;

use common::scenes::{add_quad, add_square, black, camera, diffuse, emission, render_with};
use common::stats::{block_estimates, image_estimate, z_critical, Estimate, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::bsdf::{Microfacet, MicrofacetKind};
use glint::integrators::{Integrator, PathSettings, Strategy};
use glint::lights::{AreaEmission, LightSelection};
use glint::materials::{ConductorMaterial, Material, MaterialKind};
use glint::math::{rgb, vec3, Rgb, Transform, Vec3};
use glint::world::World;

const SIZE: u32 = 32;
const BLOCK: usize = 8;
const SPP: u32 = 256;
/// For the `#[ignore]`d long run.
const LONG_SPP: u32 = 8192;
const STRATEGIES: [Strategy; 3] = [Strategy::Mis, Strategy::Light, Strategy::Bsdf];

fn glossy(b: &mut WorldBuilder, name: &str, dist: Microfacet) -> u32 {
    let (eta, k) = (rgb(0.2, 0.92, 1.1), rgb(3.9, 2.45, 2.14)); // copper
    let dist = dist.into();
    b.add_material(Material::new(
        name,
        MaterialKind::Conductor(ConductorMaterial { roughness: Some(dist), eta, k, specular: Rgb::WHITE }),
        true,
    ))
}

fn scene() -> World {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let floor = glossy(&mut b, "floor", Microfacet::new(MicrofacetKind::Ggx, 0.2));
    let ball = glossy(&mut b, "ball", Microfacet::anisotropic(MicrofacetKind::Ggx, 0.1, 0.4));
    let wall = diffuse(&mut b, "wall", Rgb::splat(0.6));
    let chalk = diffuse(&mut b, "chalk", rgb(0.7, 0.5, 0.3));
    let lamp = black(&mut b);
    add_square(&mut b, Vec3::ZERO, 1, 1.0, 3.0, floor, None);
    add_square(&mut b, vec3(0.0, 1.5, -2.0), 2, 1.0, 3.0, wall, None);
    b.add_sphere(vec3(-0.8, 0.5, -0.5), 0.5, &Transform::IDENTITY, chalk, None, false).unwrap();
    b.add_sphere(vec3(0.8, 0.45, -0.2), 0.45, &Transform::IDENTITY, ball, None, false).unwrap();
    add_square(&mut b, vec3(0.5, 2.0, 0.5), 1, -1.0, 0.1, lamp, emission(100.0));
    add_square(&mut b, vec3(-1.0, 2.5, -1.0), 1, -1.0, 0.75, lamp, emission(2.0));
    b.add_sphere(vec3(1.6, 1.2, -1.2), 0.15, &Transform::IDENTITY, lamp, emission(30.0), false).unwrap();
    let cam = camera(vec3(0.0, 1.5, 4.0), vec3(0.0, 0.5, -0.5), Vec3::Y, 45.0, SIZE, SIZE);
    b.finish(cam, LightSelection::Power).unwrap()
}

/// Renders `scene` with each strategy (seeds differ, so estimates are independent) and
/// compares every pair on the whole image and on each block, channel by channel.
fn assert_strategies_agree(scene: &World, settings: PathSettings, spp: u32) {
    let estimates: Vec<(Strategy, Vec<[Estimate; 3]>)> = STRATEGIES
        .iter()
        .enumerate()
        .map(|(i, &strategy)| {
            let integrator = Integrator::Path(PathSettings { strategy, ..settings.clone() });
            let out = render_with(scene, &integrator, spp, 500 + i as u64);
            let per_channel: Vec<Vec<Estimate>> = (0..3)
                .map(|c| std::iter::once(image_estimate(&out, c)).chain(block_estimates(&out, c, BLOCK)).collect())
                .collect();
            let regions =
                (0..per_channel[0].len()).map(|r| [per_channel[0][r], per_channel[1][r], per_channel[2][r]]).collect();
            (strategy, regions)
        })
        .collect();
    let pairs = STRATEGIES.len() * (STRATEGIES.len() - 1) / 2;
    let regions = estimates[0].1.len();
    let k = z_critical(FALSE_ALARM, pairs * regions * 3);
    let mut failures = Vec::new();
    for i in 0..estimates.len() {
        for j in i + 1..estimates.len() {
            let ((sa, ra), (sb, rb)) = (&estimates[i], &estimates[j]);
            for r in 0..regions {
                for c in 0..3 {
                    let z = ra[r][c].z_against(&rb[r][c]);
                    if r == 0 && c == 0 {
                        println!(
                            "{sa:?} vs {sb:?}: {:.5} ± {:.5} vs {:.5} ± {:.5}, z = {z:.2}",
                            ra[r][c].mean, ra[r][c].se, rb[r][c].mean, rb[r][c].se
                        );
                    }
                    // Written so that a NaN fails too.
                    let agrees = z.abs() <= k;
                    if !agrees {
                        let what = if r == 0 { "image".to_string() } else { format!("block {}", r - 1) };
                        failures.push(format!(
                            "{sa:?} vs {sb:?}, {what}, channel {c}: {:.5} ± {:.5} vs {:.5} ± {:.5} (z = {z:.1}, limit {k:.2})",
                            ra[r][c].mean, ra[r][c].se, rb[r][c].mean, rb[r][c].se
                        ));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn strategies_agree_on_glossy_and_diffuse_surfaces() {
    assert_strategies_agree(&scene(), PathSettings::default(), SPP);
}

#[test]
fn strategies_agree_at_a_fixed_depth() {
    // Depth 3: direct light and one indirect bounce, and nothing more, in every strategy.
    assert_strategies_agree(&scene(), PathSettings { max_depth: Some(3), ..Default::default() }, SPP);
}

#[test]
fn strategies_agree_on_emitters_seen_from_behind() {
    // One-sided emitters send nothing backwards: a quad light facing away from the floor
    // and a sphere light with inward normals (it lights only its inside). Light sampling
    // must not count what BSDF sampling cannot see. A plain quad light keeps the image lit.
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let floor = diffuse(&mut b, "floor", Rgb::splat(0.7));
    let lamp = black(&mut b);
    add_square(&mut b, Vec3::ZERO, 1, 1.0, 3.0, floor, None);
    add_square(&mut b, vec3(-0.8, 1.0, 0.0), 1, 1.0, 0.4, lamp, emission(10.0));
    b.add_sphere(vec3(0.8, 0.8, -0.3), 0.4, &Transform::IDENTITY, lamp, emission(10.0), true).unwrap();
    let facing_camera = [vec3(-0.3, 0.2, 1.0), vec3(0.3, 0.2, 1.0), vec3(0.3, 0.6, 1.0), vec3(-0.3, 0.6, 1.0)];
    add_quad(&mut b, facing_camera, lamp, Some(AreaEmission::constant(Rgb::splat(3.0))));
    let cam = camera(vec3(0.0, 2.0, 4.0), vec3(0.0, 0.3, 0.0), Vec3::Y, 50.0, SIZE, SIZE);
    let scene = b.finish(cam, LightSelection::Power).unwrap();
    assert_strategies_agree(&scene, PathSettings::default(), SPP);
}

#[test]
#[ignore = "long: run with `cargo test -- --ignored`"]
fn strategies_agree_with_many_samples() {
    assert_strategies_agree(&scene(), PathSettings::default(), LONG_SPP);
}
