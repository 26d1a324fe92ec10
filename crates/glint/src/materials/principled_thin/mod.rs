//! Mitsuba 3's `principledthin` BSDF: Burley's Disney BSDF (2012, 2015) for an infinitely
//! thin, translucent surface such as a leaf, paper or a curtain. It has no interior: light is
//! reflected or passes to the other side without bending, and both faces are the same
//! (Mitsuba's plugin is two-sided by itself). The lobes, their weights and their sampling
//! probabilities are Mitsuba 3.9.1's term by term (unpolarized, RGB):
//!
//! - a GGX reflection lobe weighted by `spec_trans`, with a dielectric Fresnel term blended
//!   towards a tinted Schlick one by `spec_tint`;
//! - a GGX "transmission" lobe weighted by `spec_trans`, `base_color` and 1 - F: the
//!   microfacet reflection mirrored through the surface (the refracted direction of a thin
//!   slab), with its roughness scaled by (0.65 η - 0.35) (Burley 2015, figure 15);
//! - a diffuse lobe with retro-reflection, the `flatness` fake subsurface and `sheen`,
//!   weighted by (1 - `spec_trans`) (1 - `diff_trans`/2);
//! - a Lambertian transmission lobe weighted by (1 - `spec_trans`) `diff_trans`/2.
//!
//! Parameters (Mitsuba's names and defaults; every one but the sampling rates may be a
//! texture, a float parameter reading the texture's luminance):
//!
//! | name | type | default | meaning |
//! |---|---|---|---|
//! | `base_color` | spectrum or texture | 0.5 | colour of the diffuse lobes and of the specular transmission |
//! | `roughness` | float or texture | 0.5 | roughness of the specular lobes (alpha = roughness²) |
//! | `anisotropic` | float or texture | 0.0 | degree of anisotropy of the specular lobes (0: isotropic) |
//! | `spec_trans` | float or texture | 0.0 | blends the diffuse (0) and specular (1) responses |
//! | `eta` | float or texture | 1.5 | relative index of refraction of the thin sheet (Fresnel term, transmission roughness) |
//! | `spec_tint` | float or texture | 0.0 | fraction of the specular reflection tinted towards `base_color` |
//! | `sheen` | float or texture | 0.0 | weight of the sheen lobe |
//! | `sheen_tint` | float or texture | 0.0 | fraction of the sheen tinted towards `base_color` |
//! | `flatness` | float or texture | 0.0 | blends the diffuse lobe (0) with the fake subsurface one (1) |
//! | `diff_trans` | float or texture | 0.0 | share of the diffuse energy transmitted, in [0, 2] (2: all of it) |
//! | `diffuse_reflectance_sampling_rate` | float | 1.0 | relative rate of sampling the diffuse reflection |
//! | `diffuse_transmittance_sampling_rate` | float | 1.0 | relative rate of sampling the diffuse transmission |
//! | `specular_reflectance_sampling_rate` | float | 1.0 | relative rate of sampling the specular reflection |
//! | `specular_transmittance_sampling_rate` | float | 1.0 | relative rate of sampling the specular transmission |
//!
//! As in Mitsuba, the specular reflection exists only through `spec_trans` (a thin sheet
//! with `spec_trans` 0 is purely diffuse), and a transmitted sample keeps η = 1 (no radiance
//! scaling: both sides are the same medium).
//!
//! # Differentiable
//! Every parameter `traverse` lists for it, constants or bitmap textures per texel. See `docs/differentiable.md`.

mod bsdf;

pub use bsdf::{PrincipledThin, PrincipledThinInputs, PrincipledThinRates};

use super::{Bsdf, Describe, MaterialKind, ScalarTexture, Shade, Texture, TextureCache, TexturePoint};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::{checks, TextureDesc};
use crate::error::Error;
use crate::math::Rgb;
use serde::{Deserialize, Serialize};

