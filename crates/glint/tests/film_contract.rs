//! The film's contract: however the samples are scheduled (one go, pass ranges merged, pixel
//! regions merged, 1/2/3 threads, a checkpoint written, read back and continued), the image
//! and every AOV layer are bit-identical, with the box filter and with splatting filters; AOV layers match analytic values; adaptive
//! sampling keeps the image mean within noise while sampling flat regions less.

mod common;

use common::scenes::{add_glass_and_metal_balls, add_quad, camera, cornell_box_with, diffuse, path};
use common::scratch::ScratchDir;
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::integrators::{Integrator, Strategy, WhittedSettings};
use glint::lights::LightSelection;
use glint::materials::{DiffuseMaterial, Material, MaterialKind, Texture};
use glint::math::{vec3, Rgb, Transform, Vec3};
use glint::render::{
    read_film, render, render_passes, write_film, Adaptive, Aov, Film, FilmMeta, PassRequest, Rect, RenderSettings,
    Silent,
};
use glint::sampling::{PixelFilter, SamplerKind};
use glint::world::World;
use std::sync::atomic::AtomicBool;

const W: u32 = 14;
const H: u32 = 10;
const PASS_SPP: u32 = 3;
const SPP: u32 = 8; // three passes, the last one short

fn contract_scene() -> World {
    cornell_box_with(W, H, |b| {
        add_glass_and_metal_balls(b);
    })
}

fn settings() -> RenderSettings {
    RenderSettings { spp: SPP, seed: 11, sampler: SamplerKind::Sobol, tile_size: 4, ..Default::default() }
}

fn new_film(region: Rect) -> Film {
    Film::new(W, H, region, PASS_SPP, SPP, &Aov::ALL).unwrap()
}

fn new_filtered_film(region: Rect, filter: PixelFilter) -> Film {
    Film::with_filter(W, H, region, PASS_SPP, SPP, &Aov::ALL, filter).unwrap()
}

fn run(
    scene: &World,
    integrator: &Integrator,
    film: &mut Film,
    passes: std::ops::Range<u32>,
    adaptive: Option<Adaptive>,
) {
    let request = PassRequest { passes, adaptive };
    let settings = RenderSettings { filter: film.filter(), ..settings() };
    let outcome =
        render_passes(scene, integrator, &settings, film, &request, &AtomicBool::new(false), &Silent).unwrap();
    assert!(!outcome.cancelled);
    assert_eq!(outcome.stats.discarded_samples, 0);
}

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

/// The f32 bits of the image and of every layer.
fn bits(film: &Film) -> Vec<u32> {
    let mut out: Vec<u32> = film.image().pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect();
    for aov in Aov::ALL {
        out.extend(film.aov(aov).unwrap().data.iter().map(|v| v.to_bits()));
    }
    out
}

fn one_shot(scene: &World, integrator: &Integrator, threads: usize, adaptive: Option<Adaptive>) -> Film {
    one_shot_filtered(scene, integrator, threads, adaptive, PixelFilter::Box)
}

fn one_shot_filtered(
    scene: &World,
    integrator: &Integrator,
    threads: usize,
    adaptive: Option<Adaptive>,
    filter: PixelFilter,
) -> Film {
    on_threads(threads, || {
        let mut f = new_filtered_film(Rect::full(W, H), filter);
        run(scene, integrator, &mut f, 0..3, adaptive);
        f
    })
}

#[test]
fn every_schedule_gives_the_same_bits() {
    every_schedule_gives_the_same_bits_with(PixelFilter::Box, "box");
}

#[test]
fn every_schedule_gives_the_same_bits_when_splatting() {
    every_schedule_gives_the_same_bits_with(PixelFilter::Gaussian { stddev: 0.5 }, "gaussian");
    every_schedule_gives_the_same_bits_with(PixelFilter::Tent { radius: 1.5 }, "tent");
}

