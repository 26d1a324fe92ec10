//! A full disk through the real command line. A checkpoint (or `--write-every` image) that
//! cannot be written is reported once, the previous checkpoint stays intact, the render goes
//! on and writes its image at the end, bit-identical; with no room for the image either, one
//! error line and a non-zero exit, no half-written file.
//!
//! The disk is a small tmpfs where the test may mount one (root, outside a sandbox that
//! refuses `mount`), and in any case the spawned CLI under RLIMIT_FSIZE with SIGXFSZ
//! ignored, so that an oversized write fails with EFBIG as a full disk fails with ENOSPC.

#![cfg(target_os = "linux")]

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn glint() -> Command {
    Command::new(env!("CARGO_BIN_EXE_glint"))
}

fn repo(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(p).to_string_lossy().to_string()
}

fn run(cmd: &mut Command) -> Output {
    let o = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "panic: {err}");
    o
}

fn ok(args: &[&str]) {
    let o = run(glint().args(args));
    assert!(o.status.success(), "glint {args:?} failed: {}", String::from_utf8_lossy(&o.stderr));
}

/// Where a write runs out of room, and the error that says so.
enum Disk {
    /// A tmpfs mounted at the folder (unmounted on drop), of this many bytes.
    Tmpfs(PathBuf),
    /// No mount: the spawned CLI's files may grow only as far as the room left.
    FileSizeLimit,
}

impl Disk {
    /// A tmpfs of `bytes` mounted on `dir`, if this process may mount one.
    fn tmpfs(dir: &Path, bytes: u64) -> Option<Disk> {
        let mounted = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={bytes}"), "tmpfs"])
            .arg(dir)
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        mounted.then(|| Disk::Tmpfs(dir.to_path_buf()))
    }

    /// The message of a write that does not fit.
    fn error(&self) -> &'static str {
        match self {
            Disk::Tmpfs(_) => "No space left on device",
            Disk::FileSizeLimit => "File too large",
        }
    }

    /// The command, limited to this disk's room.
    fn glint(&self, free: u64) -> Command {
        let mut cmd = glint();
        if let Disk::FileSizeLimit = self {
            // SAFETY: between fork and exec only async-signal-safe calls (signal, setrlimit)
            // on a struct built here; neither allocates nor touches the parent's state.
            unsafe {
                cmd.pre_exec(move || {
                    libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                    let limit = libc::rlimit { rlim_cur: free, rlim_max: free };
                    if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                        return Err(std::io::Error::last_os_error());
                    }
                    Ok(())
                });
            }
        }
        cmd
    }

    /// Fills a tmpfs until `free` bytes are left (a file-size limit needs nothing).
    fn leave_free(&self, dir: &Path, free: u64) {
        if let Disk::Tmpfs(_) = self {
            let _ = std::fs::remove_file(dir.join("filler"));
            // SAFETY: statvfs is plain integers, for which all zeroes is a valid value.
            let mut stat: libc::statvfs = unsafe { std::mem::zeroed() };
            let c = std::ffi::CString::new(dir.as_os_str().as_encoded_bytes()).unwrap();
            // SAFETY: a NUL-terminated path and a struct the call fills in, both live here.
            assert_eq!(unsafe { libc::statvfs(c.as_ptr(), &mut stat) }, 0);
            let available = stat.f_bavail as u64 * stat.f_frsize as u64;
            let filler = available.saturating_sub(free);
            std::fs::write(dir.join("filler"), vec![0u8; filler as usize]).unwrap();
        }
    }
}

impl Drop for Disk {
    fn drop(&mut self) {
        if let Disk::Tmpfs(dir) = self {
            let _ = Command::new("umount").arg(dir).status();
        }
    }
}

fn temp_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[test]
fn under_a_file_size_limit() {
    full_disk("limit", |_, _| Some(Disk::FileSizeLimit));
}

#[test]
fn on_a_full_tmpfs() {
    // Where mounting is refused (not root, a sandbox), the file-size limit above stands in.
    full_disk("tmpfs", Disk::tmpfs);
}