/// The description of the thin principled BSDF (Mitsuba's `principledthin`): every
/// parameter but the sampling rates may be a texture, `eta` included.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PrincipledThinDesc {
    pub base_color: TextureDesc,
    pub roughness: TextureDesc,
    pub anisotropic: TextureDesc,
    pub spec_trans: TextureDesc,
    /// Relative index of refraction of the sheet.
    pub eta: TextureDesc,
    pub spec_tint: TextureDesc,
    pub sheen: TextureDesc,
    pub sheen_tint: TextureDesc,
    pub flatness: TextureDesc,
    /// The share of the diffuse energy transmitted, in [0, 2] (2: all of it).
    pub diff_trans: TextureDesc,
    /// Relative sampling weights of the four lobes.
    pub diffuse_reflectance_sampling_rate: f32,
    pub diffuse_transmittance_sampling_rate: f32,
    pub specular_reflectance_sampling_rate: f32,
    pub specular_transmittance_sampling_rate: f32,
}

impl Default for PrincipledThinDesc {
    /// Mitsuba's defaults.
    fn default() -> Self {
        let c = |v: f32| TextureDesc::constant(Rgb::splat(v));
        PrincipledThinDesc {
            base_color: c(0.5),
            roughness: c(0.5),
            anisotropic: c(0.0),
            spec_trans: c(0.0),
            eta: c(1.5),
            spec_tint: c(0.0),
            sheen: c(0.0),
            sheen_tint: c(0.0),
            flatness: c(0.0),
            diff_trans: c(0.0),
            diffuse_reflectance_sampling_rate: 1.0,
            diffuse_transmittance_sampling_rate: 1.0,
            specular_reflectance_sampling_rate: 1.0,
            specular_transmittance_sampling_rate: 1.0,
        }
    }
}

impl PrincipledThinDesc {
    /// Mitsuba's names of the textured parameters, in the order of `textures`.
    pub const TEXTURE_NAMES: [&'static str; 10] = [
        "base_color",
        "roughness",
        "anisotropic",
        "spec_trans",
        "eta",
        "spec_tint",
        "sheen",
        "sheen_tint",
        "flatness",
        "diff_trans",
    ];

    /// The parameters that are textures, with their names (for validation and edits).
    pub fn textures(&self) -> [(&'static str, &TextureDesc); 10] {
        let t = [
            &self.base_color,
            &self.roughness,
            &self.anisotropic,
            &self.spec_trans,
            &self.eta,
            &self.spec_tint,
            &self.sheen,
            &self.sheen_tint,
            &self.flatness,
            &self.diff_trans,
        ];
        let mut i = 0;
        t.map(|t| {
            i += 1;
            (Self::TEXTURE_NAMES[i - 1], t)
        })
    }

    /// The same, mutable, in the same order.
    pub fn textures_mut(&mut self) -> [&mut TextureDesc; 10] {
        [
            &mut self.base_color,
            &mut self.roughness,
            &mut self.anisotropic,
            &mut self.spec_trans,
            &mut self.eta,
            &mut self.spec_tint,
            &mut self.sheen,
            &mut self.sheen_tint,
            &mut self.flatness,
            &mut self.diff_trans,
        ]
    }
}

impl Describe for PrincipledThinDesc {
    type Built = PrincipledThinMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<PrincipledThinMaterial, Error> {
        let p = self;
        let mut scalar =
            |t: &TextureDesc| -> Result<ScalarTexture, Error> { Ok(ScalarTexture::new(textures.texture(t)?)) };
        Ok(PrincipledThinMaterial {
            roughness: scalar(&p.roughness)?,
            anisotropic: scalar(&p.anisotropic)?,
            spec_trans: scalar(&p.spec_trans)?,
            eta: scalar(&p.eta)?,
            spec_tint: scalar(&p.spec_tint)?,
            sheen: scalar(&p.sheen)?,
            sheen_tint: scalar(&p.sheen_tint)?,
            flatness: scalar(&p.flatness)?,
            diff_trans: scalar(&p.diff_trans)?,
            base_color: textures.texture(&p.base_color)?,
            rates: PrincipledThinRates {
                diffuse_reflectance: p.diffuse_reflectance_sampling_rate,
                diffuse_transmittance: p.diffuse_transmittance_sampling_rate,
                specular_reflectance: p.specular_reflectance_sampling_rate,
                specular_transmittance: p.specular_transmittance_sampling_rate,
            },
        })
    }

