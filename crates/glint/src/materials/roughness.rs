//! Microfacet roughness as a function of surface uv: constant, or textured per axis.

use super::{Texture, TextureCache};
use crate::bsdf::{Microfacet, MicrofacetKind};
use crate::describe::{Roughness, ScalarTexture as DescScalar};
use crate::error::Error;
use crate::math::Rgb;

/// The microfacet distribution of a material at each point of its surface.
#[derive(Clone, Debug)]
pub enum RoughnessMap {
    Constant(Microfacet),
    /// `alpha_u` (along dp/du) and `alpha_v` from textures, read as their luminance as
    /// Mitsuba's `eval_1` reads a colour texture (a grey texture gives its value).
    Textured {
        kind: MicrofacetKind,
        alpha_u: Texture,
        alpha_v: Texture,
    },
}

impl RoughnessMap {
    #[inline]
    pub fn at(&self, uv: [f32; 2]) -> Microfacet {
        match self {
            RoughnessMap::Constant(m) => *m,
            RoughnessMap::Textured { kind, alpha_u, alpha_v } => {
                Microfacet::anisotropic(*kind, luminance(alpha_u.eval(uv)), luminance(alpha_v.eval(uv)))
            }
        }
    }
}

impl From<Microfacet> for RoughnessMap {
    fn from(m: Microfacet) -> RoughnessMap {
        RoughnessMap::Constant(m)
    }
}

/// Rec. 709 luminance, the weights of Mitsuba's `luminance()` (they sum to one).
fn luminance(c: Rgb) -> f32 {
    0.212671 * c.r + 0.715160 * c.g + 0.072169 * c.b
}

/// The roughness of a material: constant, or read from its textures at each hit.
pub(crate) fn roughness_map(r: &Roughness, textures: &mut TextureCache) -> Result<RoughnessMap, Error> {
    let alpha_u = &r.alpha;
    let alpha_v = r.alpha_v.as_ref().unwrap_or(alpha_u);
    Ok(match (alpha_u, alpha_v) {
        (DescScalar::Value(u), DescScalar::Value(v)) => {
            RoughnessMap::Constant(Microfacet::anisotropic(r.distribution, *u, *v))
        }
        _ => {
            let mut tex = |s: &DescScalar| -> Result<Texture, Error> {
                match s {
                    DescScalar::Value(v) => Ok(Texture::Constant(crate::math::Rgb::splat(*v))),
                    DescScalar::Texture(t) => Ok(scalar_checker_parity(textures.texture(t)?)),
                }
            };
            RoughnessMap::Textured { kind: r.distribution, alpha_u: tex(alpha_u)?, alpha_v: tex(alpha_v)? }
        }
    })
}

/// Mitsuba's checkerboard read as a number (`eval_1`, what roughness reads) puts `color1`
/// where its colour lookup (`eval`) puts `color0`, and the reverse; glint follows it, so a
/// checkerboard of roughness lands where Mitsuba puts it.
fn scalar_checker_parity(t: Texture) -> Texture {
    match t {
        Texture::Checkerboard { color0, color1, uv_scale, uv_offset } => {
            Texture::Checkerboard { color0: color1, color1: color0, uv_scale, uv_offset }
        }
        other => other,
    }
}

/// A roughness that must be one number (plastics, whose coating tables are precomputed).
pub(crate) fn constant_microfacet(r: &Roughness) -> Result<Microfacet, Error> {
    match (&r.alpha, &r.alpha_v) {
        (DescScalar::Value(a), None) => Ok(Microfacet::new(r.distribution, *a)),
        (DescScalar::Value(a), Some(DescScalar::Value(b))) if a == b => Ok(Microfacet::new(r.distribution, *a)),
        _ => Err(Error::new("this material's roughness must be one number (isotropic, untextured), as in Mitsuba")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textured_roughness_reads_each_axis_at_the_point() {
        let checker = |a: f32, b: f32| Texture::Checkerboard {
            color0: Rgb::splat(a),
            color1: Rgb::splat(b),
            uv_scale: [1.0; 2],
            uv_offset: [0.0; 2],
        };
        let map = RoughnessMap::Textured {
            kind: MicrofacetKind::Ggx,
            alpha_u: checker(0.1, 0.3),
            alpha_v: checker(0.3, 0.1),
        };
        let m = map.at([0.25, 0.25]);
        assert!((m.alpha_u - 0.1).abs() < 1e-6 && (m.alpha_v - 0.3).abs() < 1e-6, "{m:?}");
        let m = map.at([0.75, 0.25]);
        assert!((m.alpha_u - 0.3).abs() < 1e-6 && (m.alpha_v - 0.1).abs() < 1e-6, "{m:?}");
        // A zero roughness is clamped, as Mitsuba clamps it, rather than made a delta.
        let zero = RoughnessMap::Textured {
            kind: MicrofacetKind::Beckmann,
            alpha_u: Texture::Constant(Rgb::BLACK),
            alpha_v: Texture::Constant(Rgb::BLACK),
        };
        assert_eq!(zero.at([0.5, 0.5]).alpha_u, 1e-4);
    }
}
