//! Reading and writing images: PNG (8-bit sRGB), EXR (linear float32), PFM (linear float32).
//! Every write goes to a temporary file in the same folder, then is renamed, so a failed or
//! interrupted write never leaves a half-written image under the requested name.

use crate::math::{srgb_encode, Rgb};
use std::io::Write;
use std::path::Path;

/// A linear-RGB image, row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<Rgb>,
}

impl Image {
    pub fn new(width: usize, height: usize) -> Image {
        Image { width, height, pixels: vec![Rgb::BLACK; width * height] }
    }
    pub fn get(&self, x: usize, y: usize) -> Rgb {
        self.pixels[y * self.width + x]
    }
    /// Mean of each channel, accumulated in double precision.
    pub fn channel_means(&self) -> [f64; 3] {
        let mut s = [0.0f64; 3];
        for p in &self.pixels {
            s[0] += p.r as f64;
            s[1] += p.g as f64;
            s[2] += p.b as f64;
        }
        let n = self.pixels.len().max(1) as f64;
        [s[0] / n, s[1] / n, s[2] / n]
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Exr,
    Pfm,
}

impl ImageFormat {
    pub fn from_path(path: &Path) -> Result<ImageFormat, String> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("exr") => Ok(ImageFormat::Exr),
            Some("pfm") => Ok(ImageFormat::Pfm),
            _ => Err(format!("{}: unknown image format (use .png, .exr or .pfm)", path.display())),
        }
    }
}

/// Writes `img` in the format named by the extension, atomically.
pub fn write_image(img: &Image, path: &Path) -> Result<(), String> {
    let format = ImageFormat::from_path(path)?;
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(format!("{}: folder {} does not exist", path.display(), dir.display()));
    }
    super::layers::write_atomically(path, |tmp| match format {
        ImageFormat::Png => write_png(img, tmp),
        ImageFormat::Exr => write_exr(img, tmp),
        ImageFormat::Pfm => write_pfm(img, tmp),
    })
}

fn to_srgb8(v: f32) -> u8 {
    let v = if v.is_finite() { v } else { 0.0 };
    (srgb_encode(v.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8
}

fn write_png(img: &Image, path: &Path) -> Result<(), String> {
    let mut buf = Vec::with_capacity(img.pixels.len() * 3);
    for p in &img.pixels {
        buf.extend_from_slice(&[to_srgb8(p.r), to_srgb8(p.g), to_srgb8(p.b)]);
    }
    // Encoded in memory and written with one checked write: the `image` crate's file writer
    // drops its buffer unflushed, so a full disk would leave a truncated PNG reported as
    // written.
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        &buf,
        img.width as u32,
        img.height as u32,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| e.to_string())?;
    std::fs::write(path, &png).map_err(|e| e.to_string())
}

fn write_exr(img: &Image, path: &Path) -> Result<(), String> {
    use exr::prelude::{Encoding, LineOrder, SpecificChannels, Vec2, WritableImage};
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = img.pixels[y * img.width + x];
        (p.r, p.g, p.b)
    });
    // Blocks in increasing order: compressed in parallel, written in one order, so that
    // identical renders give identical files.
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::default() };
    exr::prelude::Image::from_encoded_channels((img.width, img.height), encoding, channels)
        .write()
        .to_file(path)
        .map_err(|e| e.to_string())
}

fn write_pfm(img: &Image, path: &Path) -> Result<(), String> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(|e| e.to_string())?);
    // Negative scale: little-endian. Rows are stored bottom to top.
    write!(f, "PF\n{} {}\n-1.0\n", img.width, img.height).map_err(|e| e.to_string())?;
    for y in (0..img.height).rev() {
        for x in 0..img.width {
            let p = img.get(x, y);
            for v in [p.r, p.g, p.b] {
                f.write_all(&v.to_le_bytes()).map_err(|e| e.to_string())?;
            }
        }
    }
    f.flush().map_err(|e| e.to_string())
}

/// Most bytes an image decoder may allocate for one image (as the `image` crate's default
/// limits): a header that claims more is refused before anything is decoded.
pub const IMAGE_BUDGET_BYTES: u64 = 512 << 20;

/// Largest image file glint reads.
pub const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;

