//! The wavefront schedules (a tile's paths advanced together, their rays traced in batches
//! one by one or interleaved) against the one-path reference:
//! - the world's batch queries give every ray the single-ray answer, bit for bit, on a world
//!   with a flat BVH of meshes and instances outside it (spheres, a transformed mesh), for
//!   random rays including NaN, infinite and zero directions and intervals, and rays grazing
//!   the walls in their plane;
//! - renders give the same bits and the same ray counts under every schedule: the path tracer
//!   with every strategy, hidden emitters, depth limits and fixed Russian roulette on a scene
//!   with glass, metal and instances, at tile sizes and sample counts that fill, split and
//!   leave part-full waves; and every Mitsuba agreement scene (masks, textures, media,
//!   instances, every light), every bundled scene and every bench scene as its file asks.
//!   (Every statistical test that renders through `common::scenes::render_with` also checks
//!   every schedule.)

mod common;

use common::load::load;
use common::scenes::{add_box, add_glass_and_metal_balls, assert_same_bits, cornell_box_with};
use glint::integrators::{Integrator, PathSettings, Strategy};
use glint::math::{vec3, Ray, Transform, Vec3};
use glint::render::{render, RenderOutput, RenderSettings, Schedule, Silent};
use glint::world::{Hit, World};
use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

/// The Cornell box with a glass and a metal ball (instances outside the flat BVH) and a box
/// traced through its transform (also outside it).
fn scene() -> &'static World {
    static SCENE: OnceLock<World> = OnceLock::new();
    SCENE.get_or_init(|| {
        cornell_box_with(30, 22, |b| {
            let (glass, metal) = add_glass_and_metal_balls(b);
            let xf = Transform::translate(vec3(0.0, 1.2, 0.2)).then_after(&Transform::rotate(Vec3::Y, 30.0));
            let cube = std::sync::Arc::new(glint::geometry::cube_mesh(glint::accel::BvhSplit::Sah));
            b.add_mesh_instance(
                &cube.clone(),
                &xf.then_after(&Transform::scale(vec3(0.1, 0.1, 0.1)).unwrap()),
                true,
                metal,
                None,
                false,
            )
            .unwrap();
            add_box(b, vec3(0.1, 0.1, 0.1), 45.0, vec3(0.6, 0.1, 0.6), glass);
        })
    })
}

fn hit_bits(h: &Option<Hit>) -> Option<(u32, u32, u32, u32, u32)> {
    h.map(|h| (h.instance, h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()))
}

