//! The files a scene reads, with their bytes: what a checkpoint hashes
//! ([`super::Session::scene_hash`]) and what a render farm ships to its workers
//! ([`super::Session::build_files`]), found one way for both.

use crate::error::{Error, SourceLoc};
use std::path::PathBuf;

/// A file a scene reads.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    pub path: PathBuf,
    /// `None` for a side file that cannot be read: its reader goes on without it (an OBJ
    /// file's missing material library is a warning).
    pub bytes: Option<Vec<u8>>,
}

/// `files` and, after each, the side files reading it reads ([`crate::io::side_files`]),
/// each once, with their bytes. A file of `files` that cannot be read is an error naming it.
pub fn with_side_files(files: &[PathBuf]) -> Result<Vec<SceneFile>, Error> {
    let mut out: Vec<SceneFile> = Vec::new();
    for file in files {
        if out.iter().any(|f| &f.path == file) {
            continue;
        }
        let bytes = std::fs::read(file).map_err(|e| Error::at(&SourceLoc::file(file), format!("cannot read: {e}")))?;
        let sides = crate::io::side_files(file, &bytes);
        out.push(SceneFile { path: file.clone(), bytes: Some(bytes) });
        for side in sides {
            if !out.iter().any(|f| f.path == side) && !files.contains(&side) {
                out.push(SceneFile { bytes: std::fs::read(&side).ok(), path: side });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scratch::ScratchDir;
    use std::path::Path;

    fn place(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn an_objs_material_libraries_follow_it_once_and_a_missing_one_has_no_bytes() {
        let dir = ScratchDir::new("scene-files");
        let a = place(&dir, "a.obj", "mtllib m.mtl gone.mtl\nv 0 0 0\n");
        let b = place(&dir, "b.obj", "mtllib m.mtl\n");
        let m = place(&dir, "m.mtl", "newmtl x\n");
        let png = place(&dir, "t.png", "not read as an image here");
        let files = with_side_files(&[a.clone(), png.clone(), b.clone(), a.clone()]).unwrap();
        let listed: Vec<(&Path, bool)> = files.iter().map(|f| (f.path.as_path(), f.bytes.is_some())).collect();
        let gone = dir.join("gone.mtl");
        assert_eq!(listed, [(&*a, true), (&*m, true), (&*gone, false), (&*png, true), (&*b, true)]);
        let missing = dir.join("missing.ply");
        let e = with_side_files(&[missing]).unwrap_err();
        assert!(e.to_string().contains("missing.ply: cannot read"), "{e}");
    }
}
