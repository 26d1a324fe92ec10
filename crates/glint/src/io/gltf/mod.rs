//! glTF 2.0 files as data: the JSON document, its buffers (a `.glb`'s binary chunk, `data:`
//! URIs, external files) and typed reads of its accessors, primitives and images. Every
//! size is checked against the bytes there are before anything is allocated, and every
//! error names the JSON path it is about (`meshes[3].primitives[0].attributes.POSITION:
//! accessor 12 reads past the end of buffer 0`). The scene reader (`formats::gltf`) and the
//! world build (mesh and texture loading) both read through here.

mod accessor;
mod buffers;
mod image;
mod primitive;

pub use accessor::{read_accessor, read_indices, Accessor};
pub use image::{decode_image, image_bytes, RgbaImage, MAX_IMAGE_PIXELS};
pub use primitive::{assemble_triangles, read_primitive, triangle_mode, PrimitiveData, PrimitiveMode};

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Largest glTF file, external buffer or image glint reads (2 GiB, as other meshes).
pub const MAX_GLTF_BYTES: u64 = super::MAX_MESH_FILE_BYTES;

/// A glTF file: its JSON and every buffer's bytes.
#[derive(Debug)]
pub struct GltfFile {
    pub path: PathBuf,
    pub json: Value,
    pub buffers: Vec<Vec<u8>>,
}

/// A JSON value at a path of the document, for reading fields with errors that name it.
#[derive(Clone, Copy)]
pub struct Node<'a> {
    pub value: &'a Value,
    pub path: &'a str,
}

impl GltfFile {
    /// Reads a `.gltf` or `.glb` file and every buffer it names.
    pub fn open(path: &Path) -> Result<GltfFile, String> {
        let data = super::read_file_bounded(path, MAX_GLTF_BYTES)?;
        Self::from_bytes(path, &data, true)
    }

    /// Parses a file's bytes; external buffers (files beside `path`) are read only when
    /// `external` is true (the fuzz target reads no files).
    pub fn from_bytes(path: &Path, data: &[u8], external: bool) -> Result<GltfFile, String> {
        let (json_bytes, bin) = if data.starts_with(b"glTF") { buffers::split_glb(data)? } else { (data, None) };
        let json: Value = serde_json::from_slice(json_bytes).map_err(|e| format!("invalid glTF JSON: {e}"))?;
        if !json.is_object() {
            return Err("invalid glTF JSON: the document is not an object".into());
        }
        let version = json.get("asset").and_then(|a| a.get("version")).and_then(Value::as_str);
        match version {
            Some(v) if v.starts_with("2.") => {}
            Some(v) => return Err(format!("asset.version: glTF {v} is not supported (glint reads glTF 2.0)")),
            None => return Err("asset.version: missing (not a glTF 2.0 file)".into()),
        }
        let buffers = buffers::load_buffers(path, &json, bin, external)?;
        Ok(GltfFile { path: path.to_path_buf(), json, buffers })
    }

    /// The array `name` of the document (empty when absent).
    pub fn array(&self, name: &str) -> &[Value] {
        self.json.get(name).and_then(Value::as_array).map(Vec::as_slice).unwrap_or(&[])
    }

    /// Element `index` of the top-level array `name`, or an error naming `path`.
    pub fn item(&self, name: &str, index: usize, path: &str) -> Result<&Value, String> {
        let a = self.array(name);
        a.get(index).ok_or_else(|| format!("{path}: {name}[{index}] does not exist ({} {name})", a.len()))
    }
}

