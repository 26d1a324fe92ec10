//! The `principled` and `blendbsdf` plugins (parameters as Mitsuba 3.9.1 reads them; see
//! docs/mitsuba-support.md).

use super::props::Props;
use super::Reader;
use crate::bsdf::principled_eta_of_specular;
use crate::describe::{BlendDesc, BlendPartDesc, MaterialModel, PrincipledDesc, TextureDesc};
use crate::error::Error;
use crate::math::Rgb;

impl<'a> Reader<'a> {
    /// A float parameter that may be a texture. Mitsuba 3.9.1's checkerboard gives `color1`
    /// where its colour lookup gives `color0` when read as a float (`eval_1` tests the
    /// opposite parity), so a checkerboard read here has its two values swapped to match.
    fn float_texture(&self, p: &Props<'a>, name: &str, default: f32) -> Result<TextureDesc, Error> {
        Ok(match self.texture(p, name, Rgb::splat(default))? {
            TextureDesc::Checkerboard { color0, color1, uv_scale, uv_offset } => {
                TextureDesc::Checkerboard { color0: color1, color1: color0, uv_scale, uv_offset }
            }
            t => t,
        })
    }

    pub(super) fn principled(&mut self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        let el = p.el;
        let d = PrincipledDesc::default();
        let tex = |name: &str, default: &TextureDesc| -> Result<TextureDesc, Error> {
            let fallback = match default {
                TextureDesc::Constant { color } => *color,
                _ => Rgb::BLACK,
            };
            if name == "base_color" {
                self.texture(p, name, fallback)
            } else {
                self.float_texture(p, name, fallback.r)
            }
        };
        let spec_trans = tex("spec_trans", &d.spec_trans)?;
        // Mitsuba treats a lobe as present when its parameter is given and not the float 0.
        let has_spec_trans = !matches!(&spec_trans, TextureDesc::Constant { color } if color.is_black());
        let eta = match (p.opt_float("eta")?, p.opt_float("specular")?) {
            (Some(_), Some(_)) => return Err(el.err("principled: give either 'eta' or 'specular', not both")),
            (Some(eta), None) => eta,
            (None, specular) => {
                let mut s = specular.unwrap_or(0.5);
                if !(0.0..=1.0).contains(&s) {
                    return Err(el.err(format!("principled: specular {s} must lie in [0, 1]")));
                }
                // Specular 0 is eta 1, which cannot refract: Mitsuba nudges it.
                if has_spec_trans && s == 0.0 {
                    s = 1e-3;
                }
                principled_eta_of_specular(s)
            }
        };
        Ok(MaterialModel::Principled(PrincipledDesc {
            base_color: tex("base_color", &d.base_color)?,
            roughness: tex("roughness", &d.roughness)?,
            anisotropic: tex("anisotropic", &d.anisotropic)?,
            metallic: tex("metallic", &d.metallic)?,
            spec_trans,
            eta,
            spec_tint: tex("spec_tint", &d.spec_tint)?,
            sheen: tex("sheen", &d.sheen)?,
            sheen_tint: tex("sheen_tint", &d.sheen_tint)?,
            flatness: tex("flatness", &d.flatness)?,
            clearcoat: tex("clearcoat", &d.clearcoat)?,
            clearcoat_gloss: tex("clearcoat_gloss", &d.clearcoat_gloss)?,
            diffuse_sampling_rate: p.float("diffuse_reflectance_sampling_rate", 1.0)?,
            specular_sampling_rate: p.float("main_specular_sampling_rate", 1.0)?,
            clearcoat_sampling_rate: p.float("clearcoat_sampling_rate", 1.0)?,
        }))
    }

    /// `blendbsdf`: exactly two nested BSDFs (nested or `<ref>`), in the order the file
    /// gives them, and a `weight` that Mitsuba requires.
    pub(super) fn blend(&mut self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        let el = p.el;
        let mut parts = Vec::new();
        for c in &el.children {
            let target = match c.tag.as_str() {
                "bsdf" => c,
                "ref" => {
                    let t = self.resolve(c)?;
                    if t.tag != "bsdf" {
                        continue;
                    }
                    t
                }
                _ => continue,
            };
            if parts.len() == 2 {
                return Err(c.err("blendbsdf: more than two nested BSDFs"));
            }
            let (model, two_sided) = self.material_model(target)?;
            parts.push(BlendPartDesc { model, two_sided });
        }
        if parts.len() != 2 {
            return Err(el.err(format!("blendbsdf needs two nested BSDFs, found {}", parts.len())));
        }
        if p.find("weight").is_none() {
            return Err(el.err("blendbsdf needs a 'weight' (a float or texture)"));
        }
        let weight = self.float_texture(p, "weight", 0.5)?;
        let second = parts.pop().map(Box::new).expect("two parts");
        let first = parts.pop().map(Box::new).expect("two parts");
        Ok(MaterialModel::Blend(BlendDesc { weight, first, second }))
    }
}
