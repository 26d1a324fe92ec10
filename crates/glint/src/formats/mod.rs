//! Scene readers: each turns a file into a [`SceneDesc`] and does nothing else (no mesh is
//! loaded, no BVH built): the native JSON format, Mitsuba 3 XML, glTF 2.0, and a bare OBJ or PLY mesh
//! (a preview scene around it).

pub mod gltf;
pub mod json;
mod json_spans;
pub mod mesh;
pub mod mitsuba;

use crate::error::{Error, SourceLoc};
use crate::materials::SceneDesc;
use std::path::Path;

/// A `-D name=value` override of a Mitsuba `<default>`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Define {
    pub name: String,
    pub value: String,
}

/// What a reader needs besides the file.
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    pub defines: Vec<Define>,
    /// The camera to use, by index or name, for formats with several (glTF).
    pub camera: Option<String>,
}

/// The formats glint reads, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneFormat {
    Json,
    Mitsuba,
    Mesh,
    Gltf,
}

impl SceneFormat {
    pub fn of(path: &Path) -> Result<SceneFormat, Error> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        match ext.as_str() {
            "json" => Ok(SceneFormat::Json),
            "xml" => Ok(SceneFormat::Mitsuba),
            "obj" | "ply" => Ok(SceneFormat::Mesh),
            "gltf" | "glb" => Ok(SceneFormat::Gltf),
            _ => Err(Error::at(
                &SourceLoc::file(path),
                "unknown scene format (expected .json, .xml, .gltf, .glb, or a .obj or .ply mesh)",
            )),
        }
    }
}

/// Reads a scene file of any format glint knows, choosing by extension.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<SceneDesc, Error> {
    let format = SceneFormat::of(path)?;
    if !opts.defines.is_empty() && format != SceneFormat::Mitsuba {
        return Err(Error::at(&SourceLoc::file(path), "-D overrides apply to Mitsuba XML scenes only"));
    }
    if opts.camera.is_some() && format != SceneFormat::Gltf {
        return Err(Error::at(&SourceLoc::file(path), "--camera applies to glTF scenes only"));
    }
    match format {
        SceneFormat::Mesh => mesh::describe(path),
        SceneFormat::Gltf => gltf::read(path, opts.camera.as_deref()),
        SceneFormat::Mitsuba => mitsuba::read(path, &opts.defines),
        SceneFormat::Json => {
            let text = read_text(path)?;
            json::read(path, &text)
        }
    }
}

/// A text file, with a clear error for a missing file or one that is not UTF-8 text.
pub(crate) fn read_text(path: &Path) -> Result<String, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::at(&SourceLoc::file(path), format!("cannot read: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        Error::at(
            &SourceLoc::file(path),
            format!("not a text file (invalid UTF-8 at byte {})", e.utf8_error().valid_up_to()),
        )
    })
}
