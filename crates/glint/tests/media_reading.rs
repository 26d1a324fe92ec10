//! Reading media: Mitsuba's `<medium>` (nested, by reference, on shapes and the sensor) and
//! the JSON format's `media` describe the same thing; what glint cannot render is one
//! clean error per feature, each naming its file and line, all in one run.

mod common;

use common::scratch::ScratchDir;
use glint::describe::{GridFilter, GridWrap, IntegratorDesc, PhaseDesc, VolumeDesc};
use glint::formats::{json, mitsuba};
use glint::materials::SceneDesc;
use glint::math::Rgb;
use std::path::Path;

fn xml(body: &str) -> Result<SceneDesc, String> {
    let text = format!(
        r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="9"/></integrator>
{body}
</scene>"#
    );
    mitsuba::read_str(&text, Path::new("media.xml"), &[]).map_err(|e| e.to_string())
}

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="30"/></sensor>"#;

#[test]
fn mitsuba_media_attach_to_shapes_by_nesting_and_reference_and_to_the_sensor() {
    let d = xml(r#"<medium type="homogeneous" id="fog">
        <rgb name="sigma_t" value="0.5, 0.25, 0.8"/>
        <float name="scale" value="4"/>
        <rgb name="albedo" value="0.9, 0.8, 0.7"/>
        <phase type="hg"><float name="g" value="-0.3"/></phase>
    </medium>
    <sensor type="perspective"><float name="fov" value="30"/><ref id="fog"/></sensor>
    <shape type="sphere">
        <bsdf type="null"/>
        <ref name="exterior" id="fog"/>
        <medium type="homogeneous" name="interior">
            <float name="sigma_t" value="10"/>
            <boolean name="sample_emitters" value="false"/>
        </medium>
    </shape>"#)
    .unwrap();
    assert!(matches!(d.integrator, IntegratorDesc::Volpath(ref v) if v.max_depth == Some(9)));
    assert_eq!(d.media.len(), 2);
    let fog = &d.media[d.camera.medium.unwrap()];
    assert_eq!((fog.sigma_t, fog.scale, fog.phase), (Rgb { r: 0.5, g: 0.25, b: 0.8 }, 4.0, PhaseDesc::Hg { g: -0.3 }));
    let s = &d.shapes[0];
    assert_eq!(s.media.exterior, d.camera.medium);
    let inner = &d.media[s.media.interior.unwrap()];
    // Mitsuba's defaults: albedo 0.75, isotropic.
    assert_eq!(
        (inner.sigma_t, inner.albedo.clone(), inner.phase, inner.sample_emitters),
        (Rgb::splat(10.0), VolumeDesc::Constant(Rgb::splat(0.75)), PhaseDesc::Isotropic, false)
    );
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}

#[test]
fn sigma_a_and_sigma_s_become_sigma_t_and_albedo() {
    let d = xml(&format!(
        r#"{SENSOR}<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior">
        <rgb name="sigma_a" value="0.1, 0.2, 0.3"/><rgb name="sigma_s" value="0.3, 0.2, 0.1"/></medium></shape>"#
    ))
    .unwrap();
    let m = &d.media[0];
    let albedo = m.albedo.constant().unwrap();
    assert!((m.sigma_t.r - 0.4).abs() < 1e-6 && (albedo.r - 0.75).abs() < 1e-6 && (albedo.b - 0.25).abs() < 1e-6);
}

#[test]
fn unsupported_media_features_are_all_reported_in_one_run_with_their_lines() {
    let e = xml(&format!(
        r#"{SENSOR}
    <medium type="smoke" id="smoke"/>
    <shape type="sphere"><ref name="interior" id="smoke"/></shape>
    <shape type="sphere"><medium type="homogeneous" name="interior"><phase type="rayleigh"/></medium></shape>
    <shape type="sphere"><medium type="homogeneous" name="interior"><rgb name="sigma_t" value="2, 1, 1"/></medium></shape>
    <shape type="sphere"><medium type="homogeneous" name="inside"/></shape>
    <shape type="sphere"><medium type="homogeneous" name="interior"><volume name="sigma_t" type="gridvolume"/></medium></shape>"#
    ))
    .unwrap_err();
    let lines: Vec<&str> = e.lines().collect();
    assert_eq!(lines.len(), 5, "{e}");
    for (line, (at, what)) in lines.iter().zip([
        ("media.xml:4:", "medium plugin 'smoke' is not supported"),
        ("media.xml:6:", "phase function 'rayleigh' is not supported"),
        ("media.xml:7:", "must lie in [0, 1]"),
        ("media.xml:8:", "'interior' or 'exterior'"),
        ("media.xml:9:", "<volume type=\"gridvolume\">"),
    ]) {
        assert!(line.starts_with(at) && line.contains(what), "expected {at} ... {what}, got: {line}");
    }
}

#[test]
fn media_under_another_integrator_are_a_warning() {
    let text = format!(
        r#"<scene version="3.0.0"><integrator type="path"/>{SENSOR}
        <shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior"/></shape></scene>"#
    );
    let d = mitsuba::read_str(&text, Path::new("media.xml"), &[]).unwrap();
    assert!(d.warnings.iter().any(|w| w.contains("only the volpath integrator")), "{:?}", d.warnings);
}

#[test]
fn json_media_match_the_mitsuba_description_and_round_trip() {
    let j = json::read(
        Path::new("m.json"),
        r#"{"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30, "medium": "air"},
            "film": {"width": 4, "height": 4},
            "integrator": {"type": "volpath", "max_depth": 9, "rr_depth": 7},
            "materials": {"b": {"type": "null"}},
            "media": {"air": {"sigma_t": 0.01, "albedo": 1},
                      "milk": {"sigma_t": [2, 3, 4], "scale": 2, "albedo": 0.9, "phase": {"type": "hg", "g": 0.5}}},
            "shapes": [{"type": "sphere", "material": "b", "interior": "milk", "exterior": "air"}]}"#,
    )
    .unwrap();
    let (air, milk) = (j.camera.medium.unwrap(), j.shapes[0].media.interior.unwrap());
    assert_eq!(j.shapes[0].media.exterior, Some(air));
    assert_eq!(j.media[milk].phase, PhaseDesc::Hg { g: 0.5 });
    assert_eq!(j.media[milk].scale, 2.0);
    assert!(matches!(j.integrator, IntegratorDesc::Volpath(ref v) if v.rr_depth == 7));
    let back: SceneDesc = serde_json::from_str(&serde_json::to_string(&j).unwrap()).unwrap();
    assert_eq!(back, j);
    let bad = json::read(
        Path::new("m.json"),
        r#"{"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
            "film": {"width": 4, "height": 4},
            "shapes": [{"type": "sphere", "interior": "nothing"}]}"#,
    )
    .unwrap_err();
    assert!(bad.to_string().starts_with("m.json:3:") && bad.to_string().contains("unknown medium 'nothing'"), "{bad}");
}

