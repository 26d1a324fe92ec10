//! The film's contract through the real command line: for a given scene, seed, spp and
//! pass size the image is bit-identical whether rendered in one go, interrupted (by real
//! signals) and resumed twice, split into pass ranges or pixel regions and merged, or on
//! 1, 2 or 3 threads; for the path tracer and for Whitted. And films and checkpoints that
//! are corrupted, truncated or of another scene fail with one clear line.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};
use std::time::{Duration, Instant};

fn glint() -> Command {
    Command::new(env!("CARGO_BIN_EXE_glint"))
}

fn repo(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(p).to_string_lossy().to_string()
}

struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("glint-film-cli-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }
    fn path(&self, name: &str) -> String {
        self.0.join(name).to_string_lossy().to_string()
    }
    /// No temporary files anywhere in the folder.
    fn assert_clean(&self) {
        for e in std::fs::read_dir(&self.0).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().to_string();
            assert!(!name.ends_with(".tmp"), "temporary file {name} left behind");
        }
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn ok(args: &[&str]) -> Output {
    let o = glint().args(args).output().unwrap();
    assert!(o.status.success(), "glint {args:?} failed: {}", String::from_utf8_lossy(&o.stderr));
    o
}

fn fails(args: &[&str]) -> String {
    let o = glint().args(args).output().unwrap();
    let e = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success(), "glint {args:?} should have failed");
    assert!(!e.contains("panicked"), "panic: {e}");
    assert_eq!(e.trim().lines().count(), 1, "not one line: {e}");
    e
}

fn same_file(a: &str, b: &str) {
    let (x, y) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    assert!(x == y, "{a} and {b} differ");
}

/// A scene and the settings every render of it shares in a test.
struct Case {
    scene: String,
    common: Vec<String>,
}

impl Case {
    fn path_tracer() -> Case {
        let common = ["--width", "40", "--height", "30", "--seed", "7", "--quiet"];
        Case { scene: repo("scenes/cornell-box.json"), common: common.iter().map(|s| s.to_string()).collect() }
    }
    fn whitted() -> Case {
        let common = ["--width", "40", "--height", "30", "--seed", "3", "--quiet"];
        Case { scene: repo("scenes/whitted-balls.json"), common: common.iter().map(|s| s.to_string()).collect() }
    }
    fn render(&self, out: &str, spp: u32, extra: &[&str]) {
        let spp = spp.to_string();
        let mut args: Vec<&str> = vec!["render", &self.scene, "-o", out, "--spp", &spp];
        args.extend(self.common.iter().map(String::as_str));
        args.extend(extra);
        ok(&args);
    }
}

fn contract(case: &Case, name: &str) {
    let d = Dir::new(name);
    let one = d.path("one.pfm");
    case.render(&one, 12, &[]);
    for t in ["1", "2", "3"] {
        let out = d.path(&format!("t{t}.pfm"));
        case.render(&out, 12, &["--threads", t]);
        same_file(&one, &out);
    }
    // Pass ranges rendered apart and merged.
    let (a, b) = (d.path("a.film"), d.path("b.film"));
    case.render(&d.path("a.pfm"), 12, &["--passes", "0..5", "--film-out", &a]);
    case.render(&d.path("b.pfm"), 12, &["--passes", "5..12", "--film-out", &b]);
    let merged = d.path("merged.pfm");
    ok(&["merge", &a, &b, "-o", &merged, "--quiet"]);
    same_file(&one, &merged);
    // Pixel regions rendered apart (one with another pass size: the image does not depend
    // on it) and merged.
    let (top, bottom) = (d.path("top.film"), d.path("bottom.film"));
    case.render(&d.path("top.pfm"), 12, &["--crop", "0,0,40,11", "--film-out", &top]);
    case.render(&d.path("bottom.pfm"), 12, &["--crop", "0,11,40,30", "--film-out", &bottom, "--threads", "1"]);
    let regions = d.path("regions.pfm");
    ok(&["merge", &top, &bottom, "-o", &regions, "--quiet"]);
    same_file(&one, &regions);
    // Scattered blocks (a region with fewer passes than the rest) merged into one film,
    // which `resume` fills in: what a render farm's checkpoint holds.
    let (tl, rest) = (d.path("tl.film"), d.path("rest.film"));
    case.render(&d.path("tl.pfm"), 12, &["--crop", "0,0,40,11", "--passes", "0..5", "--film-out", &tl]);
    case.render(&d.path("rest.pfm"), 12, &["--crop", "0,11,40,30", "--passes", "0..9", "--film-out", &rest]);
    let scattered = d.path("scattered.film");
    ok(&["merge", &tl, &rest, "-o", &d.path("scattered.pfm"), "--film-out", &scattered, "--quiet"]);
    let resumed = d.path("resumed.pfm");
    ok(&["resume", &scattered, "-o", &resumed, "--quiet"]);
    same_file(&one, &resumed);
    // Overlapping work is refused.
    let e = fails(&["merge", &a, &a, "-o", &d.path("x.pfm")]);
    assert!(e.contains("a.film"), "{e}");
    d.assert_clean();
}