/// A ray of one of several kinds, some untraceable on purpose.
fn ray_of((kind, a, b, c, d, e): (u8, f32, f32, f32, f32, f32)) -> Ray {
    let origin = vec3(a * 1.2, 1.0 + b * 1.2, c * 1.2);
    let dir = vec3(d, e, a - b);
    match kind % 8 {
        0 => Ray::new(origin, dir),
        1 => Ray::new(origin, Vec3::ZERO),
        2 => Ray::new(origin, vec3(f32::NAN, d, e)),
        3 => Ray::new(vec3(f32::INFINITY, b, c), dir),
        4 => Ray::segment(origin, dir, d.abs() * 3.0),
        5 => Ray { t_max: f32::NAN, ..Ray::new(origin, dir) },
        // In the floor's and the back wall's planes: grazing.
        6 => Ray::new(vec3(a, 0.0, c), vec3(d, 0.0, e)),
        _ => Ray::new(vec3(a, b + 1.0, -1.0), vec3(d, e, 0.0)),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn batch_queries_answer_each_ray_as_the_single_ray_queries(
        params in prop::collection::vec((0u8..8, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), 0..70)
    ) {
        let world = scene();
        let rays: Vec<Ray> = params.into_iter().map(ray_of).collect();
        let mut hits = vec![None; rays.len()];
        world.intersect_batch(&rays, &mut hits);
        let mut blocked = vec![false; rays.len()];
        world.occluded_batch(&rays, &mut blocked);
        let mut in_packets = vec![rays.len().is_multiple_of(2); rays.len()];
        world.occluded_packets(&rays, &mut in_packets);
        for (i, r) in rays.iter().enumerate() {
            prop_assert_eq!(hit_bits(&hits[i]), hit_bits(&world.intersect(r)), "ray {} {:?}", i, r);
            prop_assert_eq!(blocked[i], world.occluded(r), "ray {} {:?}", i, r);
            prop_assert_eq!(in_packets[i], blocked[i], "packets: ray {} {:?}", i, r);
        }
    }
}

#[test]
fn batch_queries_see_the_instances_outside_the_flat_bvh() {
    // Straight down onto the glass ball: it, not the floor under it, is the hit.
    let world = scene();
    let rays = [Ray::new(vec3(-0.4, 1.95, 0.4), vec3(0.0, -1.0, 0.0))];
    let mut hits = [None];
    world.intersect_batch(&rays, &mut hits);
    let hit = hits[0].expect("the ball is below");
    assert!((hit.t - 0.1).abs() < 1e-3, "hit at {} instead of the ball's top", hit.t);
    let mut blocked = [false];
    world.occluded_batch(&[Ray::segment(rays[0].origin, rays[0].dir, 0.2)], &mut blocked);
    assert!(blocked[0], "the ball blocks the segment");
    let mut blocked = [false];
    world.occluded_packets(&[Ray::segment(rays[0].origin, rays[0].dir, 0.2)], &mut blocked);
    assert!(blocked[0], "the ball blocks the segment in a packet too");
}

/// The one-path render and the two wavefront renders, which must match it.
fn render_all(world: &World, integrator: &Integrator, settings: &RenderSettings) -> (RenderOutput, Vec<RenderOutput>) {
    let one = render(world, integrator, &RenderSettings { schedule: Schedule::OnePath, ..settings.clone() }, &Silent);
    let waves =
        [Schedule::Wavefront, Schedule::WavefrontInterleaved, Schedule::WavefrontPackets, Schedule::WavefrontSimd]
            .map(|schedule| render(world, integrator, &RenderSettings { schedule, ..settings.clone() }, &Silent));
    (one, waves.into())
}

#[test]
fn path_tracer_gives_the_same_bits_on_every_schedule() {
    let world = scene();
    let variants = [
        PathSettings { strategy: Strategy::Mis, ..Default::default() },
        PathSettings { strategy: Strategy::Light, ..Default::default() },
        PathSettings { strategy: Strategy::Bsdf, ..Default::default() },
        PathSettings { hide_emitters: true, ..Default::default() },
        PathSettings { max_depth: Some(1), ..Default::default() },
        PathSettings { max_depth: Some(3), ..Default::default() },
        PathSettings { rr_depth: 1, rr_probability: Some(0.5), ..Default::default() },
    ];
    // (tile size, spp): waves of one tile's samples, several full waves per tile, and one
    // whole image per tile with part-full last waves.
    let layouts = [(4, 3), (64, 8), (7, 40)];
    for (k, p) in variants.iter().enumerate() {
        let integrator = Integrator::Path(p.clone());
        let (tile_size, spp) = layouts[k % layouts.len()];
        let settings = RenderSettings { spp, seed: 5, tile_size, variance: true, ..Default::default() };
        let (one, waves) = render_all(world, &integrator, &settings);
        assert!(one.image.pixels.iter().any(|p| p.max_component() > 0.0), "{p:?}: black image");
        waves.iter().for_each(|w| assert_same_bits(&one, w));
    }
}

#[test]
fn a_large_mesh_gives_the_same_bits_on_every_schedule_with_hit_prefetching() {
    // The Stanford bunny's data is over the size at which the wavefront prefetches what each
    // hit reads a step or two ahead; that must change no bits.
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/scenes/cornell-bunny.xml");
    let loaded = load(&file, &[], Some((24, 18))).unwrap();
    assert!(loaded.world.prefetches_hits(), "the bunny scene should be large enough to prefetch");
    let settings = RenderSettings { spp: 3, tile_size: 8, variance: true, ..loaded.settings.clone() };
    let (one, waves) = render_all(&loaded.world, &loaded.integrator, &settings);
    assert!(one.image.pixels.iter().any(|p| p.max_component() > 0.0), "black image");
    waves.iter().for_each(|w| assert_same_bits(&one, w));
}

/// The scene files (`.xml`, `.json`) in `dir`, relative to the repository root, sorted.
fn scene_files(dir: &str) -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(dir);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml" || e == "json"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_agreement_bundled_and_bench_scene_gives_the_same_bits_on_every_schedule() {
    let agreement = scene_files("tests/scenes/mitsuba");
    assert!(agreement.len() >= 30, "expected the agreement scenes");
    let bundled = scene_files("scenes");
    assert!(bundled.len() >= 4, "expected the bundled scenes");
    let files: Vec<_> = agreement.into_iter().chain(bundled).chain(scene_files("bench/scenes")).collect();
    for f in &files {
        // Small images (a cropped film keeps its own size: its crop window needs it).
        let loaded = load(f, &[], Some((24, 18))).or_else(|_| load(f, &[], None)).unwrap();
        let settings = RenderSettings { spp: 3, tile_size: 8, variance: true, ..loaded.settings.clone() };
        let (one, waves) = render_all(&loaded.world, &loaded.integrator, &settings);
        waves.iter().for_each(|w| assert_same_bits(&one, w));
        eprintln!("{}: same bits ({} rays)", f.display(), one.stats.rays + one.stats.shadow_rays);
    }
}