/// Checks a `width` x `height` image of `bytes_per_pixel` fits [`IMAGE_BUDGET_BYTES`].
fn check_budget(path: &Path, width: usize, height: usize, bytes_per_pixel: u64) -> Result<(), String> {
    let bytes = (width as u64).checked_mul(height as u64).and_then(|n| n.checked_mul(bytes_per_pixel));
    match bytes {
        Some(b) if b <= IMAGE_BUDGET_BYTES => Ok(()),
        _ => Err(format!(
            "{}: image of {width} x {height} pixels exceeds the {} MiB decoding budget",
            path.display(),
            IMAGE_BUDGET_BYTES >> 20
        )),
    }
}

/// Reads the RGB channels of an EXR file (first layer).
pub fn read_exr(path: &Path) -> Result<Image, String> {
    let data = super::read_file_bounded(path, MAX_IMAGE_FILE_BYTES)?;
    read_exr_bytes(&data, path)
}

/// Decodes an EXR file held in memory; `path` only names it in errors. The headers are read
/// first and every layer's size is checked against [`IMAGE_BUDGET_BYTES`] (the RGBA f32
/// pixels the decoder builds, and the `Image` made from them), since the `exr` crate has
/// no allocation limits of its own.
pub fn read_exr_bytes(data: &[u8], path: &Path) -> Result<Image, String> {
    let cannot = |e: exr::error::Error| format!("{}: cannot read EXR: {e}", path.display());
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(data), false).map_err(cannot)?;
    for header in meta.headers.iter() {
        let size = header.layer_size;
        check_budget(path, size.width(), size.height(), 16 + 12)?;
    }
    // Named functions rather than closures: the reader needs them generic over the
    // channels' lifetime, which closures do not infer.
    fn create(res: exr::math::Vec2<usize>, _: &exr::prelude::RgbaChannels) -> Image {
        Image::new(res.width(), res.height())
    }
    fn set(img: &mut Image, pos: exr::math::Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)) {
        let w = img.width;
        img.pixels[pos.y() * w + pos.x()] = Rgb { r, g, b };
    }
    use exr::prelude::{ReadChannels as _, ReadLayers as _};
    let img = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(create, set)
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(data))
        .map_err(cannot)?;
    Ok(img.layer_data.channel_data.pixels)
}

/// Decodes a PNG, JPEG or Radiance HDR file held in memory (the format guessed from its
/// contents) to RGB f32 as stored, within [`IMAGE_BUDGET_BYTES`]: the `image` crate's
/// limits bound its own allocations, and the f32 copy made here is checked before it is made.
pub fn decode_raster_bytes(data: &[u8], path: &Path) -> Result<image::Rgb32FImage, String> {
    let cannot = |e: image::ImageError| format!("{}: cannot read image: {e}", path.display());
    let mut reader = image::ImageReader::new(std::io::Cursor::new(data))
        .with_guessed_format()
        .map_err(|e| format!("{}: cannot read image: {e}", path.display()))?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(IMAGE_BUDGET_BYTES);
    reader.limits(limits);
    let (w, h) = reader.into_dimensions().map_err(cannot)?;
    check_budget(path, w as usize, h as usize, 12)?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(data))
        .with_guessed_format()
        .map_err(|e| format!("{}: cannot read image: {e}", path.display()))?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(IMAGE_BUDGET_BYTES);
    reader.limits(limits);
    Ok(reader.decode().map_err(cannot)?.to_rgb32f())
}

/// Reads a PNG, JPEG or HDR file within the decoding budget (see [`decode_raster_bytes`]).
pub fn read_raster(path: &Path) -> Result<image::Rgb32FImage, String> {
    let data = super::read_file_bounded(path, MAX_IMAGE_FILE_BYTES)?;
    decode_raster_bytes(&data, path)
}

/// Reads any image glint writes (for comparisons in tests and tools): EXR and PFM as
/// linear, PNG decoded from sRGB.
pub fn read_image(path: &Path) -> Result<Image, String> {
    match ImageFormat::from_path(path)? {
        ImageFormat::Exr => read_exr(path),
        ImageFormat::Pfm => read_pfm(path),
        ImageFormat::Png => super::read_texture_image(path, false),
    }
}

