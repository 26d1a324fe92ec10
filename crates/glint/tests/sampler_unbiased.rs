//! The Owen-scrambled Sobol sampler must converge to the same image as independent
//! sampling (it only reorders the randomness), and with less error at equal sample count.

use glint::render::{render, RenderSettings, Silent};
use glint::sampling::SamplerKind;
mod common;

use common::load::{load, Loaded};
use std::path::Path;

fn cornell(w: u32) -> Loaded {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.json");
    load(&path, &[], Some((w, w))).unwrap()
}

/// Image mean per channel and its standard error, from per-pixel variances (pixels are
/// independent of each other).
fn mean_and_error(out: &glint::render::RenderOutput) -> ([f64; 3], [f64; 3]) {
    let n = out.image.pixels.len() as f64;
    let means = out.image.channel_means();
    let var = out.variance.as_ref().unwrap();
    let mut se = [0.0; 3];
    for p in &var.pixels {
        for (k, v) in p.to_array().into_iter().enumerate() {
            se[k] += v as f64;
        }
    }
    (means, se.map(|s| s.sqrt() / n))
}

#[test]
fn sobol_and_independent_agree_in_expectation() {
    let scene = cornell(48);
    let mut outs = Vec::new();
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        let settings = RenderSettings { spp: 64, seed: 5, sampler, variance: true, ..Default::default() };
        outs.push(render(&scene.world, &scene.integrator, &settings, &Silent));
    }
    let (mi, ei) = mean_and_error(&outs[0]);
    // The per-pixel sample variance overestimates a QMC estimate's variance, so this error
    // bound is conservative for the Sobol image.
    let (ms, es) = mean_and_error(&outs[1]);
    for k in 0..3 {
        let sigma = (ei[k] * ei[k] + es[k] * es[k]).sqrt();
        // 4.5 sigma over 3 channels: false alarm rate below 2e-5.
        assert!((mi[k] - ms[k]).abs() < 4.5 * sigma, "channel {k}: {} vs {} (sigma {sigma})", mi[k], ms[k]);
    }
}

#[test]
fn sobol_has_lower_error_than_independent_at_equal_spp() {
    let scene = cornell(32);
    let reference = render(
        &scene.world,
        &scene.integrator,
        &RenderSettings { spp: 1024, seed: 1, sampler: SamplerKind::Independent, ..Default::default() },
        &Silent,
    );
    let mse = |sampler| {
        let out = render(
            &scene.world,
            &scene.integrator,
            &RenderSettings { spp: 16, seed: 2, sampler, ..Default::default() },
            &Silent,
        );
        let mut e = 0.0f64;
        for (a, b) in out.image.pixels.iter().zip(&reference.image.pixels) {
            let d = *a - *b;
            e += (d.r * d.r + d.g * d.g + d.b * d.b) as f64;
        }
        e / out.image.pixels.len() as f64
    };
    let (independent, sobol) = (mse(SamplerKind::Independent), mse(SamplerKind::Sobol));
    assert!(sobol < independent, "sobol {sobol} independent {independent}");
}
