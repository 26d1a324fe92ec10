//! The textured glTF material: what a hit evaluates into a [`GltfPbr`], and glTF textures
//! (an image with its sampler, texture coordinate set and `KHR_texture_transform`).
//!
//! # Differentiable
//! Its factors, as `traverse` lists them; its own textures (glTF images) are not
//! differentiable per texel. See `docs/differentiable.md`.

mod bsdf;
mod desc;
mod lobes;

pub use bsdf::GltfPbr;
pub use desc::{GltfAlphaMode, GltfMaterialDesc};
pub use lobes::{sheen_albedo, sheen_albedo_quadrature, SHEEN_ALBEDO_TOLERANCE, SHEEN_MIN_ROUGHNESS};

use super::{Black, Bsdf, Describe};
use super::{MaskMaterial, MaterialKind, NormalMapMaterial, Shade, Texture, TextureCache, TexturePoint};
use crate::describe::slots::Slot;
use crate::describe::{checks, GltfWrap, TextureDesc};
use crate::error::Error;
use crate::io::gltf::RgbaImage;
use crate::math::{rgb, Rgb};
use std::sync::Arc;

/// The mesh attributes a glTF primitive's extra vertex data is kept in (the build names
/// them so; `TEXCOORD_1` is (u, v, 0)).
pub const UV1_ATTRIBUTE: &str = "vertex_gltf_uv1";
pub const COLOR_ATTRIBUTE: &str = "vertex_gltf_color";
pub const ALPHA_ATTRIBUTE: &str = "vertex_gltf_alpha";
/// `TANGENT`'s xyz (object space) and its w, the bitangent's sign.
pub const TANGENT_ATTRIBUTE: &str = "vertex_gltf_tangent";
pub const TANGENT_SIGN_ATTRIBUTE: &str = "vertex_gltf_tangent_sign";

/// A glTF texture ready to sample.
#[derive(Clone, Debug)]
pub struct GltfTexture {
    pub image: Arc<RgbaImage>,
    pub texcoord: u32,
    pub wrap: [GltfWrap; 2],
    pub nearest: bool,
    pub transform: [[f32; 3]; 2],
    /// Multiplies the colour channels.
    pub scale: Rgb,
    /// For a normal map: `normalTexture.scale`, applied to the decoded normal's x and y
    /// (the result is encoded back to [0, 1], as a normal map texture reads).
    pub normal_scale: Option<f32>,
    /// Mean colour (times `scale`), for sampling weights.
    pub mean: Rgb,
}

fn wrap_index(i: i64, n: i64, mode: GltfWrap) -> usize {
    (match mode {
        GltfWrap::Repeat => i.rem_euclid(n),
        GltfWrap::Clamp => i.clamp(0, n - 1),
        GltfWrap::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m < n {
                m
            } else {
                2 * n - 1 - m
            }
        }
    }) as usize
}

/// A float texel coordinate as an integer, bounded so that NaN and infinities index a
/// texel (any) rather than overflow.
fn floor_index(x: f32) -> i64 {
    x.floor().clamp(-1e9, 1e9) as i64
}

impl GltfTexture {
    pub fn new(image: Arc<RgbaImage>, texcoord: u32, wrap: [GltfWrap; 2], nearest: bool) -> GltfTexture {
        let n = image.pixels.len().max(1) as f32;
        let sum = image.pixels.iter().fold([0.0f32; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]);
        GltfTexture {
            image,
            texcoord,
            wrap,
            nearest,
            transform: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            scale: Rgb::WHITE,
            normal_scale: None,
            mean: rgb(sum[0] / n, sum[1] / n, sum[2] / n),
        }
    }

