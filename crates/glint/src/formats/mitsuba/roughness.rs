//! Microfacet parameters of Mitsuba's rough BSDFs: `distribution`, `alpha` or the pair
//! `alpha_u`/`alpha_v` (numbers or textures where Mitsuba takes a texture), and
//! `sample_visible`.

use super::props::Props;
use super::Reader;
use crate::describe::{MicrofacetKind, Roughness, ScalarTexture, TextureDesc};
use crate::error::Error;
use crate::math::Rgb;

/// Whether a BSDF takes its roughness as textures (`roughconductor`, `roughdielectric`) or
/// as one number (`roughplastic`, whose coating is tabulated at load, as in Mitsuba).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum RoughnessInput {
    Textured,
    IsotropicNumber,
}

impl<'a> Reader<'a> {
    pub(super) fn roughness(&self, p: &Props<'a>, input: RoughnessInput) -> Result<Roughness, Error> {
        let ty = p.el.attr("type").unwrap_or("");
        let distribution = match p.string("distribution").unwrap_or("beckmann") {
            "beckmann" => MicrofacetKind::Beckmann,
            "ggx" => MicrofacetKind::Ggx,
            other => return Err(p.el.err(format!("unknown microfacet distribution '{other}'"))),
        };
        // Visible-normal sampling is always used; `false` changes only the noise in Mitsuba.
        let _ = p.bool("sample_visible", true)?;
        let (has_u, has_v, has_alpha) = (p.find("alpha_u"), p.find("alpha_v"), p.find("alpha"));
        let (alpha, alpha_v) = match (has_u.is_some() || has_v.is_some(), has_alpha.is_some()) {
            (true, true) => {
                return Err(p.el.err(format!("{ty}: give either 'alpha' or 'alpha_u'/'alpha_v', not both")))
            }
            (true, false) => {
                if has_u.is_none() || has_v.is_none() {
                    return Err(p.el.err(format!("{ty}: both 'alpha_u' and 'alpha_v' must be given")));
                }
                (self.scalar(p, "alpha_u", input)?, Some(self.scalar(p, "alpha_v", input)?))
            }
            (false, _) => (self.scalar(p, "alpha", input)?, None),
        };
        if input == RoughnessInput::IsotropicNumber {
            if let (ScalarTexture::Value(u), Some(ScalarTexture::Value(v))) = (&alpha, &alpha_v) {
                if u != v {
                    return Err(p.el.err(format!(
                        "{ty}: anisotropic roughness (alpha_u != alpha_v) is not supported by Mitsuba's {ty}"
                    )));
                }
                return Ok(Roughness::isotropic(distribution, *u));
            }
        }
        Ok(Roughness { distribution, alpha, alpha_v })
    }

    /// One roughness value: a number, or (where Mitsuba takes one) a texture or a colour.
    fn scalar(&self, p: &Props<'a>, name: &str, input: RoughnessInput) -> Result<ScalarTexture, Error> {
        let ty = p.el.attr("type").unwrap_or("");
        let Some(e) = p.find(name) else { return Ok(ScalarTexture::Value(0.1)) };
        let e = self.resolve(e)?;
        if matches!(e.tag.as_str(), "float" | "integer") {
            return Ok(ScalarTexture::Value(p.float(name, 0.1)?));
        }
        if input == RoughnessInput::IsotropicNumber {
            return Err(e.err(format!("{ty}: '{name}' must be a <float> (Mitsuba's {ty} takes no texture there)")));
        }
        Ok(match self.texture(p, name, Rgb::splat(0.1))? {
            TextureDesc::Constant { color } if color.r == color.g && color.g == color.b => {
                ScalarTexture::Value(color.r)
            }
            t => ScalarTexture::Texture(t),
        })
    }
}
