//! Light samplers against their own densities. For a light seen from a point, directions
//! are binned on the plane tangent to the direction of the light (a grid that is not the
//! sampler's own parametrization), and the counts are compared by a chi-square test with
//! the density `pdf_li` integrated over each bin by quadrature. That checks, at once, that
//! the sampler draws the density it reports, that the density integrates to one over the
//! directions that meet the light, and (each sample's `pdf` against `pdf_li` for the same
//! direction) that a BSDF-sampled direction is given the density the light sampler would
//! have given it, which multiple importance sampling relies on.
//!
//! Cases: spheres seen from outside (cone sampling), near and far; rectangles near enough
//! to be sampled by solid angle, and one so far that it is sampled by area; a rectangle
//! emitting a high-contrast bitmap, sampled by its texels; a disk (the fan of triangles
//! every disk is made as, turned, squashed into an ellipse and with its normals flipped)
//! emitting the same bitmap over its polar uvs, sampled by its texels, in solid angle and
//! again in its uv square.
//!
//! A sphere and a cylinder emitting a bitmap are sampled by its texels over their whole
//! surface (samples on the far side are refused), with a density in solid angle that grows
//! without bound towards their silhouettes; they are checked in their uv square instead, by
//! the density per unit uv that `pdf_li` implies (times cos / d² and the area Jacobian) over
//! the part seen from the point, and the share of refused samples.

mod common;

use common::bsdf_check::chi2_test;
use common::stats::{sidak, FALSE_ALARM};
use glint::accel::BvhSplit;
use glint::geometry::{disk_mesh, quad_mesh, Cylinder, Sphere, DISK_SEGMENTS};
use glint::lights::{Light, MeshEmitter, MeshImportance};
use glint::materials::{Bitmap, Texture};
use glint::math::Transform;
use glint::math::{rgb, vec3, Frame, Ray, Rgb, Vec3};
use glint::sampling::Rng;
use std::sync::Arc;

const SAMPLES: u64 = 200_000;
const BINS: usize = 12;
/// Quadrature: each bin is split into SUB² cells, and cells that the light's silhouette
/// crosses are split further, REFINE times (a cell split 2^REFINE ways a side).
const SUB: usize = 12;
const REFINE: u32 = 5;

/// What a direction from the reference point meets on the light: point and normal.
type Hit = Box<dyn Fn(Vec3, Vec3) -> Option<(Vec3, Vec3)>>;

struct Case {
    label: &'static str,
    light: Light,
    p: Vec3,
    /// Towards the light's centre: the tangent plane's normal.
    axis: Vec3,
    /// Half-width of the grid on the tangent plane (covers the whole light).
    extent: f32,
    hit: Hit,
}

fn sphere_case(label: &'static str, center: Vec3, radius: f32, p: Vec3) -> Case {
    let s = Sphere::new(center, radius);
    let d = (center - p).length();
    let hit: Hit = Box::new(move |o, w| {
        let t = s.intersect(&Ray::new(o, w))?;
        let q = o + w * t;
        Some((q, (q - center).normalize()))
    });
    Case {
        label,
        light: Light::sphere(0, s, Texture::Constant(Rgb::WHITE), false),
        p,
        axis: (center - p).normalize(),
        extent: 1.02 * radius / (d * d - radius * radius).sqrt(),
        hit,
    }
}

