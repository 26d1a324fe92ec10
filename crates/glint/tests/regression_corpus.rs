//! Replays `tests/regressions/<format>/`: inputs that once crashed, hung or blew up memory
//! (found by fuzzing, see docs/robustness.md, or crafted from the issue). Each must load to
//! `Ok` or `Err` without a panic, within a generous time limit, and without any single
//! allocation above `ALLOCATION_LIMIT` (the test's allocator refuses larger ones, which
//! aborts the run with "memory allocation of N bytes failed"). Files named `*.err.*` must
//! give an `Err`, in one line that names the file.

use glint::io::{image_io, obj, ply};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

/// No decoder should need more for these small files; the budgets in `io` are 512 MiB.
const ALLOCATION_LIMIT: usize = 768 << 20;
/// Against hangs only: each case takes milliseconds.
const CASE_TIMEOUT: Duration = Duration::from_secs(20);

struct Bounded;

// SAFETY: forwards to the system allocator, refusing (null, as `GlobalAlloc` allows) only
// requests above the limit.
unsafe impl GlobalAlloc for Bounded {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > ALLOCATION_LIMIT {
            return std::ptr::null_mut();
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > ALLOCATION_LIMIT {
            return std::ptr::null_mut();
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Bounded = Bounded;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/regressions")
}

/// Loads `data` as `format` (the corpus folder's name); `path` names it in errors.
fn load(format: &str, data: &[u8], path: &Path) -> Result<(), String> {
    match format {
        "obj" => obj::parse_obj_bytes(data, path).map(drop),
        "ply" => ply::parse_ply(data, path).map(drop),
        "exr" => image_io::read_exr_bytes(data, path).map(drop),
        "pfm" => image_io::read_pfm_bytes(data, path).map(drop),
        "png" => image_io::decode_raster_bytes(data, path).map(drop),
        "mitsuba" => mitsuba_scene(data, path),
        "gltf" => gltf_scene(path),
        other => panic!("unknown corpus folder '{other}'"),
    }
}

/// A `mitsuba_scene` fuzz input: the scene, then the files it may include (`/fuzz/inc1.xml`,
/// ...), separated by NUL bytes, read as that fuzz target reads them.
fn mitsuba_scene(data: &[u8], path: &Path) -> Result<(), String> {
    let mut parts = data.split(|&b| b == 0);
    let scene = String::from_utf8_lossy(parts.next().unwrap_or_default()).into_owned();
    let files: std::collections::HashMap<PathBuf, String> = parts
        .take(7)
        .enumerate()
        .map(|(i, p)| (PathBuf::from(format!("/fuzz/inc{}.xml", i + 1)), String::from_utf8_lossy(p).into_owned()))
        .collect();
    glint::formats::mitsuba::read_str_with_includes(&scene, path, &[], &files).map(drop).map_err(|e| e.to_string())
}

/// A `.gltf` or `.glb` file read and built as `glint render` does (its primitives, images
/// and textures are read by the build), so every size it claims meets its bound.
fn gltf_scene(path: &Path) -> Result<(), String> {
    let desc = glint::formats::gltf::read(path, None).map_err(|e| e.to_string())?;
    glint::assemble::build(&desc, &Default::default()).map(drop).map_err(|e| e.to_string())
}

/// Runs one case on its own thread: Some(result), or None if it panicked or timed out.
fn run_case(format: &str, path: &Path) -> Result<Result<(), String>, String> {
    let data = std::fs::read(path).unwrap();
    let (format, p) = (format.to_string(), path.to_path_buf());
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(load(&format, &data, &p));
    });
    match rx.recv_timeout(CASE_TIMEOUT) {
        Ok(r) => Ok(r),
        Err(mpsc::RecvTimeoutError::Timeout) => Err(format!("took more than {CASE_TIMEOUT:?}")),
        Err(mpsc::RecvTimeoutError::Disconnected) => Err("panicked".to_string()),
    }
}

