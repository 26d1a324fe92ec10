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
    let tmp = super::layers::temp_path(path);
    let result = match format {
        ImageFormat::Png => write_png(img, &tmp),
        ImageFormat::Exr => write_exr(img, &tmp),
        ImageFormat::Pfm => write_pfm(img, &tmp),
    };
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(format!("{}: {e}", path.display()));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
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
    image::save_buffer_with_format(
        path,
        &buf,
        img.width as u32,
        img.height as u32,
        image::ColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| e.to_string())
}

fn write_exr(img: &Image, path: &Path) -> Result<(), String> {
    exr::prelude::write_rgb_file(path, img.width, img.height, |x, y| {
        let p = img.pixels[y * img.width + x];
        (p.r, p.g, p.b)
    })
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

/// Reads the RGB channels of an EXR file (first layer).
pub fn read_exr(path: &Path) -> Result<Image, String> {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| self::Image::new(res.width(), res.height()),
        |img: &mut self::Image, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = img.width;
            img.pixels[pos.y() * w + pos.x()] = Rgb { r, g, b };
        },
    )
    .map_err(|e| format!("{}: cannot read EXR: {e}", path.display()))?;
    Ok(img.layer_data.channel_data.pixels)
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
    let data = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
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
    if data.len() < pos + w * h * 12 {
        return Err(bad());
    }
    let mut img = Image::new(w, h);
    for row in 0..h {
        for x in 0..w {
            let mut c = [0.0f32; 3];
            for (k, v) in c.iter_mut().enumerate() {
                let o = pos + ((row * w + x) * 3 + k) * 4;
                let b = [data[o], data[o + 1], data[o + 2], data[o + 3]];
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
        let dir = std::env::temp_dir().join(format!("glint-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut img = Image::new(7, 5);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Rgb { r: i as f32 * 0.37, g: -(i as f32), b: 1e-3 * i as f32 };
        }
        for ext in ["exr", "pfm"] {
            let path = dir.join(format!("t.{ext}"));
            write_image(&img, &path).unwrap();
            assert_eq!(read_image(&path).unwrap(), img, "{ext}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unknown_extension_and_missing_folder_are_errors() {
        let img = Image::new(1, 1);
        assert!(write_image(&img, Path::new("out.bmp")).unwrap_err().contains("unknown image format"));
        assert!(write_image(&img, Path::new("/nonexistent-folder/x.png")).is_err());
    }
}
