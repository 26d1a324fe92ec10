//! BSDFs of Mitsuba's polarized family, read as its unpolarized (RGB) variants render
//! them: `pplastic` is a rough plastic without the internal-scattering series, and
//! `polarizer` a pass-through that halves the light (what an ideal linear polarizer does
//! to unpolarized light), its angle `theta` having no effect there.

use super::props::Props;
use super::roughness::RoughnessInput;
use super::Reader;
use crate::error::Error;
use crate::materials::MaterialModel;
use crate::materials::{DielectricDesc, PPlasticDesc};
use crate::math::Rgb;

impl<'a> Reader<'a> {
    pub(super) fn pplastic(&self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        let diffuse = self.texture(p, "diffuse_reflectance", Rgb::splat(0.5))?;
        let specular = p.rgb("specular_reflectance", Rgb::WHITE)?;
        let eta = if p.find("eta").is_some() {
            if p.find("int_ior").is_some() || p.find("ext_ior").is_some() {
                return Err(p.el.err("pplastic: give either eta or int_ior/ext_ior, not both"));
            }
            p.float("eta", 1.49)?
        } else {
            let (int_ior, ext_ior) = (self.ior(p, "int_ior", 1.49)?, self.ior(p, "ext_ior", 1.000277)?);
            if int_ior == ext_ior {
                return Err(p.el.err("pplastic: the interior and exterior indices of refraction must differ"));
            }
            int_ior / ext_ior
        };
        let roughness = self.roughness(p, RoughnessInput::Textured)?;
        Ok(MaterialModel::PPlastic(PPlasticDesc { diffuse, specular, eta, roughness }))
    }

    /// A polarizer: transmits half of `transmittance` straight through, from either side,
    /// and reflects nothing (an index-matched thin sheet).
    pub(super) fn polarizer(&self, p: &Props<'a>) -> Result<MaterialModel, Error> {
        // The angle and the switch matter only to polarized light, which RGB variants do
        // not carry; they are read so that they are not reported as unknown.
        let _ = p.find("theta");
        let _ = p.bool("polarizing", true)?;
        let transmittance = p.rgb("transmittance", Rgb::WHITE)?;
        Ok(MaterialModel::Dielectric(DielectricDesc {
            eta: 1.0,
            reflect: Rgb::BLACK,
            transmit: transmittance * 0.5,
            roughness: None,
            thin: true,
        }))
    }
}
