//! glTF's `doubleSided: false` is back-face culling for every ray: a ray that meets the back
//! of a single-sided surface (the side its counter-clockwise winding's normal turns away
//! from, after the node's transform) passes through it as if it were not there; a
//! double-sided surface blocks from both sides; a single-sided emitter emits only from its
//! front. Camera rays, shadow rays and rays sampled at a bounce are each tested alone, under
//! every integrator that traces them, in small scenes whose answers are known exactly or
//! from a form factor.
//!
//! Every scene: a square of half-size 3 in the plane z = 2 (a glTF quad placed from JSON),
//! black (base colour 0, `KHR_materials_specular` 0: it scatters nothing) unless emissive,
//! over a floor at z = 0.

mod common;

use common::load::load;
use common::scratch::ScratchDir;
use glint::io::Image;
use glint::render::{render, Silent};
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::path::Path;

/// The quad's facing and sides.
#[derive(Clone, Copy, Debug)]
struct Quad {
    /// Front (counter-clockwise) towards +z; else towards -z.
    up: bool,
    double_sided: bool,
    emissive: bool,
}

const HALF: f32 = 3.0;
const HEIGHT: f64 = 2.0;

/// Writes `quad.gltf` and `quad.bin` for `q` into `dir`.
fn write_quad(dir: &Path, q: Quad) {
    let h = HALF;
    let corners = [[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]];
    let bin: Vec<u8> = corners.iter().flatten().flat_map(|x: &f32| x.to_le_bytes()).collect();
    // Counter-clockwise seen from +z: (0, 1, 2), (0, 2, 3); reversed for a quad facing down.
    let indices: [u16; 6] = if q.up { [0, 1, 2, 0, 2, 3] } else { [0, 2, 1, 0, 3, 2] };
    let mut bin = bin;
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("quad.bin"), &bin).unwrap();
    let mut material = json!({
        "doubleSided": q.double_sided,
        "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0},
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}
    });
    if q.emissive {
        material["emissiveFactor"] = json!([1.0, 1.0, 1.0]);
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_specular"],
        "buffers": [{"byteLength": bin.len(), "uri": "quad.bin"}],
        "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-h, -h, 0], "max": [h, h, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "materials": [material],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}]
    });
    std::fs::write(dir.join("quad.gltf"), doc.to_string()).unwrap();
}

/// The floor: white (albedo 0.5), or black and emitting a radiance.
#[derive(Clone, Copy)]
enum Floor {
    White,
    Emitting(f32),
}

struct Setup {
    quad: Option<Quad>,
    /// Extra transform operations of the quad's placement (before it is lifted to z = 2).
    mirror: bool,
    floor: Floor,
    /// Camera height above the floor, looking straight down.
    eye: f64,
    /// Full field of view, degrees.
    fov: f64,
    integrator: Value,
    lights: Value,
    spp: u32,
}