fn every_schedule_gives_the_same_bits_with(filter: PixelFilter, filter_name: &str) {
    let scene = contract_scene();
    let integrators = [("path", path(Strategy::Mis)), ("Whitted", Integrator::Whitted(WhittedSettings::default()))];
    let dir = ScratchDir::new(&format!("film-contract-{filter_name}"));
    let new_film = |region| new_filtered_film(region, filter);
    let settings = || RenderSettings { filter, ..settings() };
    for (name, integrator) in &integrators {
        let name = &format!("{name}, {filter_name} filter");
        let reference_film = one_shot_filtered(&scene, integrator, 2, None, filter);
        assert!(reference_film.is_complete());
        let reference = bits(&reference_film);
        let image_len = (W * H * 3) as usize;
        assert!(reference[..image_len].iter().any(|&b| b != 0), "{name}: black image");

        for threads in [1, 3] {
            assert!(
                bits(&one_shot_filtered(&scene, integrator, threads, None, filter)) == reference,
                "{name}: {threads} threads"
            );
        }

        // Pass ranges rendered into two films and merged (the later one first, for good measure).
        let mut late = new_film(Rect::full(W, H));
        run(&scene, integrator, &mut late, 1..3, None);
        let mut early = new_film(Rect::full(W, H));
        run(&scene, integrator, &mut early, 0..1, None);
        late.merge(&early).unwrap();
        assert!(late.is_complete());
        assert!(bits(&late) == reference, "{name}: pass ranges merged");

        // Two pixel regions, on different thread counts, merged.
        let left = Rect { x0: 0, y0: 0, x1: 5, y1: H };
        let right = Rect { x0: 5, y0: 0, x1: W, y1: H };
        let mut a = on_threads(1, || {
            let mut f = new_film(left);
            run(&scene, integrator, &mut f, 0..3, None);
            f
        });
        let b = on_threads(3, || {
            let mut f = new_film(right);
            run(&scene, integrator, &mut f, 0..3, None);
            f
        });
        a.merge(&b).unwrap();
        assert_eq!(a.region(), Rect::full(W, H));
        assert!(a.is_complete());
        assert!(bits(&a) == reference, "{name}: regions merged");

        // A checkpoint after the first pass, read back and continued.
        let path = dir.join(format!("{name}.glf"));
        let mut first = new_film(Rect::full(W, H));
        run(&scene, integrator, &mut first, 0..1, None);
        let meta = FilmMeta { scene_hash: 42, settings: name.to_string() };
        write_film(&path, &first, &meta).unwrap();
        let (mut resumed, read_meta) = read_film(&path).unwrap();
        assert_eq!(read_meta, meta);
        assert_eq!(resumed.passes_done(), 1);
        run(&scene, integrator, &mut resumed, 1..3, None);
        assert!(bits(&resumed) == reference, "{name}: checkpoint resumed");

        // The one-call renderer is the same sums in one pass of all samples.
        let old = render(&scene, integrator, &RenderSettings { variance: true, ..settings() }, &Silent);
        let old_bits: Vec<u32> = old.image.pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect();
        assert!(old_bits == reference[..image_len], "{name}: render() differs from the film");
        let var = reference_film.aov(Aov::Variance).unwrap().data;
        let old_var: Vec<f32> = old.variance.unwrap().pixels.iter().flat_map(|p| p.to_array()).collect();
        assert_eq!(old_var, var, "{name}: render()'s variance differs from the film's");
    }
}

#[test]
fn adaptive_renders_are_the_same_bits_across_threads_regions_and_checkpoints() {
    let scene = contract_scene();
    let integrator = path(Strategy::Mis);
    let adaptive = Some(Adaptive { threshold: 0.2, min_passes: 1 });
    let reference_film = one_shot(&scene, &integrator, 2, adaptive);
    let reference = bits(&reference_film);
    let spp = reference_film.aov(Aov::Spp).unwrap().data;
    assert!(spp.iter().any(|&n| n < SPP as f32), "no pixel stopped early: the test shows nothing");
    assert!(bits(&one_shot(&scene, &integrator, 3, adaptive)) == reference, "3 threads");

    let mut top = new_film(Rect { x0: 0, y0: 0, x1: W, y1: 4 });
    run(&scene, &integrator, &mut top, 0..3, adaptive);
    let mut bottom = new_film(Rect { x0: 0, y0: 4, x1: W, y1: H });
    run(&scene, &integrator, &mut bottom, 0..1, adaptive);
    let dir = ScratchDir::new("film-adaptive");
    let path = dir.join("bottom.glf");
    write_film(&path, &bottom, &FilmMeta::default()).unwrap();
    let (mut bottom, _) = read_film(&path).unwrap();
    run(&scene, &integrator, &mut bottom, 1..3, adaptive);
    top.merge(&bottom).unwrap();
    assert!(bits(&top) == reference, "regions, one resumed from a checkpoint");
}

