//! Scratch folders for tests that write files: each removes itself when dropped, even when
//! the test panics, so test runs leave nothing behind in the temporary folder.

use std::ops::Deref;
use std::path::{Path, PathBuf};

/// A fresh, empty folder `glint-<name>-<pid>` in the temporary folder, removed with all it
/// holds on drop. Tests of one binary run on parallel threads of one process, so `name` must be
/// unique within the binary: one test's drop would delete another's folder.
pub struct ScratchDir(PathBuf);

impl ScratchDir {
    pub fn new(name: &str) -> ScratchDir {
        let dir = std::env::temp_dir().join(format!("glint-{name}-{}", std::process::id()));
        // A folder left by a killed run of an earlier process with the same id.
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        ScratchDir(dir)
    }
}

impl Deref for ScratchDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for ScratchDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        // Ignored: a failed cleanup must not fail the test or turn a panic into an abort.
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
