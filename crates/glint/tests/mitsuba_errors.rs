//! Bad Mitsuba XML gets a one-line error naming the file and line.

mod common;

use common::load::load;
use common::scratch::ScratchDir;
use std::path::{Path, PathBuf};

/// A folder for one test's files: tests run in parallel, so each needs its own.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new(&format!("mitsuba-errors-{test}"))
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;

fn error_of(dir: &Path, name: &str, text: &str) -> String {
    let p = write(dir, name, text);
    match load(&p, &[], None) {
        Ok(_) => panic!("{name} loaded but should not"),
        Err(e) => {
            assert!(!e.contains('\n'), "not one line: {e}");
            e
        }
    }
}

#[test]
fn malformed_xml() {
    let dir = scratch("malformed");
    let e = error_of(&dir, "malformed.xml", "<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n</scene>\n");
    assert!(e.contains("malformed.xml:") && e.contains("malformed XML"), "{e}");
}

#[test]
fn unknown_plugin_names_type_file_and_line() {
    let dir = scratch("unknown-plugin");
    let e = error_of(
        &dir,
        "plugin.xml",
        &format!("<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"sphere\">\n <bsdf type=\"velvet\"/>\n</shape>\n</scene>\n"),
    );
    assert!(e.contains("plugin.xml:5:") && e.contains("velvet"), "{e}");
    let e = error_of(
        &dir,
        "shape.xml",
        &format!("<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"hair\"/>\n</scene>\n"),
    );
    assert!(e.contains("shape.xml:4:") && e.contains("hair"), "{e}");
}

#[test]
fn missing_referenced_file() {
    let dir = scratch("missing-file");
    let e = error_of(
        &dir,
        "missing.xml",
        &format!("<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"obj\">\n <string name=\"filename\" value=\"nowhere.obj\"/>\n</shape>\n</scene>\n"),
    );
    assert!(e.contains("missing.xml:4:") && e.contains("nowhere.obj"), "{e}");
    let e = error_of(&dir, "include.xml", "<scene version=\"3.0.0\">\n<include filename=\"gone.xml\"/>\n</scene>\n");
    assert!(e.contains("include.xml:2:") && e.contains("gone.xml"), "{e}");
}

#[test]
fn substitution_without_default() {
    let dir = scratch("substitution");
    let e = error_of(
        &dir,
        "subst.xml",
        &format!("<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"sphere\">\n <float name=\"radius\" value=\"$r\"/>\n</shape>\n</scene>\n"),
    );
    assert!(e.contains("subst.xml:5:") && e.contains("$r"), "{e}");
}

#[test]
fn defines_override_defaults_and_refs_resolve() {
    let dir = scratch("defines");
    let text = format!(
        "<scene version=\"3.0.0\">\n<default name=\"r\" value=\"0.5\"/>\n{SENSOR}\n<bsdf type=\"diffuse\" id=\"m\"/>\n<shape type=\"sphere\">\n <float name=\"radius\" value=\"$r\"/>\n <ref id=\"m\"/>\n</shape>\n</scene>\n"
    );
    let p = write(&dir, "ok.xml", &text);
    let s = load(&p, &[], None).unwrap();
    assert!((s.world.spheres()[0].radius - 0.5).abs() < 1e-6);
    let s = load(&p, &[("r", "2")], None).unwrap();
    assert!((s.world.spheres()[0].radius - 2.0).abs() < 1e-6);
    let e = error_of(&dir, "badref.xml", &text.replace("<ref id=\"m\"/>", "<ref id=\"nope\"/>"));
    assert!(e.contains("badref.xml:8:") && e.contains("nope"), "{e}");
}

