//! Reading typed parameters from a plugin element: `<float>`, `<integer>`, `<boolean>`,
//! `<string>`, `<rgb>`, `<spectrum>`, `<point>`, `<vector>`, `<transform>`, and textures.
//! Every read marks the parameter as used, so that misspelt or unsupported parameters can
//! be reported instead of silently ignored.

use super::spectrum::{self, SpectrumUse};
use super::xml::Element;
use crate::error::Error;
use crate::math::{Mat4, Rgb, Transform, Vec3};
use std::cell::RefCell;
use std::collections::HashSet;

pub struct Props<'a> {
    pub el: &'a Element,
    used: RefCell<HashSet<String>>,
}

pub fn parse_floats(el: &Element, s: &str) -> Result<Vec<f32>, Error> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f32>().map_err(|_| el.err(format!("'{t}' is not a number"))))
        .collect()
}

pub fn parse_float(el: &Element, s: &str) -> Result<f32, Error> {
    s.trim().parse::<f32>().map_err(|_| el.err(format!("'{s}' is not a number")))
}

fn parse_vec3(el: &Element) -> Result<Vec3, Error> {
    if let Some(v) = el.attr("value") {
        let f = parse_floats(el, v)?;
        return match f.len() {
            1 => Ok(Vec3::splat(f[0])),
            3 => Ok(Vec3 { x: f[0], y: f[1], z: f[2] }),
            _ => Err(el.err(format!("'{v}' is not a 3-vector"))),
        };
    }
    let get = |k: &str| el.attr(k).map_or(Ok(0.0), |s| parse_float(el, s));
    Ok(Vec3 { x: get("x")?, y: get("y")?, z: get("z")? })
}

impl<'a> Props<'a> {
    pub fn new(el: &'a Element) -> Props<'a> {
        Props { el, used: RefCell::new(HashSet::new()) }
    }

    /// The child element that defines parameter `name`.
    pub fn find(&self, name: &str) -> Option<&'a Element> {
        let found = self.el.children.iter().find(|c| c.attr("name") == Some(name));
        if found.is_some() {
            self.used.borrow_mut().insert(name.to_string());
        }
        found
    }

    pub fn float(&self, name: &str, default: f32) -> Result<f32, Error> {
        match self.find(name) {
            None => Ok(default),
            Some(e) if matches!(e.tag.as_str(), "float" | "integer") => parse_float(e, e.required("value")?),
            Some(e) => Err(e.err(format!("'{name}' should be a <float>, found <{}>", e.tag))),
        }
    }

    pub fn opt_float(&self, name: &str) -> Result<Option<f32>, Error> {
        Ok(if self.find(name).is_some() { Some(self.float(name, 0.0)?) } else { None })
    }

    pub fn int(&self, name: &str, default: i64) -> Result<i64, Error> {
        match self.find(name) {
            None => Ok(default),
            Some(e) => {
                let v = e.required("value")?;
                v.trim().parse::<i64>().map_err(|_| e.err(format!("'{v}' is not an integer")))
            }
        }
    }

    pub fn bool(&self, name: &str, default: bool) -> Result<bool, Error> {
        match self.find(name) {
            None => Ok(default),
            Some(e) => match e.required("value")? {
                "true" => Ok(true),
                "false" => Ok(false),
                v => Err(e.err(format!("'{v}' is not true or false"))),
            },
        }
    }

