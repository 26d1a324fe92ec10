//! The wrappers around a material that change the surface rather than how it scatters:
//! `normalmap` and `bumpmap` (a tilted shading frame) and `mask` (opacity). Each holds the
//! material it wraps; its own BSDF is black, the nested one scattering.
//!
//! # Differentiable
//! The nested material's parameters; the normal map, the height map and the opacity are
//! not differentiable. See `docs/differentiable.md`.

use super::{Black, Bsdf};
use super::{Describe, Material, MaterialKind, MaterialModel, Shade, Texture, TextureCache, TexturePoint};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::math::Rgb;
use serde::{Deserialize, Serialize};

/// How a material tilts its shading frame.
#[derive(Clone, Copy, Debug)]
pub enum Perturbation<'a> {
    NormalMap { normals: &'a Texture },
    BumpMap { height: &'a Texture, scale: f32 },
}

/// `nested`, shaded in a frame tilted by a tangent-space normal map (Mitsuba's `normalmap`):
/// the texture's RGB in [0, 1] is the normal's xyz in [-1, 1].
#[derive(Clone, Debug)]
pub struct NormalMapMaterial {
    pub normals: Texture,
    pub nested: Box<MaterialKind>,
}

/// `nested`, shaded in a frame tilted by the gradient of `scale` times a height texture
/// (Mitsuba's `bumpmap`).
#[derive(Clone, Debug)]
pub struct BumpMapMaterial {
    pub height: Texture,
    pub scale: f32,
    pub nested: Box<MaterialKind>,
}

/// `nested` where a surface point is opaque, which it is with probability `opacity`
/// (clamped to [0, 1]); light passes straight through otherwise (Mitsuba's `mask`).
#[derive(Clone, Debug)]
pub struct MaskMaterial {
    pub opacity: Texture,
    pub nested: Box<MaterialKind>,
}

/// `normalmap`'s, `bumpmap`'s and `mask`'s description: the texture and the material it
/// wraps.
///
/// | Parameter | Type | Default | |
/// |---|---|---|---|
/// | `normals` / `height` / `opacity` | texture | (required) | a tangent-space normal map; a height field; the probability of being there |
/// | `scale` (bump map) | float | 1 | height scale |
/// | `nested` | material | (required) | the material that scatters |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NormalMapDesc {
    pub normals: TextureDesc,
    pub nested: Box<MaterialModel>,
}

/// See [`NormalMapDesc`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BumpMapDesc {
    pub height: TextureDesc,
    pub scale: f32,
    pub nested: Box<MaterialModel>,
}

/// See [`NormalMapDesc`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaskDesc {
    pub opacity: TextureDesc,
    pub nested: Box<MaterialModel>,
}

impl MaterialModel {
    /// True for a normal or bump map, also inside masks: the readers accept one per
    /// material.
    pub fn perturbs_normals(&self) -> bool {
        matches!(self, MaterialModel::NormalMap(_) | MaterialModel::BumpMap(_))
            || matches!(self, MaterialModel::Mask(m) if m.nested.perturbs_normals())
    }
}

/// A wrapper's texture and nested material, built.
fn wrap(
    t: &TextureDesc,
    nested: &MaterialModel,
    textures: &mut TextureCache,
) -> Result<(Texture, Box<MaterialKind>), Error> {
    Ok((textures.texture(t)?, Box::new(nested.build(textures)?)))
}

/// The wrapper description `$desc` of texture field `$tex`, built as `$built`, with `$check`
/// its own parameters' check beside the nested material's.
macro_rules! wrapper_describe {
    ($desc:ty, $tex:ident, $built:ident { $($extra:ident),* }, $check:expr, $slots:expr) => {
        impl Describe for $desc {
            type Built = $built;

            fn build(&self, textures: &mut TextureCache) -> Result<$built, Error> {
                let ($tex, nested) = wrap(&self.$tex, &self.nested, textures)?;
                Ok($built { $tex, $($extra: self.$extra,)* nested })
            }

            fn validate(&self) -> Result<(), String> {
                let check: fn(&$desc) -> Result<(), String> = $check;
                check(self)?;
                self.nested.validate()
            }

            fn textures(&self) -> Vec<&TextureDesc> {
                std::iter::once(&self.$tex).chain(self.nested.textures()).collect()
            }

            fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
                std::iter::once(&mut self.$tex).chain(self.nested.textures_mut()).collect()
            }

            fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
                let slots: fn(&mut $desc) -> Vec<(&'static str, Slot<'_>)> = $slots;
                slots(self)
            }
        }
    };
}

