//! Small scenes built in code, and the render settings the statistical tests share.

use glint::accel::BvhSplit;
use glint::assemble::WorldBuilder;
use glint::bsdf::{Microfacet, MicrofacetKind};
use glint::camera::{Camera, FovAxis};
use glint::geometry::{cube_mesh, quad_mesh};
use glint::integrators::{Integrator, PathSettings, Strategy};
use glint::lights::{AreaEmission, LightSelection};
use glint::materials::{ConductorMaterial, DielectricMaterial, DiffuseMaterial, Material, MaterialKind, Texture};
use glint::math::{vec3, Rgb, Transform, Vec3};
use glint::render::{render, PixelFilter, RenderOutput, RenderSettings, Schedule, Silent};
use glint::sampling::SamplerKind;
use glint::world::World;
use std::sync::Arc;

pub fn camera(eye: Vec3, target: Vec3, up: Vec3, fov_degrees: f32, width: u32, height: u32) -> Camera {
    let to_world = Transform::look_at(eye, target, up).expect("valid camera");
    Camera::new(to_world, width, height, fov_degrees, FovAxis::Y)
}

/// Settings for statistical renders: per-pixel variance on, small tiles so that even tiny
/// images keep both cores busy.
pub fn settings(spp: u32, seed: u64) -> RenderSettings {
    // Independent samples: the tolerances below are derived from the variance of a mean of
    // independent samples (the Sobol default is checked against this in sampler_unbiased.rs).
    RenderSettings {
        spp,
        seed,
        filter: PixelFilter::Box,
        sampler: SamplerKind::Independent,
        variance: true,
        tile_size: 4,
        schedule: Schedule::OnePath,
    }
}

pub fn path(strategy: Strategy) -> Integrator {
    Integrator::Path(PathSettings { strategy, ..PathSettings::default() })
}

/// Renders with every path schedule, checks that they give the same bits, and returns the
/// image: so every validation test that renders through here holds for all of them.
pub fn render_with(scene: &World, integrator: &Integrator, spp: u32, seed: u64) -> RenderOutput {
    let out = render(scene, integrator, &settings(spp, seed), &Silent);
    assert_eq!(out.stats.discarded_samples, 0, "the renderer produced NaN, infinite or negative samples");
    for schedule in
        [Schedule::Wavefront, Schedule::WavefrontInterleaved, Schedule::WavefrontPackets, Schedule::WavefrontSimd]
    {
        let other = render(scene, integrator, &RenderSettings { schedule, ..settings(spp, seed) }, &Silent);
        assert_same_bits(&out, &other);
    }
    out
}

/// Asserts two renders gave the same image, variance and ray counts, bit for bit.
pub fn assert_same_bits(a: &RenderOutput, b: &RenderOutput) {
    let bits = |o: &RenderOutput| -> Vec<u32> {
        let mut v: Vec<u32> = o.image.pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect();
        if let Some(var) = &o.variance {
            v.extend(var.pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits));
        }
        v
    };
    let (x, y) = (bits(a), bits(b));
    let differ = x.iter().zip(&y).filter(|(p, q)| p != q).count();
    assert!(x.len() == y.len() && differ == 0, "the schedules' images differ in {differ} of {} values", x.len());
    assert_eq!(
        (a.stats.camera_rays, a.stats.rays, a.stats.shadow_rays),
        (b.stats.camera_rays, b.stats.rays, b.stats.shadow_rays),
        "the schedules traced different numbers of rays"
    );
}

pub fn emission(radiance: f32) -> Option<AreaEmission> {
    Some(AreaEmission::constant(Rgb::splat(radiance)))
}

/// A diffuse material, scattering on both faces.
pub fn diffuse(b: &mut WorldBuilder, name: &str, albedo: Rgb) -> u32 {
    b.add_material(Material::new(
        name,
        MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(albedo) }),
        true,
    ))
}

pub fn black(b: &mut WorldBuilder) -> u32 {
    b.black_material()
}

/// A GGX metal with reflectance 1 at every angle (eta 0, k 1), so that only the microfacet
/// model shapes the lobe.
pub fn rough_mirror(b: &mut WorldBuilder, name: &str, alpha: f32) -> u32 {
    b.add_material(Material::new(
        name,
        MaterialKind::Conductor(ConductorMaterial {
            roughness: Some(Microfacet::new(MicrofacetKind::Ggx, alpha).into()),
            eta: Rgb::BLACK,
            k: Rgb::WHITE,
            specular: Rgb::WHITE,
        }),
        true,
    ))
}