    /// The texture coordinates at `p` this texture reads (set 1 from the mesh's attribute;
    /// (0, 0) where the mesh has none), transformed.
    fn uv(&self, p: &TexturePoint) -> [f32; 2] {
        let uv = if self.texcoord == 1 {
            match p.mesh.and_then(|m| Some((m.attribute(UV1_ATTRIBUTE)?, m.indices.get(p.prim as usize)?))) {
                Some((a, tri)) => {
                    let c = a.eval(*tri, p.prim, p.bary);
                    [c.r, c.g]
                }
                None => [0.0, 0.0],
            }
        } else {
            p.uv
        };
        self.transformed(uv)
    }

    fn transformed(&self, uv: [f32; 2]) -> [f32; 2] {
        let m = &self.transform;
        [m[0][0] * uv[0] + m[0][1] * uv[1] + m[0][2], m[1][0] * uv[0] + m[1][1] * uv[1] + m[1][2]]
    }

    fn texel(&self, x: i64, y: i64) -> [f32; 4] {
        let (w, h) = (self.image.width as i64, self.image.height as i64);
        let (x, y) = (wrap_index(x, w, self.wrap[0]), wrap_index(y, h, self.wrap[1]));
        self.image.pixels[y * self.image.width + x]
    }

    /// RGBA at (already transformed) texture coordinates `uv`, with the sampler's filter;
    /// uv (0, 0) is the image's top-left corner.
    pub fn lookup(&self, uv: [f32; 2]) -> [f32; 4] {
        let x = uv[0] * self.image.width as f32;
        let y = uv[1] * self.image.height as f32;
        if self.nearest {
            return self.texel(floor_index(x), floor_index(y));
        }
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (floor_index(x), floor_index(y));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let (fx, fy) = (if fx.is_finite() { fx } else { 0.0 }, if fy.is_finite() { fy } else { 0.0 });
        let (a, b, c, d) =
            (self.texel(x0, y0), self.texel(x0 + 1, y0), self.texel(x0, y0 + 1), self.texel(x0 + 1, y0 + 1));
        std::array::from_fn(|k| (a[k] * (1.0 - fx) + b[k] * fx) * (1.0 - fy) + (c[k] * (1.0 - fx) + d[k] * fx) * fy)
    }

    /// RGBA at a hit point.
    pub fn rgba_at(&self, p: &TexturePoint) -> [f32; 4] {
        self.lookup(self.uv(p))
    }

    fn color(&self, c: [f32; 4]) -> Rgb {
        match self.normal_scale {
            None => rgb(c[0], c[1], c[2]) * self.scale,
            Some(s) => rgb((c[0] - 0.5) * s + 0.5, (c[1] - 0.5) * s + 0.5, c[2]),
        }
    }

    /// The colour at a hit point.
    pub fn eval_at(&self, p: &TexturePoint) -> Rgb {
        self.color(self.rgba_at(p))
    }

    /// The colour at texture coordinates `uv` of set 0 (lights sample emission so).
    pub fn eval(&self, uv: [f32; 2]) -> Rgb {
        self.color(self.lookup(self.transformed(uv)))
    }
}

/// A glTF material's opacity: alpha (factor x base colour texture x `COLOR_0`), through the
/// cutoff for `MASK`.
#[derive(Clone, Debug)]
pub struct GltfAlpha {
    pub factor: f32,
    pub texture: Option<Arc<GltfTexture>>,
    /// `MASK`: opaque (1) at or above, transparent (0) below.
    pub cutoff: Option<f32>,
}

impl GltfAlpha {
    pub fn eval_at(&self, p: &TexturePoint) -> f32 {
        let mut a = self.factor;
        if let Some(t) = &self.texture {
            a *= t.rgba_at(p)[3];
        }
        a *= vertex_value(p, ALPHA_ATTRIBUTE).map_or(1.0, |c| c.r);
        match self.cutoff {
            Some(c) => {
                if a >= c {
                    1.0
                } else {
                    0.0
                }
            }
            None => a,
        }
    }
}

fn vertex_value(p: &TexturePoint, name: &str) -> Option<Rgb> {
    let m = p.mesh?;
    let a = m.attribute(name)?;
    let tri = m.indices.get(p.prim as usize)?;
    Some(a.eval(*tri, p.prim, p.bary))
}

