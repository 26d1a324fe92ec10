//! `principled`: Mitsuba's principled (Disney) BSDF with textured parameters; what a hit
//! evaluates into a [`Principled`] (parameters: `describe::PrincipledDesc`).

mod bsdf;

pub use bsdf::{principled_alphas, AnisoGgx, Principled, PrincipledInputs, PrincipledRates};

use super::Bsdf;
use super::{MaterialKind, ScalarTexture, Shade, Texture, TextureCache, TexturePoint};
use crate::describe::{PrincipledDesc, TextureDesc};
use crate::error::Error;
use crate::math::Rgb;

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
    pub(crate) fn build(p: &PrincipledDesc, textures: &mut TextureCache) -> Result<PrincipledMaterial, Error> {
        let mut scalar =
            |t: &TextureDesc| -> Result<ScalarTexture, Error> { Ok(ScalarTexture::new(textures.texture(t)?)) };
        Ok(PrincipledMaterial {
            roughness: scalar(&p.roughness)?,
            anisotropic: scalar(&p.anisotropic)?,
            metallic: scalar(&p.metallic)?,
            spec_trans: scalar(&p.spec_trans)?,
            eta: p.eta,
            spec_tint: scalar(&p.spec_tint)?,
            sheen: scalar(&p.sheen)?,
            sheen_tint: scalar(&p.sheen_tint)?,
            flatness: scalar(&p.flatness)?,
            clearcoat: scalar(&p.clearcoat)?,
            clearcoat_gloss: scalar(&p.clearcoat_gloss)?,
            base_color: textures.texture(&p.base_color)?,
            rates: PrincipledRates {
                diffuse: p.diffuse_sampling_rate,
                specular: p.specular_sampling_rate,
                clearcoat: p.clearcoat_sampling_rate,
            },
        })
    }

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

impl Shade for PrincipledMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::Principled(self.bsdf(p.uv))
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.base_color.eval(uv)
    }

    fn is_transmissive(&self) -> bool {
        PrincipledMaterial::is_transmissive(self)
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
