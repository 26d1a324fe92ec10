//! The textured principled material: what a hit evaluates into a [`Principled`].

use super::{ScalarTexture, Texture};
use crate::bsdf::{Principled, PrincipledInputs, PrincipledRates};

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
