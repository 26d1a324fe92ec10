//! Participating media and the volumetric path tracer, against exact answers:
//! - a camera ray through an absorbing slab keeps exp(-σt d) of the light behind it, per
//!   channel (free-flight sampling with RGB extinction is unbiased when nothing scatters);
//! - shadow rays through a null-bounded absorbing slab carry exp(-σt d) exactly;
//! - white furnaces: albedo-1 media (RGB extinction, isotropic and Henyey-Greenstein,
//!   with and without light sampling) inside null and glass boundaries under a uniform sky
//!   are invisible: every pixel is the sky's radiance;
//! - a scattering medium with RGB extinction renders, channel by channel, what media with
//!   that channel's extinction in every channel render (the spectral sampling is unbiased).
//!
//! Scenes are written in the JSON format, so its media syntax is read on the way.

mod common;

use common::scenes::render_with;
use common::stats::{block_estimates, constant_image_comparisons, image_estimate, z_critical, FALSE_ALARM};
use glint::assemble::{build, BuildOptions};
use glint::formats::json;
use glint::integrators::Integrator;
use glint::world::World;
use std::path::Path;

fn scene(text: &str) -> (World, Integrator) {
    let desc = json::read(Path::new("media-test.json"), text).unwrap_or_else(|e| panic!("{e}"));
    let world = build(&desc, &BuildOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    (world, desc.integrator.clone())
}

/// Every channel's whole-image and block means must match `exact[c]` within `k` standard
/// errors.
fn check_channels(
    label: &str,
    out: &glint::render::RenderOutput,
    exact: [f64; 3],
    block: usize,
    k: f64,
) -> Vec<String> {
    let mut failures = Vec::new();
    for (c, &e) in exact.iter().enumerate() {
        let whole = image_estimate(out, c);
        println!("{label}, channel {c}: {:.5} ± {:.5} (exact {e:.5})", whole.mean, whole.se);
        for (what, est) in std::iter::once(("image".to_string(), whole))
            .chain(block_estimates(out, c, block).into_iter().enumerate().map(|(i, b)| (format!("block {i}"), b)))
        {
            if !((est.mean - e).abs() <= k * est.se.max(1e-6 * e)) {
                failures.push(format!("{label}, channel {c}, {what}: {:.5} ± {:.5}, exact {e:.5}", est.mean, est.se));
            }
        }
    }
    failures
}

const SIGMA: [f64; 3] = [0.5, 1.0, 2.0];

#[test]
fn a_camera_ray_through_an_absorbing_slab_keeps_exp_minus_sigma_t_d() {
    // A slab of thickness 1 (a null cube flattened along z) seen face on through a 1° field
    // of view: paths are within 1e-4 of the thickness.
    let (world, integrator) = scene(
        r#"{
        "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "fov": 1},
        "film": {"width": 8, "height": 8},
        "integrator": {"type": "volpath"},
        "materials": {"boundary": {"type": "null"}},
        "media": {"ink": {"sigma_t": [0.5, 1.0, 2.0], "albedo": 0}},
        "shapes": [{"type": "cube", "material": "boundary", "interior": "ink",
                    "transform": [{"scale": [5, 5, 0.5]}]}],
        "lights": [{"type": "constant", "radiance": 1}]
    }"#,
    );
    let out = render_with(&world, &integrator, 256, 1);
    let k = z_critical(FALSE_ALARM, 3 * constant_image_comparisons(8, 8, 4));
    let failures = check_channels("slab", &out, SIGMA.map(|s| (-s).exp()), 4, k);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn shadow_rays_through_an_absorbing_slab_carry_exp_minus_sigma_t_d() {
    // A white floor lit straight down by irradiance π through a slab of thickness 1 (null
    // boundary, absorbing medium) shows radiance exp(-σt) in every pixel and every sample:
    // with max_depth 2 only the shadow ray carries light, and its transmittance is exact.
    let (world, integrator) = scene(
        r#"{
        "camera": {"position": [0, 1.5, 3], "look_at": [0, 0, 0], "fov": 20},
        "film": {"width": 8, "height": 8},
        "integrator": {"type": "volpath", "max_depth": 2},
        "materials": {"boundary": {"type": "null"}, "white": {"type": "diffuse", "reflectance": 1}},
        "media": {"ink": {"sigma_t": [0.5, 1.0, 2.0], "albedo": 0}},
        "shapes": [
            {"type": "rectangle", "material": "white",
             "transform": [{"rotate": {"axis": [1, 0, 0], "angle": -90}}, {"scale": 10}]},
            {"type": "cube", "material": "boundary", "interior": "ink",
             "transform": [{"scale": [20, 0.5, 20]}, {"translate": [0, 2.5, 0]}]}
        ],
        "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 3.14159265}]
    }"#,
    );
    let out = render_with(&world, &integrator, 4, 1);
    let exact = SIGMA.map(|s| (-s).exp() as f32);
    for p in &out.image.pixels {
        for c in 0..3 {
            // Each of the two crossings moves the ray off the surface by 1e-4 (1 + |p|max),
            // |p|max ≤ 3 here: the medium path is up to 8e-4 short, so T is up to σ 8e-4 high.
            let tolerance = SIGMA[c] as f32 * 1e-3 + 1e-5;
            let rel = (p.channel(c) - exact[c]).abs() / exact[c];
            assert!(rel < tolerance, "channel {c}: {} instead of {}", p.channel(c), exact[c]);
        }
    }
}

