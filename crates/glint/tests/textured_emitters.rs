//! Textured area lights and emitting cylinders: light sampling reads the radiance texture at
//! the point it samples, and a ray that hits the light reads it at the hit, so the `direct`
//! integrator with emitter samples only, BSDF samples only and both (MIS) estimates the same
//! image. On a diffuse floor lit by high-contrast textured lights of every shape that emits
//! (a rectangle, sampled by solid angle; a disk mesh and a quad with flipped normals, sampled
//! by area; a sphere; cylinders, one textured), the image means and 8×8-block means of the
//! three agree pairwise within Šidák-corrected standard errors (independent seeds).

mod common;

use common::scenes::{add_quad, camera, diffuse, render_with};
use common::stats::{block_estimates, image_estimate, z_critical, Estimate, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::geometry::{disk_mesh, quad_mesh};
use glint::integrators::{DirectSettings, Integrator};
use glint::lights::{AreaEmission, Light, LightSelection, MeshImportance};
use glint::materials::{Bitmap, Texture};
use glint::math::{rgb, vec3, Frame, Ray, Rgb, Transform, Vec3};
use glint::sampling::{warp, Rng};
use glint::world::World;
use std::sync::Arc;

const SIZE: u32 = 32;
const BLOCK: usize = 8;
const SPP: u32 = 1024;

/// A 4×4 image whose texels differ by up to 30× in each channel, in no symmetric pattern:
/// reading it at a wrong uv (transposed, mirrored, of the other triangle) changes the light.
fn bitmap() -> Texture {
    let pixels = (0..16)
        .map(|i| {
            let (x, y) = ((i % 4) as f32, (i / 4) as f32);
            rgb(0.2 + 2.0 * x * x / 3.0, 0.2 + 5.8 * ((x + 2.0 * y) % 3.0) / 2.0, 0.2 + 2.0 * y)
        })
        .collect();
    let image = Arc::new(Bitmap { width: 4, height: 4, pixels });
    Texture::Bitmap { image, uv_scale: [1.0, 1.0], uv_offset: [0.0, 0.0] }
}

fn checker(scale: [f32; 2]) -> Texture {
    Texture::Checkerboard {
        color0: rgb(6.0, 1.0, 0.2),
        color1: rgb(0.2, 1.5, 5.0),
        uv_scale: scale,
        uv_offset: [0.0; 2],
    }
}

fn lit_by(radiance: Texture) -> Option<AreaEmission> {
    Some(AreaEmission { radiance, two_sided: false })
}

fn scene() -> World {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let floor = diffuse(&mut b, "floor", Rgb::splat(0.8));
    let lamp = b.black_material();
    let (a, y) = (3.0, 0.0);
    add_quad(&mut b, [vec3(-a, y, a), vec3(a, y, a), vec3(a, y, -a), vec3(-a, y, -a)], floor, None);
    // A rectangle facing down (sampled by solid angle from the floor).
    let down = [vec3(-1.6, 1.2, -0.4), vec3(-1.6, 1.2, 0.5), vec3(-0.6, 1.2, 0.5), vec3(-0.6, 1.2, -0.4)];
    add_quad(&mut b, down, lamp, lit_by(bitmap()));
    // The same, wound to face up and flipped to face down (corners of its triangles swapped).
    let up = [vec3(0.2, 1.0, 0.4), vec3(1.1, 1.0, 0.4), vec3(1.1, 1.0, -0.4), vec3(0.2, 1.0, -0.4)];
    let mesh = Arc::new(quad_mesh(up, BvhSplit::Sah));
    b.add_mesh_instance(&mesh, &Transform::IDENTITY, false, lamp, lit_by(bitmap()), true).unwrap();
    // A disk (a triangle fan: sampled by area), turned from +z to face down.
    let xf = Transform::translate(vec3(1.4, 1.4, 1.2))
        .then_after(&Transform::rotate(Vec3::X, 90.0))
        .then_after(&Transform::scale(vec3(0.5, 0.5, 0.5)).unwrap());
    let disk = Arc::new(disk_mesh(BvhSplit::Sah));
    b.add_mesh_instance(&disk, &xf, false, lamp, lit_by(checker([3.0, 2.0])), false).unwrap();
    b.add_sphere(vec3(-0.3, 0.9, -1.3), 0.35, &Transform::IDENTITY, lamp, lit_by(checker([4.0, 2.0])), false).unwrap();
    // A textured tube lying along x, and a plain one standing.
    let (p0, p1) = (vec3(-1.0, 0.5, 1.3), vec3(0.2, 0.5, 1.4));
    b.add_cylinder(p0, p1, 0.15, &Transform::IDENTITY, lamp, lit_by(bitmap()), false).unwrap();
    let (q0, q1) = (vec3(1.5, 0.0, -1.2), vec3(1.5, 0.8, -1.2));
    b.add_cylinder(q0, q1, 0.1, &Transform::IDENTITY, lamp, lit_by(Texture::Constant(Rgb::splat(4.0))), false).unwrap();
    let cam = camera(vec3(0.0, 5.0, 3.0), vec3(0.0, 0.0, 0.0), Vec3::Y, 55.0, SIZE, SIZE);
    b.finish(cam, LightSelection::Power).unwrap()
}

#[test]
fn light_and_bsdf_sampling_agree_on_textured_emitters() {
    let scene = scene();
    let strategies = [("emitter", 1, 0), ("bsdf", 0, 1), ("mis", 1, 1)];
    let estimates: Vec<(&str, Vec<[Estimate; 3]>)> = strategies
        .iter()
        .enumerate()
        .map(|(i, &(name, emitter_samples, bsdf_samples))| {
            let integrator = Integrator::Direct(DirectSettings { emitter_samples, bsdf_samples, hide_emitters: true });
            let out = render_with(&scene, &integrator, SPP, 900 + i as u64);
            let per_channel: Vec<Vec<Estimate>> = (0..3)
                .map(|c| std::iter::once(image_estimate(&out, c)).chain(block_estimates(&out, c, BLOCK)).collect())
                .collect();
            let regions = (0..per_channel[0].len()).map(|r| [0, 1, 2].map(|c| per_channel[c][r])).collect();
            (name, regions)
        })
        .collect();
    let regions = estimates[0].1.len();
    let k = z_critical(FALSE_ALARM, 3 * regions * 3);
    let mut failures = Vec::new();
    for i in 0..estimates.len() {
        for j in i + 1..estimates.len() {
            let ((sa, ra), (sb, rb)) = (&estimates[i], &estimates[j]);
            for r in 0..regions {
                for c in 0..3 {
                    let (x, y) = (ra[r][c], rb[r][c]);
                    let z = x.z_against(&y);
                    if r == 0 {
                        println!(
                            "{sa} vs {sb}, channel {c}: {:.5} ± {:.5} vs {:.5} ± {:.5}, z = {z:.2}",
                            x.mean, x.se, y.mean, y.se
                        );
                    }
                    // Written so that a NaN fails too.
                    if !(z.abs() <= k) {
                        let what = if r == 0 { "image".to_string() } else { format!("block {}", r - 1) };
                        failures.push(format!(
                            "{sa} vs {sb}, {what}, channel {c}: {:.5} ± {:.5} vs {:.5} ± {:.5} (z = {z:.1}, limit {k:.2})",
                            x.mean, x.se, y.mean, y.se
                        ));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One textured light alone (nothing occludes it) and the points, with their normals, at
/// which its irradiance is estimated: close to the light, where a few texels dominate.
fn lone_light(which: usize) -> (World, Vec<(Vec3, Vec3)>) {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let lamp = b.black_material();
    let below = |x: f32, z: f32, y: f32| (vec3(x, y, z), Vec3::Y);
    let points = match which {
        // A rectangle facing down, sampled by solid angle.
        0 => {
            let quad = [vec3(-0.5, 1.0, -0.5), vec3(0.5, 1.0, -0.5), vec3(0.5, 1.0, 0.5), vec3(-0.5, 1.0, 0.5)];
            add_quad(&mut b, quad, lamp, lit_by(bitmap()));
            vec![below(-0.3, -0.2, 0.85), below(0.25, 0.3, 0.9), below(0.1, -0.35, 0.8)]
        }
        // A quad wound to face up and flipped to face down.
        1 => {
            let up = [vec3(-0.5, 1.0, 0.5), vec3(0.5, 1.0, 0.5), vec3(0.5, 1.0, -0.5), vec3(-0.5, 1.0, -0.5)];
            let mesh = Arc::new(quad_mesh(up, BvhSplit::Sah));
            b.add_mesh_instance(&mesh, &Transform::IDENTITY, false, lamp, lit_by(bitmap()), true).unwrap();
            vec![below(-0.3, -0.2, 0.85), below(0.25, 0.3, 0.9), below(0.3, -0.3, 0.85)]
        }
        // A disk (a triangle fan, sampled by area), turned to face down.
        2 => {
            let xf = Transform::translate(vec3(0.0, 1.0, 0.0)).then_after(&Transform::rotate(Vec3::X, 90.0));
            let disk = Arc::new(disk_mesh(BvhSplit::Sah));
            b.add_mesh_instance(&disk, &xf, false, lamp, lit_by(checker([3.0, 2.0])), false).unwrap();
            vec![below(-0.3, -0.2, 0.9), below(0.4, 0.3, 0.85), below(0.0, 0.5, 0.9)]
        }
        // A sphere and a tube, from points just off them.
        3 => {
            b.add_sphere(Vec3::ZERO, 0.5, &Transform::IDENTITY, lamp, lit_by(checker([4.0, 2.0])), false).unwrap();
            [vec3(0.7, 0.1, 0.0), vec3(-0.2, 0.65, 0.3), vec3(0.1, -0.3, -0.6)].map(|p| (p, -p.normalize())).to_vec()
        }
        // A disk emitting a bitmap over its polar uvs (sampled by its texels), squashed to an
        // ellipse and turned to face down.
        5 => {
            let xf = Transform::translate(vec3(0.0, 1.0, 0.0))
                .then_after(&Transform::rotate(Vec3::X, 90.0))
                .then_after(&Transform::rotate(Vec3::Z, 25.0))
                .then_after(&Transform::scale(vec3(0.6, 0.45, 1.0)).unwrap());
            let disk = Arc::new(disk_mesh(BvhSplit::Sah));
            b.add_mesh_instance(&disk, &xf, false, lamp, lit_by(bitmap()), false).unwrap();
            vec![below(-0.3, -0.2, 0.9), below(0.35, 0.2, 0.85), below(0.05, 0.02, 0.95)]
        }
        _ => {
            let (p0, p1) = (vec3(0.0, 0.0, -1.0), vec3(0.0, 0.0, 1.0));
            b.add_cylinder(p0, p1, 0.4, &Transform::IDENTITY, lamp, lit_by(bitmap()), false).unwrap();
            [vec3(0.6, 0.0, 0.3), vec3(-0.3, 0.5, -0.5), vec3(0.1, -0.55, 0.7)]
                .map(|p| (p, -vec3(p.x, p.y, 0.0).normalize()))
                .to_vec()
        }
    };
    let cam = camera(vec3(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 45.0, 4, 4);
    (b.finish(cam, LightSelection::Power).unwrap(), points)
}

/// Mean and standard error of each channel of `n` samples.
fn estimate(n: usize, mut sample: impl FnMut() -> Rgb) -> [(f64, f64); 3] {
    let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        let v = sample();
        for (c, x) in [v.r, v.g, v.b].into_iter().enumerate() {
            s[c] += x as f64;
            s2[c] += (x as f64) * (x as f64);
        }
    }
    [0, 1, 2].map(|c| {
        let mean = s[c] / n as f64;
        (mean, ((s2[c] / n as f64 - mean * mean).max(0.0) / (n as f64 - 1.0)).sqrt())
    })
}

/// The irradiance a textured light gives points near it, estimated by light sampling and by
/// cosine-sampled rays that hit it (lights sampled by area, by solid angle and, the quads, the
/// tube and a disk that emit a bitmap, by their texels): the two read the texture at the
/// same uv and light sampling's density integrates to one over the light, so they agree
/// within Šidák-corrected standard errors at every point (a light that read its texture at
/// another point when sampled, or at the uv of the other triangle or corner order, fails).
#[test]
fn irradiance_from_textured_lights_agrees_between_light_and_ray_sampling() {
    const N: usize = 200_000;
    let lights = 6;
    let k = z_critical(FALSE_ALARM, lights * 3 * 3);
    let mut failures = Vec::new();
    for which in 0..lights {
        let (world, points) = lone_light(which);
        let light = &world.lights()[0];
        if which == 5 {
            assert!(
                matches!(light, Light::Mesh { importance: Some(i), .. } if matches!(**i, MeshImportance::Disk(_))),
                "the bitmap disk is not sampled by its texels"
            );
        }
        for (i, &(p, n)) in points.iter().enumerate() {
            let mut rng = Rng::new(40 + which as u64, i as u64);
            let by_light = estimate(N, || match light.sample_li(p, rng.next_2d()) {
                Some(ls) if ls.pdf > 0.0 => ls.radiance * (ls.wi.dot(n).max(0.0) / ls.pdf),
                _ => Rgb::BLACK,
            });
            let frame = Frame::from_normal(n);
            let mut rng = Rng::new(80 + which as u64, i as u64);
            let by_rays = estimate(N, || {
                let wi = frame.to_world(warp::cosine_hemisphere(rng.next_2d()));
                let ray = Ray::new(p, wi);
                match world.intersect(&ray) {
                    Some(hit) => world.emitted(&world.interaction(&ray, &hit), wi) * std::f32::consts::PI,
                    None => Rgb::BLACK,
                }
            });
            for c in 0..3 {
                let ((a, sa), (b, sb)) = (by_light[c], by_rays[c]);
                let z = (a - b) / (sa * sa + sb * sb).sqrt();
                if !(z.abs() <= k) || !(a > 0.0) {
                    failures.push(format!(
                        "light {which}, point {i}, channel {c}: {a:.5} ± {sa:.5} (light) vs {b:.5} ± {sb:.5} (rays), z = {z:.1}, limit {k:.2}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Light selection by power weighs a textured light by its texture's mean.
#[test]
fn a_textured_lights_power_is_its_mean_radiance() {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let lamp = b.black_material();
    let quad = [vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(0.0, 1.0, 0.0)];
    add_quad(&mut b, quad, lamp, lit_by(checker([1.0, 1.0])));
    add_quad(&mut b, quad.map(|p| p + vec3(0.0, 0.0, 2.0)), lamp, lit_by(Texture::Constant(rgb(3.1, 1.25, 2.6))));
    let cam = camera(vec3(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 45.0, 4, 4);
    let world = b.finish(cam, LightSelection::Power).unwrap();
    // The checker's mean, (6 + 0.2, 1 + 1.5, 0.2 + 5) / 2, is the second light's radiance.
    let (p0, p1) = (world.lights()[0].power(), world.lights()[1].power());
    assert!((p0 / p1 - 1.0).abs() < 1e-5, "{p0} vs {p1}");
    assert!((world.light_pmf(0) - 0.5).abs() < 1e-5, "{}", world.light_pmf(0));
}

/// The JSON format gives `emission` a texture as materials take one, and it builds into the
/// same kind of light as Mitsuba's textured `area` emitter.
#[test]
fn json_emission_takes_a_texture() {
    use glint::describe::TextureDesc;
    let text = r#"{
      "camera": { "position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40 },
      "film": { "width": 4, "height": 4 },
      "shapes": [
        { "type": "rectangle", "emission": { "checkerboard": [[4, 1, 0.5], 0.25], "uv_scale": [2, 2] } },
        { "type": "cylinder", "emission": [1, 2, 3] },
        { "type": "sphere", "emission": { "texture": "glow.png" } }
      ]
    }"#;
    let desc = glint::formats::json::read(std::path::Path::new("scene.json"), text).unwrap();
    let radiance = |i: usize| desc.shapes[i].emission.as_ref().unwrap().radiance.clone();
    assert!(
        matches!(radiance(0), TextureDesc::Checkerboard { color0, uv_scale: [2.0, 2.0], .. } if color0 == rgb(4.0, 1.0, 0.5))
    );
    assert_eq!(radiance(1), TextureDesc::constant(rgb(1.0, 2.0, 3.0)));
    assert!(matches!(radiance(2), TextureDesc::Bitmap { ref file, .. } if file.ends_with("glow.png")));
    // The bitmap does not exist: building names it, on one line.
    let err = glint::assemble::build(&desc, &Default::default()).map(|_| ()).unwrap_err().to_string();
    assert!(err.contains("glow.png") && !err.contains('\n'), "{err}");
    let mut desc = desc;
    desc.shapes.pop();
    let world = glint::assemble::build(&desc, &Default::default()).unwrap();
    assert!(matches!(world.lights()[1], glint::lights::Light::Cylinder { .. }));
}
