//! Inputs a hostile user would try (the robustness issue's examples): each gets one clear
//! line naming the file, a non-zero exit and no output file — or, where the input is valid
//! but extreme, a render that ends. Never a crash, a hang or an exhausted machine.

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("glint-hostile-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }
    fn write(&self, name: &str, text: &str) -> String {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().to_string()
    }
    fn out(&self) -> String {
        self.0.join("out.pfm").to_string_lossy().to_string()
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs glint with a deadline (a hang fails the test instead of stalling the suite).
fn run(args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("glint {args:?} did not finish within 60 s");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().unwrap()
}

/// Expects one clear error line that names `file` and contains `needle`, and no image.
fn rejects(d: &Dir, file: &str, needle: &str, extra: &[&str]) {
    let out = d.out();
    let _ = std::fs::remove_file(&out);
    let mut args = vec!["render", file, "-o", &out, "--spp", "1", "--quiet"];
    args.extend(extra);
    let o = run(&args);
    let e = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success(), "{file} rendered but should not: {e}");
    assert!(o.status.code() == Some(1), "{file}: exit {:?} (a crash?): {e}", o.status);
    assert_eq!(e.trim().lines().count(), 1, "{file}: not one line: {e}");
    let name = std::path::Path::new(file).file_name().unwrap().to_string_lossy().to_string();
    assert!(e.contains(&name) && e.contains(needle), "{file}: expected '{needle}' in: {e}");
    assert!(!std::path::Path::new(&out).exists(), "{file}: an image was written");
}

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
  <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;

fn xml(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{SENSOR}\n{body}\n</scene>\n")
}

fn json(shapes: &str, lights: &str, extra: &str) -> String {
    format!(
        r#"{{ "camera": {{ "position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40 }},
  "film": {{ "width": 8, "height": 8 }}, {extra}
  "materials": {{ "white": {{ "type": "diffuse", "reflectance": 0.5 }} }},
  "shapes": [ {shapes} ],
  "lights": [ {lights} ] }}"#
    )
}

