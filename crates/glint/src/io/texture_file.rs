//! Texture and environment images of any format glint reads, as linear RGB.

use super::image_io::{read_exr, Image};
use crate::math::{srgb_decode, Rgb};
use std::path::Path;

/// Loads PNG/JPEG (sRGB-decoded unless `raw`), EXR or HDR (linear).
pub fn read_texture_image(path: &Path, raw: bool) -> Result<Image, String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if ext == "exr" {
        return read_exr(path);
    }
    let rgb = super::image_io::read_raster(path)?;
    let linear_source = ext == "hdr";
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    let pixels = rgb
        .pixels()
        .map(|p| {
            let c = Rgb { r: p.0[0], g: p.0[1], b: p.0[2] };
            if raw || linear_source {
                c
            } else {
                c.map(srgb_decode)
            }
        })
        .collect();
    Ok(Image { width: w, height: h, pixels })
}
