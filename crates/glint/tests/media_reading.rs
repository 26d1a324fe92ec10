//! Reading media: Mitsuba's `<medium>` (nested, by reference, on shapes and the sensor) and
//! the JSON format's `media` describe the same thing; what glint cannot render is one
//! clean error per feature, each naming its file and line, all in one run.

use glint::describe::{IntegratorDesc, PhaseDesc, SceneDesc};
use glint::formats::{json, mitsuba};
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
    let d = xml(&format!(
        r#"<medium type="homogeneous" id="fog">
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
    </shape>"#
    ))
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
        (inner.sigma_t, inner.albedo, inner.phase, inner.sample_emitters),
        (Rgb::splat(10.0), Rgb::splat(0.75), PhaseDesc::Isotropic, false)
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
    assert!((m.sigma_t.r - 0.4).abs() < 1e-6 && (m.albedo.r - 0.75).abs() < 1e-6 && (m.albedo.b - 0.25).abs() < 1e-6);
}

#[test]
fn unsupported_media_features_are_all_reported_in_one_run_with_their_lines() {
    let e = xml(&format!(
        r#"{SENSOR}
    <medium type="heterogeneous" id="smoke"/>
    <shape type="sphere"><ref name="interior" id="smoke"/></shape>
    <shape type="sphere"><medium type="homogeneous" name="interior"><phase type="rayleigh"/></medium></shape>
    <shape type="sphere"><medium type="homogeneous" name="interior"><rgb name="sigma_t" value="2, 1, 1"/></medium></shape>
    <shape type="sphere"><medium type="homogeneous" name="inside"/></shape>
    <shape type="sphere"><medium type="homogeneous" name="interior"><volume name="albedo" type="gridvolume"/></medium></shape>"#
    ))
    .unwrap_err();
    let lines: Vec<&str> = e.lines().collect();
    assert_eq!(lines.len(), 5, "{e}");
    for (line, (at, what)) in lines.iter().zip([
        ("media.xml:4:", "medium plugin 'heterogeneous' is not supported"),
        ("media.xml:6:", "phase function 'rayleigh' is not supported"),
        ("media.xml:7:", "must lie in [0, 1]"),
        ("media.xml:8:", "'interior' or 'exterior'"),
        ("media.xml:9:", "<volume"),
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
            glint::build::build(&d, &Default::default()).map(|_| ()).map_err(|e| e.to_string())
        });
        let e = result.expect_err(body);
        assert!(e.contains(what) && e.contains("media.xml:"), "{body}: {e}");
    }
}