#[test]
fn a_cancelled_pass_leaves_the_film_as_it_was_and_passes_cannot_be_rendered_twice() {
    let scene = contract_scene();
    let integrator = path(Strategy::Mis);
    let mut film = new_film(Rect::full(W, H));
    run(&scene, &integrator, &mut film, 0..1, None);
    let before = film.clone();
    let request = PassRequest { passes: 1..3, adaptive: None };
    let cancel = AtomicBool::new(true);
    let outcome = render_passes(&scene, &integrator, &settings(), &mut film, &request, &cancel, &Silent).unwrap();
    assert!(outcome.cancelled);
    assert_eq!(outcome.passes_rendered, 1..1);
    assert!(film == before, "a cancelled pass changed the film");
    let again = PassRequest { passes: 0..2, adaptive: None };
    let err = render_passes(&scene, &integrator, &settings(), &mut film, &again, &AtomicBool::new(false), &Silent)
        .unwrap_err();
    assert!(err.contains("overlaps"), "{err}");
}

/// A plane `z = 0` seen head-on from `z = DIST`, a unit sphere in front of it, sky light.
const DIST: f32 = 4.0;
const SPHERE_C: Vec3 = Vec3 { x: 0.9, y: -0.5, z: 1.2 };
const SPHERE_R: f32 = 0.5;
const PLANE_HALF: f32 = 3.0;
const CHECKS: f32 = 4.0;

fn checker() -> Texture {
    Texture::Checkerboard {
        color0: Rgb { r: 0.8, g: 0.3, b: 0.1 },
        color1: Rgb { r: 0.1, g: 0.2, b: 0.9 },
        uv_scale: [CHECKS, CHECKS],
        uv_offset: [0.0, 0.0],
    }
}

fn aov_scene() -> World {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let plane = b.add_material(Material::new(
        "checker",
        MaterialKind::Diffuse(DiffuseMaterial { reflectance: checker() }),
        true,
    ));
    let ball = diffuse(&mut b, "ball", Rgb::splat(0.5));
    let h = PLANE_HALF;
    add_quad(&mut b, [vec3(-h, -h, 0.0), vec3(h, -h, 0.0), vec3(h, h, 0.0), vec3(-h, h, 0.0)], plane, None);
    b.add_sphere(SPHERE_C, SPHERE_R, &Transform::IDENTITY, ball, None, false).unwrap();
    b.add_constant_environment(Rgb::splat(0.5));
    let cam = camera(vec3(0.0, 0.0, DIST), Vec3::ZERO, Vec3::Y, 50.0, 40, 30);
    b.finish(cam, LightSelection::Power).unwrap()
}

/// Where the ray through film position (fx, fy) meets the plane, if it does before the sphere.
fn plane_point(scene: &World, fx: f32, fy: f32) -> Option<(Vec3, f32)> {
    let r = scene.camera().generate_ray(fx, fy, [0.5, 0.5]);
    let t = -r.origin.z / r.dir.z;
    let p = r.origin + r.dir * t;
    let oc = r.origin - SPHERE_C;
    let disc = oc.dot(r.dir).powi(2) - (oc.dot(oc) - SPHERE_R * SPHERE_R);
    (disc < 0.0 && p.x.abs() < PLANE_HALF && p.y.abs() < PLANE_HALF).then_some((p, t))
}

