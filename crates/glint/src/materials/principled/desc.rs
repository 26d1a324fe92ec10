//! The description of the principled BSDF (Mitsuba's `principled`): its parameters, with
//! Mitsuba's names and defaults (see [`PrincipledDesc::default`]). Scalar parameters that
//! Mitsuba accepts as textures are [`TextureDesc`]s here, read as the luminance of the
//! colour they give (Mitsuba's `eval_1`).

use crate::describe::TextureDesc;
use crate::math::Rgb;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PrincipledDesc {
    pub base_color: TextureDesc,
    pub roughness: TextureDesc,
    pub anisotropic: TextureDesc,
    pub metallic: TextureDesc,
    pub spec_trans: TextureDesc,
    /// Interior over exterior index of refraction (Mitsuba's `eta`, or derived from its
    /// `specular`).
    pub eta: f32,
    pub spec_tint: TextureDesc,
    pub sheen: TextureDesc,
    pub sheen_tint: TextureDesc,
    pub flatness: TextureDesc,
    pub clearcoat: TextureDesc,
    pub clearcoat_gloss: TextureDesc,
    /// Relative sampling weights of the diffuse, main specular and clearcoat lobes.
    pub diffuse_sampling_rate: f32,
    pub specular_sampling_rate: f32,
    pub clearcoat_sampling_rate: f32,
}

impl Default for PrincipledDesc {
    /// Mitsuba's defaults (specular 0.5, that is eta ≈ 1.5).
    fn default() -> Self {
        let c = |v: f32| TextureDesc::constant(Rgb::splat(v));
        PrincipledDesc {
            base_color: c(0.5),
            roughness: c(0.5),
            anisotropic: c(0.0),
            metallic: c(0.0),
            spec_trans: c(0.0),
            eta: principled_eta_of_specular(0.5),
            spec_tint: c(0.0),
            sheen: c(0.0),
            sheen_tint: c(0.0),
            flatness: c(0.0),
            clearcoat: c(0.0),
            clearcoat_gloss: c(0.0),
            diffuse_sampling_rate: 1.0,
            specular_sampling_rate: 1.0,
            clearcoat_sampling_rate: 1.0,
        }
    }
}

impl PrincipledDesc {
    /// Mitsuba's names of the textured parameters, in the order of `textures`.
    pub const TEXTURE_NAMES: [&'static str; 11] = [
        "base_color",
        "roughness",
        "anisotropic",
        "metallic",
        "spec_trans",
        "spec_tint",
        "sheen",
        "sheen_tint",
        "flatness",
        "clearcoat",
        "clearcoat_gloss",
    ];

    /// The parameters that are textures, with their names (for validation and edits).
    pub fn textures(&self) -> [(&'static str, &TextureDesc); 11] {
        let t = [
            &self.base_color,
            &self.roughness,
            &self.anisotropic,
            &self.metallic,
            &self.spec_trans,
            &self.spec_tint,
            &self.sheen,
            &self.sheen_tint,
            &self.flatness,
            &self.clearcoat,
            &self.clearcoat_gloss,
        ];
        let mut i = 0;
        t.map(|t| {
            i += 1;
            (Self::TEXTURE_NAMES[i - 1], t)
        })
    }

    /// The same, mutable, in the same order.
    pub fn textures_mut(&mut self) -> [&mut TextureDesc; 11] {
        [
            &mut self.base_color,
            &mut self.roughness,
            &mut self.anisotropic,
            &mut self.metallic,
            &mut self.spec_trans,
            &mut self.spec_tint,
            &mut self.sheen,
            &mut self.sheen_tint,
            &mut self.flatness,
            &mut self.clearcoat,
            &mut self.clearcoat_gloss,
        ]
    }
}

/// `eta` from Mitsuba's `specular` parameter (normal reflectance 0.08 · specular).
pub fn principled_eta_of_specular(specular: f32) -> f32 {
    2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
}