/// A glTF material with its textures.
#[derive(Clone, Debug)]
pub struct GltfMaterial {
    /// The material's factors and extensions; each is multiplied by its texture's channel
    /// at each hit.
    pub factors: GltfPbr,
    pub base_color_texture: Option<Arc<GltfTexture>>,
    pub metallic_roughness_texture: Option<Arc<GltfTexture>>,
    /// The extensions' textures.
    pub extension_textures: GltfExtensionTextures,
    /// `KHR_materials_unlit`: scatters nothing (the reader makes the surface emit).
    pub unlit: bool,
}

/// The textures of the KHR material extensions, each multiplying its factor by the channel
/// the extension names.
#[derive(Clone, Debug, Default)]
pub struct GltfExtensionTextures {
    /// `specularTexture`: alpha multiplies `specularFactor`.
    pub specular: Option<Arc<GltfTexture>>,
    /// `specularColorTexture` (sRGB): RGB multiplies `specularColorFactor`.
    pub specular_color: Option<Arc<GltfTexture>>,
    /// `transmissionTexture`: red multiplies `transmissionFactor`.
    pub transmission: Option<Arc<GltfTexture>>,
    /// `clearcoatTexture`: red multiplies `clearcoatFactor`.
    pub clearcoat: Option<Arc<GltfTexture>>,
    /// `clearcoatRoughnessTexture`: green multiplies `clearcoatRoughnessFactor`.
    pub clearcoat_roughness: Option<Arc<GltfTexture>>,
    /// `sheenColorTexture` (sRGB): RGB multiplies `sheenColorFactor`.
    pub sheen_color: Option<Arc<GltfTexture>>,
    /// `sheenRoughnessTexture`: alpha multiplies `sheenRoughnessFactor`.
    pub sheen_roughness: Option<Arc<GltfTexture>>,
}

impl GltfMaterial {
    /// The BSDF inputs at a hit.
    #[inline]
    pub fn bsdf(&self, p: &TexturePoint) -> GltfPbr {
        let mut b = self.factors;
        if let Some(t) = &self.base_color_texture {
            let c = t.rgba_at(p);
            b.base_color *= rgb(c[0], c[1], c[2]);
        }
        if let Some(c) = vertex_value(p, COLOR_ATTRIBUTE) {
            b.base_color *= c;
        }
        if let Some(t) = &self.metallic_roughness_texture {
            let c = t.rgba_at(p);
            b.roughness *= c[1];
            b.metallic *= c[2];
        }
        let x = &self.extension_textures;
        let read = |t: &Option<Arc<GltfTexture>>| t.as_ref().map(|t| t.rgba_at(p));
        if let Some(c) = read(&x.specular) {
            b.specular *= c[3];
        }
        if let Some(c) = read(&x.specular_color) {
            b.specular_color *= rgb(c[0], c[1], c[2]);
        }
        if let Some(c) = read(&x.transmission) {
            b.transmission *= c[0];
        }
        if let Some(c) = read(&x.clearcoat) {
            b.clearcoat *= c[0];
        }
        if let Some(c) = read(&x.clearcoat_roughness) {
            b.clearcoat_roughness *= c[1];
        }
        if let Some(c) = read(&x.sheen_color) {
            b.sheen_color *= rgb(c[0], c[1], c[2]);
        }
        if let Some(c) = read(&x.sheen_roughness) {
            b.sheen_roughness *= c[3];
        }
        b
    }

    pub fn is_transmissive(&self) -> bool {
        self.factors.transmission > 0.0
    }

    /// Base colour at `uv` (texture coordinate set 0), the denoiser's albedo guide.
    pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
        let t = self.base_color_texture.as_ref().map_or(Rgb::WHITE, |t| {
            let c = t.lookup(t.transformed(uv));
            rgb(c[0], c[1], c[2])
        });
        self.factors.base_color * t
    }
}