fn read_pfm(path: &Path) -> Result<Image, String> {
    let data = super::read_file_bounded(path, MAX_IMAGE_FILE_BYTES)?;
    read_pfm_bytes(&data, path)
}

/// Decodes a colour PFM file held in memory; `path` only names it in errors.
pub fn read_pfm_bytes(data: &[u8], path: &Path) -> Result<Image, String> {
    let bad = || format!("{}: not a colour PFM file", path.display());
    let mut fields = Vec::new();
    let mut pos = 0;
    while fields.len() < 4 {
        while pos < data.len() && data[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < data.len() && !data[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            return Err(bad());
        }
        fields.push(String::from_utf8_lossy(&data[start..pos]).to_string());
    }
    pos += 1;
    if fields[0] != "PF" {
        return Err(bad());
    }
    let w: usize = fields[1].parse().map_err(|_| bad())?;
    let h: usize = fields[2].parse().map_err(|_| bad())?;
    let scale: f32 = fields[3].parse().map_err(|_| bad())?;
    check_budget(path, w, h, 12)?;
    // Within the budget, so `w * h * 12` cannot overflow.
    let body = data.get(pos..).unwrap_or(&[]);
    if body.len() < w * h * 12 {
        return Err(format!(
            "{}: PFM header says {w} x {h} pixels but the file holds only {} bytes of pixels (truncated)",
            path.display(),
            body.len()
        ));
    }
    let mut img = Image::new(w, h);
    for row in 0..h {
        for x in 0..w {
            let mut c = [0.0f32; 3];
            for (k, v) in c.iter_mut().enumerate() {
                let o = ((row * w + x) * 3 + k) * 4;
                let b = [body[o], body[o + 1], body[o + 2], body[o + 3]];
                *v = if scale < 0.0 { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) };
            }
            img.pixels[(h - 1 - row) * w + x] = Rgb::from_array(c);
        }
    }
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_and_pfm_round_trip_exactly() {
        let dir = crate::scratch::ScratchDir::new("io");
        let mut img = Image::new(7, 5);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Rgb { r: i as f32 * 0.37, g: -(i as f32), b: 1e-3 * i as f32 };
        }
        for ext in ["exr", "pfm"] {
            let path = dir.join(format!("t.{ext}"));
            write_image(&img, &path).unwrap();
            assert_eq!(read_image(&path).unwrap(), img, "{ext}");
        }
    }

    #[test]
    fn identical_images_give_identical_exr_files() {
        // Many blocks, compressed on several threads: the file must not depend on which
        // thread finished first (the beauty alone, and with layers).
        let dir = crate::scratch::ScratchDir::new("exr-bytes");
        let (w, h) = (300, 200);
        let mut img = Image::new(w, h);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            let v = ((i * 2654435761) % 1000) as f32 / 7.0;
            *p = Rgb { r: v, g: v * 0.5 + (i % 13) as f32, b: (i % w) as f32 };
        }
        let depth: Vec<f32> = (0..w * h).map(|i| (i % 977) as f32 * 0.25).collect();
        let r: Vec<f32> = img.pixels.iter().map(|p| p.r).collect();
        let channels = [
            crate::io::layers::Channel { name: "R".into(), values: &r },
            crate::io::layers::Channel { name: "depth.Z".into(), values: &depth },
        ];
        let write_both = |k: usize| {
            let (a, b) = (dir.join(format!("beauty{k}.exr")), dir.join(format!("layers{k}.exr")));
            write_image(&img, &a).unwrap();
            crate::io::layers::write_exr_channels(&b, w, h, &channels).unwrap();
            (std::fs::read(a).unwrap(), std::fs::read(b).unwrap())
        };
        let first = write_both(0);
        for k in 1..8 {
            assert!(write_both(k) == first, "write {k} differs from the first");
        }
    }

    #[test]
    fn unknown_extension_and_missing_folder_are_errors() {
        let img = Image::new(1, 1);
        assert!(write_image(&img, Path::new("out.bmp")).unwrap_err().contains("unknown image format"));
        assert!(write_image(&img, Path::new("/nonexistent-folder/x.png")).is_err());
    }
}