/// A checkpoint that does not fit warns and the render finishes, bit-identical, keeping the
/// previous checkpoint; an image that does not fit is one error line and exit 1.
fn full_disk(name: &str, make: impl FnOnce(&Path, u64) -> Option<Disk>) {
    let root = std::env::temp_dir().join(format!("glint-full-disk-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let disk_dir = root.join("disk");
    std::fs::create_dir_all(&disk_dir).unwrap();
    let at = |d: &Path, n: &str| d.join(n).to_string_lossy().to_string();
    let scene = repo("scenes/cornell-box.json");
    let common = ["--width", "32", "--height", "32", "--seed", "5"];

    // The reference, and a checkpoint at 4 of its 12 spp, on an ordinary disk.
    let (reference, start) = (at(&root, "reference.pfm"), at(&root, "start.film"));
    let mut args = vec!["render", &scene, "-o", &reference, "--spp", "12", "--quiet"];
    ok(&[&args[..], &common].concat());
    let start_out = at(&root, "start.pfm");
    args = vec!["render", &scene, "-o", &start_out, "--spp", "4", "--checkpoint", &start, "--quiet"];
    ok(&[&args[..], &common].concat());
    let checkpoint_bytes = std::fs::read(&start).unwrap();
    let image_bytes = std::fs::metadata(&reference).unwrap().len();
    assert!(checkpoint_bytes.len() as u64 > 4 * image_bytes, "the film should be far larger than the image");

    // Room for the image but not for a second copy of the checkpoint (its temporary file
    // sits beside the one it replaces).
    let free = 2 * image_bytes + 16384;
    let Some(disk) = make(&disk_dir, checkpoint_bytes.len() as u64 + free + 16384) else {
        eprintln!("skipped: cannot mount a tmpfs here (not root, or a sandbox refuses mount)");
        std::fs::remove_dir_all(&root).unwrap();
        return;
    };
    let ck = at(&disk_dir, "render.film");
    std::fs::write(&ck, &checkpoint_bytes).unwrap();
    disk.leave_free(&disk_dir, free);
    let out = at(&disk_dir, "out.pfm");
    let o = run(disk.glint(free).args([
        "resume",
        &ck,
        "-o",
        &out,
        "--spp",
        "12",
        "--checkpoint-every",
        "0.001",
        "--write-every",
        "0.001",
    ]));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "the render should finish: {err}");
    // Eight passes tried eight checkpoints: one warning while it keeps failing the same way,
    // for the error intended (not a signal, not another error), then one at the end.
    let periodic: Vec<&str> = err.lines().filter(|l| l.contains("next try in")).collect();
    assert_eq!(periodic.len(), 1, "{err}");
    let warning = periodic[0];
    assert!(warning.starts_with("glint: warning: ") && warning.contains(&ck), "{err}");
    assert!(warning.contains(disk.error()), "not the failure intended: {err}");
    assert!(err.lines().any(|l| l.contains("the checkpoint keeps its last good state")), "{err}");
    assert!(!err.lines().any(|l| l.starts_with("glint: error")), "{err}");
    assert!(std::fs::read(&out).unwrap() == std::fs::read(&reference).unwrap(), "not the reference's bits");
    assert!(std::fs::read(&ck).unwrap() == checkpoint_bytes, "the previous checkpoint was damaged");
    assert_eq!(temp_files(&disk_dir), Vec::<String>::new());

    // No room for the image either (a PNG, whose encoder used to drop a failed write).
    std::fs::remove_file(&out).unwrap();
    disk.leave_free(&disk_dir, 0);
    let png = at(&disk_dir, "out.png");
    let o = run(disk.glint(0).args([
        "resume",
        &ck,
        "-o",
        &png,
        "--spp",
        "12",
        "--checkpoint-every",
        "0.001",
        "--write-every",
        "0.001",
    ]));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("glint: error: ")).collect();
    assert_eq!(errors.len(), 1, "{err}");
    assert!(errors[0].contains(&png) && errors[0].contains(disk.error()), "{err}");
    assert_eq!(err.lines().filter(|l| l.contains("next try in")).count(), 2, "image and checkpoint: {err}");
    assert!(!Path::new(&png).exists(), "no image should be left half-written");
    assert!(std::fs::read(&ck).unwrap() == checkpoint_bytes, "the previous checkpoint was damaged");
    assert_eq!(temp_files(&disk_dir), Vec::<String>::new());
    drop(disk);
    std::fs::remove_dir_all(&root).unwrap();
}