impl Shade for GltfMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        if self.unlit {
            return Bsdf::Black(Black);
        }
        Bsdf::GltfPbr(self.bsdf(p))
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        GltfMaterial::albedo(self, uv)
    }

    fn is_transmissive(&self) -> bool {
        GltfMaterial::is_transmissive(self)
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}

impl Describe for GltfMaterialDesc {
    type Built = MaterialKind;

    fn build(&self, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
        build_gltf(self, textures)
    }

    fn validate(&self) -> Result<(), String> {
        check_gltf(self)
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        GltfMaterialDesc::textures(self)
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        GltfMaterialDesc::textures_mut(self)
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        vec![
            ("base_color", Slot::Color(&mut self.base_color)),
            ("metallic", Slot::Float(&mut self.metallic)),
            ("roughness", Slot::Float(&mut self.roughness)),
        ]
    }
}

/// The material kind of a glTF material: the textured [`GltfMaterial`], inside a normal
/// map and a mask where it has them.
fn build_gltf(g: &GltfMaterialDesc, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
    let base_color_texture = textures.optional_gltf(&g.base_color_texture)?;
    let factors = GltfPbr {
        base_color: g.base_color,
        metallic: g.metallic,
        roughness: g.roughness,
        ior: g.ior,
        specular: g.specular,
        specular_color: g.specular_color,
        transmission: g.transmission,
        thin_walled: g.thin_walled,
        clearcoat: g.clearcoat,
        clearcoat_roughness: g.clearcoat_roughness,
        sheen_color: g.sheen_color,
        sheen_roughness: g.sheen_roughness,
    };
    let mut kind = MaterialKind::Gltf(GltfMaterial {
        factors,
        base_color_texture: base_color_texture.clone(),
        metallic_roughness_texture: textures.optional_gltf(&g.metallic_roughness_texture)?,
        extension_textures: GltfExtensionTextures {
            specular: textures.optional_gltf(&g.specular_texture)?,
            specular_color: textures.optional_gltf(&g.specular_color_texture)?,
            transmission: textures.optional_gltf(&g.transmission_texture)?,
            clearcoat: textures.optional_gltf(&g.clearcoat_texture)?,
            clearcoat_roughness: textures.optional_gltf(&g.clearcoat_roughness_texture)?,
            sheen_color: textures.optional_gltf(&g.sheen_color_texture)?,
            sheen_roughness: textures.optional_gltf(&g.sheen_roughness_texture)?,
        },
        unlit: g.unlit,
    });
    if let Some(n) = textures.optional_gltf(&g.normal_texture)? {
        let mut n = (*n).clone();
        n.normal_scale = Some(g.normal_scale);
        kind =
            MaterialKind::NormalMap(NormalMapMaterial { normals: Texture::Gltf(Arc::new(n)), nested: Box::new(kind) });
    }
    let cutoff = match g.alpha {
        GltfAlphaMode::Opaque => return Ok(kind),
        GltfAlphaMode::Mask { cutoff } => Some(cutoff),
        GltfAlphaMode::Blend => None,
    };
    let alpha = GltfAlpha { factor: g.base_alpha, texture: base_color_texture, cutoff };
    Ok(MaterialKind::Mask(MaskMaterial { opacity: Texture::GltfAlpha(Arc::new(alpha)), nested: Box::new(kind) }))
}

