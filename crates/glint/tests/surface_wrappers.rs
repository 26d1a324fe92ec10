//! Normal maps, bump maps and masks (Mitsuba's `normalmap`, `bumpmap`, `mask`) on scenes
//! whose answer is known: an opacity-0.5 sheet halves the light that crosses it, on shadow
//! rays (exactly: they carry the transmittance) and on camera rays (in expectation); a flat
//! normal map and a constant height map leave the image as it was.

mod common;

use common::load::load;
use common::scratch::ScratchDir;
use glint::io::Image;
use glint::render::{render, Silent};
use std::path::Path;

fn scratch(name: &str) -> ScratchDir {
    ScratchDir::new(&format!("surface-{name}"))
}

fn render_xml(dir: &Path, name: &str, xml: &str) -> Image {
    let path = dir.join(format!("{name}.xml"));
    std::fs::write(&path, xml).unwrap();
    let scene = load(&path, &[], None).unwrap();
    render(&scene.world, &scene.integrator, &scene.settings, &Silent).image
}

/// The mean of all pixels and channels, and its standard error estimated from the spread of
/// the pixels (conservative: it counts the image's own variation as noise too).
fn mean_and_error(img: &Image) -> (f64, f64) {
    let v: Vec<f64> = img.pixels.iter().map(|p| (0..3).map(|k| p.channel(k) as f64).sum::<f64>() / 3.0).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// A floor lit by a small downward-facing light at height 2; optionally a black sheet of
/// opacity 0.5 at height `sheet_z`; the camera at `eye_z` looking down at the floor.
fn scene(integrator: &str, sheet_z: Option<f32>, eye_z: f32, light_z: f32) -> String {
    let sheet = sheet_z.map_or(String::new(), |z| {
        format!(
            r#"<shape type="rectangle"><transform name="to_world"><scale value="20"/><translate z="{z}"/></transform>
            <bsdf type="mask"><float name="opacity" value="0.5"/>
                <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></bsdf></shape>"#
        )
    });
    format!(
        r#"<scene version="3.0.0">
    {integrator}
    <sensor type="perspective"><float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, {eye_z}" target="0, 0.01, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/>
            <rfilter type="box"/></film></sensor>
    <shape type="rectangle"><transform name="to_world"><scale value="20"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
    <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="180"/><translate z="{light_z}"/></transform>
        <emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
    {sheet}
</scene>"#
    )
}

const DIRECT_LIGHT_SAMPLES: &str = r#"<integrator type="direct"><integer name="emitter_samples" value="1"/><integer name="bsdf_samples" value="0"/></integrator>"#;

#[test]
fn a_half_opaque_sheet_halves_light_on_shadow_rays() {
    let dir = scratch("shadow");
    // Light sampling only: the shadow rays see the same points with and without the sheet,
    // so the transmittance 0.5 they carry halves every pixel exactly.
    let plain = render_xml(&dir, "plain", &scene(DIRECT_LIGHT_SAMPLES, None, 0.5, 2.0));
    let masked = render_xml(&dir, "masked", &scene(DIRECT_LIGHT_SAMPLES, Some(1.0), 0.5, 2.0));
    let (a, _) = mean_and_error(&plain);
    let (b, _) = mean_and_error(&masked);
    assert!(a > 0.01, "the floor is lit: {a}");
    for (p, q) in plain.pixels.iter().zip(&masked.pixels) {
        for k in 0..3 {
            let (p, q) = (p.channel(k), q.channel(k));
            assert!((q - 0.5 * p).abs() <= 1e-5 * p.abs() + 1e-7, "{q} is not half of {p}");
        }
    }
    assert!((b - 0.5 * a).abs() < 1e-5 * a);
    // The path tracers also reach the light through the sheet by BSDF sampling (a random
    // pass with probability 0.5), so there the half holds in expectation.
    for (name, integrator) in [("path", r#"<integrator type="path"/>"#), ("volpath", r#"<integrator type="volpath"/>"#)]
    {
        let (a, ea) = mean_and_error(&render_xml(&dir, &format!("plain-{name}"), &scene(integrator, None, 0.5, 2.0)));
        let (b, eb) =
            mean_and_error(&render_xml(&dir, &format!("masked-{name}"), &scene(integrator, Some(1.0), 0.5, 2.0)));
        let tol = 4.0 * (eb * eb + 0.25 * ea * ea).sqrt();
        assert!((b - 0.5 * a).abs() < tol, "{name}: {b} vs half of {a} (tolerance {tol})");
    }
}

#[test]
fn a_half_opaque_sheet_halves_what_the_camera_sees_through_it() {
    let dir = scratch("camera");
    // The light is under the sheet, the camera above: camera rays pass with probability 0.5
    // and the black sheet returns nothing when they do not.
    for (name, integrator) in [
        ("direct", DIRECT_LIGHT_SAMPLES),
        ("path", r#"<integrator type="path"/>"#),
        ("volpath", r#"<integrator type="volpath"/>"#),
    ] {
        let (a, ea) = mean_and_error(&render_xml(&dir, &format!("{name}-plain"), &scene(integrator, None, 3.0, 0.8)));
        let (b, eb) =
            mean_and_error(&render_xml(&dir, &format!("{name}-masked"), &scene(integrator, Some(1.5), 3.0, 0.8)));
        assert!(a > 0.01, "{name}: the floor is lit: {a}");
        let tol = 4.0 * (eb * eb + 0.25 * ea * ea).sqrt();
        assert!((b - 0.5 * a).abs() < tol, "{name}: {b} vs half of {a} (tolerance {tol})");
    }
}

fn object_scene(bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective"><float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, -3, 2" target="0, 0, 0.3" up="0, 0, 1"/></transform>
        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/>
            <rfilter type="box"/></film></sensor>
    <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform>{bsdf}</shape>
    <shape type="sphere"><point name="center" x="0" y="0" z="0.5"/><float name="radius" value="0.5"/>{bsdf}</shape>
    <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="1" z="0.3"/></transform>{bsdf}</shape>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
</scene>"#
    )
}

#[test]
fn a_flat_normal_map_leaves_the_image_unchanged() {
    let dir = scratch("flat-normals");
    let inner = r#"<bsdf type="roughplastic"><float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.2, 0.5, 0.7"/></bsdf>"#;
    let plain = render_xml(&dir, "plain", &object_scene(inner));
    let mapped = render_xml(
        &dir,
        "mapped",
        &object_scene(&format!(r#"<bsdf type="normalmap"><rgb name="normalmap" value="0.5, 0.5, 1"/>{inner}</bsdf>"#)),
    );
    // (0.5, 0.5, 1) is the normal (0, 0, 1) exactly: the tilted frame is the identity and
    // every random number is used as before, so the images are the same.
    for (p, q) in plain.pixels.iter().zip(&mapped.pixels) {
        for k in 0..3 {
            assert!((p.channel(k) - q.channel(k)).abs() <= 1e-5 * p.channel(k).abs() + 1e-6);
        }
    }
}

#[test]
fn a_constant_height_map_leaves_the_image_unchanged() {
    let dir = scratch("flat-height");
    let height = dir.join("flat.png");
    let img = Image { width: 4, height: 4, pixels: vec![glint::math::Rgb::splat(0.5); 16] };
    glint::io::write_image(&img, &height).unwrap();
    let inner = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.5, 0.4"/></bsdf>"#;
    let plain = render_xml(&dir, "plain", &object_scene(inner));
    let bumped = render_xml(
        &dir,
        "bumped",
        &object_scene(&format!(
            r#"<bsdf type="bumpmap"><float name="scale" value="3"/><texture type="bitmap" name="h"><string name="filename" value="{}"/></texture>{inner}</bsdf>"#,
            height.display()
        )),
    );
    // The gradient is zero, so the bumped normal is the shading normal up to rounding: the
    // images agree up to the rare sample that rounding sends another way.
    let (a, _) = mean_and_error(&plain);
    let (b, _) = mean_and_error(&bumped);
    assert!((a - b).abs() < 1e-3 * a, "{a} vs {b}");
}

#[test]
fn wrappers_that_cannot_work_are_one_line_errors() {
    let dir = scratch("errors");
    let cases = [
        (r#"<bsdf type="mask"/>"#, "exactly one nested <bsdf>"),
        (
            r#"<bsdf type="bumpmap"><texture type="checkerboard" name="h"/><bsdf type="diffuse"/></bsdf>"#,
            "must be a bitmap",
        ),
        (
            r#"<bsdf type="normalmap"><rgb name="normalmap" value="0.5, 0.5, 1"/><bsdf type="normalmap"><rgb name="normalmap" value="0.5, 0.5, 1"/><bsdf type="diffuse"/></bsdf></bsdf>"#,
            "inside another one",
        ),
        (r#"<bsdf type="normalmap"><bsdf type="diffuse"/></bsdf>"#, "named 'normalmap'"),
        (
            r#"<bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance"><string name="name" value="vertex_color"/></texture></bsdf>"#,
            "mesh attribute 'vertex_color'",
        ),
    ];
    for (i, (bsdf, want)) in cases.iter().enumerate() {
        let path = dir.join(format!("case{i}.xml"));
        std::fs::write(&path, object_scene(bsdf)).unwrap();
        let err = load(&path, &[], None).err().unwrap_or_else(|| panic!("case {i} loaded"));
        // One line per shape that uses the BSDF, each naming the file and line.
        for line in err.lines() {
            assert!(line.contains(want) && line.contains(&format!("case{i}.xml:")), "case {i}: {err}");
        }
    }
}
