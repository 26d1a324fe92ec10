//! The textured principled material and blends of two materials: what a hit evaluates into
//! a [`Principled`] or a [`BlendBsdf`].

use super::{MaterialKind, Texture};
use crate::bsdf::{BlendBsdf, BlendPart, Bsdf, Principled, PrincipledInputs, PrincipledRates};
use crate::math::Rgb;

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

#[derive(Clone, Debug)]
pub struct PrincipledMaterial {
    pub base_color: Texture,
    pub roughness: ScalarTexture,
    pub anisotropic: ScalarTexture,
    pub metallic: ScalarTexture,
    pub spec_trans: ScalarTexture,
    pub eta: f32,
    pub spec_tint: ScalarTexture,
    pub sheen: ScalarTexture,
    pub sheen_tint: ScalarTexture,
    pub flatness: ScalarTexture,
    pub clearcoat: ScalarTexture,
    pub clearcoat_gloss: ScalarTexture,
    pub rates: PrincipledRates,
}

impl PrincipledMaterial {
    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> Principled {
        Principled::new(&PrincipledInputs {
            base_color: self.base_color.eval(uv),
            roughness: self.roughness.eval(uv),
            anisotropic: self.anisotropic.eval(uv),
            metallic: self.metallic.eval(uv),
            spec_trans: self.spec_trans.eval(uv),
            eta: self.eta,
            spec_tint: self.spec_tint.eval(uv),
            sheen: self.sheen.eval(uv),
            sheen_tint: self.sheen_tint.eval(uv),
            flatness: self.flatness.eval(uv),
            clearcoat: self.clearcoat.eval(uv),
            clearcoat_gloss: self.clearcoat_gloss.eval(uv),
            rates: self.rates,
        })
    }

    /// Transmits light somewhere (both faces matter).
    pub fn is_transmissive(&self) -> bool {
        !self.spec_trans.is_zero()
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