#[test]
fn invalid_media_numbers_are_errors_at_build() {
    for (body, what) in [
        (r#"<float name="sigma_t" value="nan"/>"#, "sigma_t"),
        (r#"<float name="scale" value="-1"/>"#, "scale"),
        (r#"<float name="sigma_t" value="1e30"/>"#, "sigma_t"),
        (r#"<rgb name="albedo" value="1, 0.5, 0.5"/><float name="albedo2" value="1"/>"#, "albedo2"),
    ] {
        let text = format!(
            r#"<scene version="3.0.0"><integrator type="volpath"/>{SENSOR}
            <shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior">{body}</medium></shape></scene>"#
        );
        let result = mitsuba::read_str(&text, Path::new("media.xml"), &[]).map_err(|e| e.to_string()).and_then(|d| {
            if d.warnings.iter().any(|w| w.contains(what)) {
                return Err(d.warnings.join("\n"));
            }
            glint::assemble::build(&d, &Default::default()).map(|_| ()).map_err(|e| e.to_string())
        });
        let e = result.expect_err(body);
        assert!(e.contains(what) && e.contains("media.xml:"), "{body}: {e}");
    }
}

fn medium_xml(medium: &str) -> String {
    format!(
        r#"{SENSOR}
<shape type="sphere"><bsdf type="null"/><medium type="homogeneous" name="interior">
{medium}
</medium></shape>"#
    )
}

#[test]
fn gridvolume_albedo_and_constvolumes_are_read() {
    let d = xml(&medium_xml(
        r#"<volume name="albedo" type="gridvolume">
    <string name="filename" value="textures/albedo.vol"/>
    <string name="filter_type" value="nearest"/>
    <string name="wrap_mode" value="mirror"/>
    <boolean name="raw" value="true"/>
    <transform name="to_world"><translate x="1" y="2" z="3"/></transform>
</volume>
<volume name="sigma_t" type="constvolume"><rgb name="value" value="0.5"/></volume>"#,
    ))
    .unwrap();
    let m = &d.media[0];
    assert_eq!(m.sigma_t, Rgb::splat(0.5));
    let VolumeDesc::Grid(g) = &m.albedo else { panic!("{:?}", m.albedo) };
    assert!(g.file.ends_with("textures/albedo.vol"), "{:?}", g.file);
    assert_eq!((g.filter, g.wrap), (GridFilter::Nearest, GridWrap::Mirror));
    assert_eq!([g.to_world[0][3], g.to_world[1][3], g.to_world[2][3]], [1.0, 2.0, 3.0]);
    assert_eq!(g.loc.line, 5);
    assert!(d.build_inputs().contains(&g.file), "{:?}", d.build_inputs());
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    // Mitsuba's defaults: trilinear, clamp; a constvolume's value is 1.
    let d = xml(&medium_xml(
        r#"<volume name="albedo" type="gridvolume"><string name="filename" value="a.vol"/></volume>
<volume name="sigma_t" type="constvolume"/>"#,
    ))
    .unwrap();
    let VolumeDesc::Grid(g) = &d.media[0].albedo else { panic!() };
    assert_eq!((g.filter, g.wrap), (GridFilter::Trilinear, GridWrap::Clamp));
    assert_eq!(d.media[0].sigma_t, Rgb::WHITE);
    let back: SceneDesc = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
    assert_eq!(back, d);
}

#[test]
fn unsupported_volume_parameters_are_one_line_errors_with_their_lines() {
    for (body, line, what) in [
        (r#"<volume name="albedo" type="gridvolume"/>"#, 5, "needs 'filename'"),
        (
            "<volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"a.vol\"/>\n<string name=\"filter_type\" value=\"cubic\"/></volume>",
            6,
            "filter_type 'cubic'",
        ),
        (
            "<volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"a.vol\"/>\n<string name=\"wrap_mode\" value=\"border\"/></volume>",
            6,
            "wrap_mode 'border'",
        ),
        (
            "<volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"a.vol\"/>\n<boolean name=\"use_grid_bbox\" value=\"true\"/></volume>",
            6,
            "use_grid_bbox",
        ),
        (
            "<volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"a.vol\"/>\n<float name=\"density\" value=\"1\"/></volume>",
            6,
            "parameter 'density'",
        ),
        (r#"<volume name="albedo" type="sdfvolume"/>"#, 5, "'sdfvolume'"),
        (
            "<volume name=\"albedo\" type=\"constvolume\">\n<texture name=\"value\" type=\"bitmap\"/></volume>",
            6,
            "'value' should be",
        ),
        (r#"<volume name="sigma_s" type="gridvolume"/>"#, 5, "'sigma_s' given as a <volume type=\"gridvolume\">"),
    ] {
        let e = xml(&medium_xml(body)).expect_err(body);
        assert!(!e.contains('\n'), "not one line: {e}");
        let at = format!("media.xml:{line}:");
        assert!(e.starts_with(&at) && e.contains(what), "{body}: expected {at} ... {what}, got {e}");
    }
}

/// A `.vol` file's bytes: version 3, f32, the given resolution and channels, then `values`.
fn vol_bytes(res: [i32; 3], channels: i32, values: &[f32]) -> Vec<u8> {
    let mut out = b"VOL\x03".to_vec();
    for v in [1, res[0], res[1], res[2], channels] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0f32, 0.0, 0.0, 1.0, 1.0, 1.0].iter().chain(values) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

#[test]
fn bad_albedo_grid_files_are_one_line_errors_at_build() {
    let dir = ScratchDir::new("media-grid");
    let cases: [(&str, Vec<u8>, &str); 5] = [
        ("truncated.vol", vol_bytes([2, 2, 2], 3, &[0.5; 20]), "truncated volume grid"),
        ("channels.vol", vol_bytes([1, 1, 1], 2, &[0.5; 2]), "2 channels cannot be an albedo"),
        ("range.vol", vol_bytes([2, 1, 1], 1, &[0.5, 1.5]), "albedo 1.5 in cell (1, 0, 0)"),
        ("nan.vol", vol_bytes([1, 1, 1], 1, &[f32::NAN]), "must lie in [0, 1]"),
        ("text.vol", b"not a volume at all".to_vec(), "does not start with 'VOL'"),
    ];
    for (name, bytes, what) in
        cases.iter().map(|(n, b, w)| (*n, b.clone(), *w)).chain([("missing.vol", vec![], "missing.vol")])
    {
        let path = dir.join(name);
        if name != "missing.vol" {
            std::fs::write(&path, &bytes).unwrap();
        }
        let scene = dir.join(format!("{name}.xml"));
        let text = format!(
            "<scene version=\"3.0.0\"><integrator type=\"volpath\"/>{SENSOR}\n<shape type=\"sphere\"><bsdf type=\"null\"/>\n<medium type=\"homogeneous\" name=\"interior\">\n<volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"{name}\"/></volume></medium></shape></scene>"
        );
        std::fs::write(&scene, &text).unwrap();
        let d = mitsuba::read(&scene, &[]).unwrap();
        let e = match glint::assemble::build(&d, &Default::default()) {
            Ok(_) => panic!("{name} built"),
            Err(e) => e.to_string(),
        };
        assert!(!e.contains('\n'), "not one line: {e}");
        let at = format!("{}:4:", scene.display());
        assert!(
            e.starts_with(&at) && e.contains(what) && e.contains(name),
            "{name}: expected {at} ... {what}, got {e}"
        );
    }
    // A good grid builds.
    std::fs::write(dir.join("good.vol"), vol_bytes([2, 1, 1], 3, &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6])).unwrap();
    let scene = dir.join("good.xml");
    std::fs::write(&scene, format!("<scene version=\"3.0.0\"><integrator type=\"volpath\"/>{SENSOR}<shape type=\"sphere\"><bsdf type=\"null\"/><medium type=\"homogeneous\" name=\"interior\"><volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"good.vol\"/></volume></medium></shape></scene>")).unwrap();
    glint::assemble::build(&mitsuba::read(&scene, &[]).unwrap(), &Default::default()).unwrap();
}

#[test]
fn heterogeneous_media_take_a_density_grid_as_sigma_t() {
    let d = xml(&format!(
        r#"{SENSOR}
<shape type="cube"><bsdf type="null"/><medium type="heterogeneous" name="interior">
<float name="scale" value="4"/>
<volume name="sigma_t" type="gridvolume"><string name="filename" value="density.vol"/></volume>
<rgb name="albedo" value="0.5"/>
</medium></shape>"#
    ))
    .unwrap();
    let m = &d.media[0];
    assert_eq!((m.sigma_t, m.scale, m.albedo.clone()), (Rgb::WHITE, 4.0, VolumeDesc::Constant(Rgb::splat(0.5))));
    let g = m.density.as_ref().unwrap();
    assert!(g.file.ends_with("density.vol") && g.loc.line == 6, "{g:?}");
    assert!(d.build_inputs().contains(&g.file));
    // A homogeneous medium's extinction stays constant.
    let e = xml(&medium_xml(
        r#"<volume name="sigma_t" type="gridvolume"><string name="filename" value="d.vol"/></volume>"#,
    ))
    .unwrap_err();
    assert!(e.starts_with("media.xml:5:") && e.contains("heterogeneous medium's sigma_t may be a gridvolume"), "{e}");
}

#[test]
fn bad_density_grids_are_one_line_errors_at_build() {
    let dir = ScratchDir::new("media-density");
    for (name, bytes, what) in [
        ("rgb.vol", vol_bytes([1, 1, 1], 3, &[0.5; 3]), "1 channel, not 3"),
        ("negative.vol", vol_bytes([2, 1, 1], 1, &[0.5, -1.0]), "density -1"),
        ("huge.vol", vol_bytes([1, 1, 1], 1, &[1e30]), "exceeds"),
    ] {
        std::fs::write(dir.join(name), bytes).unwrap();
        let scene = dir.join(format!("{name}.xml"));
        std::fs::write(
            &scene,
            format!(
                "<scene version=\"3.0.0\"><integrator type=\"volpath\"/>{SENSOR}\n<shape type=\"cube\"><bsdf type=\"null\"/>\n<medium type=\"heterogeneous\" name=\"interior\">\n<volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"{name}\"/></volume></medium></shape></scene>"
            ),
        )
        .unwrap();
        let e = match glint::assemble::build(&mitsuba::read(&scene, &[]).unwrap(), &Default::default()) {
            Ok(_) => panic!("{name} built"),
            Err(e) => e.to_string(),
        };
        let at = format!("{}:4:", scene.display());
        assert!(
            !e.contains('\n') && e.starts_with(&at) && e.contains(what),
            "{name}: expected {at} ... {what}, got {e}"
        );
    }
}