/// A rectangle `corner + s ex + t ey` (ex ⟂ ey) emitting towards `p`, sampled from there by
/// solid angle or by area as `by_solid_angle` says.
fn rectangle_case(label: &'static str, corner: Vec3, ex: Vec3, ey: Vec3, p: Vec3, by_solid_angle: bool) -> Case {
    let (c1, c2, c3) = (corner + ex, corner + ex + ey, corner + ey);
    let mut n = ex.cross(ey).normalize();
    let mut tris = [[corner, c1, c2], [corner, c2, c3]];
    if n.dot(p - corner) < 0.0 {
        tris = [[corner, c2, c1], [corner, c3, c2]];
        n = -n;
    }
    let emitter = MeshEmitter::new(tris.to_vec()).unwrap();
    assert!(emitter.rectangle.is_some(), "{label}: not detected as a rectangle");
    assert_eq!(emitter.samples_by_solid_angle(p), by_solid_angle, "{label}: the other sampler");
    let center = corner + (ex + ey) * 0.5;
    let axis = (center - p).normalize();
    let frame = Frame::from_normal(axis);
    let extent = [corner, c1, c2, c3]
        .iter()
        .map(|&c| {
            let l = frame.to_local(c - p);
            (l.x / l.z).abs().max((l.y / l.z).abs())
        })
        .fold(0.0f32, f32::max)
        * 1.02;
    let hit: Hit = Box::new(move |o, w| {
        let t = (corner - o).dot(n) / w.dot(n);
        if !(t > 0.0) {
            return None;
        }
        let q = o + w * t;
        let (s, r) = ((q - corner).dot(ex) / ex.length_squared(), (q - corner).dot(ey) / ey.length_squared());
        ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&r)).then_some((q, n))
    });
    Case { label, light: Light::mesh(0, Arc::new(emitter), Texture::Constant(Rgb::WHITE), false), p, axis, extent, hit }
}

/// An 8 × 6 bitmap of a few bright texels (up to 400× the rest) on a dim, uneven ground.
fn contrast_bitmap() -> Texture {
    let pixels = (0..48)
        .map(|k| match k {
            9 => rgb(60.0, 40.0, 20.0),
            30 => rgb(5.0, 30.0, 50.0),
            47 => Rgb::splat(20.0),
            k => Rgb::splat(0.05 + 0.1 * ((k * 7) % 5) as f32),
        })
        .collect();
    Texture::Bitmap { image: Arc::new(Bitmap { width: 8, height: 6, pixels }), uv_scale: [1.0; 2], uv_offset: [0.0; 2] }
}

/// The tangent-plane half-width that covers `points` seen from `p` along `axis`.
fn extent_of(points: impl Iterator<Item = Vec3>, p: Vec3, axis: Vec3) -> f32 {
    let frame = Frame::from_normal(axis);
    let e = points.map(|c| frame.to_local(c - p)).map(|l| (l.x / l.z).abs().max((l.y / l.z).abs())).fold(0.0, f32::max);
    e * 1.02
}

fn textured_rectangle_case(p: Vec3) -> Case {
    let quad = [vec3(-0.6, 1.0, -0.4), vec3(0.6, 1.0, -0.4), vec3(0.6, 1.0, 0.4), vec3(-0.6, 1.0, 0.4)];
    let mesh = Arc::new(quad_mesh(quad, BvhSplit::Sah));
    // Wound to face down, towards p.
    let tris = (0..2).map(|t| mesh.vertices(t)).collect();
    let emitter = MeshEmitter::of_mesh(tris, mesh, false).unwrap();
    let light = Light::mesh(0, Arc::new(emitter), contrast_bitmap(), false);
    assert!(matches!(&light, Light::Mesh { importance: Some(_), .. }), "not sampled by its texels");
    let hit: Hit = Box::new(move |o, w| {
        let t = (1.0 - o.y) / w.y;
        let q = o + w * t;
        (t > 0.0 && q.x.abs() <= 0.6 && q.z.abs() <= 0.4).then_some((q, vec3(0.0, -1.0, 0.0)))
    });
    let axis = (vec3(0.0, 1.0, 0.0) - p).normalize();
    Case { label: "textured rectangle", light, p, axis, extent: extent_of(quad.into_iter(), p, axis), hit }
}

