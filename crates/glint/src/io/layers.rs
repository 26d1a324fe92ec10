//! Images with extra layers: an EXR file whose beauty is `R, G, B` and whose AOV layers sit
//! beside it as channels named `layer.channel` (`albedo.R`, `depth.Z`: the convention tev,
//! OpenEXR's tools and Blender read). Written atomically, like every image glint writes.

use std::path::{Path, PathBuf};

/// One channel of an image: its full name and its values, row-major from the top left.
pub struct Channel<'a> {
    pub name: String,
    pub values: &'a [f32],
}

/// The temporary file an atomic write of `path` goes through (same folder, hidden, this
/// process's id): public so that a front end can remove it if it is interrupted.
pub fn temp_path(path: &Path) -> PathBuf {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let file_name = path.file_name().and_then(|n| n.to_str()).unwrap_or("image");
    dir.join(format!(".{file_name}.{}.tmp", std::process::id()))
}

/// Runs `write` on the temporary path of `path`, then renames the result into place; the
/// temporary file is removed on any error, so `path` is never half-written.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), String> {
    let tmp = temp_path(path);
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(format!("{}: {e}", path.display()));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}

/// Writes a float EXR with the given channels (all `width * height` long).
pub fn write_exr_channels(path: &Path, width: usize, height: usize, channels: &[Channel]) -> Result<(), String> {
    use exr::prelude::*;
    if let Some(c) = channels.iter().find(|c| c.values.len() != width * height) {
        return Err(format!(
            "{}: channel {} has {} values for {width}x{height} pixels",
            path.display(),
            c.name,
            c.values.len()
        ));
    }
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> =
        channels.iter().map(|c| AnyChannel::new(c.name.as_str(), FlatSamples::F32(c.values.to_vec()))).collect();
    // Blocks in increasing order (not as compression threads finish them): identical
    // renders give identical files.
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
    let layer = Layer::new((width, height), LayerAttributes::default(), encoding, AnyChannels::sort(list));
    write_atomically(path, |tmp| exr::prelude::Image::from_layer(layer).write().to_file(tmp).map_err(|e| e.to_string()))
}
