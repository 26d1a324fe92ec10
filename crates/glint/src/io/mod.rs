//! File input and output: images and meshes.

pub mod curves;
pub mod gltf;
pub mod image_io;
pub mod layers;
pub mod obj;
pub mod ply;
mod ply_attributes;
pub mod serialized;
mod texture_file;
pub mod vol;

pub use image_io::{read_image, write_image, Image};
pub use texture_file::read_texture_image;

use std::io::Read;
use std::path::{Path, PathBuf};

/// What reading the file at `path` (whose bytes are `data`) reads besides it, by its
/// format: the material files an OBJ file's `mtllib` lines name, the buffers and images a glTF
/// file names; nothing for the other
/// files a scene reads (PLY and serialized meshes, images, volume grids), and nothing for
/// scene files, whose includes their description lists.
pub fn side_files(path: &Path, data: &[u8]) -> Vec<PathBuf> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "obj" => obj::mtllib_files(data, path),
        "gltf" | "glb" => gltf::side_files(path, data),
        _ => Vec::new(),
    }
}

/// Largest mesh or material file glint reads (2 GiB).
pub const MAX_MESH_FILE_BYTES: u64 = 2 << 30;

/// Reads a whole regular file of at most `max_bytes`, so that a path naming a device
/// (/dev/zero), a pipe or an enormous file ends in a clear error instead of exhausting memory.
pub fn read_file_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let meta = file.metadata().map_err(|e| format!("{}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!("{}: not a regular file", path.display()));
    }
    if meta.len() > max_bytes {
        return Err(format!("{}: file is {} bytes, more than the {max_bytes} allowed", path.display(), meta.len()));
    }
    let mut data = Vec::with_capacity(meta.len() as usize);
    // `take` also bounds a file that grows while it is read.
    file.take(max_bytes + 1).read_to_end(&mut data).map_err(|e| format!("{}: {e}", path.display()))?;
    if data.len() as u64 > max_bytes {
        return Err(format!("{}: file is larger than the {max_bytes} bytes allowed", path.display()));
    }
    Ok(data)
}
