//! Gradients of a render (`Session::render_gradient`, path replay backpropagation) against
//! central finite differences of glint's own renders with the same seeds.
//!
//! For each parameter kind, on a small scene: K seeds each give a gradient and a finite
//! difference `(loss(θ + h) - loss(θ - h)) / 2h` of renders with that seed, the loss being
//! `sum(G * image)` for a fixed, uneven adjoint image `G`. With the same seed, and a scene
//! set up so that no sampling decision depends on the parameter, the finite difference is
//! the derivative of the same random function the gradient estimates, so the two agree
//! seed by seed up to rounding; the test compares them pair by pair, allowing z standard
//! errors of the paired differences (z from the family-wise false-alarm rate over every
//! scalar compared) plus a bound on the finite difference's rounding (each image value is
//! rounded to f32, 2^-24 relative, so the loss is good to 2^-24 of itself, and the
//! difference to that over the step). Every comparison must also be able to see a
//! gradient 20% off, or the test could not fail.
//!
//! Two set-ups keep sampling independent of the parameters: lights chosen uniformly (so an
//! emission does not move light selection) under MIS, for the parameters sampling does not
//! read (a Lambertian reflectance, a principled base colour, emission); and direct light by
//! light sampling alone (`strategy: light`, `max_depth: 2`), where no BSDF sample is used,
//! for the parameters BSDF sampling reads (roughness, metallic, plastic's diffuse). The
//! first covers the adjoint pass's term for the radiance still to come, many bounces deep;
//! the second the derivative of each material's BSDF value. The comparison with Mitsuba's
//! prb (`python/tests/test_gradient_mitsuba.py`) covers the general case.
//!
//! The gradients are also the same bits for any thread count.

mod common;

use common::scratch::ScratchDir;
use common::stats::{z_critical, FALSE_ALARM};
use glint::formats::ReadOptions;
use glint::math::{rgb, Rgb};
use glint::render::Silent;
use glint::session::{FilmOptions, Param, ParamValue, RenderControl, Session};
use std::sync::atomic::AtomicBool;

const SCENE: &str = r#"{
  "camera": { "position": [0, 1.2, 4.2], "look_at": [0, 0.7, 0], "up": [0, 1, 0], "fov": 45 },
  "film": { "width": 14, "height": 12, "filter": "box" },
  "integrator": { "type": "path", "max_depth": MAX_DEPTH, "rr_depth": 100, "strategy": "STRATEGY", "light_selection": "uniform" },
  "sampler": { "spp": 8, "seed": 0, "type": "independent" },
  "materials": {
    "floor": { "type": "diffuse", "reflectance": [0.5, 0.4, 0.3] },
    "wall": { "type": "plastic", "diffuse": [0.2, 0.5, 0.3], "alpha": 0.3 },
    "metal": { "type": "conductor", "metal": "Au", "distribution": "ggx", "alpha": 0.3 },
    "paint": { "type": "principled", "base_color": [0.7, 0.3, 0.2], "roughness": 0.5, "metallic": 0.3 },
    "lamp": { "type": "diffuse", "reflectance": 0 }
  },
  "shapes": [
    { "type": "rectangle", "material": "floor",
      "transform": [{ "scale": [3, 3, 1] }, { "rotate": { "axis": [1, 0, 0], "angle": -90 } }] },
    { "type": "rectangle", "material": "wall",
      "transform": [{ "scale": [3, 2, 1] }, { "translate": [0, 1, -1.5] }] },
    { "type": "sphere", "center": [-0.7, 0.5, 0], "radius": 0.5, "material": "metal" },
    { "type": "sphere", "center": [0.7, 0.5, 0.2], "radius": 0.5, "material": "paint" },
    { "type": "rectangle", "material": "lamp", "emission": [6, 5, 4],
      "transform": [{ "scale": [0.6, 0.6, 1] }, { "rotate": { "axis": [1, 0, 0], "angle": 90 } }, { "translate": [0, 2.6, 0] }] }
  ],
  "lights": [
    { "type": "point", "position": [1.5, 2, 2], "intensity": [4, 3, 2] },
    { "type": "constant", "radiance": [0.2, 0.25, 0.3] }
  ]
}"#;

