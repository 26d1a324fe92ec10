//! Textures: a colour as a function of surface uv.

use crate::math::{srgb_decode, Rgb};
use std::sync::Arc;

/// An RGB image in linear space, sampled with bilinear filtering and wrap-around.
#[derive(Clone, Debug)]
pub struct Bitmap {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<Rgb>,
}

impl Bitmap {
    /// Loads PNG/JPEG (sRGB-decoded unless `raw`), EXR or HDR (linear).
    pub fn load(path: &std::path::Path, raw: bool) -> Result<Bitmap, String> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        if ext == "exr" {
            let img = crate::io::image_io::read_exr(path)?;
            return Ok(Bitmap { width: img.width, height: img.height, pixels: img.pixels });
        }
        let rgb = crate::io::image_io::read_raster(path)?;
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
        Ok(Bitmap { width: w, height: h, pixels })
    }

    #[inline]
    fn texel(&self, x: i64, y: i64) -> Rgb {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.pixels[y * self.width + x]
    }

    /// Bilinear lookup with wrap-around. uv (0,0) is the top-left of the image, as in
    /// Mitsuba; mesh loaders flip OBJ/PLY's upward v to match (v' = 1 - v).
    pub fn eval(&self, uv: [f32; 2]) -> Rgb {
        let x = uv[0] * self.width as f32 - 0.5;
        let y = uv[1] * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self.texel(x0, y0) * (1.0 - fx) + self.texel(x0 + 1, y0) * fx;
        let b = self.texel(x0, y0 + 1) * (1.0 - fx) + self.texel(x0 + 1, y0 + 1) * fx;
        a * (1.0 - fy) + b * fy
    }

    pub fn mean(&self) -> Rgb {
        let s = self.pixels.iter().fold(Rgb::BLACK, |a, &p| a + p);
        s / self.pixels.len().max(1) as f32
    }
}

#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Rgb),
    Bitmap {
        image: Arc<Bitmap>,
        uv_scale: [f32; 2],
        uv_offset: [f32; 2],
    },
    /// Two colours in a checker of 2x2 squares over the unit uv square, laid out as Mitsuba's:
    /// `color0` where both or neither of the uv fractions exceed one half.
    Checkerboard {
        color0: Rgb,
        color1: Rgb,
        uv_scale: [f32; 2],
        uv_offset: [f32; 2],
    },
}

impl Texture {
    #[inline]
    pub fn eval(&self, uv: [f32; 2]) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap { image, uv_scale, uv_offset } => {
                image.eval([uv[0] * uv_scale[0] + uv_offset[0], uv[1] * uv_scale[1] + uv_offset[1]])
            }
            Texture::Checkerboard { color0, color1, uv_scale, uv_offset } => {
                let u = uv[0] * uv_scale[0] + uv_offset[0];
                let v = uv[1] * uv_scale[1] + uv_offset[1];
                let fu = u - u.floor();
                let fv = v - v.floor();
                if (fu > 0.5) == (fv > 0.5) {
                    *color0
                } else {
                    *color1
                }
            }
        }
    }

    /// Mean value, for sampling weights.
    pub fn mean(&self) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap { image, .. } => image.mean(),
            Texture::Checkerboard { color0, color1, .. } => (*color0 + *color1) * 0.5,
        }
    }
}

impl From<Rgb> for Texture {
    fn from(c: Rgb) -> Texture {
        Texture::Constant(c)
    }
}