#[test]
fn every_regression_input_loads_or_fails_cleanly() {
    let mut cases = 0;
    let mut failures = Vec::new();
    for dir in std::fs::read_dir(corpus()).unwrap() {
        let dir = dir.unwrap().path();
        if !dir.is_dir() {
            continue;
        }
        let format = dir.file_name().unwrap().to_str().unwrap().to_string();
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
        files.sort();
        for file in files {
            cases += 1;
            let name = file.file_name().unwrap().to_str().unwrap().to_string();
            match run_case(&format, &file) {
                Err(why) => failures.push(format!("{format}/{name}: {why}")),
                Ok(Ok(())) if name.contains(".err.") => {
                    failures.push(format!("{format}/{name}: loaded, expected an error"))
                }
                Ok(Err(e)) => {
                    if !e.contains(&name) || e.contains('\n') {
                        failures.push(format!("{format}/{name}: error does not name the file in one line: {e}"));
                    }
                }
                Ok(Ok(())) => {}
            }
        }
    }
    assert!(cases >= 20, "only {cases} cases found under {}", corpus().display());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn error_of(format: &str, name: &str) -> String {
    let path = corpus().join(format).join(name);
    run_case(format, &path).unwrap().unwrap_err()
}

/// Every size a glTF file can claim is refused with the reason before it is allocated.
#[test]
fn oversized_gltf_claims_are_refused_with_the_reason() {
    let e = error_of("gltf", "accessor-count-4e9-in-36-bytes.err.gltf");
    assert!(e.contains("attributes.POSITION: accessor 0 reads past the end of buffer 0"), "{e}");
    let e = error_of("gltf", "unbacked-accessor-1e9.err.gltf");
    assert!(e.contains("no bufferView and 1000000000 elements"), "{e}");
    let e = error_of("gltf", "sparse-count-above-the-accessor.err.gltf");
    assert!(e.contains("sparse.count: 1000000 substitutions in an accessor of 3 elements"), "{e}");
    let e = error_of("gltf", "png-claiming-65535x65535.err.gltf");
    assert!(e.contains("images[0]: image of 65535 x 65535 pixels"), "{e}");
    let e = error_of("gltf", "json-chunk-of-4-gib.err.glb");
    assert!(e.contains("length 4294967280 runs past the end of the file"), "{e}");
    let e = error_of("gltf", "node-is-its-own-child.err.gltf");
    assert!(e.contains("node 0 appears twice"), "{e}");
    assert!(run_case("gltf", &corpus().join("gltf").join("one-triangle.gltf")).unwrap().is_ok());
}

/// The specific complaints of the issue get specific messages.
#[test]
fn oversized_counts_and_images_are_refused_with_the_reason() {
    let e = error_of("ply", "list-length-0xffffffff.err.ply");
    assert!(e.contains("list of 4294967295 values is longer than the rest of the file"), "{e}");
    let e = error_of("ply", "list-length-float-1e30.err.ply");
    assert!(e.contains("longer than the rest of the file"), "{e}");
    let e = error_of("ply", "element-count-1e30.err.ply");
    assert!(e.contains(":3: malformed element line"), "{e}");
    let e = error_of("ply", "element-count-above-u32.err.ply");
    assert!(e.contains(":3:") && e.contains("more than the 4294967295 allowed"), "{e}");
    let e = error_of("ply", "vertex-count-0xffffffff-in-a-tiny-file.err.ply");
    assert!(e.contains("claims 4294967295 entries"), "{e}");
    let e = error_of("ply", "nan-vertex-index.err.ply");
    assert!(e.contains("uses vertex NaN"), "{e}");
    let e = error_of("obj", "huge-index.err.obj");
    assert!(e.contains(":4:") && e.contains("out of range"), "{e}");
    let e = error_of("obj", "index-beyond-i64.err.obj");
    assert!(e.contains(":4:") && e.contains("bad vertex index"), "{e}");
    let e = error_of("obj", "mtllib-dev-zero.err.obj");
    assert!(e.contains(":1:") && e.contains("/dev/zero: not a regular file"), "{e}");
    for (format, name) in [
        ("exr", "65536x65536-in-a-10kb-file.err.exr"),
        ("pfm", "65536x65536-in-a-tiny-file.err.pfm"),
        ("pfm", "size-overflows-usize.err.pfm"),
        ("png", "65535x65535-in-a-tiny-file.err.png"),
    ] {
        let e = error_of(format, name);
        assert!(e.contains("exceeds the 512 MiB decoding budget"), "{name}: {e}");
    }
    let e = error_of("pfm", "truncated.err.pfm");
    assert!(e.contains("truncated"), "{e}");
}

/// The crafted EXR differs from a good file only in its claimed size: the good one loads.
#[test]
fn the_unmodified_exr_still_loads() {
    let sky = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/scenes/mitsuba/assets/sky.exr");
    let img = image_io::read_exr(&sky).unwrap();
    assert_eq!((img.width, img.height), (64, 32));
}