    pub fn string(&self, name: &str) -> Option<&'a str> {
        self.find(name).and_then(|e| e.attr("value"))
    }

    /// A reflectance-like colour from `<rgb>`, `<spectrum>` or `<float>`.
    pub fn rgb(&self, name: &str, default: Rgb) -> Result<Rgb, Error> {
        self.rgb_as(name, default, SpectrumUse::Reflectance)
    }

    /// A colour, spectra converted for `usage` (an emitter's radiance, a conductor's eta).
    pub fn rgb_as(&self, name: &str, default: Rgb, usage: SpectrumUse) -> Result<Rgb, Error> {
        match self.find(name) {
            None => Ok(default),
            Some(e) => color_of(e, usage),
        }
    }

    pub fn point(&self, name: &str) -> Result<Option<Vec3>, Error> {
        match self.find(name) {
            None => Ok(None),
            Some(e) if matches!(e.tag.as_str(), "point" | "vector") => Ok(Some(parse_vec3(e)?)),
            Some(e) => Err(e.err(format!("'{name}' should be a <point> or <vector>, found <{}>", e.tag))),
        }
    }

    pub fn transform(&self, name: &str) -> Result<Transform, Error> {
        match self.find(name) {
            None => Ok(Transform::IDENTITY),
            Some(e) if e.tag == "transform" => transform_of(e),
            Some(e) => Err(e.err(format!("'{name}' should be a <transform>, found <{}>", e.tag))),
        }
    }

    /// Parameters given but never read, for a warning.
    pub fn unused(&self) -> Vec<(String, usize)> {
        let used = self.used.borrow();
        self.el
            .children
            .iter()
            .filter_map(|c| c.attr("name").map(|n| (n, c)))
            .filter(|(n, c)| {
                !used.contains(*n) && !matches!(c.tag.as_str(), "bsdf" | "emitter" | "ref" | "rfilter" | "medium")
            })
            .map(|(n, c)| (n.to_string(), c.line))
            .collect()
    }
}

/// A colour from `<rgb>` (1 or 3 numbers), `<float>` or `<spectrum>`, spectra converted to
/// RGB as Mitsuba's RGB variants convert them for `usage` (see [`super::spectrum`]).
pub fn color_of(e: &Element, usage: SpectrumUse) -> Result<Rgb, Error> {
    match e.tag.as_str() {
        "rgb" => {
            let f = parse_floats(e, e.required("value")?)?;
            match f.len() {
                1 => Ok(Rgb::splat(f[0])),
                3 => Ok(Rgb { r: f[0], g: f[1], b: f[2] }),
                _ => Err(e.err("an <rgb> value needs 1 or 3 numbers")),
            }
        }
        "spectrum" => spectrum_of(e, usage),
        "float" => Ok(Rgb::splat(parse_float(e, e.required("value")?)?)),
        other => Err(e.err(format!("expected a colour (<rgb>, <spectrum> or <float>), found <{other}>"))),
    }
}

/// The most wavelength:value pairs one `<spectrum>` may list.
pub const MAX_SPECTRUM_SAMPLES: usize = 100_000;

fn spectrum_of(e: &Element, usage: SpectrumUse) -> Result<Rgb, Error> {
    if let Some(ty) = e.attr("type") {
        let p = Props::new(e);
        let finite = |name: &str, v: f32| {
            if v.is_finite() {
                Ok(v as f64)
            } else {
                Err(e.err(format!("<spectrum type=\"{ty}\">: '{name}' must be finite")))
            }
        };
        let rgb = match ty {
            "blackbody" => {
                if p.find("temperature").is_none() {
                    return Err(e.err("<spectrum type=\"blackbody\"> needs a 'temperature'"));
                }
                let t = finite("temperature", p.float("temperature", 0.0)?)?;
                let lo = finite("wavelength_min", p.float("wavelength_min", 360.0)?)?;
                let hi = finite("wavelength_max", p.float("wavelength_max", 830.0)?)?;
                if !(t > 0.0) {
                    return Err(e.err(format!("blackbody temperature {t} must be positive (kelvin)")));
                }
                if !(lo < hi) {
                    return Err(e.err("blackbody: wavelength_min must be below wavelength_max"));
                }
                spectrum::blackbody_to_rgb(t, lo, hi)
            }
            "uniform" => Rgb::splat(p.float("value", 1.0)?),
            "srgb" => p.rgb("color", Rgb::WHITE)?,
            other => {
                return Err(e.err(format!(
                    "spectrum plugin '{other}' is not supported (blackbody, uniform, srgb; give other spectra as value=\"wavelength:value, ...\")"
                )))
            }
        };
        if let Some((name, line)) = p.unused().first() {
            return Err(Error::at(
                &crate::error::SourceLoc::new(e.file.as_path(), *line as u32, 0),
                format!("<spectrum type=\"{ty}\"> has no parameter '{name}'"),
            ));
        }
        return Ok(rgb);
    }
    if e.attr("filename").is_some() {
        return Err(e.err(
            "spectra read from files (<spectrum filename>) are not supported; give value=\"wavelength:value, ...\"",
        ));
    }
    let v = e.required("value")?;
    let tokens: Vec<&str> = v.split(|c: char| c == ',' || c.is_whitespace()).filter(|t| !t.is_empty()).collect();
    if tokens.len() == 1 && !tokens[0].contains(':') {
        let x = parse_float(e, tokens[0])?;
        return Ok(spectrum::constant_to_rgb(x as f64, usage));
    }
    if tokens.len() > MAX_SPECTRUM_SAMPLES {
        return Err(e.err(format!("a <spectrum> may list at most {MAX_SPECTRUM_SAMPLES} wavelengths")));
    }
    let mut wavelengths = Vec::with_capacity(tokens.len());
    let mut values = Vec::with_capacity(tokens.len());
    for t in &tokens {
        let (w, x) = t.split_once(':').ok_or_else(|| e.err(format!("'{t}' is not a wavelength:value pair")))?;
        let num = |s: &str| -> Result<f64, Error> {
            match s.trim().parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(e.err(format!("'{t}' is not a wavelength:value pair of finite numbers"))),
            }
        };
        wavelengths.push(num(w)?);
        values.push(num(x)?);
    }
    if wavelengths.len() < 2 {
        return Err(e.err("a sampled <spectrum> needs at least two wavelength:value pairs"));
    }
    if wavelengths.windows(2).any(|p| p[1] <= p[0]) {
        return Err(e.err("the wavelengths of a <spectrum> must increase"));
    }
    Ok(spectrum::list_to_rgb(&wavelengths, &values, usage))
}