/// `-D name=value` for a name the scene gives no `<default>` still substitutes `$name`, and is
/// a warning naming the file and the name (most often a typo); one with a default is silent.
#[test]
fn a_define_without_a_default_is_a_warning() {
    use glint::formats::Define;
    let text = format!(
        "<scene version=\"3.0.0\">\n<default name=\"r\" value=\"0.5\"/>\n{SENSOR}\n<shape type=\"sphere\">\n <float name=\"radius\" value=\"$r\"/>\n</shape>\n</scene>\n"
    );
    let define = |name: &str, value: &str| Define { name: name.into(), value: value.into() };
    let path = std::path::Path::new("defines.xml");
    let with_default = glint::formats::mitsuba::read_str(&text, path, &[define("r", "2")]).unwrap();
    assert!(!with_default.warnings.iter().any(|w| w.contains("-D")), "{:?}", with_default.warnings);
    let typo = glint::formats::mitsuba::read_str(&text, path, &[define("radius", "2")]).unwrap();
    let warned: Vec<_> = typo.warnings.iter().filter(|w| w.contains("-D radius")).collect();
    assert_eq!(warned.len(), 1, "{:?}", typo.warnings);
    assert!(warned[0].starts_with("defines.xml") && !warned[0].contains('\n'), "{}", warned[0]);
    // Without a default the define still substitutes (as Mitsuba does).
    let text = text.replace("<default name=\"r\" value=\"0.5\"/>\n", "");
    let s = glint::formats::mitsuba::read_str(&text, path, &[define("r", "2")]).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("-D r:")), "{:?}", s.warnings);
}