#[test]
fn non_finite_values_are_rejected_where_they_are_written() {
    let d = Dir::new("nonfinite");
    // An emitting sphere at 1e39: a finite f64, infinite as f32.
    let f = d.write(
        "far.xml",
        &xml("<shape type=\"sphere\"><point name=\"center\" x=\"1e39\" y=\"0\" z=\"0\"/>\n<emitter type=\"area\"/></shape>"),
    );
    rejects(&d, &f, "not finite", &[]);
    // JSON numbers are read exactly into their fields (serde_json's float_roundtrip), so one
    // beyond f32's range is refused where it is parsed, at its line and column.
    let f = d.write("far.json", &json(r#"{ "type": "sphere", "center": [1e39, 0, 0], "emission": 1 }"#, "", ""));
    rejects(&d, &f, "far.json:4:49: number out of range", &[]);
    // A spot light whose `up` is infinite.
    let f = d.write(
        "spot.xml",
        &xml("<emitter type=\"spot\"><transform name=\"to_world\"><lookat origin=\"0,2,0\" target=\"0,0,0\" up=\"inf,1,0\"/></transform></emitter>"),
    );
    let o = run(&["render", &f, "-o", &d.out(), "--spp", "1", "--quiet"]);
    assert!(!o.status.success() && o.status.code() == Some(1), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn invalid_values_are_errors_with_their_range() {
    let d = Dir::new("values");
    let cases: Vec<(&str, String, &str)> = vec![
        ("neg.xml", xml("<shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"-1\"/></emitter></shape>"), "negative"),
        ("nan.json", json("", r#"{ "type": "point", "position": [0, 1, 0], "intensity": -2 }"#, ""), "negative"),
        ("spot.json", json("", r#"{ "type": "spot", "position": [0, 1, 0], "target": [0, 1, 0], "intensity": 1 }"#, ""), "zero"),
        ("dir.json", json("", r#"{ "type": "directional", "direction": [0, 0, 0], "irradiance": 1 }"#, ""), "zero"),
        ("fov0.xml", xml("").replace("\"fov\" value=\"40\"", "\"fov\" value=\"0\""), "field of view"),
        ("fov180.xml", xml("").replace("\"fov\" value=\"40\"", "\"fov\" value=\"180\""), "field of view"),
        ("clip.xml", xml("").replace("<float name=\"fov\" value=\"40\"/>", "<float name=\"fov\" value=\"40\"/><float name=\"near_clip\" value=\"10\"/><float name=\"far_clip\" value=\"1\"/>"), "near_clip"),
        ("filter.xml", xml("").replace("</film>", "<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"nan\"/></rfilter></film>"), "filter"),
        ("rr.json", json("", "", r#""integrator": { "type": "path", "rr_probability": 0 },"#), "rr_probability"),
        ("phong.json", json(r#"{ "type": "sphere", "material": "p" }"#, "", "").replace(r#""white": {"#, r#""p": { "type": "phong", "kd": 0.5, "exponent": -3 }, "white": {"#), "exponent"),
        ("twice.json", json("", "", "").replace(r#""white": { "type": "diffuse", "reflectance": 0.5 }"#, r#""white": { "type": "diffuse", "reflectance": 0.5 }, "white": { "type": "diffuse", "reflectance": 0.9 }"#), "twice"),
        ("spp.xml", xml("").replace("</film>", "</film><sampler type=\"independent\"><integer name=\"sample_count\" value=\"4294967297\"/></sampler>"), "out of range"),
        ("depth.xml", format!("<scene version=\"3.0.0\"><integrator type=\"path\"><integer name=\"max_depth\" value=\"4294967296\"/></integrator>\n{SENSOR}</scene>"), "out of range"),
    ];
    for (name, text, needle) in &cases {
        let f = d.write(name, text);
        rejects(&d, &f, needle, &[]);
    }
}

#[test]
fn work_without_end_is_bounded() {
    let d = Dir::new("unbounded");
    // A default defined as itself: substituted once, then a clear error (not a loop).
    let f = d.write(
        "self.xml",
        &xml("<default name=\"a\" value=\"$a\"/><shape type=\"sphere\"><float name=\"radius\" value=\"$a\"/></shape>"),
    );
    rejects(&d, &f, "not a number", &[]);
    let f = d.write("d.xml", &xml("<shape type=\"sphere\"><float name=\"radius\" value=\"$spp\"/></shape>"));
    rejects(&d, &f, "not a number", &["-D", "spp=$spp"]);
    // Nine files each including the next ten times: 10^9 expansions unless bounded.
    for i in 0..9 {
        let inner = if i == 8 {
            "<shape type=\"sphere\"/>".to_string()
        } else {
            format!("<include filename=\"inc{}.xml\"/>", i + 1).repeat(10)
        };
        d.write(&format!("inc{i}.xml"), &format!("<scene version=\"3.0.0\">{inner}</scene>"));
    }
    let f = d.write("bomb.xml", &xml("<include filename=\"inc0.xml\"/>"));
    let o = run(&["render", &f, "-o", &d.out(), "--spp", "1", "--quiet"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && e.contains("<include>s") && e.trim().lines().count() == 1, "{e}");
    // 20,000 nested elements.
    let f = d
        .write("deep.xml", &xml(&format!("{}{}", "<shape type=\"sphere\">".repeat(20_000), "</shape>".repeat(20_000))));
    rejects(&d, &f, "nested", &[]);
    // A camera inside a closed mirror box with roulette that never kills: the path depth has
    // a ceiling, so the render ends.
    let mirror = d.write(
        "mirror.json",
        &json(
            r#"{ "type": "cube", "material": "m", "flip_normals": true, "transform": [ { "scale": 3 } ] },
               { "type": "sphere", "radius": 0.2, "center": [0, 1, 0], "emission": 1 }"#,
            "",
            r#""integrator": { "type": "path", "rr_probability": 1 },"#,
        )
        .replace(r#""white": {"#, r#""m": { "type": "mirror" }, "white": {"#),
    );
    let o = run(&["render", &mirror, "-o", &d.out(), "--spp", "1", "--width", "4", "--height", "4", "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Far more threads than cores: a warning and a cap, not 100,000 threads.
    let o = run(&[
        "render",
        &mirror,
        "-o",
        &d.out(),
        "--spp",
        "1",
        "--width",
        "2",
        "--height",
        "2",
        "--threads",
        "100000",
        "--integrator",
        "whitted",
    ]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--threads 100000"));
    // Whitted recursion 3000 deep runs (iteratively).
    let o = run(&[
        "render",
        &mirror,
        "-o",
        &d.out(),
        "--spp",
        "1",
        "--width",
        "2",
        "--height",
        "2",
        "--integrator",
        "whitted",
        "--max-depth",
        "3000",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn messages_stay_on_one_line_and_point_at_the_problem() {
    let d = Dir::new("messages");
    // Stray text is reported at its own line, not at the next tag's.
    let f = d.write("stray.xml", "<scene version=\"3.0.0\">\n\n  oops\n\n<shape type=\"sphere\"/>\n</scene>\n");
    rejects(&d, &f, "stray.xml:3:", &[]);
    // Control characters from the input are escaped.
    let f = d.write("ctl.xml", &xml("<shape type=\"sph\u{1b}[31mere\"/>"));
    rejects(&d, &f, "\\u{1b}", &[]);
    // A byte-order mark is accepted.
    let f = d.write(
        "bom.json",
        &format!("\u{feff}{}", json("", r#"{ "type": "point", "position": [0, 1, 0], "intensity": 1 }"#, "")),
    );
    assert!(run(&["render", &f, "-o", &d.out(), "--spp", "1", "--quiet"]).status.success());
    // A binary file with an unknown extension: "unknown scene format".
    let bin = d.0.join("scene.bin");
    std::fs::write(&bin, [0u8, 159, 146, 150, 255]).unwrap();
    rejects(&d, bin.to_str().unwrap(), "unknown scene format", &[]);
    // --width 0 names the width, not a height of 1.
    let f = d.write("ok.json", &json("", r#"{ "type": "point", "position": [0, 1, 0], "intensity": 1 }"#, ""));
    let o = run(&["render", &f, "-o", &d.out(), "--width", "0"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("0x8") && !e.contains("x1 "), "{e}");
    // A scene without lights renders black, with a warning.
    let dark = d.write("dark.json", &json(r#"{ "type": "sphere" }"#, "", ""));
    let o = run(&["render", &dark, "-o", &d.out(), "--spp", "1"]);
    assert!(o.status.success() && String::from_utf8_lossy(&o.stderr).contains("no lights"));
    // `glint info SCENE | head -1`: a closed pipe is no panic.
    let mut child = Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(["info", &f])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert!(!String::from_utf8_lossy(&o.stderr).contains("panicked"), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn outputs_are_checked_before_the_render() {
    let d = Dir::new("outputs");
    let f = d.write("ok.json", &json("", r#"{ "type": "point", "position": [0, 1, 0], "intensity": 1 }"#, ""));
    let missing = d.0.join("no-such-folder").join("o.png");
    let o = run(&["render", &f, "-o", missing.to_str().unwrap(), "--spp", "1"]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("does not exist"));
    // The output must not overwrite one of the scene's own files (here, its texture).
    let tex = d.0.join("tex.png").to_string_lossy().to_string();
    assert!(run(&["render", &f, "-o", &tex, "--spp", "1", "--quiet"]).status.success());
    let before = std::fs::read(&tex).unwrap();
    let textured = d.write(
        "textured.json",
        &json(
            r#"{ "type": "sphere", "material": "t" }"#,
            r#"{ "type": "point", "position": [0, 1, 3], "intensity": 5 }"#,
            "",
        )
        .replace(r#""white": {"#, r#""t": { "type": "diffuse", "reflectance": { "texture": "tex.png" } }, "white": {"#),
    );
    let o = run(&["render", &textured, "-o", &tex, "--spp", "1"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("overwrite"), "{e}");
    assert_eq!(std::fs::read(&tex).unwrap(), before, "the texture was overwritten");
    assert!(std::fs::read_to_string(&f).unwrap().contains("camera"), "the scene file was overwritten");
}

#[test]
fn whitted_in_glass_does_not_double_its_work_forever() {
    // Glass spheres inside a glass box: every hit splits into reflection and refraction, so
    // depth 3000 would be 2^3000 rays without the per-camera-ray budget.
    let d = Dir::new("glass");
    let f = d.write(
        "glass.json",
        &json(
            r#"{ "type": "cube", "material": "g", "transform": [ { "scale": 3 } ] },
               { "type": "sphere", "material": "g", "radius": 0.5 },
               { "type": "sphere", "material": "g", "radius": 0.3, "center": [1, 1, 0] }"#,
            r#"{ "type": "point", "position": [0, 2, 1], "intensity": 5 }"#,
            r#""integrator": { "type": "whitted", "max_depth": 3000 },"#,
        )
        .replace(r#""white": {"#, r#""g": { "type": "dielectric", "ior": 1.5 }, "white": {"#)
        .replace("\"position\": [0, 0, 5]", "\"position\": [0, 0, 2]"),
    );
    let o = run(&["render", &f, "-o", &d.out(), "--spp", "1", "--width", "4", "--height", "4", "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn bad_volume_grids_are_one_line_errors() {
    let d = Dir::new("vol");
    let header = |res: [i32; 3], channels: i32| {
        let mut b = b"VOL\x03".to_vec();
        for v in [1, res[0], res[1], res[2], channels] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&[0u8; 24]);
        b
    };
    let mut nan = header([1, 1, 1], 1);
    nan.extend_from_slice(&f32::NAN.to_le_bytes());
    for (vol, bytes, needle) in [
        // Claims 2^31 cells per axis: refused from the header, nothing allocated.
        ("huge.vol", header([i32::MAX, i32::MAX, i32::MAX], 3), "truncated volume grid"),
        ("short.vol", b"VOL\x03\x01\x00".to_vec(), "truncated volume grid header"),
        ("v2.vol", b"VOL\x02".to_vec(), "version 2"),
        ("nan.vol", nan, "must lie in [0, 1]"),
    ] {
        std::fs::write(d.0.join(vol), bytes).unwrap();
        let f = d.write(
            &format!("{vol}.xml"),
            &xml(&format!(
                r#"<integrator type="volpath"/><shape type="sphere"><bsdf type="null"/>
<medium type="homogeneous" name="interior"><volume name="albedo" type="gridvolume"><string name="filename" value="{vol}"/></volume></medium></shape>"#
            )),
        );
        rejects(&d, &f, needle, &[]);
    }
    // An unknown wrap mode is named at its line.
    let f = d.write(
        "wrap.xml",
        &xml(r#"<integrator type="volpath"/><shape type="sphere"><bsdf type="null"/>
<medium type="homogeneous" name="interior"><volume name="albedo" type="gridvolume"><string name="filename" value="a.vol"/>
<string name="wrap_mode" value="wobble"/></volume></medium></shape>"#),
    );
    rejects(&d, &f, "wrap.xml:7:", &[]);
}
