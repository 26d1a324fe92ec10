//! `principled`: Mitsuba's principled (Disney) BSDF with textured parameters; what a hit
//! evaluates into a [`Principled`] (parameters: `describe::PrincipledDesc`).
//!
//! # Differentiable
//! Every parameter `traverse` lists for it (`base_color`, `roughness`, `metallic`, `specular`,
//! `sheen`, `clearcoat`, ...), constants or bitmap textures per texel. See `docs/differentiable.md`.

mod bsdf;
mod desc;

pub(crate) use bsdf::{compatible, disney_diffuse, lerp, schlick, schlick_r0, schlick_weight, tint_of};
pub use bsdf::{principled_alphas, AnisoGgx, Principled, PrincipledInputs, PrincipledRates};
pub use desc::{principled_eta_of_specular, PrincipledDesc};

use super::Bsdf;
use super::Describe;
use super::{MaterialKind, ScalarTexture, Shade, Texture, TextureCache, TexturePoint};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::{checks, TextureDesc};
use crate::error::Error;
use crate::math::Rgb;

impl Describe for PrincipledDesc {
    type Built = PrincipledMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<PrincipledMaterial, Error> {
        let p = self;
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

    fn validate(&self) -> Result<(), String> {
        check_principled(self)
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        PrincipledDesc::textures(self).into_iter().map(|(_, t)| t).collect()
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        PrincipledDesc::textures_mut(self).into_iter().collect()
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = Vec::new();
        for (name, t) in PrincipledDesc::TEXTURE_NAMES.into_iter().zip(PrincipledDesc::textures_mut(self)) {
            texture_slot(name, t, &mut out);
        }
        out
    }
}

/// Mitsuba documents every principled parameter but `eta` and the sampling rates as lying
/// in [0, 1]; out of it the model has no meaning (anisotropic above 1/0.9 is a NaN).
fn check_principled(p: &PrincipledDesc) -> Result<(), String> {
    checks::eta(p.eta)?;
    for (name, t) in p.textures() {
        let unit = |c: Rgb| -> Result<(), String> {
            if name != "base_color" && c.to_array().iter().any(|v| *v > 1.0) {
                return Err(format!("principled: {name} ({}, {}, {}) must lie in [0, 1]", c.r, c.g, c.b));
            }
            Ok(())
        };
        match t {
            TextureDesc::Constant { color: c } => unit(*c)?,
            TextureDesc::Checkerboard { color0, color1, .. } => {
                unit(*color0)?;
                unit(*color1)?;
            }
            // Images are clamped to [0, 1] by their formats or read as given (EXR).
            TextureDesc::Bitmap { .. } | TextureDesc::MeshAttribute { .. } | TextureDesc::Gltf(_) => {}
        }
    }
    for (rate, name) in [
        (p.diffuse_sampling_rate, "diffuse_reflectance_sampling_rate"),
        (p.specular_sampling_rate, "main_specular_sampling_rate"),
        (p.clearcoat_sampling_rate, "clearcoat_sampling_rate"),
    ] {
        if !(rate >= 0.0 && rate.is_finite()) {
            return Err(format!("principled: {name} {rate} must be finite and not negative"));
        }
    }
    if !(p.specular_sampling_rate > 0.0) {
        // The main lobe must be sampleable: it is the only one seen from inside.
        return Err("principled: main_specular_sampling_rate must be positive".to_string());
    }
    Ok(())
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