fn hits_sphere(scene: &World, fx: f32, fy: f32) -> bool {
    let r = scene.camera().generate_ray(fx, fy, [0.5, 0.5]);
    let oc = r.origin - SPHERE_C;
    oc.dot(r.dir).powi(2) - (oc.dot(oc) - SPHERE_R * SPHERE_R) > 0.0
}

/// Pixel corners, a little outside the pixel (the box filter reaches its edges).
fn corners(x: u32, y: u32) -> [(f32, f32); 4] {
    let (x, y) = (x as f32, y as f32);
    [(x - 0.01, y - 0.01), (x + 1.01, y - 0.01), (x - 0.01, y + 1.01), (x + 1.01, y + 1.01)]
}

#[test]
fn aov_layers_match_analytic_values() {
    let scene = aov_scene();
    let (w, h) = (scene.camera().width, scene.camera().height);
    let mut film =
        Film::new(w, h, Rect::full(w, h), 4, 8, &[Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Position]).unwrap();
    let integrator = path(Strategy::Mis);
    let settings = RenderSettings { spp: 8, seed: 3, sampler: SamplerKind::Independent, ..Default::default() };
    let request = PassRequest { passes: 0..2, adaptive: None };
    render_passes(&scene, &integrator, &settings, &mut film, &request, &AtomicBool::new(false), &Silent).unwrap();
    let albedo = film.aov(Aov::Albedo).unwrap().data;
    let normal = film.aov(Aov::Normal).unwrap().data;
    let depth = film.aov(Aov::Depth).unwrap().data;
    let position = film.aov(Aov::Position).unwrap().data;
    let texture = checker();
    let (mut plane_pixels, mut sphere_pixels) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let on_plane: Vec<Option<(Vec3, f32)>> =
                corners(x, y).iter().map(|&(fx, fy)| plane_point(&scene, fx, fy)).collect();
            if on_plane.iter().all(Option::is_some) {
                let hits: Vec<(Vec3, f32)> = on_plane.into_iter().flatten().collect();
                let uv = |p: Vec3| [(p.x + PLANE_HALF) / (2.0 * PLANE_HALF), (p.y + PLANE_HALF) / (2.0 * PLANE_HALF)];
                let colours: Vec<Rgb> = hits.iter().map(|h| texture.eval(uv(h.0))).collect();
                // Depth is the distance along the ray, which varies over the pixel by at
                // most what it varies between the corners.
                let (t_min, t_max) = hits.iter().fold((f32::MAX, f32::MIN), |(a, b), h| (a.min(h.1), b.max(h.1)));
                let d = depth[i];
                assert!(
                    d >= t_min - 1e-4 && d <= t_max + 1e-4,
                    "pixel ({x}, {y}): depth {d} not in [{t_min}, {t_max}]"
                );
                if colours.iter().all(|c| *c == colours[0]) {
                    plane_pixels += 1;
                    let a = &albedo[i * 3..i * 3 + 3];
                    assert_eq!(a, colours[0].to_array(), "pixel ({x}, {y}): albedo");
                }
            }
            if corners(x, y).iter().all(|&(fx, fy)| hits_sphere(&scene, fx, fy)) {
                sphere_pixels += 1;
                // The normal is linear in the hit point, so the mean normal is (mean p − c) / r.
                let p = Vec3 { x: position[i * 3], y: position[i * 3 + 1], z: position[i * 3 + 2] };
                let expected = (p - SPHERE_C) / SPHERE_R;
                for k in 0..3 {
                    let got = normal[i * 3 + k];
                    assert!(
                        (got - expected.to_array()[k]).abs() < 1e-4,
                        "pixel ({x}, {y}): normal {got} vs {expected:?}"
                    );
                }
                // Points on the sphere average to a point just inside it.
                assert!((p - SPHERE_C).length() <= SPHERE_R * 1.0001, "pixel ({x}, {y}): position off the sphere");
            }
        }
    }
    assert!(plane_pixels > 200 && sphere_pixels > 10, "{plane_pixels} plane, {sphere_pixels} sphere pixels checked");
}