/// The `direct` integrator's counts as Mitsuba reads them: `shading_samples` sets both, each
/// of `emitter_samples` and `bsdf_samples` overrides one; giving both kinds, a negative count,
/// or no sample at all is an error.
#[test]
fn direct_integrator_sample_counts() {
    let dir = scratch("direct-counts");
    use glint::describe::{DirectSettings, IntegratorDesc};
    let scene = |params: &str| {
        format!("<scene version=\"3.0.0\">\n{SENSOR}\n<integrator type=\"direct\">{params}</integrator>\n</scene>\n")
    };
    let read = |params: &str| {
        let desc = glint::formats::mitsuba::read_str(&scene(params), std::path::Path::new("direct.xml"), &[]).unwrap();
        match desc.integrator {
            IntegratorDesc::Direct(d) => d,
            other => panic!("{params}: read as {other:?}"),
        }
    };
    let counts = |d: DirectSettings| (d.emitter_samples, d.bsdf_samples);
    assert_eq!(counts(read("")), (1, 1));
    assert_eq!(counts(read(r#"<integer name="shading_samples" value="3"/>"#)), (3, 3));
    assert_eq!(counts(read(r#"<integer name="emitter_samples" value="0"/>"#)), (0, 1));
    assert_eq!(
        counts(read(r#"<integer name="bsdf_samples" value="4"/><integer name="emitter_samples" value="2"/>"#)),
        (2, 4)
    );
    assert!(read(r#"<boolean name="hide_emitters" value="true"/>"#).hide_emitters);
    for (params, needle) in [
        (r#"<integer name="shading_samples" value="2"/><integer name="bsdf_samples" value="1"/>"#, "not both"),
        (r#"<integer name="emitter_samples" value="-1"/>"#, "out of range"),
        (r#"<integer name="emitter_samples" value="0"/><integer name="bsdf_samples" value="0"/>"#, "at least one"),
    ] {
        let e = error_of(&dir, "direct.xml", &scene(params));
        assert!(e.contains("direct.xml:4:") && e.contains(needle), "{params}: {e}");
    }
}

/// Integrators that render what glint's do: `prb` and `prb_basic` read as `path`,
/// `prbvolpath` as `volpath`, with their parameters; `aov` renders its nested integrator
/// (its layers: tests/scene_aovs.rs), and without one it is an error.
#[test]
fn integrators_read_as_the_ones_they_render_like() {
    let dir = scratch("integrator-aliases");
    use glint::describe::IntegratorDesc;
    let scene = |integrator: &str| format!("<scene version=\"3.0.0\">\n{SENSOR}\n{integrator}\n</scene>\n");
    let read = |integrator: &str| {
        glint::formats::mitsuba::read_str(&scene(integrator), std::path::Path::new("aliases.xml"), &[]).unwrap()
    };
    for ty in ["prb", "prb_basic"] {
        let d = read(&format!(r#"<integrator type="{ty}"><integer name="max_depth" value="3"/></integrator>"#));
        match d.integrator {
            IntegratorDesc::Path(p) => assert_eq!(p.max_depth, Some(3), "{ty}"),
            other => panic!("{ty}: read as {other:?}"),
        }
        assert!(d.warnings.is_empty(), "{ty}: {:?}", d.warnings);
    }
    let d = read(r#"<integrator type="prbvolpath"><integer name="rr_depth" value="2"/></integrator>"#);
    assert!(matches!(&d.integrator, IntegratorDesc::Volpath(v) if v.rr_depth == 2), "{:?}", d.integrator);

    let d = read(
        r#"<integrator type="aov"><string name="aovs" value="dd.y:depth,nn:sh_normal"/>
    <integrator type="volpath" name="image"><integer name="max_depth" value="7"/></integrator>
</integrator>"#,
    );
    assert!(matches!(&d.integrator, IntegratorDesc::Volpath(v) if v.max_depth == Some(7)), "{:?}", d.integrator);
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);

    let e = error_of(&dir, "aov.xml", &scene(r#"<integrator type="aov"/>"#));
    assert!(e.contains("aov.xml:4:") && e.contains("nested <integrator>"), "{e}");
}

/// A one-channel `.vol` file of `res` samples per axis (values x fastest).
fn vol_bytes(res: [i32; 3], channels: i32, values: &[f32]) -> Vec<u8> {
    let mut b = b"VOL\x03".to_vec();
    for v in [1, res[0], res[1], res[2], channels] {
        b.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0].iter().chain(values) {
        b.extend(v.to_le_bytes());
    }
    b
}

fn sdf_scene(shape_body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"sdfgrid\">\n{shape_body}\n</shape>\n</scene>\n")
}

#[test]
fn sdfgrid_bad_files_and_parameters() {
    let dir = scratch("sdfgrid");
    // Missing file, a file that is not a grid, a truncated one, three channels, no surface.
    let e = error_of(&dir, "sdf-missing.xml", &sdf_scene(" <string name=\"filename\" value=\"nowhere.vol\"/>"));
    assert!(e.contains("sdf-missing.xml:4:") && e.contains("nowhere.vol"), "{e}");
    std::fs::write(dir.join("sdf-text.vol"), "not a grid").unwrap();
    let e = error_of(&dir, "sdf-corrupt.xml", &sdf_scene(" <string name=\"filename\" value=\"sdf-text.vol\"/>"));
    assert!(e.contains("sdf-corrupt.xml:4:") && e.contains("VOL"), "{e}");
    let mut short = vol_bytes([2, 2, 2], 1, &[1.0; 8]);
    short.truncate(short.len() - 4);
    std::fs::write(dir.join("sdf-short.vol"), short).unwrap();
    let e = error_of(&dir, "sdf-short.xml", &sdf_scene(" <string name=\"filename\" value=\"sdf-short.vol\"/>"));
    assert!(e.contains("sdf-short.xml:4:") && e.contains("sdf-short.vol"), "{e}");
    std::fs::write(dir.join("sdf-rgb.vol"), vol_bytes([2, 2, 2], 3, &[1.0; 24])).unwrap();
    let e = error_of(&dir, "sdf-rgb.xml", &sdf_scene(" <string name=\"filename\" value=\"sdf-rgb.vol\"/>"));
    assert!(e.contains("sdf-rgb.xml:4:") && e.contains("1 channel, this one has 3"), "{e}");
    std::fs::write(dir.join("sdf-empty.vol"), vol_bytes([2, 2, 2], 1, &[1.0; 8])).unwrap();
    let e = error_of(&dir, "sdf-empty.xml", &sdf_scene(" <string name=\"filename\" value=\"sdf-empty.vol\"/>"));
    assert!(e.contains("sdf-empty.xml:4:") && e.contains("no surface"), "{e}");
    std::fs::write(dir.join("sdf-flat.vol"), vol_bytes([1, 2, 2], 1, &[1.0; 4])).unwrap();
    let e = error_of(&dir, "sdf-flat.xml", &sdf_scene(" <string name=\"filename\" value=\"sdf-flat.vol\"/>"));
    assert!(e.contains("sdf-flat.xml:4:") && e.contains("at least 2 samples"), "{e}");

    // Unsupported parameters and uses.
    let good = vol_bytes([2, 2, 2], 1, &[-1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
    std::fs::write(dir.join("sdf-good.vol"), good).unwrap();
    let file = " <string name=\"filename\" value=\"sdf-good.vol\"/>";
    let e =
        error_of(&dir, "sdf-normals.xml", &sdf_scene(&format!("{file}\n <string name=\"normals\" value=\"flat\"/>")));
    assert!(e.contains("sdf-normals.xml:6:") && e.contains("'flat'"), "{e}");
    let e = error_of(&dir, "sdf-noname.xml", &sdf_scene(" <string name=\"normals\" value=\"smooth\"/>"));
    assert!(e.contains("sdf-noname.xml:4:") && e.contains("needs 'filename'"), "{e}");
    let emitter = "<emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter>";
    let e = error_of(&dir, "sdf-emit.xml", &sdf_scene(&format!("{file}\n {emitter}")));
    assert!(e.contains("sdf-emit.xml:4:") && e.contains("cannot emit"), "{e}");
    let e = error_of(
        &dir,
        "sdf-flip.xml",
        &sdf_scene(&format!("{file}\n <boolean name=\"flip_normals\" value=\"true\"/>")),
    );
    assert!(e.contains("sdf-flip.xml:4:") && e.contains("flip_normals"), "{e}");
    // The good grid loads, by itself and through an instance.
    let p = write(&dir, "sdf-ok.xml", &sdf_scene(file));
    assert!(load(&p, &[], None).is_ok());
}

/// `principledthin`'s documented ranges: [0, 1], but `diff_trans` in [0, 2] and `eta`
/// positive (a texture's values included); the limits themselves load.
#[test]
fn principledthin_parameter_ranges() {
    let dir = scratch("principledthin-ranges");
    let scene = |params: &str| {
        format!(
            "<scene version=\"3.0.0\">\n{SENSOR}\n<shape type=\"sphere\">\n <bsdf type=\"principledthin\">{params}</bsdf>\n</shape>\n</scene>\n"
        )
    };
    for (params, wanted) in [
        (r#"<float name="diff_trans" value="2.5"/>"#, "diff_trans (2.5, 2.5, 2.5) must lie in [0, 2]"),
        (r#"<float name="spec_trans" value="1.2"/>"#, "spec_trans (1.2, 1.2, 1.2) must lie in [0, 1]"),
        (r#"<float name="sheen" value="-0.1"/>"#, "colour (-0.1, -0.1, -0.1) must be finite and not negative"),
        (
            r#"<texture type="checkerboard" name="eta"><float name="color0" value="1.3"/><float name="color1" value="0"/></texture>"#,
            "index of refraction 0 must be positive",
        ),
        (r#"<float name="specular_transmittance_sampling_rate" value="-1"/>"#, "must be finite and not negative"),
    ] {
        let e = error_of(&dir, "thin.xml", &scene(params));
        assert!(e.contains("thin.xml:5") && e.contains(wanted), "{params}: {e}");
    }
    let ok = write(
        &dir,
        "thin-ok.xml",
        &scene(
            r#"<float name="diff_trans" value="2"/><float name="spec_trans" value="1"/><float name="eta" value="0.9"/>"#,
        ),
    );
    load(&ok, &[], None).unwrap();
}