// The wrapped material's parameters, a bump map's scale and a mask's constant opacity.
wrapper_describe!(NormalMapDesc, normals, NormalMapMaterial {}, |_| Ok(()), |d| d.nested.slots());
wrapper_describe!(MaskDesc, opacity, MaskMaterial {}, |_| Ok(()), |d| {
    let mut out = Vec::new();
    texture_slot("opacity", &mut d.opacity, &mut out);
    out.extend(d.nested.slots());
    out
});
wrapper_describe!(
    BumpMapDesc,
    height,
    BumpMapMaterial { scale },
    |d| {
        if d.scale.is_finite() {
            Ok(())
        } else {
            Err(format!("bump map scale {} must be finite", d.scale))
        }
    },
    |d| {
        let mut out = vec![("bump_scale", Slot::Float(&mut d.scale))];
        out.extend(d.nested.slots());
        out
    }
);

/// The wrappers answer as black, non-transmissive surfaces: the integrators ask the nested
/// material ([`MaterialKind::base`]).
macro_rules! wrapper_shade {
    ($($ty:ty),+) => {$(
        impl Shade for $ty {
            #[inline]
            fn bsdf_at(&self, _p: &TexturePoint) -> Bsdf {
                Bsdf::Black(Black)
            }

            fn albedo(&self, _uv: [f32; 2]) -> Rgb {
                Rgb::BLACK
            }

            fn is_transmissive(&self) -> bool {
                false
            }

            fn nested(&self) -> Option<&MaterialKind> {
                Some(&self.nested)
            }
        }
    )+};
}

wrapper_shade!(NormalMapMaterial, BumpMapMaterial, MaskMaterial);

impl MaterialKind {
    /// The material inside every normal map, bump map and mask: the one that scatters.
    pub fn base(&self) -> &MaterialKind {
        let mut k = self;
        while let Some(nested) = k.nested() {
            k = nested;
        }
        k
    }

    /// The wrappers from the outside in, as (kind) references, then the base.
    fn wrappers(&self) -> impl Iterator<Item = &MaterialKind> {
        std::iter::successors(Some(self), |k| k.nested())
    }
}

impl Material {
    /// The normal or bump map of the material, if it has one (the reader accepts at most
    /// one per material).
    pub fn perturbation(&self) -> Option<Perturbation<'_>> {
        self.kind.wrappers().find_map(|k| {
            if let MaterialKind::NormalMap(NormalMapMaterial { normals, .. }) = k {
                return Some(Perturbation::NormalMap { normals });
            }
            if let MaterialKind::BumpMap(BumpMapMaterial { height, scale, .. }) = k {
                return Some(Perturbation::BumpMap { height, scale: *scale });
            }
            None
        })
    }

    /// True when the material has a mask (its surface may let light through unscattered).
    pub fn is_masked(&self) -> bool {
        self.kind.wrappers().any(|k| matches!(k, MaterialKind::Mask(_)))
    }

    /// True when rays may pass the surface unscattered: it has a mask, or its back faces
    /// are culled ([`Material::cull_back_faces`]).
    pub fn may_pass_rays(&self) -> bool {
        self.cull_back_faces || self.is_masked()
    }

    /// Probability that light meeting the surface at `p` scatters off it rather than passing
    /// straight through: the product of the masks' opacities (luminance of the texture,
    /// clamped to [0, 1] as Mitsuba does; NaN counts as opaque); 1 without a mask.
    pub fn opacity(&self, p: &TexturePoint) -> f32 {
        let mut o = 1.0f32;
        for k in self.kind.wrappers() {
            if let MaterialKind::Mask(MaskMaterial { opacity, .. }) = k {
                let v = opacity.eval_at(p).luminance();
                o *= if v.is_nan() { 1.0 } else { v.clamp(0.0, 1.0) };
            }
        }
        o
    }
}
