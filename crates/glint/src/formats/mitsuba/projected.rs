//! Mitsuba's lights that project a texture: `spot` with a `texture`, and `projector`.

use super::props::Props;
use super::spectrum::SpectrumUse;
use super::Reader;
use crate::describe::{FovAxis, LightKind, TextureDesc};
use crate::error::Error;
use crate::math::{Rgb, Transform};

impl<'a> Reader<'a> {
    pub(super) fn textured_spot(&mut self, p: &Props<'a>, to_world: &Transform) -> Result<LightKind, Error> {
        let el = p.el;
        let texture = self.texture(p, "texture", Rgb::WHITE)?;
        if matches!(texture, TextureDesc::Constant { .. }) {
            // As Mitsuba: a constant would only scale the intensity.
            return Err(el.err("spot: 'texture' must be spatially varying (a bitmap, say)"));
        }
        let cutoff = p.float("cutoff_angle", 20.0)?;
        Ok(LightKind::TexturedSpot {
            to_world: super::matrix(to_world),
            intensity: p.rgb_as("intensity", Rgb::WHITE, SpectrumUse::Emission)?,
            cutoff_degrees: cutoff,
            beam_degrees: p.float("beam_width", cutoff * 0.75)?,
            texture,
        })
    }

    pub(super) fn projector(&mut self, p: &Props<'a>, to_world: &Transform) -> Result<LightKind, Error> {
        let el = p.el;
        let is_texture = p.find("irradiance").and_then(|e| self.resolve(e).ok()).is_some_and(|e| e.tag == "texture");
        let irradiance = if is_texture {
            self.texture(p, "irradiance", Rgb::WHITE)?
        } else {
            TextureDesc::constant(p.rgb_as("irradiance", Rgb::WHITE, SpectrumUse::Emission)?)
        };
        let (fov_degrees, fov_axis) = match (p.opt_float("fov")?, p.string("focal_length")) {
            (Some(_), Some(_)) => return Err(el.err("projector: give 'fov' or 'focal_length', not both")),
            (Some(f), None) => {
                let axis = match p.string("fov_axis") {
                    Some(a) => a.parse().map_err(|e: String| el.err(e))?,
                    None => FovAxis::X,
                };
                (f, axis)
            }
            (None, fl) => {
                let fl = fl.unwrap_or("50mm");
                let mm: f32 =
                    fl.trim_end_matches("mm").parse().map_err(|_| el.err(format!("bad focal_length '{fl}'")))?;
                // As for cameras: 35 mm film, the field of view along its diagonal.
                (2.0 * (43.266_615 / (2.0 * mm)).atan().to_degrees(), FovAxis::Diagonal)
            }
        };
        Ok(LightKind::Projector {
            to_world: super::matrix(to_world),
            irradiance,
            scale: p.float("scale", 1.0)?,
            fov_degrees,
            fov_axis,
        })
    }
}