/// The disk of `textured_disk`, written out here independently of the light's own map: the
/// unit disk's fan of `DISK_SEGMENTS` triangles scaled to 0.6 × 0.4, turned to lie in the
/// plane y = 1 facing up and, by flipped normals, emitting downwards. Local (x, y) is world
/// (x / 0.6, -z / 0.4); the azimuth runs from +x towards -z.
struct DiskGeometry;

impl DiskGeometry {
    const HALF: [f32; 2] = [0.6, 0.4];

    fn transform() -> Transform {
        // (x, y, 0) goes to (0.6 x, 1, -0.4 y), as `textured_disk` checks.
        Transform::translate(vec3(0.0, 1.0, 0.0))
            .then_after(&Transform::rotate(Vec3::X, -90.0))
            .then_after(&Transform::scale(vec3(Self::HALF[0], Self::HALF[1], 1.0)).unwrap())
    }

    fn local(q: Vec3) -> (f32, f32) {
        (q.x / Self::HALF[0], -q.z / Self::HALF[1])
    }

    fn world(x: f32, y: f32) -> Vec3 {
        vec3(x * Self::HALF[0], 1.0, -y * Self::HALF[1])
    }

    /// The polygon's point at polar uv (u, v): segment k = ⌊vN⌋, the point t = vN - k along
    /// its rim edge, scaled by u from the centre; with the area per unit uv, u N |e0 × e1|.
    fn at(uv: [f32; 2]) -> (Vec3, f32) {
        let n = DISK_SEGMENTS as f32;
        let k = (uv[1] * n).floor().min(n - 1.0);
        let t = uv[1] * n - k;
        let rim = |j: f32| {
            let phi = 2.0 * std::f32::consts::PI * j / n;
            (phi.cos(), phi.sin())
        };
        let ((x0, y0), (x1, y1)) = (rim(k), rim(k + 1.0));
        let jacobian = n * (x0 * y1 - x1 * y0) * Self::HALF[0] * Self::HALF[1];
        (Self::world(uv[0] * (x0 + t * (x1 - x0)), uv[0] * (y0 + t * (y1 - y0))), uv[0] * jacobian)
    }

    /// The polar uv of a point of the polygon.
    fn uv(q: Vec3) -> [f32; 2] {
        let n = DISK_SEGMENTS as f32;
        let (x, y) = Self::local(q);
        let turn = y.atan2(x) / (2.0 * std::f32::consts::PI);
        let turn = if turn < 0.0 { turn + 1.0 } else { turn };
        let k = (turn * n).floor().min(n - 1.0);
        // Solve (x, y) = u ((1 - t) r_k + t r_k+1).
        let rim = |j: f32| {
            let phi = 2.0 * std::f32::consts::PI * j / n;
            (phi.cos(), phi.sin())
        };
        let ((x0, y0), (x1, y1)) = (rim(k), rim(k + 1.0));
        let det = x0 * y1 - x1 * y0;
        let (a, b) = ((x * y1 - y * x1) / det, (x0 * y - y0 * x) / det);
        let u = a + b;
        let t = if u > 0.0 { b / u } else { 0.5 };
        [u, (k + t.clamp(0.0, 1.0)) / n]
    }

    /// Whether a point of the plane is on the polygon.
    fn inside(q: Vec3) -> bool {
        let [u, _] = Self::uv(q);
        u <= 1.0
    }
}

fn textured_disk() -> Light {
    let xf = DiskGeometry::transform();
    let mesh = Arc::new(disk_mesh(BvhSplit::Sah));
    // What the builder hands the light: world-space triangles, corners 1 and 2 swapped for the
    // flipped normals, and the mesh for its uvs.
    let tris = (0..mesh.indices.len())
        .map(|t| mesh.vertices(t).map(|v| xf.point(v)))
        .map(|[a, b, c]| [a, c, b])
        .collect::<Vec<_>>();
    let [a, b, c] = tris[0];
    assert!((b - a).cross(c - a).y < 0.0, "the disk does not face down");
    for (x, y) in [(1.0, 0.0), (0.0, 1.0)] {
        assert!((xf.point(vec3(x, y, 0.0)) - DiskGeometry::world(x, y)).length() < 1e-6);
    }
    let emitter = MeshEmitter::of_mesh(tris, mesh, true).unwrap();
    let light = Light::mesh(0, Arc::new(emitter), contrast_bitmap(), false);
    assert!(
        matches!(&light, Light::Mesh { importance: Some(i), .. } if matches!(**i, MeshImportance::Disk(_))),
        "not sampled by its texels"
    );
    light
}

