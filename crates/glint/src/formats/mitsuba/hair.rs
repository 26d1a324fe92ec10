//! Mitsuba's `hair` BSDF: pigment concentrations or an absorption coefficient, the two
//! roughnesses, the scale tilt and the indices of refraction, with Mitsuba's defaults and
//! checks.

use super::props::Props;
use super::spectrum::SpectrumUse;
use super::Reader;
use crate::error::Error;
use crate::materials::{HairDesc, MaterialModel};
use crate::materials::{EUMELANIN_SIGMA_A, PHEOMELANIN_SIGMA_A};
use crate::math::Rgb;

impl<'a> Reader<'a> {
    pub(super) fn hair(&self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        let longitudinal_roughness = p.float("longitudinal_roughness", 0.3)?;
        let azimuthal_roughness = p.float("azimuthal_roughness", 0.3)?;
        for (name, v) in
            [("longitudinal_roughness", longitudinal_roughness), ("azimuthal_roughness", azimuthal_roughness)]
        {
            if !(0.0..=1.0).contains(&v) {
                let at = p.find(name).unwrap_or(p.el);
                return Err(at.err(format!("hair: {name} {v} must be in [0, 1]")));
            }
        }
        let scale_tilt = p.float("scale_tilt", 2.0)?;
        let (int_ior, ext_ior) = (self.ior(p, "int_ior", 1.55)?, self.ior(p, "ext_ior", 1.000277)?);
        if !(int_ior > 0.0 && ext_ior > 0.0) || int_ior == ext_ior {
            return Err(p.el.err("hair: the interior and exterior indices of refraction must be positive and differ"));
        }
        let pigments = p.find("eumelanin").is_some() || p.find("pheomelanin").is_some();
        let eumelanin = p.float("eumelanin", 1.3)?;
        let pheomelanin = p.float("pheomelanin", 0.2)?;
        let scale = p.float("scale", 1.0)?;
        let sigma_a = match p.find("sigma_a") {
            Some(at) if pigments => {
                return Err(at.err("hair: give either sigma_a or eumelanin/pheomelanin, not both"));
            }
            Some(at) => {
                if at.tag == "texture" {
                    return Err(at.err("hair: a textured sigma_a is not supported (a colour is)"));
                }
                p.rgb_as("sigma_a", Rgb::BLACK, SpectrumUse::Unbounded)? * scale
            }
            None => EUMELANIN_SIGMA_A * eumelanin + PHEOMELANIN_SIGMA_A * pheomelanin,
        };
        Ok(MaterialModel::Hair(HairDesc {
            sigma_a,
            eta: int_ior / ext_ior,
            longitudinal_roughness,
            azimuthal_roughness,
            scale_tilt,
        }))
    }
}
