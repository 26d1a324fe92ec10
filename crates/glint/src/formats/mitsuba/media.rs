//! Mitsuba's participating media: `<medium type="homogeneous">` with its `<phase>`
//! (`isotropic`, `hg`), attached to shapes as `interior`/`exterior` (nested or by
//! `<ref name=... id=...>`) and to the sensor. The albedo may be a `gridvolume` (a `.vol`
//! file, looked up at each scattering point) and any coefficient a `constvolume`;
//! `heterogeneous` media take a grey `gridvolume` `sigma_t` too. Grid extinction in a
//! homogeneous medium and other phase functions are errors that name the file and line.

use super::props::{color_of, Props};
use super::spectrum::SpectrumUse;
use super::xml::Element;
use super::Reader;
use crate::describe::{GridFilter, GridVolumeDesc, GridWrap, MediumDesc, PhaseDesc, ShapeMedia, VolumeDesc};
use crate::error::Error;
use crate::math::Rgb;

impl<'a> Reader<'a> {
    /// Whether `el` is a `<medium>` or a `<ref>` to one.
    pub(super) fn is_medium(&self, el: &'a Element) -> bool {
        el.tag == "medium" || (el.tag == "ref" && self.resolve(el).is_ok_and(|t| t.tag == "medium"))
    }

    /// Describes (once) the medium `el` defines or refers to; its index in the media.
    pub(super) fn medium(&mut self, el: &'a Element) -> Result<usize, Error> {
        let el = self.resolve(el)?;
        if let Some(&i) = self.medium_index.get(&(el as *const Element)) {
            return Ok(i);
        }
        let desc = self.medium_desc(el)?;
        let i = self.media.len();
        self.media.push(desc);
        self.medium_index.insert(el as *const Element, i);
        Ok(i)
    }

    /// A shape's medium child `c` (nested or a `<ref>`), on the side its `name` says.
    pub(super) fn shape_medium(&mut self, c: &'a Element, media: &mut ShapeMedia) -> Result<(), Error> {
        let side = match c.attr("name") {
            Some("interior") => &mut media.interior,
            Some("exterior") => &mut media.exterior,
            Some(other) => {
                return Err(c.err(format!("a shape's medium is named 'interior' or 'exterior', not '{other}'")))
            }
            None => return Err(c.err("a shape's medium needs name=\"interior\" or name=\"exterior\"")),
        };
        if side.is_some() {
            return Err(c.err(format!("the shape has two {} media", c.attr("name").unwrap_or(""))));
        }
        *side = Some(self.medium(c)?);
        Ok(())
    }

    /// The sensor's medium (nested or a `<ref>`), if it names one; two are an error.
    pub(super) fn sensor_medium(&mut self, sensor: &'a Element) -> Result<Option<usize>, Error> {
        let mut found = None;
        for c in &sensor.children {
            if self.is_medium(c) {
                if found.is_some() {
                    return Err(c.err("only one medium can be given per sensor"));
                }
                found = Some(self.medium(c)?);
            }
        }
        Ok(found)
    }

