//! The wrappers around a material's BSDF that change the surface rather than how it
//! scatters: normal and bump maps (a tilted shading frame) and masks (opacity).

use super::{Material, MaterialKind, Texture, TexturePoint};

/// How a material tilts its shading frame.
#[derive(Clone, Copy, Debug)]
pub enum Perturbation<'a> {
    NormalMap { normals: &'a Texture },
    BumpMap { height: &'a Texture, scale: f32 },
}

impl MaterialKind {
    /// The material a normal map, bump map or mask wraps; `None` for a material that
    /// scatters.
    pub fn nested(&self) -> Option<&MaterialKind> {
        match self {
            MaterialKind::NormalMap { nested, .. }
            | MaterialKind::BumpMap { nested, .. }
            | MaterialKind::Mask { nested, .. } => Some(nested),
            MaterialKind::Diffuse { .. }
            | MaterialKind::Phong { .. }
            | MaterialKind::Conductor { .. }
            | MaterialKind::RoughConductor { .. }
            | MaterialKind::Dielectric { .. }
            | MaterialKind::RoughDielectric { .. }
            | MaterialKind::ThinDielectric { .. }
            | MaterialKind::Plastic { .. }
            | MaterialKind::Black
            | MaterialKind::Null
            | MaterialKind::Principled(_)
            | MaterialKind::Blend(_)
            | MaterialKind::PPlastic { .. }
            | MaterialKind::Hair(_)
            | MaterialKind::Gltf(_) => None,
        }
    }

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
            if let MaterialKind::NormalMap { normals, .. } = k {
                return Some(Perturbation::NormalMap { normals });
            }
            if let MaterialKind::BumpMap { height, scale, .. } = k {
                return Some(Perturbation::BumpMap { height, scale: *scale });
            }
            None
        })
    }

    /// True when the material has a mask (its surface may let light through unscattered).
    pub fn is_masked(&self) -> bool {
        self.kind.wrappers().any(|k| matches!(k, MaterialKind::Mask { .. }))
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
            if let MaterialKind::Mask { opacity, .. } = k {
                let v = opacity.eval_at(p).luminance();
                o *= if v.is_nan() { 1.0 } else { v.clamp(0.0, 1.0) };
            }
        }
        o
    }
}
