//! Monte Carlo error falls as spp^(-1/2): the root-mean-square error of renders at 4, 16,
//! 64 and 256 samples per pixel is fitted on a log-log scale and the slope must be -1/2
//! within its standard error (times a Šidák-corrected critical value).
//! - Cornell box against a 4096-spp reference render. E[(x - ref)²] = Var(x) + Var(ref) for
//!   independent renders, so the reference's own variance (which the renderer reports) is
//!   subtracted: what remains is exactly proportional to 1/spp.
//! - The emitting enclosure of the white-furnace test against its exact radiance 2: a bias
//!   would show as an error that stops falling.
//!
//! The standard error of each level's mean squared error comes from the spread of the
//! per-pixel squared errors; the delta method carries it to log RMSE and weighted least
//! squares to the slope. Each level uses its own seed, so levels are independent.

mod common;

use common::scenes::{cornell_box, emission, render_with};
use common::stats::{z_critical, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::geometry::cube_mesh;
use glint::integrators::{Integrator, PathSettings, Strategy};
use glint::lights::LightSelection;
use glint::materials::{DiffuseMaterial, Material, MaterialKind, Texture};
use glint::math::{vec3, Rgb, Transform, Vec3};
use glint::render::RenderOutput;
use glint::world::World;
use std::sync::Arc;

const LEVELS: [u32; 4] = [4, 16, 64, 256];

/// What the renders are compared with.
enum Truth<'a> {
    Reference(&'a RenderOutput),
    Exact(f64),
}

/// Mean over pixels of the channel-averaged squared error (less the reference's variance),
/// and its standard error.
fn mean_squared_error(out: &RenderOutput, truth: &Truth) -> (f64, f64) {
    let per_pixel: Vec<f64> = (0..out.image.pixels.len())
        .map(|i| {
            (0..3)
                .map(|c| {
                    let x = out.image.pixels[i].channel(c) as f64;
                    match truth {
                        Truth::Exact(v) => (x - v).powi(2),
                        Truth::Reference(r) => {
                            let var = r.variance.as_ref().unwrap().pixels[i].channel(c) as f64;
                            (x - r.image.pixels[i].channel(c) as f64).powi(2) - var
                        }
                    }
                })
                .sum::<f64>()
                / 3.0
        })
        .collect();
    let n = per_pixel.len() as f64;
    let mean = per_pixel.iter().sum::<f64>() / n;
    let var = per_pixel.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Weighted least-squares slope of log RMSE against log spp, and its standard error.
fn fitted_slope(scene: &World, integrator: &Integrator, truth: &Truth, seed: u64) -> (f64, f64) {
    let (mut xs, mut ys, mut ws) = (Vec::new(), Vec::new(), Vec::new());
    for (i, &spp) in LEVELS.iter().enumerate() {
        let out = render_with(scene, integrator, spp, seed + i as u64);
        let (mse, se) = mean_squared_error(&out, truth);
        assert!(mse > 0.0, "{spp} spp: mean squared error {mse}");
        // log RMSE = ½ log MSE, so its standard error is ½ se / MSE.
        let se_log = 0.5 * se / mse;
        println!("{spp:4} spp: RMSE {:.5} (log ± {se_log:.4})", mse.sqrt());
        xs.push((spp as f64).ln());
        ys.push(0.5 * mse.ln());
        ws.push(1.0 / (se_log * se_log));
    }
    let sw: f64 = ws.iter().sum();
    let xm = xs.iter().zip(&ws).map(|(x, w)| x * w).sum::<f64>() / sw;
    let ym = ys.iter().zip(&ws).map(|(y, w)| y * w).sum::<f64>() / sw;
    let sxx: f64 = xs.iter().zip(&ws).map(|(x, w)| w * (x - xm).powi(2)).sum();
    let sxy: f64 = xs.iter().zip(&ys).zip(&ws).map(|((x, y), w)| w * (x - xm) * (y - ym)).sum();
    (sxy / sxx, (1.0 / sxx).sqrt())
}

fn assert_slope_is_minus_half(label: &str, (slope, se): (f64, f64)) {
    // Two independent slope tests in this file share the false-alarm rate.
    let k = z_critical(FALSE_ALARM, 2);
    println!("{label}: slope {slope:.4} ± {se:.4}");
    assert!((slope + 0.5).abs() <= k * se, "{label}: RMSE slope {slope:.4} ± {se:.4}, expected -0.5 (limit {k:.2} se)");
}

#[test]
fn cornell_box_error_falls_as_inverse_sqrt_spp() {
    let scene = cornell_box(24, 24);
    // The light seen directly would put a few pixels of radiance 17 (half covered by the
    // light) in charge of the whole mean squared error; hiding it keeps the estimate of
    // the error stable without changing what converges.
    let integrator = Integrator::Path(PathSettings { hide_emitters: true, ..Default::default() });
    let reference = render_with(&scene, &integrator, 4096, 9999);
    let fit = fitted_slope(&scene, &integrator, &Truth::Reference(&reference), 1);
    assert_slope_is_minus_half("Cornell box", fit);
}

#[test]
fn furnace_error_falls_as_inverse_sqrt_spp() {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let wall = b.add_material(Material::new(
        "wall",
        MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(0.5)) }),
        false,
    ));
    b.add_sphere(Vec3::ZERO, 2.5, &Transform::IDENTITY, wall, emission(1.0), true).unwrap();
    let xf = Transform::translate(vec3(0.3, -0.4, 0.2)).then_after(&Transform::scale(Vec3::splat(0.6)).unwrap());
    b.add_mesh_instance(&Arc::new(cube_mesh(BvhSplit::Sah)), &xf, false, wall, emission(1.0), false).unwrap();
    let cam = glint::camera::Camera::new(
        Transform::look_at(vec3(-0.8, 0.8, -1.8), vec3(0.2, -0.3, 0.0), Vec3::Y).unwrap(),
        24,
        24,
        70.0,
        glint::camera::FovAxis::Y,
    );
    let scene = b.finish(cam, LightSelection::Power).unwrap();
    let integrator = Integrator::Path(PathSettings { strategy: Strategy::Mis, ..Default::default() });
    let fit = fitted_slope(&scene, &integrator, &Truth::Exact(2.0), 100);
    assert_slope_is_minus_half("furnace", fit);
}