/// Renders `s` (16 x 16 pixels) in a scratch folder of its own.
fn render_setup(name: &str, s: &Setup) -> Image {
    let dir = ScratchDir::new(&format!("gltf-sides-{name}"));
    let floor = match s.floor {
        Floor::White => json!({"type": "rectangle", "material": "white", "transform": [{"scale": 50}]}),
        Floor::Emitting(e) => json!({"type": "rectangle", "material": "black", "emission": e,
                                     "transform": [{"scale": 50}]}),
    };
    let mut shapes = vec![floor];
    if let Some(q) = s.quad {
        write_quad(&dir, q);
        let mut transform = Vec::new();
        if s.mirror {
            // A mirroring placement: glTF keeps each face's front where it was.
            transform.push(json!({"scale": [-1, 1, 1]}));
        }
        transform.push(json!({"translate": [0, 0, HEIGHT]}));
        shapes.push(json!({"type": "gltf", "file": "quad.gltf", "transform": transform}));
    }
    let scene = json!({
        "camera": {"position": [0, 0, s.eye], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": s.fov},
        "film": {"width": 16, "height": 16},
        "sampler": {"spp": s.spp, "seed": 3},
        "integrator": s.integrator,
        "materials": {"white": {"type": "diffuse", "reflectance": 0.5},
                      "black": {"type": "diffuse", "reflectance": 0.0}},
        "shapes": shapes,
        "lights": s.lights
    });
    let path = dir.join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let scene = load(&path, &[], None).unwrap();
    render(&scene.world, &scene.integrator, &scene.settings, &Silent).image
}

fn mean(img: &Image) -> f64 {
    img.channel_means()[0]
}

/// The standard error of the image mean, from the spread of its (independent) pixels.
fn standard_error(img: &Image) -> f64 {
    let m = mean(img);
    let n = img.pixels.len() as f64;
    let var = img.pixels.iter().map(|p| (p.r as f64 - m).powi(2)).sum::<f64>() / (n - 1.0);
    (var / n).sqrt()
}

/// Every pixel's red channel equals `v` within `tol`.
fn assert_all(img: &Image, v: f64, tol: f64, what: &str) {
    for (i, p) in img.pixels.iter().enumerate() {
        assert!((p.r as f64 - v).abs() <= tol, "{what}: pixel {i} is {} (expected {v})", p.r);
    }
}

fn integrators() -> Vec<(&'static str, Value)> {
    vec![
        ("path", json!({"type": "path", "max_depth": 2})),
        ("volpath", json!({"type": "volpath", "max_depth": 2})),
        ("direct", json!({"type": "direct"})),
        ("whitted", json!({"type": "whitted"})),
    ]
}

const UP: Quad = Quad { up: true, double_sided: false, emissive: false };
const DOWN: Quad = Quad { up: false, double_sided: false, emissive: false };

/// Camera rays: from above, through a single-sided quad that faces down (its back to the
/// camera) the emitting floor shows exactly; the same quad facing up, or double-sided,
/// hides it (black). The same under a mirroring placement.
#[test]
fn camera_rays_pass_a_back_face() {
    for (name, integrator) in integrators() {
        let setup = |quad: Quad, mirror: bool| Setup {
            quad: Some(quad),
            mirror,
            floor: Floor::Emitting(1.0),
            eye: 5.0,
            fov: 30.0,
            integrator: integrator.clone(),
            lights: json!([]),
            spp: 2,
        };
        for mirror in [false, true] {
            let tag = |t: &str| format!("{name}-{t}-{}", if mirror { "mirrored" } else { "plain" });
            let img = render_setup(&tag("camera-back"), &setup(DOWN, mirror));
            assert_all(&img, 1.0, 1e-6, &format!("{name}: floor through the back face (mirror {mirror})"));
            let img = render_setup(&tag("camera-front"), &setup(UP, mirror));
            assert_all(&img, 0.0, 0.0, &format!("{name}: the quad's black front (mirror {mirror})"));
            let img = render_setup(&tag("camera-double"), &setup(Quad { double_sided: true, ..DOWN }, mirror));
            assert_all(&img, 0.0, 0.0, &format!("{name}: a double-sided quad's back (mirror {mirror})"));
        }
    }
}

/// The floor's radiance under a point light of 1 W/sr at height 4 straight above, seen
/// at its centre: albedo / pi x I cos / d^2 (the camera's 2-degree view varies it by 3e-5).
fn lit_floor() -> f64 {
    0.5 / PI * 4.0 / 64.0
}

/// Shadow rays: a camera between the floor and the quad looks down at the floor (its rays
/// never meet the quad), lit by a point light above the quad. Shadow rays travel up: they
/// meet the back of a quad facing up and pass (the floor is lit as if the quad were not
/// there); a quad facing down, or a double-sided one, shadows the floor completely.
#[test]
fn shadow_rays_pass_a_back_face() {
    for (name, integrator) in integrators() {
        let setup = |quad: Option<Quad>| Setup {
            quad,
            mirror: false,
            floor: Floor::White,
            eye: 1.0,
            fov: 2.0,
            integrator: integrator.clone(),
            lights: json!([{"type": "point", "position": [0, 0, 4], "intensity": 1}]),
            spp: 2,
        };
        let open = render_setup(&format!("{name}-shadow-none"), &setup(None));
        assert_all(&open, lit_floor(), 1e-4 * lit_floor(), &format!("{name}: the floor without a quad"));
        let img = render_setup(&format!("{name}-shadow-back"), &setup(Some(UP)));
        assert_all(&img, lit_floor(), 1e-4 * lit_floor(), &format!("{name}: light through the back face"));
        let img = render_setup(&format!("{name}-shadow-front"), &setup(Some(DOWN)));
        assert_all(&img, 0.0, 0.0, &format!("{name}: the front casts a shadow"));
        let img = render_setup(&format!("{name}-shadow-double"), &setup(Some(Quad { double_sided: true, ..UP })));
        assert_all(&img, 0.0, 0.0, &format!("{name}: a double-sided quad casts a shadow"));
    }
}

/// The cosine-weighted share of the sky a square of half-size `a` at height `h` hides from
/// the point below its centre: four times the differential-area-to-parallel-rectangle
/// form factor with the normal through a corner (A = B = a / h).
fn square_form_factor(a: f64, h: f64) -> f64 {
    let x = a / h;
    let s = (1.0 + x * x).sqrt();
    4.0 * (2.0 * x / s * (x / s).atan()) / (2.0 * PI)
}

/// Rays sampled at a bounce: a white floor under a uniform sky of radiance 1, rendered by
/// BSDF sampling only (no shadow rays), one bounce. Each sample is 0.5 where its bounce ray
/// escapes, 0 where the black quad stops it: exactly 0.5 everywhere when the rays meet the
/// quad's back (facing up); 0.5 (1 - F) on average when they meet its front or a
/// double-sided quad, F the form factor (0.735), within 5 standard errors.
#[test]
fn bounce_rays_pass_a_back_face() {
    let sky = json!([{"type": "constant", "radiance": 1}]);
    let cases = [
        ("path", json!({"type": "path", "max_depth": 2, "strategy": "bsdf"})),
        ("direct", json!({"type": "direct", "emitter_samples": 0, "bsdf_samples": 1})),
    ];
    let f = square_form_factor(HALF as f64, HEIGHT);
    assert!((f - 0.7352).abs() < 1e-3, "form factor {f}");
    for (name, integrator) in cases {
        let setup = |quad: Quad| Setup {
            quad: Some(quad),
            mirror: false,
            floor: Floor::White,
            eye: 1.0,
            fov: 2.0,
            integrator: integrator.clone(),
            lights: sky.clone(),
            spp: 16,
        };
        let img = render_setup(&format!("{name}-bounce-back"), &setup(UP));
        assert_all(&img, 0.5, 1e-5, &format!("{name}: bounce rays through the back face"));
        for (tag, quad) in [("front", DOWN), ("double", Quad { double_sided: true, ..UP })] {
            let img = render_setup(&format!("{name}-bounce-{tag}"), &setup(quad));
            let (m, se) = (mean(&img), standard_error(&img));
            let expected = 0.5 * (1.0 - f);
            // The spread of 256 pixels of 16 samples each: about 0.0035 here.
            assert!(se > 0.0 && se < 0.01, "{name} {tag}: standard error {se}");
            assert!((m - expected).abs() < 5.0 * se, "{name} {tag}: mean {m}, expected {expected} +- {se}");
        }
    }
}

/// A single-sided emitter emits from its front only, and is not there from behind: seen from
/// above, a quad facing up shows its emission (1), one facing down shows the floor behind it
/// (emitting 0.25), and a double-sided one emits on both sides (1). Lighting the floor below (seen
/// from between the two): a quad facing down lights it; one facing up leaves it black (its
/// light samples face away, and the bounce rays that reach it meet its back).
#[test]
fn single_sided_emitters_emit_from_the_front_only() {
    let seen = |quad: Quad, mirror: bool, tag: &str| {
        render_setup(
            tag,
            &Setup {
                quad: Some(quad),
                mirror,
                floor: Floor::Emitting(0.25),
                eye: 5.0,
                fov: 30.0,
                integrator: json!({"type": "path", "max_depth": 1}),
                lights: json!([]),
                spp: 2,
            },
        )
    };
    let lamp = |up: bool, double_sided: bool| Quad { up, double_sided, emissive: true };
    for mirror in [false, true] {
        let tag = |t: &str| format!("emit-{t}-{mirror}");
        assert_all(&seen(lamp(true, false), mirror, &tag("front")), 1.0, 1e-6, "an emitter's front");
        assert_all(&seen(lamp(false, false), mirror, &tag("back")), 0.25, 1e-6, "the floor behind an emitter's back");
        assert_all(&seen(lamp(false, true), mirror, &tag("double")), 1.0, 1e-6, "a double-sided emitter's back");
    }
    let lit = |quad: Quad, tag: &str| {
        render_setup(
            tag,
            &Setup {
                quad: Some(quad),
                mirror: false,
                floor: Floor::White,
                eye: 1.0,
                fov: 2.0,
                integrator: json!({"type": "path", "max_depth": 2}),
                lights: json!([]),
                spp: 16,
            },
        )
    };
    let img = lit(lamp(false, false), "emit-lights-floor");
    let (m, se) = (mean(&img), standard_error(&img));
    // The floor's radiance: albedo x form factor x 1.
    let expected = 0.5 * square_form_factor(HALF as f64, HEIGHT);
    assert!((m - expected).abs() < 5.0 * se, "floor under the lamp: {m}, expected {expected} +- {se}");
    assert_all(&lit(lamp(true, false), "emit-faces-away"), 0.0, 0.0, "floor under a lamp facing away");
}