/// Composes the operations of a `<transform>` in document order (each applies after the
/// ones before it), as Mitsuba does.
pub fn transform_of(el: &Element) -> Result<Transform, Error> {
    let mut t = Transform::IDENTITY;
    for op in &el.children {
        let step = match op.tag.as_str() {
            "translate" => Transform::translate(parse_vec3(op)?),
            "scale" => {
                let s = if let Some(v) = op.attr("value") {
                    let f = parse_floats(op, v)?;
                    match f.len() {
                        1 => Vec3::splat(f[0]),
                        3 => Vec3 { x: f[0], y: f[1], z: f[2] },
                        _ => return Err(op.err("<scale value> needs 1 or 3 numbers")),
                    }
                } else {
                    let get = |k: &str| op.attr(k).map_or(Ok(1.0), |s| parse_float(op, s));
                    Vec3 { x: get("x")?, y: get("y")?, z: get("z")? }
                };
                Transform::scale(s).ok_or_else(|| op.err("a scale of zero is not invertible"))?
            }
            "rotate" => {
                let axis = parse_vec3(op)?;
                if axis.length_squared() == 0.0 {
                    return Err(op.err("<rotate> needs a non-zero axis (x, y, z or value)"));
                }
                Transform::rotate(axis, parse_float(op, op.required("angle")?)?)
            }
            "matrix" => {
                let f = parse_floats(op, op.required("value")?)?;
                let n = match f.len() {
                    16 => 4,
                    9 => 3,
                    _ => return Err(op.err("<matrix> needs 16 (or 9) numbers")),
                };
                let mut m = Mat4::IDENTITY.0;
                for i in 0..n {
                    for j in 0..n {
                        m[i][j] = f[i * n + j] as f64;
                    }
                }
                Transform::from_matrix(Mat4(m)).ok_or_else(|| op.err("the matrix is not invertible"))?
            }
            "lookat" => {
                let v = |k: &str| -> Result<Vec3, Error> {
                    let f = parse_floats(op, op.required(k)?)?;
                    if f.len() != 3 {
                        return Err(op.err(format!("'{k}' needs 3 numbers")));
                    }
                    Ok(Vec3 { x: f[0], y: f[1], z: f[2] })
                };
                let up = if op.attr("up").is_some() { v("up")? } else { Vec3::Y };
                Transform::look_at(v("origin")?, v("target")?, up)
                    .ok_or_else(|| op.err("lookat: origin equals target, or up is parallel to the view direction"))?
            }
            other => return Err(op.err(format!("unknown transform operation <{other}>"))),
        };
        t = step.then_after(&t);
    }
    Ok(t)
}
