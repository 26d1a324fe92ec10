//! Images do not depend on how the work is scheduled: every camera sample draws from a
//! generator keyed by (seed, pixel, sample) and each pixel sums its samples in order, so
//! renders on 1, 2 and 3 threads, and with different tile sizes, are bit-identical (the
//! variance image too). Checked for the path tracer (every strategy) and Whitted, on the
//! Cornell box with a glass ball and a glossy ball added, where paths branch and end by
//! Russian roulette.

mod common;

use common::scenes::{add_glass_and_metal_balls, cornell_box_with, path};
use glint::integrators::{Integrator, Strategy, WhittedSettings};
use glint::render::{render, RenderOutput, RenderSettings, Silent};
use glint::world::World;

fn scene() -> World {
    // 30×22: tiles of most sizes leave partial tiles at the right and bottom.
    cornell_box_with(30, 22, |b| {
        add_glass_and_metal_balls(b);
    })
}

fn render_on(threads: usize, scene: &World, integrator: &Integrator, tile_size: usize) -> RenderOutput {
    let settings = RenderSettings { spp: 8, seed: 3, tile_size, variance: true, ..Default::default() };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| render(scene, integrator, &settings, &Silent))
}

fn bits(out: &RenderOutput) -> Vec<u32> {
    let var = out.variance.as_ref().unwrap();
    out.image.pixels.iter().chain(&var.pixels).flat_map(|p| p.to_array()).map(f32::to_bits).collect()
}

#[test]
fn images_are_identical_whatever_the_threads_and_tiles() {
    let scene = scene();
    let integrators = [
        ("path MIS", path(Strategy::Mis)),
        ("path light", path(Strategy::Light)),
        ("path BSDF", path(Strategy::Bsdf)),
        ("Whitted", Integrator::Whitted(WhittedSettings::default())),
    ];
    for (name, integrator) in &integrators {
        let reference = bits(&render_on(1, &scene, integrator, 16));
        assert!(reference.iter().any(|&b| b != 0), "{name}: black image");
        for (threads, tile) in [(2, 16), (3, 16), (3, 1), (2, 7), (1, 64)] {
            let other = bits(&render_on(threads, &scene, integrator, tile));
            assert!(
                reference == other,
                "{name}: {threads} threads, {tile}-pixel tiles differ from 1 thread, 16-pixel tiles"
            );
        }
    }
}
