//! Checks of described numbers that materials, lights and the build share: colours and
//! textures finite and not negative, indices of refraction and roughness positive. Each
//! returns a message naming the parameter, which the caller places.

use super::{Roughness, ScalarTexture, Texels, TextureDesc};
use crate::math::Rgb;

/// A colour: every channel finite and not negative.
pub fn color(c: Rgb, what: &str) -> Result<(), String> {
    if c.to_array().iter().all(|v| v.is_finite() && *v >= 0.0) {
        Ok(())
    } else {
        Err(format!("{what} ({}, {}, {}) must be finite and not negative", c.r, c.g, c.b))
    }
}

/// A texture's uv transform: finite.
pub fn uv(scale: &[f32; 2], offset: &[f32; 2]) -> Result<(), String> {
    if scale.iter().chain(offset).all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err("uv scale and offset must be finite".into())
    }
}

/// Texels given as data: at least one, as many as the size says, all finite.
pub fn texels(t: &Texels) -> Result<(), String> {
    if t.width == 0 || t.height == 0 || t.width.checked_mul(t.height) != Some(t.pixels.len()) {
        return Err(format!("an image of {}x{} texels cannot hold {}", t.width, t.height, t.pixels.len()));
    }
    match t.pixels.iter().position(|p| !p.is_finite()) {
        Some(i) => Err(format!("texel ({}, {}) is not finite", i % t.width, i / t.width)),
        None => Ok(()),
    }
}

/// A texture's colours (named `what` when constant), uv transform, texels and attribute name.
pub fn texture(t: &TextureDesc, what: &str) -> Result<(), String> {
    match t {
        TextureDesc::Constant { color: c } => color(*c, what)?,
        TextureDesc::Checkerboard { color0, color1, uv_scale, uv_offset } => {
            color(*color0, "color0")?;
            color(*color1, "color1")?;
            uv(uv_scale, uv_offset)?;
        }
        TextureDesc::Bitmap { uv_scale, uv_offset, texels: t, .. } => {
            uv(uv_scale, uv_offset)?;
            t.as_ref().map_or(Ok(()), texels)?;
        }
        TextureDesc::MeshAttribute { name, scale, .. } => {
            if !scale.is_finite() {
                return Err(format!("mesh attribute '{name}': scale {scale} must be finite"));
            }
            if !(name.starts_with("vertex_") || name.starts_with("face_")) {
                return Err(format!("mesh attribute name '{name}' must start with 'vertex_' or 'face_'"));
            }
        }
        TextureDesc::Gltf(g) => {
            color(g.scale, what)?;
            if g.texcoord > 1 {
                return Err(format!("glTF texture coordinate set {} (glint reads sets 0 and 1)", g.texcoord));
            }
            if g.transform.iter().flatten().any(|v| !v.is_finite()) {
                return Err("glTF texture transform must be finite".into());
            }
        }
    }
    Ok(())
}

/// An index of refraction: positive and finite.
pub fn eta(eta: f32) -> Result<(), String> {
    if eta > 0.0 && eta.is_finite() {
        Ok(())
    } else {
        Err(format!("index of refraction {eta} must be positive and finite"))
    }
}

/// A constant roughness must be positive (0 is a smooth surface, described as such); a
/// textured one may reach 0 where it is checked as a colour, and is clamped, as Mitsuba
/// clamps it, to 1e-4.
pub fn roughness(r: Option<&Roughness>) -> Result<(), String> {
    let Some(r) = r else { return Ok(()) };
    for (name, value) in [("alpha", Some(&r.alpha)), ("alpha_v", r.alpha_v.as_ref())] {
        if let Some(ScalarTexture::Value(a)) = value {
            if !(*a > 0.0 && a.is_finite()) {
                return Err(format!("roughness {name} {a} must be positive and finite"));
            }
        }
    }
    Ok(())
}