#[test]
fn adaptive_sampling_keeps_the_mean_and_samples_flat_regions_less() {
    // A lit diffuse plane on the lower half of the view, a constant sky on the upper half:
    // the sky's pixels are exactly flat and should stop after `min_passes`.
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let white = diffuse(&mut b, "white", Rgb::splat(0.7));
    add_quad(
        &mut b,
        [vec3(-50.0, 0.0, 50.0), vec3(50.0, 0.0, 50.0), vec3(50.0, 0.0, -50.0), vec3(-50.0, 0.0, -50.0)],
        white,
        None,
    );
    b.add_sphere(vec3(0.0, 0.5, 0.0), 0.5, &Transform::IDENTITY, white, None, false).unwrap();
    b.add_constant_environment(Rgb::splat(0.5));
    let cam = camera(vec3(0.0, 0.5, 4.0), vec3(0.0, 0.5, 0.0), Vec3::Y, 40.0, 24, 16);
    let scene = b.finish(cam, LightSelection::Power).unwrap();
    let (w, h) = (24, 16);
    let (pass_spp, spp, min_passes) = (4, 64, 2);
    let settings =
        RenderSettings { spp, seed: 9, sampler: SamplerKind::Independent, tile_size: 4, ..Default::default() };
    let integrator = path(Strategy::Mis);
    let render_film = |adaptive: Option<Adaptive>| {
        let mut film = Film::new(w, h, Rect::full(w, h), pass_spp, spp, &[]).unwrap();
        let request = PassRequest { passes: 0..film.pass_count(), adaptive };
        render_passes(&scene, &integrator, &settings, &mut film, &request, &AtomicBool::new(false), &Silent).unwrap();
        film
    };
    let uniform = render_film(None);
    let adaptive = render_film(Some(Adaptive { threshold: 0.05, min_passes }));
    let counts = adaptive.aov(Aov::Spp).unwrap().data;
    let mut sky = Vec::new();
    let mut ground = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let n = counts[(y * w + x) as usize];
            // Pixels whose every sample escapes (above the horizon and past the ball) are
            // exactly flat; those on the ground are noisy.
            let escapes = |(fx, fy): (f32, f32)| {
                let r = scene.camera().generate_ray(fx, fy, [0.5; 2]);
                let oc = r.origin - vec3(0.0, 0.5, 0.0);
                r.dir.y > 0.0 && oc.dot(r.dir).powi(2) - (oc.dot(oc) - 0.25) < 0.0
            };
            if corners(x, y).into_iter().all(escapes) {
                sky.push(n);
            } else if scene.camera().generate_ray(x as f32 + 0.5, y as f32 + 0.5, [0.5; 2]).dir.y < -0.05 {
                ground.push(n);
            }
        }
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    assert!(!sky.is_empty() && !ground.is_empty());
    assert!(
        sky.iter().all(|&n| n == (min_passes * pass_spp) as f32),
        "sky pixels should stop after min_passes: {sky:?}"
    );
    assert!(mean(&ground) > 2.0 * mean(&sky), "ground {} vs sky {} samples", mean(&ground), mean(&sky));
    assert!(mean(&ground) < spp as f32, "no ground pixel stopped early: the threshold shows nothing");

    // Image means agree within noise: the per-pixel variances of both means give the
    // standard error of the difference of the image means (pixels are independent). Both
    // renders share their first samples, which only makes the difference smaller.
    let (ua, va) = (uniform.image(), uniform.variance_image());
    let (ub, vb) = (adaptive.image(), adaptive.variance_image());
    let n = (w * h) as f64;
    for c in 0..3 {
        let diff: f64 =
            ua.pixels.iter().zip(&ub.pixels).map(|(a, b)| (a.channel(c) - b.channel(c)) as f64).sum::<f64>() / n;
        let var: f64 =
            va.pixels.iter().zip(&vb.pixels).map(|(a, b)| (a.channel(c) + b.channel(c)) as f64).sum::<f64>() / (n * n);
        let z = diff / var.sqrt();
        // 4.5 sigma: a one-in-150000 false alarm per channel.
        assert!(z.abs() < 4.5, "channel {c}: image means differ by {diff} ({z} standard errors)");
    }
}
