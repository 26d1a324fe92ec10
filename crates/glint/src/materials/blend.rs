//! `blendbsdf`: (1 - `weight`) times the first material plus `weight` times the second,
//! the weight a texture; what a hit evaluates into a [`BlendBsdf`].
//!
//! # The BSDF
//! Mitsuba's `blendbsdf`: (1 - w) · first + w · second, with `w` in [0, 1].
//!
//! `eval` and `pdf` are the weighted mixtures. `sample` picks a part with probability
//! 1 - w or w, samples it, and returns the whole mixture's value over the whole mixture's
//! pdf at that direction, as Mitsuba 3.9.1 does. For a delta lobe that mixture adds the
//! lobe's discrete probability (1 by convention) to the other part's density there, so a
//! delta lobe blended with a glossy one at 0 < w < 1 is weighted less than its share:
//! Mitsuba's behaviour, kept so that the two renderers agree (docs/mitsuba-support.md).
//!
//! Each part may be two-sided on its own (Mitsuba's `twosided` nested inside the blend):
//! seen from below, such a part is evaluated with both directions mirrored to its front.
//! The parts live behind a `Box` (a blend is built per hit, the one material kind that
//! allocates); every other BSDF stays inline.
//!
//! # Differentiable
//! `weight` and both parts' parameters, as `traverse` lists them. See `docs/differentiable.md`.

use super::{Bsdf, MaterialKind, ScalarTexture, Shade, TextureCache, TexturePoint};
use super::{Describe, MaterialModel};
use crate::bsdf::{BsdfSample, Scatter};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug)]
pub struct BlendPart {
    pub bsdf: Bsdf,
    /// Mitsuba's `twosided` around this part alone.
    pub two_sided: bool,
}

#[derive(Clone, Debug)]
pub struct BlendBsdf {
    /// Weight of the second part, in [0, 1].
    pub weight: f32,
    pub parts: Box<[BlendPart; 2]>,
}

fn mirror(v: Vec3) -> Vec3 {
    Vec3 { x: v.x, y: v.y, z: -v.z }
}

impl BlendPart {
    /// Whether `wo` must be mirrored to this part's front.
    #[inline]
    fn flips(&self, wo: Vec3) -> bool {
        self.two_sided && wo.z < 0.0
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if self.flips(wo) {
            self.bsdf.eval(mirror(wo), mirror(wi))
        } else {
            self.bsdf.eval(wo, wi)
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.flips(wo) {
            self.bsdf.pdf(mirror(wo), mirror(wi))
        } else {
            self.bsdf.pdf(wo, wi)
        }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if self.flips(wo) {
            let mut s = self.bsdf.sample(mirror(wo), u_lobe, u)?;
            s.wi = mirror(s.wi);
            Some(s)
        } else {
            self.bsdf.sample(wo, u_lobe, u)
        }
    }
}

impl BlendBsdf {
    pub fn new(weight: f32, first: BlendPart, second: BlendPart) -> BlendBsdf {
        // Mitsuba clips the weight; NaN (a texture cannot give one) would pick neither.
        let weight = if weight.is_nan() { 0.5 } else { weight.clamp(0.0, 1.0) };
        BlendBsdf { weight, parts: Box::new([first, second]) }
    }

    /// (1 - w, w): the weights of the two parts.
    #[inline]
    fn weights(&self) -> [f32; 2] {
        [1.0 - self.weight, self.weight]
    }
}

impl Scatter for BlendBsdf {
    fn is_delta(&self) -> bool {
        self.parts.iter().all(|p| p.bsdf.is_delta())
    }

    fn has_delta_lobe(&self) -> bool {
        self.parts.iter().any(|p| p.bsdf.has_delta_lobe())
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let [a, b] = self.weights();
        let mut v = Rgb::BLACK;
        if a > 0.0 {
            v += self.parts[0].eval(wo, wi) * a;
        }
        if b > 0.0 {
            v += self.parts[1].eval(wo, wi) * b;
        }
        v
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let [a, b] = self.weights();
        let mut p = 0.0;
        if a > 0.0 {
            p += self.parts[0].pdf(wo, wi) * a;
        }
        if b > 0.0 {
            p += self.parts[1].pdf(wo, wi) * b;
        }
        p
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let w = self.weight;
        // Mitsuba: the first part when u_lobe > w, with u_lobe rescaled to [0, 1).
        let (chosen, other, u_lobe) = if w <= 0.0 || (w < 1.0 && u_lobe > w) {
            (0, 1, ((u_lobe - w) / (1.0 - w)).min(1.0 - f32::EPSILON / 2.0))
        } else {
            (1, 0, (u_lobe / w).min(1.0 - f32::EPSILON / 2.0))
        };
        let weights = self.weights();
        let (wc, wx) = (weights[chosen], weights[other]);
        let mut s = self.parts[chosen].sample(wo, u_lobe, u)?;
        let (value_other, pdf_other) = if wx > 0.0 {
            (self.parts[other].eval(wo, s.wi), self.parts[other].pdf(wo, s.wi))
        } else {
            (Rgb::BLACK, 0.0)
        };
        let pdf = wc * s.pdf + wx * pdf_other;
        if !(pdf > 0.0) {
            return None;
        }
        // The chosen part's value is its weight times its pdf (for a delta lobe, the
        // lobe's own weight: its pdf is the lobe's probability).
        s.weight = (s.weight * (wc * s.pdf) + value_other * wx) / pdf;
        s.pdf = pdf;
        Some(s)
    }