impl<'a> Node<'a> {
    pub fn new(value: &'a Value, path: &'a str) -> Node<'a> {
        Node { value, path }
    }

    pub fn get(&self, key: &str) -> Option<&'a Value> {
        self.value.get(key)
    }

    /// An optional non-negative integer field.
    pub fn index(&self, key: &str) -> Result<Option<usize>, String> {
        match self.value.get(key) {
            None => Ok(None),
            Some(v) => v
                .as_u64()
                .filter(|&n| n <= u32::MAX as u64)
                .map(|n| Some(n as usize))
                .ok_or_else(|| format!("{}.{key}: expected a non-negative integer, found {v}", self.path)),
        }
    }

    /// A required non-negative integer field.
    pub fn required_index(&self, key: &str) -> Result<usize, String> {
        self.index(key)?.ok_or_else(|| format!("{}.{key}: missing", self.path))
    }

    /// An optional number field (finite).
    pub fn number(&self, key: &str) -> Result<Option<f64>, String> {
        match self.value.get(key) {
            None => Ok(None),
            Some(v) => v
                .as_f64()
                .filter(|x| x.is_finite())
                .map(Some)
                .ok_or_else(|| format!("{}.{key}: expected a number, found {v}", self.path)),
        }
    }

    /// A number field with a default.
    pub fn number_or(&self, key: &str, default: f64) -> Result<f64, String> {
        Ok(self.number(key)?.unwrap_or(default))
    }

    /// An optional array of exactly `n` finite numbers.
    pub fn numbers(&self, key: &str, n: usize) -> Result<Option<Vec<f64>>, String> {
        let Some(v) = self.value.get(key) else { return Ok(None) };
        let bad = || format!("{}.{key}: expected an array of {n} numbers, found {v}", self.path);
        let a = v.as_array().ok_or_else(bad)?;
        if a.len() != n {
            return Err(bad());
        }
        a.iter().map(|x| x.as_f64().filter(|x| x.is_finite()).ok_or_else(bad)).collect::<Result<Vec<_>, _>>().map(Some)
    }

    /// An optional string field.
    pub fn string(&self, key: &str) -> Result<Option<&'a str>, String> {
        match self.value.get(key) {
            None => Ok(None),
            Some(v) => v.as_str().map(Some).ok_or_else(|| format!("{}.{key}: expected a string, found {v}", self.path)),
        }
    }
}

impl GltfFile {
    /// Mesh and primitive of the `flat`-th primitive, counting every mesh's primitives in
    /// order (how a scene description names one primitive as one mesh).
    pub fn primitive_at(&self, flat: usize) -> Option<(usize, usize)> {
        let mut k = flat;
        for (m, mesh) in self.array("meshes").iter().enumerate() {
            let n = mesh.get("primitives").and_then(Value::as_array).map_or(0, Vec::len);
            if k < n {
                return Some((m, k));
            }
            k -= n;
        }
        None
    }
}

/// The last glTF file the build opened, kept while its primitives are loaded one by one
/// (each is a mesh of its own; without this each would read and parse the whole file).
static LAST: Mutex<Option<(PathBuf, FileStamp, Arc<GltfFile>)>> = Mutex::new(None);

#[derive(Clone, PartialEq, Eq)]
struct FileStamp {
    len: u64,
    modified: Option<std::time::SystemTime>,
}

fn stamp(path: &Path) -> Option<FileStamp> {
    let m = std::fs::metadata(path).ok()?;
    Some(FileStamp { len: m.len(), modified: m.modified().ok() })
}

/// [`GltfFile::open`], reusing the last file opened this way while it is unchanged on disk
/// (same length and modification time). The lock is held while a file is read, so that the
/// parallel loads of one file's primitives read it once.
pub fn open_cached(path: &Path) -> Result<Arc<GltfFile>, String> {
    let mut last = LAST.lock().unwrap_or_else(|p| p.into_inner());
    let now = stamp(path);
    if let (Some((p, s, f)), Some(now)) = (last.as_ref(), now.as_ref()) {
        if p == path && s == now {
            return Ok(f.clone());
        }
    }
    let f = Arc::new(GltfFile::open(path)?);
    *last = now.map(|s| (path.to_path_buf(), s, f.clone()));
    Ok(f)
}

/// The files a glTF file reads besides itself: its external buffers and images (relative
/// URIs; `data:` URIs are inside the file). Unreadable JSON names none.
pub fn side_files(path: &Path, data: &[u8]) -> Vec<PathBuf> {
    let json_bytes = if data.starts_with(b"glTF") {
        match buffers::split_glb(data) {
            Ok((j, _)) => j,
            Err(_) => return Vec::new(),
        }
    } else {
        data
    };
    let Ok(json) = serde_json::from_slice::<Value>(json_bytes) else { return Vec::new() };
    let mut out = Vec::new();
    for key in ["buffers", "images"] {
        for item in json.get(key).and_then(Value::as_array).map(Vec::as_slice).unwrap_or(&[]) {
            if let Some(uri) = item.get("uri").and_then(Value::as_str) {
                if let Some(p) = buffers::uri_path(path, uri) {
                    if !out.contains(&p) {
                        out.push(p);
                    }
                }
            }
        }
    }
    out
}
