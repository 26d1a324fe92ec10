//! Media of a description: checked (every number finite and in range, every index in
//! bounds) and turned into the world's [`Medium`]s.

use crate::describe::{GridVolumeDesc, MediumDesc, PhaseDesc, VolumeDesc};

use crate::error::{Error, SourceLoc};
use crate::io::vol::read_vol;
use crate::materials::SceneDesc;
use crate::math::{Mat4, Transform};
use crate::media::{Albedo, GridVolume, Medium, MediumBoundary, Phase};
use std::sync::Arc;

use crate::describe::limits::MAX_EXTINCTION;

pub fn check(d: &SceneDesc) -> Result<(), Error> {
    for m in &d.media {
        medium(m).map_err(|e| Error::at(&m.loc, format!("medium '{}': {e}", m.name)))?;
    }
    let n = d.media.len();
    let in_range = |i: Option<usize>, loc: &SourceLoc, what: &str| match i {
        Some(i) if i >= n => Err(Error::at(loc, format!("{what} medium index {i} is out of range ({n} media)"))),
        _ => Ok(()),
    };
    for s in &d.shapes {
        in_range(s.media.interior, &s.loc, "interior")?;
        in_range(s.media.exterior, &s.loc, "exterior")?;
    }
    in_range(d.camera.medium, &d.camera.loc, "camera")
}

fn medium(m: &MediumDesc) -> Result<(), String> {
    if !(m.scale >= 0.0 && m.scale.is_finite()) {
        return Err(format!("scale {} must be finite and at least 0", m.scale));
    }
    for (k, s) in m.sigma_t.to_array().into_iter().enumerate() {
        let scaled = s * m.scale;
        if !(s >= 0.0 && scaled <= MAX_EXTINCTION) {
            return Err(format!(
                "sigma_t ({}, {}, {}) times scale {} must be at least 0 and at most {MAX_EXTINCTION:e} (channel {k})",
                m.sigma_t.r, m.sigma_t.g, m.sigma_t.b, m.scale
            ));
        }
    }
    if m.density.is_some() && !(m.sigma_t.r == m.sigma_t.g && m.sigma_t.g == m.sigma_t.b) {
        return Err("a heterogeneous medium's sigma_t must be grey".into());
    }
    for g in m.density.iter().chain(match &m.albedo {
        VolumeDesc::Grid(g) => Some(g),
        VolumeDesc::Constant(_) => None,
    }) {
        if Transform::from_matrix(Mat4(g.to_world)).is_none_or(|t| !t.is_finite()) {
            return Err("a grid volume's to_world must be finite and invertible".into());
        }
    }
    match &m.albedo {
        VolumeDesc::Constant(a) => {
            if !a.to_array().iter().all(|a| (0.0..=1.0).contains(a)) {
                return Err(format!("albedo ({}, {}, {}) must lie in [0, 1]", a.r, a.g, a.b));
            }
        }
        VolumeDesc::Grid(_) => {}
    }
    if m.absorbing_only && (m.density.is_some() || m.albedo != VolumeDesc::Constant(crate::math::Rgb::BLACK)) {
        return Err("an absorbing-only medium must be homogeneous with albedo 0".into());
    }
    if let PhaseDesc::Hg { g } = m.phase {
        if !(g > -1.0 && g < 1.0) {
            return Err(format!("hg: g {g} must lie in (-1, 1)"));
        }
    }
    Ok(())
}