/// An uneven adjoint image, so that pixels and channels weigh differently.
fn adjoint(w: usize, h: usize) -> Vec<Rgb> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            rgb(1.0 + 0.05 * x, 1.5 - 0.04 * y, 0.5 + 0.03 * (x + y))
        })
        .collect()
}

/// Light sampling alone, or MIS.
#[derive(Clone, Copy)]
enum Setup {
    DirectByLightSampling,
    Mis,
}

fn open(dir: &ScratchDir, setup: Setup) -> Session {
    let path = dir.join("scene.json");
    let (strategy, depth) = match setup {
        Setup::DirectByLightSampling => ("light", "2"),
        Setup::Mis => ("mis", "4"),
    };
    std::fs::write(&path, SCENE.replace("STRATEGY", strategy).replace("MAX_DEPTH", depth)).unwrap();
    Session::open(&path, &ReadOptions::default()).unwrap()
}

/// `sum(g * image)` of a render with `seed` and `spp`.
fn loss(session: &mut Session, g: &[Rgb], spp: u32, seed: u64) -> f64 {
    session.edit().sampler.spp = spp;
    session.edit().sampler.seed = seed;
    let mut film = session.new_film(&FilmOptions::default()).unwrap();
    let cancel = AtomicBool::new(false);
    session.render(&mut film, &RenderControl::new(&cancel, &Silent), &mut |_| Ok(())).unwrap();
    let image = film.image();
    image
        .pixels
        .iter()
        .zip(g)
        .map(|(p, g)| p.r as f64 * g.r as f64 + p.g as f64 * g.g as f64 + p.b as f64 * g.b as f64)
        .sum()
}

fn get(session: &mut Session, name: &str) -> ParamValue {
    session.params().into_iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name}")).value
}

fn set(session: &mut Session, name: &str, value: ParamValue) {
    session.set_params(&[Param { name: name.into(), value }]).unwrap();
}

/// `value` with scalar `k` moved by `by`.
fn moved(value: ParamValue, k: usize, by: f32) -> ParamValue {
    match value {
        ParamValue::Float(v) => ParamValue::Float(v + by),
        ParamValue::Color(c) => {
            let mut a = c.to_array();
            a[k] += by;
            ParamValue::Color(rgb(a[0], a[1], a[2]))
        }
        ParamValue::Matrix(_) | ParamValue::Image(_) => unreachable!("not a test parameter"),
    }
}

/// One scalar's comparison over the seeds.
struct Paired {
    gradients: Vec<f64>,
    finite_differences: Vec<f64>,
    /// Per seed, the bound on the finite difference's rounding.
    rounding: Vec<f64>,
}

/// Per scalar of parameter `name`: the gradients and the finite differences, seed by seed.
fn paired(session: &mut Session, name: &str, relative_step: f32, spp: u32, seeds: u64) -> Vec<Paired> {
    let (w, h) = (session.description().film.width as usize, session.description().film.height as usize);
    let g = adjoint(w, h);
    let value = get(session, name);
    let values = match &value {
        ParamValue::Float(v) => vec![*v],
        ParamValue::Color(c) => c.to_array().to_vec(),
        ParamValue::Matrix(_) | ParamValue::Image(_) => unreachable!("not a test parameter"),
    };
    let cancel = AtomicBool::new(false);
    let mut out: Vec<Paired> =
        values.iter().map(|_| Paired { gradients: vec![], finite_differences: vec![], rounding: vec![] }).collect();
    for seed in 0..seeds {
        let grad = session.render_gradient(&[name.to_string()], &g, spp, seed, &cancel).unwrap().remove(0).values;
        for (k, v) in values.iter().enumerate() {
            let step = (v.abs() * relative_step).max(1e-3);
            set(session, name, moved(value.clone(), k, step));
            let up = loss(session, &g, spp, seed);
            set(session, name, moved(value.clone(), k, -step));
            let down = loss(session, &g, spp, seed);
            set(session, name, value.clone());
            let p = &mut out[k];
            p.gradients.push(grad[k]);
            p.finite_differences.push((up - down) / (2.0 * step as f64));
            p.rounding.push(2f64.powi(-24) * (up.abs() + down.abs()) / (2.0 * step as f64));
        }
    }
    out
}

