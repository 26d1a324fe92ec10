//! The `<bsdf>` plugins, one function each (parameters as Mitsuba 3.9.1 reads them; see
//! docs/mitsuba-support.md). The wrappers that change the surface rather than the
//! scattering (`normalmap`, `bumpmap`, `mask`) are in `surface`, the polarized family in
//! `polarized`. Adding a plugin is one function here and one line in `material_model`.

use super::props::Props;
use super::roughness::RoughnessInput;
use super::spectrum::SpectrumUse;
use super::xml::Element;
use super::{named_ior, props, Reader};
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::materials::conductor_preset;
use crate::materials::{
    principled_eta_of_specular, BlendDesc, BlendPartDesc, MaterialDesc, MaterialModel, PrincipledDesc,
    PrincipledThinDesc,
};
use crate::materials::{ConductorDesc, DielectricDesc, DiffuseDesc, NullDesc, PlasticDesc};
use crate::math::Rgb;

impl<'a> Reader<'a> {
    /// Describes (once) the material of a `<bsdf>` element; its index in the materials.
    pub(super) fn material(&mut self, el: &'a Element) -> Result<usize, Error> {
        let el = self.resolve(el)?;
        if let Some(&i) = self.material_index.get(&(el as *const Element)) {
            return Ok(i);
        }
        if el.tag != "bsdf" {
            return Err(el.err(format!("expected a <bsdf>, found <{}>", el.tag)));
        }
        let (model, two_sided) = self.material_model(el)?;
        let name = el.attr("id").map_or_else(|| format!("bsdf@{}:{}", el.file.display(), el.line), str::to_string);
        let i = self.materials.len();
        self.materials.push(MaterialDesc { name, model, two_sided, loc: el.loc() });
        self.material_index.insert(el as *const Element, i);
        Ok(i)
    }

    /// The material a `<bsdf>` describes, and whether it is two-sided.
    pub(super) fn material_model(&mut self, el: &'a Element) -> Result<(MaterialModel, bool), Error> {
        let ty = el.attr("type").unwrap_or("");
        let p = Props::new(el);
        let model = match ty {
            "twosided" => return Ok((self.twosided(el)?, true)),
            "normalmap" | "bumpmap" | "mask" => return self.surface_material(el, ty),
            "diffuse" => self.diffuse(&p)?,
            "conductor" => self.conductor(&p, false)?,
            "roughconductor" => self.conductor(&p, true)?,
            "dielectric" => self.dielectric(&p, DielectricForm::Smooth)?,
            "roughdielectric" => self.dielectric(&p, DielectricForm::Rough)?,
            "thindielectric" => self.dielectric(&p, DielectricForm::Thin)?,
            "plastic" => self.plastic(&p, false)?,
            "roughplastic" => self.plastic(&p, true)?,
            // Passes light through unchanged: the boundary of a medium (see the volpath integrator).
            "null" => MaterialModel::Null(NullDesc {}),
            "principled" => self.principled(&p)?,
            // Two-sided by itself: both faces are the same sheet.
            "principledthin" => return Ok((self.principled_thin(&p)?, true)),
            "blendbsdf" => self.blend(&p)?,
            "pplastic" => self.pplastic(&p)?,
            "hair" => self.hair(&p)?,
            "polarizer" => self.polarizer(&p)?,
            other => return Err(el.err(format!("bsdf plugin '{other}' is not supported"))),
        };
        self.warn_unused(&p);
        Ok((model, false))
    }

    /// `twosided`: the one nested BSDF, on both faces.
    fn twosided(&mut self, el: &'a Element) -> Result<MaterialModel, Error> {
        let inner: Vec<&Element> = el.children.iter().filter(|c| c.tag == "bsdf" || c.tag == "ref").collect();
        if inner.len() != 1 {
            return Err(el.err("twosided: give exactly one nested <bsdf> (different BSDFs per side are not supported)"));
        }
        let inner = self.resolve(inner[0])?;
        let (m, _) = self.material_model(inner)?;
        Ok(m)
    }

    fn diffuse(&self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        Ok(MaterialModel::Diffuse(DiffuseDesc { reflectance: self.texture(p, "reflectance", Rgb::splat(0.5))? }))
    }

    /// `conductor` and (`rough`) `roughconductor`.
    fn conductor(&self, p: &Props<'a>, rough: bool) -> Result<MaterialModel, Error> {
        let roughness = if rough { Some(self.roughness(p, RoughnessInput::Textured)?) } else { None };
        let (eta, k) = self.conductor_ior(p)?;
        Ok(MaterialModel::Conductor(ConductorDesc {
            eta,
            k,
            specular: p.rgb("specular_reflectance", Rgb::WHITE)?,
            roughness,
        }))
    }