/// The quad p0 p1 p2 p3; its face (and, when it emits, its emission) points along
/// (p1 - p0) × (p2 - p0).
pub fn add_quad(b: &mut WorldBuilder, p: [Vec3; 4], material: u32, emission: Option<AreaEmission>) {
    let mesh = Arc::new(quad_mesh(p, BvhSplit::Sah));
    b.add_mesh_instance(&mesh, &Transform::IDENTITY, false, material, emission, false).unwrap();
}

/// An axis-aligned square of half-size `half` centred at `c` in the plane normal to `axis`
/// (0, 1, 2), facing `+axis` if `sign > 0`.
pub fn add_square(
    b: &mut WorldBuilder,
    c: Vec3,
    axis: usize,
    sign: f32,
    half: f32,
    material: u32,
    e: Option<AreaEmission>,
) {
    let mut t1 = [0.0f32; 3];
    t1[(axis + 1) % 3] = half;
    let mut t2 = [0.0f32; 3];
    t2[(axis + 2) % 3] = half;
    let (t1, t2) = (Vec3::from_array(t1), Vec3::from_array(t2));
    // (t1 × t2) points along +axis.
    let p = if sign > 0.0 {
        [c - t1 - t2, c + t1 - t2, c + t1 + t2, c - t1 + t2]
    } else {
        [c - t1 - t2, c - t1 + t2, c + t1 + t2, c + t1 - t2]
    };
    add_quad(b, p, material, e);
}

/// A box `[-1, 1]³` scaled, rotated about y and moved.
pub fn add_box(b: &mut WorldBuilder, size: Vec3, rotate_y: f32, at: Vec3, material: u32) {
    let xf = Transform::translate(at)
        .then_after(&Transform::rotate(Vec3::Y, rotate_y))
        .then_after(&Transform::scale(size).unwrap());
    b.add_mesh_instance(&Arc::new(cube_mesh(BvhSplit::Sah)), &xf, false, material, None, false).unwrap();
}

/// A Cornell-like box: white floor, ceiling and back wall, red left and green right walls,
/// two white boxes and a small square light under the ceiling. Open at the front.
pub fn cornell_box(width: u32, height: u32) -> World {
    cornell_box_with(width, height, |_| {})
}

/// The Cornell-like box with more objects added by `extra`.
pub fn cornell_box_with(width: u32, height: u32, extra: impl FnOnce(&mut WorldBuilder)) -> World {
    let mut b = WorldBuilder::new(BvhSplit::Sah);
    let white = diffuse(&mut b, "white", Rgb::splat(0.73));
    let red = diffuse(&mut b, "red", Rgb { r: 0.63, g: 0.065, b: 0.05 });
    let green = diffuse(&mut b, "green", Rgb { r: 0.14, g: 0.45, b: 0.09 });
    let light = black(&mut b);
    add_square(&mut b, vec3(0.0, 0.0, 0.0), 1, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(0.0, 2.0, 0.0), 1, -1.0, 1.0, white, None);
    add_square(&mut b, vec3(0.0, 1.0, -1.0), 2, 1.0, 1.0, white, None);
    add_square(&mut b, vec3(-1.0, 1.0, 0.0), 0, 1.0, 1.0, red, None);
    add_square(&mut b, vec3(1.0, 1.0, 0.0), 0, -1.0, 1.0, green, None);
    add_square(&mut b, vec3(0.0, 1.98, 0.0), 1, -1.0, 0.25, light, emission(17.0));
    add_box(&mut b, vec3(0.3, 0.3, 0.3), -17.0, vec3(0.33, 0.3, 0.35), white);
    add_box(&mut b, vec3(0.3, 0.6, 0.3), 18.0, vec3(-0.33, 0.6, -0.3), white);
    extra(&mut b);
    let cam = camera(vec3(0.0, 1.0, 3.9), vec3(0.0, 1.0, 0.0), Vec3::Y, 39.0, width, height);
    b.finish(cam, LightSelection::Power).unwrap()
}

/// The glass ball and the glossy metal ball the scheduling tests add to the Cornell box
/// (paths there branch, refract and end by Russian roulette); returns (glass, metal).
pub fn add_glass_and_metal_balls(b: &mut WorldBuilder) -> (u32, u32) {
    let glass = b.add_material(Material::new(
        "glass",
        MaterialKind::Dielectric(DielectricMaterial::smooth(1.5, Rgb::WHITE, Rgb::WHITE)),
        false,
    ));
    let metal = rough_mirror(b, "metal", 0.2);
    b.add_sphere(vec3(-0.4, 1.6, 0.4), 0.25, &Transform::IDENTITY, glass, None, false).unwrap();
    b.add_sphere(vec3(0.5, 1.3, -0.4), 0.2, &Transform::IDENTITY, metal, None, false).unwrap();
    (glass, metal)
}
