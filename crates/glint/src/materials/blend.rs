//! Blends of two materials (Mitsuba's `blendbsdf`): what a hit evaluates into a
//! [`BlendBsdf`].

use super::{MaterialKind, ScalarTexture};
use crate::bsdf::{BlendBsdf, BlendPart, Bsdf};
use crate::math::Rgb;

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