/// The world's media, in the description's order (checked first by [`check`]); grid
/// volumes are read here.
pub fn media(d: &SceneDesc) -> Result<Vec<Medium>, Error> {
    d.media
        .iter()
        .map(|m| {
            let phase = match m.phase {
                PhaseDesc::Isotropic => Phase::Isotropic,
                PhaseDesc::Hg { g } => Phase::HenyeyGreenstein { g },
            };
            let albedo = match &m.albedo {
                VolumeDesc::Constant(a) => Albedo::Constant(*a),
                VolumeDesc::Grid(g) => Albedo::Grid(Arc::new(
                    albedo_grid(g).map_err(|e| Error::at(&g.loc, format!("medium '{}': albedo: {e}", m.name)))?,
                )),
            };
            let Some(g) = &m.density else {
                let mut out = Medium::new(m.sigma_t * m.scale, albedo, phase, m.sample_emitters);
                out.absorbing_only = m.absorbing_only;
                return Ok(out);
            };
            let sigma_t = m.sigma_t.r * m.scale;
            let density = density_grid(g, sigma_t)
                .map_err(|e| Error::at(&g.loc, format!("medium '{}': sigma_t: {e}", m.name)))?;
            Ok(Medium::heterogeneous(sigma_t, Arc::new(density), albedo, phase, m.sample_emitters))
        })
        .collect()
}

/// Reads a density grid: 1 channel, every value finite and at least 0, its largest times
/// `sigma_t` (the majorant) at most [`MAX_EXTINCTION`].
fn density_grid(g: &GridVolumeDesc, sigma_t: f32) -> Result<GridVolume, String> {
    let grid = read_vol(&g.file)?;
    let file = g.file.display();
    if grid.channels != 1 {
        return Err(format!("{file}: a density grid has 1 channel, not {}", grid.channels));
    }
    if let Some(v) = grid.data.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(format!("{file}: density {v} must be finite and at least 0"));
    }
    let max = grid.data.iter().copied().fold(0.0f32, f32::max);
    if !(max * sigma_t <= MAX_EXTINCTION) {
        return Err(format!(
            "{file}: the largest density {max} times sigma_t and scale ({sigma_t}) exceeds {MAX_EXTINCTION:e}"
        ));
    }
    let to_world = Transform::from_matrix(Mat4(g.to_world)).ok_or("the grid's to_world is not invertible")?;
    GridVolume::new(grid.resolution, 1, grid.data, g.filter, g.wrap, to_world)
        .ok_or_else(|| format!("{file}: the grid's size does not match its resolution"))
}

/// Reads an albedo grid: 1 or 3 channels, every value in [0, 1].
fn albedo_grid(g: &GridVolumeDesc) -> Result<GridVolume, String> {
    let grid = read_vol(&g.file)?;
    let file = g.file.display();
    if !matches!(grid.channels, 1 | 3) {
        return Err(format!("{file}: a grid of {} channels cannot be an albedo (1 or 3 channels are)", grid.channels));
    }
    if let Some(i) = grid.data.iter().position(|v| !(0.0..=1.0).contains(v)) {
        let cell = i / grid.channels as usize;
        let [rx, ry, _] = grid.resolution.map(|r| r as usize);
        return Err(format!(
            "{file}: albedo {} in cell ({}, {}, {}) must lie in [0, 1]",
            grid.data[i],
            cell % rx,
            cell / rx % ry,
            cell / (rx * ry)
        ));
    }
    let to_world = Transform::from_matrix(Mat4(g.to_world)).ok_or("the grid's to_world is not invertible")?;
    GridVolume::new(grid.resolution, grid.channels, grid.data, g.filter, g.wrap, to_world)
        .ok_or_else(|| format!("{file}: the grid's size does not match its resolution"))
}

/// The media on the two sides of a shape, as the world indexes them.
pub fn boundary(m: &crate::describe::ShapeMedia) -> MediumBoundary {
    MediumBoundary { interior: m.interior.map(|i| i as u32), exterior: m.exterior.map(|i| i as u32) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rgb;

    #[test]
    fn an_absorbing_only_medium_must_scatter_nothing() {
        let mut m = MediumDesc {
            name: "ink".into(),
            sigma_t: Rgb::splat(1.0),
            albedo: VolumeDesc::Constant(Rgb::BLACK),
            scale: 1.0,
            phase: PhaseDesc::Isotropic,
            sample_emitters: false,
            density: None,
            absorbing_only: true,
            loc: SourceLoc::default(),
        };
        assert!(medium(&m).is_ok());
        m.albedo = VolumeDesc::Constant(Rgb::splat(0.5));
        assert!(medium(&m).unwrap_err().contains("absorbing-only"));
    }
}