#[test]
fn path_tracer_images_are_identical_however_they_are_split() {
    contract(&Case::path_tracer(), "path");
}

#[test]
fn whitted_images_are_identical_however_they_are_split() {
    contract(&Case::whitted(), "whitted");
}

fn kill(child: &Child, signal: &str) {
    let s = Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap();
    assert!(s.success());
}

/// Waits until `path` exists with a modification time after `after`.
fn wait_for_write(path: &str, after: Option<std::time::SystemTime>, child: &mut Child) {
    let start = Instant::now();
    loop {
        if let Ok(m) = std::fs::metadata(path).and_then(|m| m.modified()) {
            if after.is_none_or(|a| m > a) {
                return;
            }
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the render ended ({status}) before its checkpoint was written");
        }
        assert!(start.elapsed() < Duration::from_secs(60), "no checkpoint written");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn interrupted_twice_and_resumed_is_identical() {
    let d = Dir::new("interrupt");
    let case = Case::path_tracer();
    let spp = 3000;
    let one = d.path("one.pfm");
    case.render(&one, spp, &[]);
    let (out, ck) = (d.path("out.pfm"), d.path("render.ck"));
    let spp_text = spp.to_string();
    let mut args: Vec<&str> =
        vec!["render", &case.scene, "-o", &out, "--spp", &spp_text, "--checkpoint", &ck, "--checkpoint-every", "0.05"];
    args.extend(case.common.iter().map(String::as_str));
    // First stop: Ctrl-C (SIGINT) once a checkpoint exists, so the render is under way.
    let mut child = glint().args(&args).spawn().unwrap();
    wait_for_write(&ck, None, &mut child);
    kill(&child, "-INT");
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "SIGINT should end the render with 130");
    assert!(Path::new(&out).exists(), "the image so far is written on interrupt");
    // Second stop: SIGTERM during the resumed render.
    let before = std::fs::metadata(&ck).unwrap().modified().unwrap();
    let mut child = glint().args(["resume", &ck, "--checkpoint-every", "0.05", "--quiet"]).spawn().unwrap();
    wait_for_write(&ck, Some(before), &mut child);
    kill(&child, "-TERM");
    assert_eq!(child.wait().unwrap().code(), Some(143), "SIGTERM should end the render with 143");
    // Then to the end.
    ok(&["resume", &ck, "--quiet"]);
    same_file(&one, &out);
    d.assert_clean();
}

#[test]
fn time_limit_stops_with_fewer_samples() {
    let d = Dir::new("time");
    let case = Case::path_tracer();
    let out = d.path("t.pfm");
    let o = glint()
        .args([
            "render",
            &case.scene,
            "-o",
            &out,
            "--spp",
            "1000000",
            "--time-limit",
            "1",
            "--width",
            "40",
            "--height",
            "32",
        ])
        .output()
        .unwrap();
    assert!(o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    let reached: u32 = e
        .split("time limit reached at ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no time-limit note in: {e}"));
    assert!((1..1_000_000).contains(&reached), "{reached} spp");
    assert!(Path::new(&out).exists());
}

#[test]
fn damaged_and_foreign_films_fail_cleanly() {
    let d = Dir::new("damaged");
    // A scene of our own, so that changing it can be tested.
    let scene = d.path("s.json");
    let text = std::fs::read_to_string(repo("scenes/cornell-box.json")).unwrap();
    let text = text.replace("\"assets/", &format!("\"{}/", repo("scenes/assets")));
    std::fs::write(&scene, &text).unwrap();
    let ck = d.path("s.ck");
    ok(&[
        "render",
        &scene,
        "-o",
        &d.path("s.pfm"),
        "--spp",
        "4",
        "--width",
        "16",
        "--height",
        "16",
        "--checkpoint",
        &ck,
        "--quiet",
    ]);
    let good = std::fs::read(&ck).unwrap();

    // A flipped byte in the middle, a truncated file, a file that is no film at all.
    let mut bad = good.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0x40;
    let corrupt = d.path("corrupt.ck");
    std::fs::write(&corrupt, &bad).unwrap();
    let e = fails(&["resume", &corrupt, "--quiet"]);
    assert!(e.contains("corrupt.ck"), "{e}");
    let truncated = d.path("truncated.ck");
    std::fs::write(&truncated, &good[..good.len() - 100]).unwrap();
    let e = fails(&["resume", &truncated, "--quiet"]);
    assert!(e.contains("truncated.ck"), "{e}");
    let e = fails(&["merge", &scene, "-o", &d.path("m.pfm")]);
    assert!(e.contains("s.json"), "{e}");

    // A film of another scene does not merge with this one.
    let other = d.path("other.ck");
    ok(&[
        "render",
        &repo("scenes/whitted-balls.json"),
        "-o",
        &d.path("o.pfm"),
        "--spp",
        "4",
        "--width",
        "16",
        "--height",
        "16",
        "--film-out",
        &other,
        "--quiet",
    ]);
    let e = fails(&["merge", &ck, &other, "-o", &d.path("m.pfm")]);
    assert!(e.contains("other.ck") && e.contains("another scene"), "{e}");
    // Other settings (seed) do not merge either.
    let seeded = d.path("seeded.ck");
    ok(&[
        "render",
        &scene,
        "-o",
        &d.path("q.pfm"),
        "--spp",
        "4",
        "--width",
        "16",
        "--height",
        "16",
        "--seed",
        "9",
        "--film-out",
        &seeded,
        "--quiet",
    ]);
    let e = fails(&["merge", &ck, &seeded, "-o", &d.path("m.pfm")]);
    assert!(e.contains("seeded.ck"), "{e}");

    // The scene changed since the checkpoint: resume refuses, and the checkpoint is kept.
    std::fs::write(&scene, text.replacen("\"fov\": 40", "\"fov\": 41", 1)).unwrap();
    let e = fails(&["resume", &ck, "--quiet"]);
    assert!(e.contains("s.ck") && e.contains("changed"), "{e}");
    assert_eq!(std::fs::read(&ck).unwrap(), good, "a refused resume must not touch the checkpoint");
    assert!(!Path::new(&d.path("m.pfm")).exists(), "a failed merge wrote an image");
    d.assert_clean();
}

#[test]
fn exr_output_carries_the_aov_layers() {
    let d = Dir::new("aov");
    let out = d.path("a.exr");
    ok(&[
        "render",
        &repo("scenes/cornell-box.json"),
        "-o",
        &out,
        "--spp",
        "2",
        "--width",
        "16",
        "--height",
        "16",
        "--aov",
        "albedo,normal,depth,spp",
        "--quiet",
    ]);
    let bytes = std::fs::read(&out).unwrap();
    for name in ["albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Z", "depth.Z", "spp.Y"] {
        let needle = format!("{name}\0");
        assert!(bytes.windows(needle.len()).any(|w| w == needle.as_bytes()), "no channel {name} in the EXR header");
    }
    // PNG output writes one file per layer.
    let png = d.path("b.png");
    ok(&[
        "render",
        &repo("scenes/cornell-box.json"),
        "-o",
        &png,
        "--spp",
        "1",
        "--width",
        "16",
        "--height",
        "16",
        "--aov",
        "normal,bvh-cost",
        "--quiet",
    ]);
    assert!(Path::new(&d.path("b.normal.png")).exists() && Path::new(&d.path("b.bvh-cost.png")).exists());
}