/// A sphere (null or glass) of albedo-1 medium in a uniform sky of radiance 0.5.
fn furnace(boundary: &str, phase: &str, sample_emitters: bool) -> String {
    format!(
        r#"{{
        "camera": {{"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 35}},
        "film": {{"width": 16, "height": 16}},
        "integrator": {{"type": "volpath", "rr_depth": 3}},
        "materials": {{"boundary": {boundary}}},
        "media": {{"cloud": {{"sigma_t": [0.5, 2, 6], "albedo": 1, "phase": {phase},
                              "sample_emitters": {sample_emitters}}}}},
        "shapes": [{{"type": "sphere", "radius": 1, "material": "boundary", "interior": "cloud"}}],
        "lights": [{{"type": "constant", "radiance": 0.5}}]
    }}"#
    )
}

#[test]
fn albedo_one_media_in_a_white_furnace_are_invisible() {
    let cases = [
        ("null, isotropic", furnace(r#"{"type": "null"}"#, r#"{"type": "isotropic"}"#, true)),
        ("null, hg 0.7", furnace(r#"{"type": "null"}"#, r#"{"type": "hg", "g": 0.7}"#, true)),
        ("null, hg -0.5, no light sampling", furnace(r#"{"type": "null"}"#, r#"{"type": "hg", "g": -0.5}"#, false)),
        ("glass, hg 0.3", furnace(r#"{"type": "dielectric", "ior": 1.5}"#, r#"{"type": "hg", "g": 0.3}"#, true)),
    ];
    let k = z_critical(FALSE_ALARM, cases.len() * 3 * constant_image_comparisons(16, 16, 8));
    let mut failures = Vec::new();
    for (i, (label, text)) in cases.iter().enumerate() {
        let (world, integrator) = scene(text);
        let out = render_with(&world, &integrator, 128, 20 + i as u64);
        failures.extend(check_channels(label, &out, [0.5; 3], 8, k));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A scattering sphere (null boundary, extinction `sigma_t`) under an area light.
fn lit_cloud(sigma_t: [f64; 3]) -> String {
    format!(
        r#"{{
        "camera": {{"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 40}},
        "film": {{"width": 16, "height": 16}},
        "integrator": {{"type": "volpath"}},
        "materials": {{"boundary": {{"type": "null"}}, "grey": {{"type": "diffuse", "reflectance": 0.4}}}},
        "media": {{"cloud": {{"sigma_t": [{}, {}, {}], "albedo": [0.9, 0.6, 0.8],
                              "phase": {{"type": "hg", "g": 0.4}}}}}},
        "shapes": [
            {{"type": "sphere", "radius": 1, "material": "boundary", "interior": "cloud"}},
            {{"type": "rectangle", "material": "grey",
              "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle": -90}}}}, {{"scale": 3}}, {{"translate": [0, -1.2, 0]}}]}},
            {{"type": "rectangle", "emission": 6,
              "transform": [{{"rotate": {{"axis": [1, 0, 0], "angle": 90}}}}, {{"scale": 0.7}}, {{"translate": [0.5, 2, 0.3]}}]}}
        ]
    }}"#,
        sigma_t[0], sigma_t[1], sigma_t[2]
    )
}

#[test]
fn rgb_extinction_is_sampled_without_bias_per_channel() {
    let sigma = [0.3, 1.5, 6.0];
    let (world, integrator) = scene(&lit_cloud(sigma));
    let rgb = render_with(&world, &integrator, 256, 5);
    let k = z_critical(FALSE_ALARM, 3);
    let mut failures = Vec::new();
    for (c, &sigma_c) in sigma.iter().enumerate() {
        let (grey_world, grey_integrator) = scene(&lit_cloud([sigma_c; 3]));
        let grey = render_with(&grey_world, &grey_integrator, 256, 50 + c as u64);
        let (a, b) = (image_estimate(&rgb, c), image_estimate(&grey, c));
        println!("channel {c}: rgb {:.5} ± {:.5}, grey {:.5} ± {:.5}", a.mean, a.se, b.mean, b.se);
        if !(a.z_against(&b).abs() <= k) {
            failures.push(format!(
                "channel {c}: {:.5} ± {:.5} with RGB extinction, {:.5} ± {:.5} with grey",
                a.mean, a.se, b.mean, b.se
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