    fn diffuse_reflectance(&self) -> Rgb {
        let [a, b] = self.weights();
        self.parts[0].bsdf.diffuse_reflectance() * a + self.parts[1].bsdf.diffuse_reflectance() * b
    }
}

/// One of a blend's two materials, with its own sidedness (a `twosided` inside the blend).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlendPartDesc {
    pub model: MaterialModel,
    pub two_sided: bool,
}

/// `blendbsdf`'s parameters: (1 - `weight`) · `first` + `weight` · `second`.
///
/// | Parameter | Type | Default (JSON, Mitsuba) | |
/// |---|---|---|---|
/// | `weight` | texture | (Mitsuba 0.5) | read as a grey value (its luminance) |
/// | `first`, `second` | material | (required) | each with its own sidedness |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlendDesc {
    pub weight: TextureDesc,
    pub first: Box<BlendPartDesc>,
    pub second: Box<BlendPartDesc>,
}

impl Describe for BlendDesc {
    type Built = BlendMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<BlendMaterial, Error> {
        let mut part = |p: &BlendPartDesc| -> Result<BlendMaterialPart, Error> {
            Ok(BlendMaterialPart { kind: p.model.build(textures)?, two_sided: p.two_sided })
        };
        let (first, second) = (part(&self.first)?, part(&self.second)?);
        Ok(BlendMaterial::new(ScalarTexture::new(textures.texture(&self.weight)?), first, second))
    }

    fn validate(&self) -> Result<(), String> {
        // Each part is checked as a material of its own (its textures included).
        self.first.model.validate().map_err(|e| format!("blend, first part: {e}"))?;
        self.second.model.validate().map_err(|e| format!("blend, second part: {e}"))
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        let parts = [&self.first, &self.second].into_iter().flat_map(|p| p.model.textures());
        std::iter::once(&self.weight).chain(parts).collect()
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        let parts = [&mut self.first, &mut self.second].into_iter().flat_map(|p| p.model.textures_mut());
        std::iter::once(&mut self.weight).chain(parts).collect()
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        // A blend's parts are not editable one by one (yet).
        let mut out = Vec::new();
        texture_slot("weight", &mut self.weight, &mut out);
        out
    }
}

/// One part of a blend: a material kind and whether it alone is two-sided.
#[derive(Clone, Debug)]
pub struct BlendMaterialPart {
    pub kind: MaterialKind,
    pub two_sided: bool,
}

#[derive(Clone, Debug)]
pub struct BlendMaterial {
    pub weight: ScalarTexture,
    pub parts: Box<[BlendMaterialPart; 2]>,
}

impl BlendMaterial {
    pub fn new(weight: ScalarTexture, first: BlendMaterialPart, second: BlendMaterialPart) -> BlendMaterial {
        BlendMaterial { weight, parts: Box::new([first, second]) }
    }

    pub fn bsdf(&self, uv: [f32; 2]) -> Bsdf {
        // A transmissive part keeps its frame, as a top-level one does.
        let part = |p: &BlendMaterialPart| BlendPart {
            bsdf: p.kind.bsdf(uv),
            two_sided: p.two_sided && !p.kind.is_transmissive(),
        };
        Bsdf::Blend(BlendBsdf::new(self.weight.eval(uv), part(&self.parts[0]), part(&self.parts[1])))
    }

    pub fn is_transmissive(&self) -> bool {
        self.parts.iter().any(|p| p.kind.is_transmissive())
    }

    pub fn albedo(&self, uv: [f32; 2]) -> Rgb {
        let w = self.weight.eval(uv).clamp(0.0, 1.0);
        self.parts[0].kind.albedo(uv) * (1.0 - w) + self.parts[1].kind.albedo(uv) * w
    }
}

impl Shade for BlendMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        self.bsdf(p.uv)
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        BlendMaterial::albedo(self, uv)
    }

    fn is_transmissive(&self) -> bool {
        BlendMaterial::is_transmissive(self)
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