fn textured_disk_case(p: Vec3) -> Case {
    let hit: Hit = Box::new(move |o, w| {
        let t = (1.0 - o.y) / w.y;
        let q = o + w * t;
        (t > 0.0 && DiskGeometry::inside(q)).then_some((q, vec3(0.0, -1.0, 0.0)))
    });
    let axis = (vec3(0.0, 1.0, 0.0) - p).normalize();
    let rim = (0..64).map(|k| {
        let phi = 2.0 * std::f32::consts::PI * k as f32 / 64.0;
        DiskGeometry::world(phi.cos(), phi.sin())
    });
    Case { label: "textured disk", light: textured_disk(), p, axis, extent: extent_of(rim, p, axis), hit }
}

fn cases() -> Vec<Case> {
    vec![
        textured_rectangle_case(vec3(0.1, 0.2, 0.05)),
        textured_disk_case(vec3(0.15, 0.3, -0.1)),
        sphere_case("sphere at 3 radii", vec3(0.3, 3.0, -0.2), 1.0, Vec3::ZERO),
        sphere_case("sphere filling 110 degrees", vec3(0.0, 0.0, 0.6), 0.5, Vec3::ZERO),
        sphere_case("small distant sphere", vec3(40.0, 10.0, 5.0), 0.2, vec3(0.1, 0.2, 0.3)),
        rectangle_case(
            "rectangle overhead",
            vec3(-1.0, 0.5, -0.7),
            vec3(2.0, 0.0, 0.0),
            vec3(0.0, 0.0, 1.4),
            Vec3::ZERO,
            true,
        ),
        rectangle_case(
            // Close to the light's plane and beside its edge, where area sampling's density
            // varies 8x or more across the light (the bound for solid-angle sampling).
            "oblique rectangle off to the side",
            vec3(0.4, 0.2, 0.9),
            vec3(0.6, 0.8, 0.0),
            vec3(0.0, 0.0, 0.7),
            vec3(0.23, 0.14, 1.1),
            true,
        ),
        rectangle_case(
            "far rectangle (area sampling)",
            vec3(20.0, 0.0, 0.0),
            vec3(0.0, 0.1, 0.0),
            vec3(0.0, 0.0, 0.1),
            Vec3::ZERO,
            false,
        ),
    ]
}

/// The direction through tangent-plane coordinates (x, y).
fn direction(frame: &Frame, x: f32, y: f32) -> Vec3 {
    frame.to_world(vec3(x, y, 1.0)).normalize()
}

/// pdf · dω/dxdy at tangent-plane coordinates (x, y), and whether that direction meets the light.
fn density(c: &Case, frame: &Frame, x: f64, y: f64) -> (f64, bool) {
    let w = direction(frame, x as f32, y as f32);
    let Some((q, n)) = (c.hit)(c.p, w) else { return (0.0, false) };
    (c.light.pdf_li(c.p, w, q, n) as f64 * (1.0 + x * x + y * y).powf(-1.5), true)
}