    /// `dielectric`, `roughdielectric` and `thindielectric`.
    fn dielectric(&self, p: &Props<'a>, form: DielectricForm) -> Result<MaterialModel, Error> {
        let eta = self.ior(p, "int_ior", 1.5046)? / self.ior(p, "ext_ior", 1.000277)?;
        let reflect = p.rgb("specular_reflectance", Rgb::WHITE)?;
        let transmit = p.rgb("specular_transmittance", Rgb::WHITE)?;
        let roughness = match form {
            DielectricForm::Rough => Some(self.roughness(p, RoughnessInput::Textured)?),
            DielectricForm::Smooth | DielectricForm::Thin => None,
        };
        Ok(MaterialModel::Dielectric(DielectricDesc {
            eta,
            reflect,
            transmit,
            roughness,
            thin: form == DielectricForm::Thin,
        }))
    }

    /// `plastic` and (`rough`) `roughplastic`.
    fn plastic(&self, p: &Props<'a>, rough: bool) -> Result<MaterialModel, Error> {
        let eta = self.ior(p, "int_ior", 1.49)? / self.ior(p, "ext_ior", 1.000277)?;
        let diffuse = self.texture(p, "diffuse_reflectance", Rgb::splat(0.5))?;
        let specular = p.rgb("specular_reflectance", Rgb::WHITE)?;
        let nonlinear = p.bool("nonlinear", false)?;
        let roughness = if rough { Some(self.roughness(p, RoughnessInput::IsotropicNumber)?) } else { None };
        Ok(MaterialModel::Plastic(PlasticDesc { diffuse, specular, eta, roughness, nonlinear }))
    }

    pub(super) fn ior(&self, p: &Props, name: &str, default: f32) -> Result<f32, Error> {
        match p.find(name) {
            None => Ok(default),
            Some(e) if e.tag == "string" => {
                let v = e.required("value")?;
                named_ior(v).ok_or_else(|| e.err(format!("unknown index of refraction '{v}'")))
            }
            Some(e) => props::parse_float(e, e.required("value")?),
        }
    }

    fn conductor_ior(&self, p: &Props) -> Result<(Rgb, Rgb), Error> {
        let (eta_el, k_el) = (p.find("eta"), p.find("k"));
        if eta_el.is_some() || k_el.is_some() {
            return Ok((
                p.rgb_as("eta", Rgb::BLACK, SpectrumUse::Unbounded)?,
                p.rgb_as("k", Rgb::WHITE, SpectrumUse::Unbounded)?,
            ));
        }
        let name = p.string("material").unwrap_or("none");
        conductor_preset(name)
            .ok_or_else(|| p.el.err(format!("conductor material '{name}' is not one of Mitsuba's conductor presets (Au, Ag, Cu, Al, Cr, ...: see docs/mitsuba-support.md)")))
    }

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

    /// A parameter of `principled` or `principledthin`: `base_color` a colour texture, the
    /// others float textures, each defaulting to the constant `default` gives.
    fn principled_texture(&self, p: &Props<'a>, name: &str, default: &TextureDesc) -> Result<TextureDesc, Error> {
        let fallback = match default {
            TextureDesc::Constant { color } => *color,
            _ => Rgb::BLACK,
        };
        if name == "base_color" {
            self.texture(p, name, fallback)
        } else {
            self.float_texture(p, name, fallback.r)
        }
    }

    fn principled(&mut self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        let el = p.el;
        let d = PrincipledDesc::default();
        let tex = |name: &str, default: &TextureDesc| self.principled_texture(p, name, default);
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

    /// `principledthin`: every parameter but the sampling rates a texture or a value (`eta`
    /// too, unbounded), with Mitsuba's defaults.
    fn principled_thin(&mut self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        let d = PrincipledThinDesc::default();
        let tex = |name: &str, default: &TextureDesc| self.principled_texture(p, name, default);
        let model = MaterialModel::PrincipledThin(PrincipledThinDesc {
            base_color: tex("base_color", &d.base_color)?,
            roughness: tex("roughness", &d.roughness)?,
            anisotropic: tex("anisotropic", &d.anisotropic)?,
            spec_trans: tex("spec_trans", &d.spec_trans)?,
            eta: tex("eta", &d.eta)?,
            spec_tint: tex("spec_tint", &d.spec_tint)?,
            sheen: tex("sheen", &d.sheen)?,
            sheen_tint: tex("sheen_tint", &d.sheen_tint)?,
            flatness: tex("flatness", &d.flatness)?,
            diff_trans: tex("diff_trans", &d.diff_trans)?,
            diffuse_reflectance_sampling_rate: p.float("diffuse_reflectance_sampling_rate", 1.0)?,
            diffuse_transmittance_sampling_rate: p.float("diffuse_transmittance_sampling_rate", 1.0)?,
            specular_reflectance_sampling_rate: p.float("specular_reflectance_sampling_rate", 1.0)?,
            specular_transmittance_sampling_rate: p.float("specular_transmittance_sampling_rate", 1.0)?,
        });
        self.warn_unused(p);
        Ok(model)
    }

    /// `blendbsdf`: exactly two nested BSDFs (nested or `<ref>`), in the order the file
    /// gives them, and a `weight` that Mitsuba requires.
    fn blend(&mut self, p: &Props<'a>) -> Result<MaterialModel, Error> {
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

/// The three dielectric plugins.
#[derive(Clone, Copy, PartialEq, Eq)]
enum DielectricForm {
    Smooth,
    Rough,
    Thin,
}