/// Compares every scalar of `params` (name, relative step), returning the failures.
fn compare(setup: Setup, params: &[(&str, f32)], spp: u32, seeds: u64, z: f64) -> Vec<String> {
    let dir = ScratchDir::new(match setup {
        Setup::DirectByLightSampling => "gradient-direct",
        Setup::Mis => "gradient-mis",
    });
    let mut session = open(&dir, setup);
    let mut failures = Vec::new();
    for &(name, step) in params {
        for (k, p) in paired(&mut session, name, step, spp, seeds).iter().enumerate() {
            let diffs: Vec<f64> = p.gradients.iter().zip(&p.finite_differences).map(|(g, f)| g - f).collect();
            let (d, se) = mean_se(&diffs);
            let (fd, _) = mean_se(&p.finite_differences);
            let (gm, _) = mean_se(&p.gradients);
            let (rounding, _) = mean_se(&p.rounding);
            let allowed = z * se + rounding;
            println!(
                "{name}[{k}]: gradient {gm:.6}, finite difference {fd:.6}, difference {d:.2e} (allowed {allowed:.2e})"
            );
            if d.abs() > allowed {
                failures.push(format!("{name}[{k}]: gradient {gm} but finite difference {fd} (allowed {allowed:.2e})"));
            }
            if allowed > 0.2 * fd.abs() {
                failures.push(format!(
                    "{name}[{k}]: cannot see a 20% error (allowed {allowed:.2e}, finite difference {fd})"
                ));
            }
        }
    }
    failures
}

/// Parameters no sampling decision reads (see the module doc), and their steps.
const MIS_PARAMS: &[(&str, f32)] = &[
    ("materials.floor.reflectance", 0.05),
    ("materials.paint.base_color", 0.03),
    ("shapes.4.emission", 0.05),
    ("lights.0.intensity", 0.05),
    ("lights.1.radiance", 0.05),
];

/// Parameters BSDF sampling reads, compared on direct light by light sampling. Their steps
/// are the adjoint pass's own (1% of the value): a rough plastic's roughness acts through
/// coating tables estimated by a fixed quadrature, smooth only at about that scale (with
/// a step three times longer its finite difference moves by 3.5%).
const DIRECT_PARAMS: &[(&str, f32)] = &[
    ("materials.wall.diffuse", 0.01),
    ("materials.wall.alpha", 0.01),
    ("materials.metal.alpha", 0.01),
    ("materials.paint.roughness", 0.01),
    ("materials.paint.metallic", 0.01),
];

#[test]
fn gradients_agree_with_finite_differences_of_renders() {
    let scalars = 3 * (MIS_PARAMS.len() + DIRECT_PARAMS.len());
    let z = z_critical(FALSE_ALARM, scalars);
    let mut failures = compare(Setup::Mis, MIS_PARAMS, 8, 16, z);
    failures.extend(compare(Setup::DirectByLightSampling, DIRECT_PARAMS, 8, 16, z));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn gradients_are_the_same_bits_for_any_thread_count() {
    let dir = ScratchDir::new("gradient-threads");
    let mut session = open(&dir, Setup::Mis);
    let names: Vec<String> = MIS_PARAMS.iter().chain(DIRECT_PARAMS).map(|(n, _)| n.to_string()).collect();
    let g = adjoint(14, 12);
    let cancel = AtomicBool::new(false);
    let mut run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| session.render_gradient(&names, &g, 4, 7, &cancel).unwrap())
    };
    let one = run(1);
    assert!(one.iter().all(|p| p.values.iter().any(|v| *v != 0.0)), "every parameter has a gradient");
    for threads in [2, 3, 8] {
        let other = run(threads);
        for (a, b) in one.iter().zip(&other) {
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a.values), bits(&b.values), "{} with {threads} threads", a.name);
        }
    }
}