    fn medium_desc(&mut self, el: &'a Element) -> Result<MediumDesc, Error> {
        let ty = el.attr("type").unwrap_or("");
        if !matches!(ty, "homogeneous" | "heterogeneous") {
            return Err(el.err(format!("medium plugin '{ty}' is not supported (homogeneous, heterogeneous)")));
        }
        let heterogeneous = ty == "heterogeneous";
        let p = Props::new(el);
        // Volumes: a constant anywhere, a grid only for the albedo (the extinction of a
        // homogeneous medium is constant).
        for name in ["sigma_t", "sigma_a", "sigma_s"] {
            if let Some(e) = p.find(name) {
                let grid_extinction = heterogeneous && name == "sigma_t" && e.attr("type") == Some("gridvolume");
                if e.tag == "volume" && e.attr("type") != Some("constvolume") && !grid_extinction {
                    return Err(e.err(format!(
                        "homogeneous: '{name}' given as a <volume type=\"{}\"> is not supported (a homogeneous medium's \
                         extinction is constant: give a <float>, <rgb>, <spectrum> or a constvolume; a heterogeneous \
                         medium's sigma_t may be a gridvolume)",
                        e.attr("type").unwrap_or("")
                    )));
                }
            }
        }
        let coefficient = |name: &str, default: f32| -> Result<Rgb, Error> {
            match p.find(name) {
                None => Ok(Rgb::splat(default)),
                Some(e) => {
                    let e = self.resolve(e)?;
                    if e.tag == "volume" {
                        return self.const_volume(e);
                    }
                    let v = color_of(e, SpectrumUse::Reflectance)?;
                    // Mitsuba reads these as reflectance-like textures, which reject RGB
                    // values outside [0, 1] (its documentation: use `scale` for more).
                    if e.tag == "rgb" && !v.to_array().iter().all(|x| (0.0..=1.0).contains(x)) {
                        return Err(e.err(format!(
                            "homogeneous: an <rgb> '{name}' must lie in [0, 1], as in Mitsuba (use 'scale' for denser media)"
                        )));
                    }
                    Ok(v)
                }
            }
        };
        let split = p.find("sigma_a").is_some() || p.find("sigma_s").is_some();
        let (sigma_t, albedo) = if split {
            // Mitsuba 0.6's parametrisation, which glint also reads.
            if p.find("sigma_t").is_some() || p.find("albedo").is_some() {
                return Err(el.err("homogeneous: give either sigma_t and albedo or sigma_a and sigma_s, not both"));
            }
            let (a, s) = (coefficient("sigma_a", 0.0)?, coefficient("sigma_s", 0.0)?);
            let t = a + s;
            let albedo = Rgb { r: ratio(s.r, t.r), g: ratio(s.g, t.g), b: ratio(s.b, t.b) };
            (t, VolumeDesc::Constant(albedo))
        } else {
            let albedo = match p.find("albedo") {
                Some(e) if e.tag == "volume" && e.attr("type") == Some("gridvolume") => {
                    VolumeDesc::Grid(self.grid_volume(e)?)
                }
                _ => VolumeDesc::Constant(coefficient("albedo", 0.75)?),
            };
            let sigma_t = match p.find("sigma_t") {
                Some(e) if e.tag == "volume" && e.attr("type") == Some("gridvolume") => Rgb::WHITE,
                _ => coefficient("sigma_t", 1.0)?,
            };
            (sigma_t, albedo)
        };
        let density = match p.find("sigma_t") {
            Some(e) if e.tag == "volume" && e.attr("type") == Some("gridvolume") => Some(self.grid_volume(e)?),
            _ => None,
        };
        let scale = p.float("scale", 1.0)?;
        let spectral = p.bool("has_spectral_extinction", true)?;
        if !spectral && (sigma_t.r != sigma_t.g || sigma_t.g != sigma_t.b) {
            self.warnings.push(
                el.err(
                    "homogeneous: has_spectral_extinction=false with a sigma_t that varies by channel: glint renders the \
                     varying extinction exactly, where Mitsuba would sample one channel's distance without correcting \
                     for the others",
                )
                .to_string(),
            );
        }
        let sample_emitters = p.bool("sample_emitters", true)?;
        let mut phase = PhaseDesc::Isotropic;
        let mut phases = 0;
        for c in &el.children {
            let target = if c.tag == "ref" { self.resolve(c)? } else { c };
            if target.tag == "phase" {
                phases += 1;
                if phases > 1 {
                    return Err(c.err("only a single phase function can be specified per medium"));
                }
                phase = self.phase(target)?;
            } else if target.tag == "volume" && c.attr("name").is_none() {
                return Err(c.err("homogeneous: a <volume> needs a name (sigma_t or albedo)"));
            }
        }
        self.warn_unused(&p);
        let name = el.attr("id").map_or_else(|| format!("medium@{}:{}", el.file.display(), el.line), str::to_string);
        Ok(MediumDesc {
            name,
            sigma_t,
            albedo,
            scale,
            phase,
            sample_emitters,
            density,
            absorbing_only: false,
            loc: el.loc(),
        })
    }