/// A glTF material's factors: the specification's ranges ([0, 1] but for the index of
/// refraction and the attenuation distance), so that a BSDF never sees a value it has no
/// meaning for.
fn check_gltf(g: &GltfMaterialDesc) -> Result<(), String> {
    checks::eta(g.ior)?;
    for (name, c) in [
        ("baseColorFactor", g.base_color),
        ("specularColorFactor", g.specular_color),
        ("sheenColorFactor", g.sheen_color),
        ("attenuationColor", g.attenuation_color),
    ] {
        checks::color(c, name)?;
    }
    for (name, v) in [
        ("alpha", g.base_alpha),
        ("metallicFactor", g.metallic),
        ("roughnessFactor", g.roughness),
        ("specularFactor", g.specular),
        ("transmissionFactor", g.transmission),
        ("clearcoatFactor", g.clearcoat),
        ("clearcoatRoughnessFactor", g.clearcoat_roughness),
        ("sheenRoughnessFactor", g.sheen_roughness),
    ] {
        if !(0.0..=1.0).contains(&v) {
            return Err(format!("glTF material: {name} {v} must lie in [0, 1]"));
        }
    }
    if !g.normal_scale.is_finite() {
        return Err(format!("glTF material: normalTexture.scale {} must be finite", g.normal_scale));
    }
    if !(g.attenuation_distance > 0.0) {
        return Err(format!("glTF material: attenuationDistance {} must be positive", g.attenuation_distance));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> GltfTexture {
        // 2 x 1: black, white.
        let image = RgbaImage { width: 2, height: 1, pixels: vec![[0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 0.5]] };
        GltfTexture::new(Arc::new(image), 0, [GltfWrap::Repeat, GltfWrap::Repeat], true)
    }

    #[test]
    fn wrap_modes_repeat_clamp_and_mirror() {
        assert_eq!(wrap_index(5, 4, GltfWrap::Repeat), 1);
        assert_eq!(wrap_index(-1, 4, GltfWrap::Repeat), 3);
        assert_eq!(wrap_index(-3, 4, GltfWrap::Clamp), 0);
        assert_eq!(wrap_index(9, 4, GltfWrap::Clamp), 3);
        // Mirrored: 0 1 2 3 3 2 1 0 0 1 ...
        assert_eq!(wrap_index(4, 4, GltfWrap::Mirror), 3);
        assert_eq!(wrap_index(7, 4, GltfWrap::Mirror), 0);
        assert_eq!(wrap_index(8, 4, GltfWrap::Mirror), 0);
        assert_eq!(wrap_index(-1, 4, GltfWrap::Mirror), 0);
    }

    #[test]
    fn nearest_and_linear_filters_and_the_transform() {
        let mut t = checker();
        assert_eq!(t.lookup([0.25, 0.5])[0], 0.0);
        assert_eq!(t.lookup([0.75, 0.5])[0], 1.0);
        t.nearest = false;
        // Half-way between the texel centres.
        assert!((t.lookup([0.5, 0.5])[0] - 0.5).abs() < 1e-6);
        // KHR_texture_transform offset by half the image swaps the texels.
        t.nearest = true;
        t.transform = [[1.0, 0.0, 0.5], [0.0, 1.0, 0.0]];
        assert_eq!(t.eval([0.25, 0.5]).r, 1.0);
        // NaN and infinite coordinates read some texel, without a panic.
        assert!(t.eval([f32::NAN, f32::INFINITY]).r.is_finite());
    }

    #[test]
    fn normal_scale_scales_x_and_y_about_the_flat_normal() {
        let image = RgbaImage { width: 1, height: 1, pixels: vec![[1.0, 0.5, 1.0, 1.0]] };
        let mut t = GltfTexture::new(Arc::new(image), 0, [GltfWrap::Repeat; 2], false);
        t.normal_scale = Some(0.5);
        let c = t.eval([0.5, 0.5]);
        assert_eq!((c.r, c.g, c.b), (0.75, 0.5, 1.0));
    }

    #[test]
    fn mask_cutoff_is_a_step() {
        let a = GltfAlpha { factor: 0.6, texture: None, cutoff: Some(0.5) };
        assert_eq!(a.eval_at(&TexturePoint::uv([0.0, 0.0])), 1.0);
        let a = GltfAlpha { factor: 0.4, texture: None, cutoff: Some(0.5) };
        assert_eq!(a.eval_at(&TexturePoint::uv([0.0, 0.0])), 0.0);
        let a = GltfAlpha { factor: 0.4, texture: Some(Arc::new(checker())), cutoff: None };
        assert!((a.eval_at(&TexturePoint::uv([0.75, 0.5])) - 0.2).abs() < 1e-6);
    }
}
