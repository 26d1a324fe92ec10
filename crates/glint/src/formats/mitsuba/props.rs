//! Reading typed parameters from a plugin element: `<float>`, `<integer>`, `<boolean>`,
//! `<string>`, `<rgb>`, `<spectrum>`, `<point>`, `<vector>`, `<transform>`, and textures.
//! Every read marks the parameter as used, so that misspelt or unsupported parameters can
//! be reported instead of silently ignored.

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

    /// A colour from `<rgb>`, a constant `<spectrum>` or a `<float>`.
    pub fn rgb(&self, name: &str, default: Rgb) -> Result<Rgb, Error> {
        match self.find(name) {
            None => Ok(default),
            Some(e) => color_of(e),
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
            .filter(|(n, c)| !used.contains(*n) && !matches!(c.tag.as_str(), "bsdf" | "emitter" | "ref" | "rfilter"))
            .map(|(n, c)| (n.to_string(), c.line))
            .collect()
    }
}

pub fn color_of(e: &Element) -> Result<Rgb, Error> {
    match e.tag.as_str() {
        "rgb" => {
            let f = parse_floats(e, e.required("value")?)?;
            match f.len() {
                1 => Ok(Rgb::splat(f[0])),
                3 => Ok(Rgb { r: f[0], g: f[1], b: f[2] }),
                _ => Err(e.err("an <rgb> value needs 1 or 3 numbers")),
            }
        }
        "spectrum" => {
            let v = e.required("value")?;
            if v.contains(':') {
                return Err(e.err("sampled spectra (wavelength:value lists) are not supported; give an <rgb>"));
            }
            let f = parse_floats(e, v)?;
            if f.len() != 1 {
                return Err(e.err("a <spectrum> must be a single constant value (or use <rgb>)"));
            }
            Ok(Rgb::splat(f[0]))
        }
        "float" => Ok(Rgb::splat(parse_float(e, e.required("value")?)?)),
        other => Err(e.err(format!("expected a colour (<rgb>, <spectrum> or <float>), found <{other}>"))),
    }
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