#[test]
fn parameters_without_gradients_are_refused_in_one_line() {
    let dir = ScratchDir::new("gradient-refused");
    let mut session = open(&dir, Setup::Mis);
    let g = adjoint(14, 12);
    let cancel = AtomicBool::new(false);
    for (name, says) in [
        ("shapes.2.to_world", "geometry"),
        ("camera.fov", "geometry"),
        ("materials.nothing.reflectance", "no parameter"),
        ("materials.metal.eta", ""),
    ] {
        match session.render_gradient(&[name.to_string()], &g, 1, 0, &cancel) {
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.contains(says) && !msg.contains('\n'), "{name}: {msg}");
            }
            Ok(_) if name == "materials.metal.eta" => {}
            Ok(_) => panic!("{name} has a gradient"),
        }
    }
    let short = vec![Rgb::WHITE; 3];
    let e = session.render_gradient(&["materials.floor.reflectance".into()], &short, 1, 0, &cancel).unwrap_err();
    assert!(e.to_string().contains("grad_image"), "{e}");
}

/// A scene lit by an environment map alone, seen through BSDF sampling alone (so no
/// sampling decision reads the map's texels or the floor's texture), with a textured floor.
const TEXEL_SCENE: &str = r#"{
  "camera": { "position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "fov": 50 },
  "film": { "width": 12, "height": 10, "filter": "box" },
  "integrator": { "type": "path", "max_depth": 3, "rr_depth": 100, "strategy": "bsdf" },
  "sampler": { "spp": 8, "seed": 0, "type": "independent" },
  "materials": {
    "floor": { "type": "diffuse", "reflectance": { "texture": "TEXTURE" } },
    "ball": { "type": "principled", "base_color": [0.6, 0.5, 0.4], "roughness": 0.4 }
  },
  "shapes": [
    { "type": "rectangle", "material": "floor",
      "transform": [{ "scale": [2, 2, 1] }, { "rotate": { "axis": [1, 0, 0], "angle": -90 } }] },
    { "type": "sphere", "center": [0.3, 0.5, 0], "radius": 0.5, "material": "ball" }
  ],
  "lights": [ { "type": "envmap", "file": "sky.exr", "scale": 1.5 } ]
}"#;

/// A direction in texel space: ±1 by a hash of the texel and channel.
fn direction(len: usize) -> Vec<f32> {
    (0..len as u64).map(|i| if (i.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40) & 1 == 0 { 1.0 } else { -1.0 }).collect()
}

/// Texels moved by `by` along `v`.
fn along(t: &glint::describe::Texels, v: &[f32], by: f32) -> ParamValue {
    let mut t = t.clone();
    for (i, p) in t.pixels.iter_mut().enumerate() {
        *p = rgb(p.r + by * v[3 * i], p.g + by * v[3 * i + 1], p.b + by * v[3 * i + 2]);
    }
    ParamValue::Image(t)
}

/// The gradient of image parameter `name` projected on direction `v`, against the finite
/// difference of renders along `v` with the same seeds: the mean of the paired differences,
/// its standard error, the mean finite difference, and the mean bound on its rounding.
fn along_direction(
    session: &mut Session,
    name: &str,
    texels: &glint::describe::Texels,
    v: &[f32],
    step: f32,
    seeds: u64,
) -> (f64, f64, f64, f64) {
    let (w, h) = (session.description().film.width as usize, session.description().film.height as usize);
    let g = adjoint(w, h);
    let cancel = AtomicBool::new(false);
    let (mut diffs, mut fds, mut rounding) = (Vec::new(), Vec::new(), Vec::new());
    for seed in 0..seeds {
        let grad = session.render_gradient(&[name.to_string()], &g, 8, seed, &cancel).unwrap().remove(0);
        assert_eq!(grad.shape, vec![texels.height, texels.width, 3], "{name}");
        let projected: f64 = grad.values.iter().zip(v).map(|(a, b)| a * *b as f64).sum();
        set(session, name, along(texels, v, step));
        let up = loss(session, &g, 8, seed);
        set(session, name, along(texels, v, -step));
        let down = loss(session, &g, 8, seed);
        set(session, name, ParamValue::Image(texels.clone()));
        let fd = (up - down) / (2.0 * step as f64);
        diffs.push(projected - fd);
        fds.push(fd);
        rounding.push(2f64.powi(-24) * (up.abs() + down.abs()) / (2.0 * step as f64));
    }
    let ((d, se), (fd, _), (r, _)) = (mean_se(&diffs), mean_se(&fds), mean_se(&rounding));
    (d, se, fd, r)
}