    fn validate(&self) -> Result<(), String> {
        check(self)
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        PrincipledThinDesc::textures(self).into_iter().map(|(_, t)| t).collect()
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        PrincipledThinDesc::textures_mut(self).into_iter().collect()
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = Vec::new();
        for (name, t) in PrincipledThinDesc::TEXTURE_NAMES.into_iter().zip(PrincipledThinDesc::textures_mut(self)) {
            texture_slot(name, t, &mut out);
        }
        out
    }
}

/// Mitsuba documents every `principledthin` parameter but `eta`, `diff_trans` (in [0, 2])
/// and the sampling rates as lying in [0, 1]; `eta` must be positive (the transmission's
/// roughness scale 0.65 eta - 0.35 and the Fresnel term need it).
fn check(p: &PrincipledThinDesc) -> Result<(), String> {
    for (name, t) in p.textures() {
        let check = |c: Rgb| -> Result<(), String> {
            let in_range = |hi: f32| c.to_array().iter().all(|v| (0.0..=hi).contains(v));
            match name {
                "base_color" => Ok(()),
                "eta" => c.to_array().into_iter().try_for_each(checks::eta),
                "diff_trans" if !in_range(2.0) => {
                    Err(format!("principledthin: diff_trans ({}, {}, {}) must lie in [0, 2]", c.r, c.g, c.b))
                }
                "diff_trans" => Ok(()),
                _ if !in_range(1.0) => {
                    Err(format!("principledthin: {name} ({}, {}, {}) must lie in [0, 1]", c.r, c.g, c.b))
                }
                _ => Ok(()),
            }
        };
        match t {
            TextureDesc::Constant { color: c } => check(*c)?,
            TextureDesc::Checkerboard { color0, color1, .. } => {
                check(*color0)?;
                check(*color1)?;
            }
            // Images are clamped to [0, 1] by their formats or read as given (EXR).
            TextureDesc::Bitmap { .. } | TextureDesc::MeshAttribute { .. } | TextureDesc::Gltf(_) => {}
        }
    }
    let rates = [
        (p.diffuse_reflectance_sampling_rate, "diffuse_reflectance_sampling_rate"),
        (p.diffuse_transmittance_sampling_rate, "diffuse_transmittance_sampling_rate"),
        (p.specular_reflectance_sampling_rate, "specular_reflectance_sampling_rate"),
        (p.specular_transmittance_sampling_rate, "specular_transmittance_sampling_rate"),
    ];
    for (rate, name) in rates {
        if !(rate >= 0.0 && rate.is_finite()) {
            return Err(format!("principledthin: {name} {rate} must be finite and not negative"));
        }
    }
    if !rates.iter().any(|(r, _)| *r > 0.0) {
        return Err("principledthin: at least one sampling rate must be positive".to_string());
    }
    Ok(())
}

#[derive(Clone, Debug)]
pub struct PrincipledThinMaterial {
    pub base_color: Texture,
    pub roughness: ScalarTexture,
    pub anisotropic: ScalarTexture,
    pub spec_trans: ScalarTexture,
    pub eta: ScalarTexture,
    pub spec_tint: ScalarTexture,
    pub sheen: ScalarTexture,
    pub sheen_tint: ScalarTexture,
    pub flatness: ScalarTexture,
    /// As Mitsuba gives it, in [0, 2].
    pub diff_trans: ScalarTexture,
    pub rates: PrincipledThinRates,
}

impl PrincipledThinMaterial {
    #[inline]
    pub fn bsdf(&self, uv: [f32; 2]) -> PrincipledThin {
        PrincipledThin::new(&PrincipledThinInputs {
            base_color: self.base_color.eval(uv),
            roughness: self.roughness.eval(uv),
            anisotropic: self.anisotropic.eval(uv),
            spec_trans: self.spec_trans.eval(uv),
            eta: self.eta.eval(uv),
            spec_tint: self.spec_tint.eval(uv),
            sheen: self.sheen.eval(uv),
            sheen_tint: self.sheen_tint.eval(uv),
            flatness: self.flatness.eval(uv),
            diff_trans: self.diff_trans.eval(uv),
            rates: self.rates,
        })
    }

    /// Transmits light somewhere (specularly or diffusely). Both faces scatter either way:
    /// the BSDF is two-sided by itself.
    pub fn is_transmissive(&self) -> bool {
        !self.spec_trans.is_zero() || !self.diff_trans.is_zero()
    }
}

impl Shade for PrincipledThinMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::PrincipledThin(self.bsdf(p.uv))
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.base_color.eval(uv)
    }

    fn is_transmissive(&self) -> bool {
        PrincipledThinMaterial::is_transmissive(self)
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