    /// A `constvolume`'s value (its `value`, a colour; 1 by default).
    fn const_volume(&self, el: &'a Element) -> Result<Rgb, Error> {
        match el.attr("type").unwrap_or("") {
            "constvolume" => {}
            other => {
                return Err(el.err(format!(
                    "volume plugin '{other}' is not supported here (constvolume; gridvolume for an albedo)"
                )));
            }
        }
        let mut value = Rgb::WHITE;
        for c in &el.children {
            match (c.attr("name"), c.tag.as_str()) {
                (Some("value"), "float" | "rgb" | "spectrum") => value = color_of(c, SpectrumUse::Reflectance)?,
                (Some("value"), tag) => {
                    return Err(
                        c.err(format!("constvolume: 'value' should be a <float>, <rgb> or <spectrum>, found <{tag}>"))
                    )
                }
                // Mitsuba's constvolume accepts a to_world, which a constant ignores.
                (Some("to_world"), "transform") => {}
                (name, _) => {
                    return Err(c.err(format!(
                        "constvolume: parameter '{}' is not supported (value, to_world)",
                        name.unwrap_or(&c.tag)
                    )))
                }
            }
        }
        Ok(value)
    }

    /// A `gridvolume`: its file, filter, wrap mode and placement (an albedo, or a
    /// heterogeneous medium's density).
    fn grid_volume(&self, el: &'a Element) -> Result<GridVolumeDesc, Error> {
        let p = Props::new(el);
        let file = p.string("filename").ok_or_else(|| el.err("gridvolume needs 'filename' (a .vol file)"))?;
        let filter = match p.string("filter_type").unwrap_or("trilinear") {
            "trilinear" => GridFilter::Trilinear,
            "nearest" => GridFilter::Nearest,
            other => {
                let e = p.find("filter_type").unwrap_or(el);
                return Err(e.err(format!("gridvolume: filter_type '{other}' is not one of trilinear, nearest")));
            }
        };
        let wrap = match p.string("wrap_mode").unwrap_or("clamp") {
            "clamp" => GridWrap::Clamp,
            "repeat" => GridWrap::Repeat,
            "mirror" => GridWrap::Mirror,
            other => {
                let e = p.find("wrap_mode").unwrap_or(el);
                return Err(e.err(format!("gridvolume: wrap_mode '{other}' is not one of clamp, repeat, mirror")));
            }
        };
        let to_world = p.transform("to_world")?;
        // `raw` only changes spectral variants (no spectral upsampling); `accel` and
        // `max_value` change nothing an albedo lookup sees.
        let _ = p.bool("raw", false)?;
        let _ = p.bool("accel", true)?;
        let _ = p.float("max_value", 0.0)?;
        if p.bool("use_grid_bbox", false)? {
            let e = p.find("use_grid_bbox").unwrap_or(el);
            return Err(e.err("gridvolume: use_grid_bbox=true is not supported (place the grid with to_world)"));
        }
        for c in &el.children {
            if let Some(name) = c.attr("name") {
                if !matches!(
                    name,
                    "filename"
                        | "filter_type"
                        | "wrap_mode"
                        | "to_world"
                        | "raw"
                        | "accel"
                        | "max_value"
                        | "use_grid_bbox"
                ) {
                    return Err(c.err(format!(
                        "gridvolume: parameter '{name}' is not supported (filename, filter_type, wrap_mode, to_world, raw)"
                    )));
                }
            }
        }
        Ok(GridVolumeDesc { file: self.resolve_file(el, file), filter, wrap, to_world: to_world.m.0, loc: el.loc() })
    }

    fn phase(&mut self, el: &'a Element) -> Result<PhaseDesc, Error> {
        let p = Props::new(el);
        let phase = match el.attr("type").unwrap_or("") {
            "isotropic" => PhaseDesc::Isotropic,
            "hg" => {
                let g = p.float("g", 0.8)?;
                if !(g > -1.0 && g < 1.0) {
                    return Err(el.err(format!("hg: the asymmetry parameter g {g} must lie in (-1, 1)")));
                }
                PhaseDesc::Hg { g }
            }
            other => return Err(el.err(format!("phase function '{other}' is not supported (isotropic, hg)"))),
        };
        self.warn_unused(&p);
        Ok(phase)
    }
}

/// s / t, 0 where t is 0 (a channel with no extinction scatters nothing).
fn ratio(s: f32, t: f32) -> f32 {
    if t > 0.0 {
        (s / t).clamp(0.0, 1.0)
    } else {
        0.0
    }
}