/// Per texel gradients (a bitmap texture's, an environment map's) against the finite
/// difference of renders along a direction that moves every texel: the gradient's inner
/// product with that direction is the derivative along it.
#[test]
fn texel_gradients_agree_with_finite_differences_along_a_direction() {
    let dir = ScratchDir::new("gradient-texels");
    let sky: Vec<Rgb> = (0..8 * 4)
        .map(|i| rgb(0.5 + 0.1 * (i % 8) as f32, 0.4 + 0.2 * (i / 8) as f32, 0.3 + 0.05 * (i % 5) as f32))
        .collect();
    glint::io::write_image(&glint::io::Image { width: 8, height: 4, pixels: sky }, &dir.join("sky.exr")).unwrap();
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/gradients/texture.exr");
    let scene = TEXEL_SCENE.replace("TEXTURE", &texture.to_string_lossy());
    std::fs::write(dir.join("scene.json"), scene).unwrap();
    let mut session = Session::open(&dir.join("scene.json"), &ReadOptions::default()).unwrap();
    let params = ["materials.floor.reflectance", "lights.0.data"];
    let z = z_critical(FALSE_ALARM, params.len());
    let mut failures = Vec::new();
    for name in params {
        let ParamValue::Image(texels) = get(&mut session, name) else { panic!("{name} is not an image") };
        let v = direction(texels.pixels.len() * 3);
        let step = 0.02;
        let (d, se, fd, r) = along_direction(&mut session, name, &texels, &v, step, 8);
        let allowed = z * se + r;
        println!("{name}: along the direction, gradient - finite difference {d:.2e} (allowed {allowed:.2e}), finite difference {fd:.4}");
        if d.abs() > allowed {
            failures.push(format!("{name}: gradient and finite difference differ by {d} (allowed {allowed:.2e})"));
        }
        if allowed > 0.2 * fd.abs() {
            failures.push(format!("{name}: cannot see a 20% error (allowed {allowed:.2e}, finite difference {fd})"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A reflectance of zero reflects nothing, yet raising it brightens the image: its gradient
/// is not zero, and agrees with a one-sided finite difference.
#[test]
fn a_black_reflectance_has_a_gradient() {
    let dir = ScratchDir::new("gradient-black");
    let mut session = open(&dir, Setup::DirectByLightSampling);
    let name = "materials.floor.reflectance";
    set(&mut session, name, ParamValue::Color(Rgb::BLACK));
    let g = adjoint(14, 12);
    let cancel = AtomicBool::new(false);
    let grad = session.render_gradient(&[name.to_string()], &g, 8, 3, &cancel).unwrap().remove(0).values;
    let base = loss(&mut session, &g, 8, 3);
    set(&mut session, name, ParamValue::Color(rgb(0.01, 0.0, 0.0)));
    let up = loss(&mut session, &g, 8, 3);
    let fd = (up - base) / 0.01;
    // Direct light only: the image is linear in the floor's reflectance, so the one-sided
    // difference is exact up to rounding.
    assert!(
        grad[0] > 0.0 && (grad[0] - fd).abs() <= 1e-4 * fd.abs() + 2f64.powi(-24) * up.abs() / 0.01,
        "{grad:?} against {fd}"
    );
}

/// The environment map's texel gradient through next-event estimation too: under MIS the
/// map's importance sampling reads the texels, so no finite difference with one seed is
/// smooth; but the image's expectation, and so the gradient's, does not depend on the
/// strategy, so the MIS gradient's mean (projected on a direction) must agree with that of
/// BSDF sampling alone, checked above against finite differences.
#[test]
fn environment_map_gradients_agree_across_strategies() {
    let dir = ScratchDir::new("gradient-env-strategies");
    let sky: Vec<Rgb> =
        (0..8 * 4).map(|i| rgb(0.2 + 0.3 * (i % 3) as f32, 0.5, 0.1 + 0.9 * ((i / 8) % 2) as f32)).collect();
    glint::io::write_image(&glint::io::Image { width: 8, height: 4, pixels: sky }, &dir.join("sky.exr")).unwrap();
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/gradients/texture.exr");
    std::fs::write(dir.join("scene.json"), TEXEL_SCENE.replace("TEXTURE", &texture.to_string_lossy())).unwrap();
    let mut session = Session::open(&dir.join("scene.json"), &ReadOptions::default()).unwrap();
    let g = adjoint(12, 10);
    let cancel = AtomicBool::new(false);
    let name = "lights.0.data";
    let v = direction(8 * 4 * 3);
    let projected = |session: &mut Session, strategy: glint::integrators::Strategy, seeds: std::ops::Range<u64>| {
        if let glint::integrators::Integrator::Path(p) = &mut session.edit().integrator {
            p.strategy = strategy;
        }
        let values: Vec<f64> = seeds
            .map(|seed| {
                let grad = session.render_gradient(&[name.to_string()], &g, 16, seed, &cancel).unwrap().remove(0);
                grad.values.iter().zip(&v).map(|(a, b)| a * *b as f64).sum()
            })
            .collect();
        mean_se(&values)
    };
    let (bsdf, se_bsdf) = projected(&mut session, glint::integrators::Strategy::Bsdf, 0..24);
    let (mis, se_mis) = projected(&mut session, glint::integrators::Strategy::Mis, 100..124);
    let se = (se_bsdf * se_bsdf + se_mis * se_mis).sqrt();
    let z = z_critical(FALSE_ALARM, 1);
    println!("along the direction: BSDF sampling {bsdf:.4} ± {se_bsdf:.4}, MIS {mis:.4} ± {se_mis:.4}");
    assert!((bsdf - mis).abs() <= z * se, "BSDF sampling {bsdf} ± {se_bsdf}, MIS {mis} ± {se_mis}");
    assert!(z * se < 0.2 * bsdf.abs(), "cannot see a 20% error: {bsdf} ± {se}");
}

/// A diffuse floor and ball lit by a rectangle whose radiance is a bitmap (importance-sampled
/// by its texels), and a dim sky so that BSDF sampling alone sees light everywhere.
const TEXTURED_LIGHT_SCENE: &str = r#"{
  "camera": { "position": [0, 2.5, 3.5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 50 },
  "film": { "width": 12, "height": 10, "filter": "box" },
  "integrator": { "type": "path", "max_depth": 3, "rr_depth": 100, "strategy": "STRATEGY" },
  "sampler": { "spp": 8, "seed": 0, "type": "independent" },
  "materials": {
    "floor": { "type": "diffuse", "reflectance": [0.6, 0.5, 0.4] },
    "ball": { "type": "diffuse", "reflectance": [0.3, 0.6, 0.5] }
  },
  "shapes": [
    { "type": "rectangle", "material": "floor",
      "transform": [{ "scale": [3, 3, 1] }, { "rotate": { "axis": [1, 0, 0], "angle": -90 } }] },
    { "type": "sphere", "center": [0.2, 0.4, 0], "radius": 0.4, "material": "ball" },
    { "type": "rectangle", "id": "panel", "emission": { "texture": "TEXTURE" },
      "transform": [{ "scale": [0.8, 0.8, 1] }, { "rotate": { "axis": [1, 0, 0], "angle": 90 } }, { "translate": [0, 1.6, 0] }] }
  ],
  "lights": [ { "type": "constant", "radiance": 0.05 } ]
}"#;

/// A textured area light's radiance, per texel: through emission seen by BSDF sampling,
/// against finite differences along a direction; through next-event estimation (whose
/// sampling reads the texels), against BSDF sampling's gradient, as for the environment map.
#[test]
fn textured_area_light_gradients() {
    let dir = ScratchDir::new("gradient-textured-light");
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/gradients/texture.exr");
    let open_with = |strategy: &str| {
        let scene = TEXTURED_LIGHT_SCENE.replace("TEXTURE", &texture.to_string_lossy()).replace("STRATEGY", strategy);
        std::fs::write(dir.join(format!("{strategy}.json")), scene).unwrap();
        Session::open(&dir.join(format!("{strategy}.json")), &ReadOptions::default()).unwrap()
    };
    let name = "shapes.panel.emission";
    let g = adjoint(12, 10);
    let cancel = AtomicBool::new(false);
    let mut bsdf = open_with("bsdf");
    let ParamValue::Image(texels) = get(&mut bsdf, name) else { panic!("{name} is not an image") };
    let v = direction(texels.pixels.len() * 3);
    let step = 0.05;
    let z = z_critical(FALSE_ALARM, 2);
    let (d, se, fd, r) = along_direction(&mut bsdf, name, &texels, &v, step, 16);
    println!(
        "emission seen: gradient - finite difference {d:.2e} (allowed {:.2e}), finite difference {fd:.4}",
        z * se + r
    );
    assert!(d.abs() <= z * se + r, "gradient and finite difference differ by {d}");
    assert!(z * se + r < 0.2 * fd.abs(), "cannot see a 20% error");

    // Across strategies, along a direction of positive, uneven weights (1 or 3 by texel and
    // channel), whose projection is large next to the noise yet depends on which texels get
    // which share.
    let weights: Vec<f64> = v.iter().map(|x| 2.0 + *x as f64).collect();
    let weigh =
        |grad: &glint::gradient::ParamGradient| -> f64 { grad.values.iter().zip(&weights).map(|(a, b)| a * b).sum() };
    let mut mis = open_with("mis");
    let along_weights = |s: &mut Session, seeds: std::ops::Range<u64>| -> Vec<f64> {
        seeds.map(|seed| weigh(&s.render_gradient(&[name.to_string()], &g, 8, seed, &cancel).unwrap()[0])).collect()
    };
    let ((a, se_a), (b, se_b)) =
        (mean_se(&along_weights(&mut bsdf, 0..32)), mean_se(&along_weights(&mut mis, 100..132)));
    let se = (se_a * se_a + se_b * se_b).sqrt();
    println!("along the direction: BSDF sampling {a:.4} ± {se_a:.4}, MIS {b:.4} ± {se_b:.4}");
    assert!((a - b).abs() <= z * se, "BSDF sampling {a} ± {se_a}, MIS {b} ± {se_b}");
    assert!(z * se < 0.2 * a.abs(), "cannot see a 20% error: {a} ± {se}");
}

/// Texels that do not fill their image, or are not finite, are refused before the build
/// whichever way they come (an edit, or a description made elsewhere), in one line.
#[test]
fn malformed_texels_are_refused() {
    let dir = ScratchDir::new("gradient-bad-texels");
    let sky: Vec<Rgb> = vec![Rgb::WHITE; 8 * 4];
    glint::io::write_image(&glint::io::Image { width: 8, height: 4, pixels: sky }, &dir.join("sky.exr")).unwrap();
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/gradients/texture.exr");
    std::fs::write(dir.join("scene.json"), TEXEL_SCENE.replace("TEXTURE", &texture.to_string_lossy())).unwrap();
    let short = glint::describe::Texels { width: 4, height: 4, pixels: vec![Rgb::WHITE; 15] };
    let nan = glint::describe::Texels { width: 1, height: 1, pixels: vec![rgb(f32::NAN, 0.0, 0.0)] };
    for (bad, says) in [(short, "cannot hold 15"), (nan, "not finite")] {
        // Through an edit: refused, nothing changed.
        let mut session = Session::open(&dir.join("scene.json"), &ReadOptions::default()).unwrap();
        let e = session.set_params(&[Param { name: "lights.0.data".into(), value: ParamValue::Image(bad.clone()) }]);
        let msg = e.unwrap_err().to_string();
        assert!(msg.contains(says) && !msg.contains('\n'), "{msg}");
        // Through the description: the build refuses it.
        let mut desc = session.description().clone();
        if let glint::describe::LightKind::EnvMap { texels, .. } = &mut desc.lights[0].light {
            *texels = Some(bad.clone());
        }
        let msg = Session::from_description(desc).world().err().expect("refused").to_string();
        assert!(msg.contains(says) && !msg.contains('\n'), "{msg}");
    }
}
