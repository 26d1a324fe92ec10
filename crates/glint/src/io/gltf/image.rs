//! Images of a glTF file: their bytes (an external file, a `data:` URI or a bufferView)
//! and their decoding to linear RGBA within a size budget.

use super::{buffers, GltfFile, Node};
use crate::math::srgb_decode;
use std::borrow::Cow;

/// Most pixels of one glTF texture (8192 x 8192: 1 GiB as linear RGBA floats).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// A decoded image, linear RGBA, row 0 at the top.
#[derive(Clone, Debug)]
pub struct RgbaImage {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 4]>,
}

/// The encoded bytes of image `index` (PNG or JPEG).
pub fn image_bytes(f: &GltfFile, index: usize) -> Result<Cow<'_, [u8]>, String> {
    let p = format!("images[{index}]");
    let v = f.item("images", index, &p)?;
    let n = Node::new(v, &p);
    if let Some(uri) = n.string("uri")? {
        if uri.starts_with("data:") {
            return Ok(Cow::Owned(buffers::data_uri(uri, &format!("{p}.uri"))?));
        }
        let file = buffers::uri_path(&f.path, uri).ok_or_else(|| format!("{p}.uri: cannot read '{uri}'"))?;
        let data =
            super::super::read_file_bounded(&file, super::MAX_GLTF_BYTES).map_err(|e| format!("{p}.uri: {e}"))?;
        return Ok(Cow::Owned(data));
    }
    let view = n.index("bufferView")?.ok_or_else(|| format!("{p}: neither uri nor bufferView"))?;
    let vp = format!("bufferViews[{view}]");
    let vn = Node::new(f.item("bufferViews", view, &format!("{p}.bufferView"))?, &vp);
    let buffer = vn.required_index("buffer")?;
    let data = f.buffers.get(buffer).ok_or_else(|| format!("{vp}.buffer: buffers[{buffer}] does not exist"))?;
    let offset = vn.index("byteOffset")?.unwrap_or(0);
    let length = vn.required_index("byteLength")?;
    let end = offset
        .checked_add(length)
        .filter(|&e| e <= data.len())
        .ok_or_else(|| format!("{p}.bufferView: bufferView {view} reads past the end of buffer {buffer}"))?;
    Ok(Cow::Borrowed(&data[offset..end]))
}

/// Decodes image bytes; the colour channels are sRGB-decoded when `srgb` (alpha is linear).
/// The dimensions are read and bounded before the pixels are decoded.
pub fn decode_image(data: &[u8], srgb: bool, what: &str) -> Result<RgbaImage, String> {
    let cannot = |e: image::ImageError| format!("{what}: cannot decode image: {e}");
    let reader = || -> Result<image::ImageReader<std::io::Cursor<&[u8]>>, String> {
        let mut r = image::ImageReader::new(std::io::Cursor::new(data))
            .with_guessed_format()
            .map_err(|e| format!("{what}: cannot read image: {e}"))?;
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(MAX_IMAGE_PIXELS * 4);
        r.limits(limits);
        Ok(r)
    };
    let (w, h) = reader()?.into_dimensions().map_err(cannot)?;
    if w as u64 * h as u64 > MAX_IMAGE_PIXELS || w == 0 || h == 0 {
        return Err(format!("{what}: image of {w} x {h} pixels (at most {MAX_IMAGE_PIXELS} pixels, none empty)"));
    }
    let img = reader()?.decode().map_err(cannot)?.to_rgba8();
    // A table: 256 sRGB decodes instead of one per channel of every pixel.
    let table: Vec<f32> =
        (0..256).map(|v| if srgb { srgb_decode(v as f32 / 255.0) } else { v as f32 / 255.0 }).collect();
    let pixels = img
        .pixels()
        .map(|p| [table[p.0[0] as usize], table[p.0[1] as usize], table[p.0[2] as usize], p.0[3] as f32 / 255.0])
        .collect();
    Ok(RgbaImage { width: w as usize, height: h as usize, pixels })
}
