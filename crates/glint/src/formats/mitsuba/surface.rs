//! The BSDF wrappers that change the surface, not the scattering: `normalmap`, `bumpmap`,
//! `mask`; and the `mesh_attribute` texture.

use super::props::Props;
use super::xml::Element;
use super::Reader;
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::materials::MaterialModel;
use crate::materials::{BumpMapDesc, MaskDesc, NormalMapDesc};
use crate::math::Rgb;

impl<'a> Reader<'a> {
    /// The one nested BSDF of a wrapper (`<bsdf>` or `<ref>` to one), described; with
    /// whether it (or a `twosided` inside it) is two-sided.
    fn nested_bsdf(&mut self, el: &'a Element, ty: &str) -> Result<(MaterialModel, bool), Error> {
        let mut inner = Vec::new();
        for c in el.children.iter().filter(|c| c.tag == "bsdf" || c.tag == "ref") {
            let c = self.resolve(c)?;
            if c.tag == "bsdf" {
                inner.push(c);
            }
        }
        let [inner] = inner[..] else {
            return Err(el.err(format!("{ty}: give exactly one nested <bsdf> (found {})", inner.len())));
        };
        self.material_model(inner)
    }

    /// `normalmap`, `bumpmap` and `mask`: the model and whether it is two-sided.
    pub(super) fn surface_material(&mut self, el: &'a Element, ty: &str) -> Result<(MaterialModel, bool), Error> {
        let p = Props::new(el);
        let (nested, two_sided) = self.nested_bsdf(el, ty)?;
        if ty != "mask" && nested.perturbs_normals() {
            return Err(el.err(format!("{ty}: a normal or bump map inside another one is not supported")));
        }
        if ty != "mask" {
            for flag in ["flip_invalid_normals", "use_shadowing_function"] {
                if !p.bool(flag, true)? {
                    return Err(el.err(format!("{ty}: {flag}=false is not supported")));
                }
            }
        }
        let nested = Box::new(nested);
        let model = match ty {
            "normalmap" => {
                if p.find("normalmap").is_none() {
                    return Err(el.err("normalmap: needs a texture named 'normalmap'"));
                }
                MaterialModel::NormalMap(NormalMapDesc {
                    normals: self.texture(&p, "normalmap", Rgb::splat(0.5))?,
                    nested,
                })
            }
            "bumpmap" => {
                let textures: Vec<&Element> = el
                    .children
                    .iter()
                    .filter(|c| {
                        c.tag == "texture" || (c.tag == "ref" && self.resolve(c).is_ok_and(|t| t.tag == "texture"))
                    })
                    .collect();
                let [t] = textures[..] else {
                    return Err(
                        el.err(format!("bumpmap: give exactly one height <texture> (found {})", textures.len()))
                    );
                };
                let height = self.texture_element(t)?;
                if !matches!(height, TextureDesc::Bitmap { .. }) {
                    return Err(
                        t.err("bumpmap: the height texture must be a bitmap (Mitsuba differentiates only those)")
                    );
                }
                if let Some(name) = t.attr("name") {
                    p.find(name);
                }
                MaterialModel::BumpMap(BumpMapDesc { height, scale: p.float("scale", 1.0)?, nested })
            }
            _ => MaterialModel::Mask(MaskDesc { opacity: self.texture(&p, "opacity", Rgb::splat(0.5))?, nested }),
        };
        self.warn_unused(&p);
        Ok((model, two_sided))
    }

    /// `<texture type="mesh_attribute">`: `name` (`vertex_...` or `face_...`), `scale`.
    pub(super) fn mesh_attribute(&self, e: &'a Element, tp: &Props<'a>) -> Result<TextureDesc, Error> {
        let name = tp.string("name").ok_or_else(|| e.err("mesh_attribute texture needs 'name'"))?;
        if !(name.starts_with("vertex_") || name.starts_with("face_")) {
            return Err(e.err(format!("mesh_attribute: name '{name}' must start with 'vertex_' or 'face_'")));
        }
        Ok(TextureDesc::MeshAttribute { name: name.to_string(), scale: tp.float("scale", 1.0)?, loc: e.loc() })
    }
}
