//! Media of a description: checked (every number finite and in range, every index in
//! bounds) and turned into the world's [`Medium`]s.

use crate::describe::{MediumDesc, PhaseDesc, SceneDesc};
use crate::error::{Error, SourceLoc};
use crate::media::{Medium, MediumBoundary, Phase};

/// The largest extinction (per unit length, after `scale`) a medium may have: denser ones
/// would make paths of billions of tiny steps.
pub const MAX_EXTINCTION: f32 = 1e9;

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
    if !m.albedo.to_array().iter().all(|a| (0.0..=1.0).contains(a)) {
        return Err(format!("albedo ({}, {}, {}) must lie in [0, 1]", m.albedo.r, m.albedo.g, m.albedo.b));
    }
    if let PhaseDesc::Hg { g } = m.phase {
        if !(g > -1.0 && g < 1.0) {
            return Err(format!("hg: g {g} must lie in (-1, 1)"));
        }
    }
    Ok(())
}

/// The world's media, in the description's order (checked first by [`check`]).
pub fn media(d: &SceneDesc) -> Vec<Medium> {
    d.media
        .iter()
        .map(|m| {
            let phase = match m.phase {
                PhaseDesc::Isotropic => Phase::Isotropic,
                PhaseDesc::Hg { g } => Phase::HenyeyGreenstein { g },
            };
            Medium::new(m.sigma_t * m.scale, m.albedo, phase, m.sample_emitters)
        })
        .collect()
}

/// The media on the two sides of a shape, as the world indexes them.
pub fn boundary(m: &crate::describe::ShapeMedia) -> MediumBoundary {
    MediumBoundary { interior: m.interior.map(|i| i as u32), exterior: m.exterior.map(|i| i as u32) }
}
