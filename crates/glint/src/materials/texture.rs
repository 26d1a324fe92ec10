//! Textures: a colour as a function of surface uv (and, for mesh attributes, of the hit
//! triangle).

use crate::geometry::TriangleMesh;
use crate::math::Rgb;
use std::sync::Arc;

/// Where a texture is looked up: the uv, and for mesh attributes the triangle hit, its
/// barycentrics and its mesh (none for spheres).
#[derive(Clone, Copy, Debug)]
pub struct TexturePoint<'a> {
    pub uv: [f32; 2],
    pub prim: u32,
    pub bary: [f32; 2],
    pub mesh: Option<&'a TriangleMesh>,
}

impl TexturePoint<'_> {
    /// A point known only by its uv (no mesh attributes).
    pub fn uv(uv: [f32; 2]) -> TexturePoint<'static> {
        TexturePoint { uv, prim: 0, bary: [0.0, 0.0], mesh: None }
    }
}

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
        let img = crate::io::read_texture_image(path, raw)?;
        Ok(Bitmap { width: img.width, height: img.height, pixels: img.pixels })
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

    /// The gradient of the luminance of [`Bitmap::eval`] in (u, v): the exact derivative of
    /// the bilinear interpolation (as Mitsuba's `eval_1_grad`), for bump maps.
    pub fn luminance_gradient(&self, uv: [f32; 2]) -> [f32; 2] {
        let x = uv[0] * self.width as f32 - 0.5;
        let y = uv[1] * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let f = |dx: i64, dy: i64| self.texel(x0 + dx, y0 + dy).luminance();
        let (f00, f10, f01, f11) = (f(0, 0), f(1, 0), f(0, 1), f(1, 1));
        let dfdx = (1.0 - fy) * (f10 - f00) + fy * (f11 - f01);
        let dfdy = (1.0 - fx) * (f01 - f00) + fx * (f11 - f10);
        [dfdx * self.width as f32, dfdy * self.height as f32]
    }

    /// An image of texels given as data.
    pub fn of_texels(t: &crate::describe::Texels) -> Bitmap {
        Bitmap { width: t.width, height: t.height, pixels: t.pixels.clone() }
    }

    /// The texels [`Bitmap::eval`] blends at `uv` (indices into `pixels`) and their weights.
    pub fn taps(&self, uv: [f32; 2]) -> [(usize, f32); 4] {
        let x = uv[0] * self.width as f32 - 0.5;
        let y = uv[1] * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let at = |x: i64, y: i64| {
            y.rem_euclid(self.height as i64) as usize * self.width + x.rem_euclid(self.width as i64) as usize
        };
        [
            (at(x0, y0), (1.0 - fx) * (1.0 - fy)),
            (at(x0 + 1, y0), fx * (1.0 - fy)),
            (at(x0, y0 + 1), (1.0 - fx) * fy),
            (at(x0 + 1, y0 + 1), fx * fy),
        ]
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
    /// A per-vertex or per-face attribute of the mesh hit (Mitsuba's `mesh_attribute`),
    /// times `scale`; black where the shape has no such attribute (the build checks that
    /// every shape using one has it).
    MeshAttribute {
        name: String,
        scale: f32,
    },
    /// A glTF texture (its own sampler, texture coordinate set and transform).
    Gltf(Arc<super::GltfTexture>),
    /// A glTF material's opacity (alpha through its mode), grey.
    GltfAlpha(Arc<super::GltfAlpha>),
}

impl Texture {
    /// The value at a hit point: as [`Texture::eval`], and mesh attributes from the mesh.
    #[inline]
    pub fn eval_at(&self, p: &TexturePoint) -> Rgb {
        match self {
            Texture::MeshAttribute { name, scale } => {
                let Some(mesh) = p.mesh else { return Rgb::BLACK };
                let (Some(a), Some(tri)) = (mesh.attribute(name), mesh.indices.get(p.prim as usize)) else {
                    return Rgb::BLACK;
                };
                a.eval(*tri, p.prim, p.bary) * *scale
            }
            Texture::Gltf(t) => t.eval_at(p),
            Texture::GltfAlpha(a) => Rgb::splat(a.eval_at(p)),
            _ => self.eval(p.uv),
        }
    }

    /// The gradient in (u, v) of the texture's luminance, for bump maps: exact for bitmaps,
    /// zero for the piecewise-constant and constant ones.
    pub fn luminance_gradient(&self, uv: [f32; 2]) -> [f32; 2] {
        match self {
            Texture::Bitmap { image, uv_scale, uv_offset } => {
                let g =
                    image.luminance_gradient([uv[0] * uv_scale[0] + uv_offset[0], uv[1] * uv_scale[1] + uv_offset[1]]);
                [g[0] * uv_scale[0], g[1] * uv_scale[1]]
            }
            _ => [0.0, 0.0],
        }
    }

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
            // Needs the hit triangle: see `eval_at`.
            Texture::MeshAttribute { .. } => Rgb::BLACK,
            Texture::Gltf(t) => t.eval(uv),
            Texture::GltfAlpha(a) => Rgb::splat(a.eval_at(&TexturePoint::uv(uv))),
        }
    }

    /// Mean value, for sampling weights.
    pub fn mean(&self) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap { image, .. } => image.mean(),
            Texture::Checkerboard { color0, color1, .. } => (*color0 + *color1) * 0.5,
            Texture::MeshAttribute { scale, .. } => Rgb::splat(0.5 * scale),
            Texture::Gltf(t) => t.mean * t.scale,
            Texture::GltfAlpha(a) => Rgb::splat(a.factor),
        }
    }
}

impl From<Rgb> for Texture {
    fn from(c: Rgb) -> Texture {
        Texture::Constant(c)
    }
}

/// A scalar parameter: a constant, or a texture read as its luminance (Mitsuba's `eval_1`).
#[derive(Clone, Debug)]
pub enum ScalarTexture {
    Constant(f32),
    Texture(Texture),
}

impl ScalarTexture {
    pub fn new(t: Texture) -> ScalarTexture {
        match t {
            Texture::Constant(c) => ScalarTexture::Constant(c.luminance()),
            t => ScalarTexture::Texture(t),
        }
    }

    #[inline]
    pub fn eval(&self, uv: [f32; 2]) -> f32 {
        match self {
            ScalarTexture::Constant(v) => *v,
            ScalarTexture::Texture(t) => t.eval(uv).luminance(),
        }
    }

    /// True when the value is zero everywhere (a constant 0).
    pub fn is_zero(&self) -> bool {
        matches!(self, ScalarTexture::Constant(v) if *v == 0.0)
    }
}