/// ∫ over the square cell at (x, y) of side h: a 2×2 Gauss rule where the cell lies wholly
/// on or off the light (by a 3×3 grid of probes), split in four where the edge crosses it.
fn integrate_cell(c: &Case, frame: &Frame, x: f64, y: f64, h: f64, depth: u32) -> f64 {
    let probes = [0.0, 0.5, 1.0];
    let hits = probes
        .iter()
        .flat_map(|a| probes.iter().map(move |b| (a, b)))
        .filter(|(a, b)| density(c, frame, x + *a * h, y + *b * h).1)
        .count();
    if hits == 0 || hits == 9 || depth == 0 {
        if hits == 0 {
            return 0.0;
        }
        let g = 0.5 - 0.5 / 3f64.sqrt();
        let nodes = [(g, g), (1.0 - g, g), (g, 1.0 - g), (1.0 - g, 1.0 - g)];
        return nodes.iter().map(|(a, b)| density(c, frame, x + a * h, y + b * h).0).sum::<f64>() * h * h / 4.0;
    }
    let k = h / 2.0;
    [(0.0, 0.0), (k, 0.0), (0.0, k), (k, k)]
        .iter()
        .map(|(a, b)| integrate_cell(c, frame, x + a, y + b, k, depth - 1))
        .sum()
}

/// ∫ pdf dω over each bin (dω = dx dy / (1 + x² + y²)^(3/2) on the tangent plane).
fn expected_fractions(c: &Case, frame: &Frame) -> Vec<f64> {
    let e = c.extent as f64;
    let h = 2.0 * e / (BINS * SUB) as f64;
    let mut bins = vec![0.0f64; BINS * BINS];
    for i in 0..BINS * SUB {
        for j in 0..BINS * SUB {
            let (x, y) = (-e + i as f64 * h, -e + j as f64 * h);
            bins[(i / SUB) * BINS + j / SUB] += integrate_cell(c, frame, x, y, h, REFINE);
        }
    }
    bins
}

#[test]
fn light_samplers_draw_the_density_they_report() {
    let all = cases();
    let alpha = sidak(FALSE_ALARM, all.len());
    let mut failures = Vec::new();
    for (k, c) in all.iter().enumerate() {
        let frame = Frame::from_normal(c.axis);
        let mut rng = Rng::new(0x5eed + k as u64, 0);
        let mut observed = vec![0u64; BINS * BINS + 1];
        let mut worst_pdf_mismatch = 0.0f64;
        for _ in 0..SAMPLES {
            let u = [rng.next_f32(), rng.next_f32()];
            let Some(ls) = c.light.sample_li(c.p, u) else {
                observed[BINS * BINS] += 1;
                continue;
            };
            let l = frame.to_local(ls.wi);
            let (x, y) = (l.x / l.z, l.y / l.z);
            let cell = |v: f32| ((v + c.extent) / (2.0 * c.extent) * BINS as f32).floor();
            let (bx, by) = (cell(x), cell(y));
            if l.z <= 0.0 || !(0.0..BINS as f32).contains(&bx) || !(0.0..BINS as f32).contains(&by) {
                observed[BINS * BINS] += 1;
                continue;
            }
            observed[bx as usize * BINS + by as usize] += 1;
            // The density a BSDF-sampled ray along the same direction would be given.
            if let Some((q, n)) = (c.hit)(c.p, ls.wi) {
                let pdf = c.light.pdf_li(c.p, ls.wi, q, n) as f64;
                worst_pdf_mismatch = worst_pdf_mismatch.max((pdf / ls.pdf as f64 - 1.0).abs());
            }
        }
        let fractions = expected_fractions(c, &frame);
        let total: f64 = fractions.iter().sum();
        let mut expected: Vec<f64> = fractions.iter().map(|f| f * SAMPLES as f64).collect();
        // Outside the grid or no sample: nothing is expected there (a tiny amount lets the
        // quadrature's shortfall be pooled rather than declared impossible).
        expected.push((SAMPLES as f64 * (1.0 - total)).max(1e-9));
        let outcome = chi2_test(&observed, &expected);

        println!("{}: ∫pdf = {total:.5}, worst pdf mismatch {worst_pdf_mismatch:.2e}, {outcome:?}", c.label);
        // The quadrature's error along the silhouette is far below this.
        if (total - 1.0).abs() > 1e-3 {
            failures.push(format!("{}: the density integrates to {total:.5}, not 1", c.label));
        }
        if worst_pdf_mismatch > 1e-3 {
            failures.push(format!("{}: pdf_li differs from the sample's pdf by {worst_pdf_mismatch:.2e}", c.label));
        }
        match outcome {
            Ok(o) if o.p_value >= alpha => {}
            Ok(o) => failures
                .push(format!("{}: chi-square {:.1} on {} dof, p = {:.2e}", c.label, o.statistic, o.dof, o.p_value)),
            Err(e) => failures.push(format!("{}: {e}", c.label)),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A light emitting `contrast_bitmap` over a curved surface, the point it is seen from, and
/// the map from uv to the surface (point, outward normal, area per unit uv).
struct CurvedCase {
    label: &'static str,
    light: Light,
    p: Vec3,
    surface: Box<dyn Fn([f32; 2]) -> (Vec3, Vec3, f32)>,
    uv_of: Box<dyn Fn(Vec3) -> [f32; 2]>,
}

fn curved_cases() -> Vec<CurvedCase> {
    // Turned, so that its uvs are not the world's.
    let axes = [vec3(0.0, 0.6, 0.8), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.8, -0.6)];
    let s = Sphere { center: vec3(0.2, 1.5, -0.3), radius: 0.5, axes };
    let c = Cylinder::new(vec3(-0.7, 1.2, 0.1), vec3(0.8, 1.3, -0.2), 0.3, &Transform::IDENTITY).unwrap();
    let two_pi_sq = 2.0 * std::f32::consts::PI * std::f32::consts::PI;
    vec![
        CurvedCase {
            label: "textured sphere",
            light: Light::sphere(0, s, contrast_bitmap(), false),
            p: Vec3::ZERO,
            surface: Box::new(move |uv| {
                let (st, ct) = (std::f32::consts::PI * uv[1]).sin_cos();
                let (sp, cp) = (2.0 * std::f32::consts::PI * uv[0]).sin_cos();
                let n = s.axes[0] * (st * cp) + s.axes[1] * (st * sp) + s.axes[2] * ct;
                (s.center + n * s.radius, n, two_pi_sq * s.radius * s.radius * st)
            }),
            uv_of: Box::new(move |q| s.uv((q - s.center).normalize())),
        },
        CurvedCase {
            label: "textured cylinder",
            light: Light::cylinder(0, c, contrast_bitmap(), false),
            p: vec3(0.1, 0.0, 0.0),
            surface: Box::new(move |uv| {
                let q = c.sample(uv);
                (q.p, q.n, c.area())
            }),
            uv_of: Box::new(move |q| c.uv_at(q)),
        },
        CurvedCase {
            label: "textured disk",
            light: textured_disk(),
            p: vec3(-0.2, 0.4, 0.1),
            surface: Box::new(|uv| {
                let (q, jacobian) = DiskGeometry::at(uv);
                (q, vec3(0.0, -1.0, 0.0), jacobian)
            }),
            uv_of: Box::new(DiskGeometry::uv),
        },
    ]
}

/// The density per unit uv that `pdf_li` implies at `uv`, where the point sees the light
/// there (None where it does not).
fn uv_density(c: &CurvedCase, uv: [f32; 2]) -> Option<f64> {
    let (q, n, jacobian) = (c.surface)(uv);
    let d = q - c.p;
    let wi = d.normalize();
    let cos = -n.dot(wi);
    (cos > 0.0).then(|| c.light.pdf_li(c.p, wi, q, n) as f64 * cos as f64 / d.length_squared() as f64 * jacobian as f64)
}

/// ∫ of `uv_density` over a uv cell: the midpoint rule where its corners agree on whether
/// the light is seen, split in four (`depth` times) where the terminator crosses it.
fn integrate_uv_cell(c: &CurvedCase, at: [f32; 2], size: [f32; 2], depth: u32) -> f64 {
    let seen = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]
        .iter()
        .filter(|k| uv_density(c, [at[0] + k[0] * size[0], at[1] + k[1] * size[1]]).is_some())
        .count();
    if depth == 0 || seen == 0 || seen == 4 {
        let mid = uv_density(c, [at[0] + 0.5 * size[0], at[1] + 0.5 * size[1]]).unwrap_or(0.0);
        return mid * (size[0] * size[1]) as f64;
    }
    let h = [0.5 * size[0], 0.5 * size[1]];
    [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]
        .iter()
        .map(|k| integrate_uv_cell(c, [at[0] + k[0] * h[0], at[1] + k[1] * h[1]], h, depth - 1))
        .sum()
}

#[test]
fn textured_curved_lights_draw_their_density_in_uv() {
    // Bins that do not line up with the 8 × 6 texels; midpoint quadrature on SUB_UV² cells.
    const BU: usize = 9;
    const BV: usize = 7;
    const SUB_UV: usize = 24;
    let all = curved_cases();
    let alpha = sidak(FALSE_ALARM, all.len());
    let mut failures = Vec::new();
    for (k, c) in all.iter().enumerate() {
        let mut rng = Rng::new(0xc0ffee + k as u64, 0);
        let mut observed = vec![0u64; BU * BV + 1];
        let mut mismatches = 0u64;
        for _ in 0..SAMPLES {
            let Some(ls) = c.light.sample_li(c.p, [rng.next_f32(), rng.next_f32()]) else {
                observed[BU * BV] += 1;
                continue;
            };
            let q = c.p + ls.wi * ls.dist;
            let uv = (c.uv_of)(q);
            let bin = |t: f32, n: usize| ((t * n as f32) as usize).min(n - 1);
            observed[bin(uv[0], BU) * BV + bin(uv[1], BV)] += 1;
            let (_, n, _) = (c.surface)(uv);
            let pdf = c.light.pdf_li(c.p, ls.wi, q, n) as f64;
            // Written so that a NaN counts.
            if !((pdf / ls.pdf as f64 - 1.0).abs() <= 1e-3) {
                mismatches += 1;
            }
        }
        // ∫ over each bin of the density per unit uv that pdf_li gives where p sees the light.
        let mut expected = vec![0.0f64; BU * BV + 1];
        let (nu, nv) = (BU * SUB_UV, BV * SUB_UV);
        for i in 0..nu {
            for j in 0..nv {
                let corner = [i as f32 / nu as f32, j as f32 / nv as f32];
                let size = [1.0 / nu as f32, 1.0 / nv as f32];
                expected[(i / SUB_UV) * BV + j / SUB_UV] += integrate_uv_cell(c, corner, size, 6);
            }
        }
        let seen: f64 = expected.iter().sum();
        expected[BU * BV] = 1.0 - seen;
        // A bin the terminator just grazes can have no quadrature point on the lit side; a
        // tiny expectation lets it be pooled rather than declared impossible.
        let expected: Vec<f64> = expected.iter().map(|e| (e * SAMPLES as f64).max(1e-9)).collect();
        let outcome = chi2_test(&observed, &expected);
        println!("{}: share seen {seen:.4}, {mismatches} pdf mismatches, {outcome:?}", c.label);
        // pdf_li and the sample's pdf agree to rounding except at grazing angles, where the
        // round trip through uv moves cos (which tends to 0) by a large fraction.
        if mismatches * 1000 > SAMPLES {
            failures.push(format!("{}: pdf_li differs from the sample's pdf on {mismatches} samples", c.label));
        }
        match outcome {
            Ok(o) if o.p_value >= alpha => {}
            Ok(o) => failures
                .push(format!("{}: chi-square {:.1} on {} dof, p = {:.2e}", c.label, o.statistic, o.dof, o.p_value)),
            Err(e) => failures.push(format!("{}: {e}", c.label)),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
