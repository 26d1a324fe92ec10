//! Checks a description before anything is built: every number that enters the world is
//! finite and in its range, so that no NaN or infinity reaches the BVH or the integrators.
//! Each error names the entity's source location and the allowed range.

use crate::describe::{CameraDesc, FilmDesc, Geometry, IntegratorDesc, LightKind, Matrix4, PixelFilter};

use crate::describe::checks::{color, texels, texture};
use crate::error::{Error, SourceLoc};
use crate::materials::SceneDesc;
use crate::math::{Rgb, Vec3};

use crate::describe::limits::{check_resolution, MAX_DIRECT_SAMPLES, MAX_SPP, MAX_WHITTED_DEPTH};

pub fn check(d: &SceneDesc) -> Result<(), Error> {
    film(&d.film)?;
    camera(&d.camera)?;
    let origin = d.source.as_deref().map(SourceLoc::file).unwrap_or_default();
    if d.sampler.spp == 0 || d.sampler.spp > MAX_SPP {
        return Err(Error::at(
            &origin,
            format!("samples per pixel {} is out of range (1 to {MAX_SPP})", d.sampler.spp),
        ));
    }
    match &d.integrator {
        IntegratorDesc::Whitted(w) => {
            if w.max_depth == 0 || w.max_depth > MAX_WHITTED_DEPTH {
                return Err(Error::at(
                    &origin,
                    format!("whitted: max_depth {} is out of range (1 to {MAX_WHITTED_DEPTH})", w.max_depth),
                ));
            }
            color(Rgb::from_array(w.background), "whitted: background").map_err(|m| Error::at(&origin, m))?;
        }
        IntegratorDesc::Direct(s) => {
            for (n, what) in [(s.emitter_samples, "emitter_samples"), (s.bsdf_samples, "bsdf_samples")] {
                if n > MAX_DIRECT_SAMPLES {
                    return Err(Error::at(
                        &origin,
                        format!("direct: {what} {n} is out of range (0 to {MAX_DIRECT_SAMPLES})"),
                    ));
                }
            }
            if s.emitter_samples == 0 && s.bsdf_samples == 0 {
                return Err(Error::at(&origin, "direct: emitter_samples and bsdf_samples are both 0"));
            }
        }
        IntegratorDesc::Path(p) => {
            if let Some(q) = p.rr_probability {
                if !(q > 0.0 && q <= 1.0) {
                    return Err(Error::at(&origin, format!("path: rr_probability {q} is out of range (0, 1]")));
                }
            }
        }
        IntegratorDesc::Volpath(_) => {}
    }
    super::media::check(d)?;
    let mut names = std::collections::HashSet::new();
    for m in &d.materials {
        if !names.insert(m.name.as_str()) {
            return Err(Error::at(&m.loc, format!("material '{}' is defined twice", m.name)));
        }
        m.model.validate().map_err(|e| Error::at(&m.loc, format!("material '{}': {e}", m.name)))?;
    }
    for s in &d.shapes {
        matrix(&s.to_world, "to_world").map_err(|m| Error::at(&s.loc, m))?;
        axis_scales(&s.to_world, "to_world").map_err(|m| Error::at(&s.loc, m))?;
        if let Some(e) = &s.emission {
            texture(&e.radiance, "emitted radiance").map_err(|m| Error::at(&s.loc, m))?;
        }
        match &s.geometry {
            Geometry::Sphere { center, radius } => {
                vector(*center, "sphere centre").map_err(|m| Error::at(&s.loc, m))?;
                if !(*radius > 0.0 && radius.is_finite()) {
                    return Err(Error::at(&s.loc, format!("sphere radius {radius} must be positive and finite")));
                }
            }
            Geometry::Cylinder { p0, p1, radius } => {
                vector(*p0, "cylinder p0").map_err(|m| Error::at(&s.loc, m))?;
                vector(*p1, "cylinder p1").map_err(|m| Error::at(&s.loc, m))?;
                if !(*radius > 0.0 && radius.is_finite()) {
                    return Err(Error::at(&s.loc, format!("cylinder radius {radius} must be positive and finite")));
                }
                if !((*p1 - *p0).length() > 0.0) {
                    return Err(Error::at(&s.loc, "cylinder: p0 and p1 must differ"));
                }
            }
            Geometry::Mesh(m) => {
                if let Some(i) = m.positions.iter().position(|p| !p.is_finite()) {
                    return Err(Error::at(&s.loc, format!("mesh vertex {i} is not finite")));
                }
            }
            _ => {}
        }
    }
    for l in &d.lights {
        light(&l.light).map_err(|m| Error::at(&l.loc, m))?;
    }
    Ok(())
}

fn film(f: &FilmDesc) -> Result<(), Error> {
    check_resolution(f.width, f.height).map_err(|e| Error::at(&f.loc, e))?;
    if let Some(c) = &f.crop {
        let fits = |offset: u32, size: u32, full: u32| size >= 1 && offset as u64 + size as u64 <= full as u64;
        if !fits(c.offset_x, c.width, f.width) || !fits(c.offset_y, c.height, f.height) {
            return Err(Error::at(
                &f.loc,
                format!(
                    "the crop window ({}x{} at {}, {}) must be at least one pixel and lie within the {}x{} film",
                    c.width, c.height, c.offset_x, c.offset_y, f.width, f.height
                ),
            ));
        }
    }
    let ok = match f.filter {
        PixelFilter::Box => true,
        PixelFilter::Tent { radius } => radius > 0.0 && radius.is_finite() && radius <= 64.0,
        PixelFilter::Gaussian { stddev } => stddev > 0.0 && stddev.is_finite() && stddev <= 16.0,
    };
    if !ok {
        return Err(Error::at(
            &f.loc,
            format!(
                "{:?}: the filter width is out of range (tent radius in (0, 64], gaussian stddev in (0, 16])",
                f.filter
            ),
        ));
    }
    Ok(())
}

fn camera(c: &CameraDesc) -> Result<(), Error> {
    let here = |m: String| Error::at(&c.loc, format!("camera: {m}"));
    if let Some(m) = &c.to_world {
        matrix(m, "to_world").map_err(here)?;
    }
    if !(c.fov_degrees > 0.0 && c.fov_degrees < 180.0) {
        return Err(here(format!("field of view {} is out of range (0, 180) degrees", c.fov_degrees)));
    }
    if !(c.lens_radius >= 0.0 && c.lens_radius.is_finite()) {
        return Err(here(format!("aperture radius {} must be finite and at least 0", c.lens_radius)));
    }
    if c.lens_radius > 0.0 && !(c.focus_distance > 0.0 && c.focus_distance.is_finite()) {
        return Err(here(format!("focus distance {} must be positive and finite", c.focus_distance)));
    }
    if !(c.near_clip >= 0.0 && c.near_clip.is_finite() && c.far_clip > c.near_clip) {
        return Err(here(format!(
            "near_clip {} and far_clip {}: need 0 <= near_clip < far_clip, near_clip finite",
            c.near_clip, c.far_clip
        )));
    }
    Ok(())
}

fn light(l: &LightKind) -> Result<(), String> {
    match l {
        LightKind::Point { position, intensity } => {
            vector(*position, "position")?;
            color(*intensity, "intensity")
        }
        LightKind::Spot { position, direction, intensity, cutoff_degrees, beam_degrees, .. } => {
            vector(*position, "position")?;
            direction_of(*direction, "spot direction (its target equals its position?)")?;
            color(*intensity, "intensity")?;
            if !(*cutoff_degrees > 0.0 && *cutoff_degrees <= 180.0) {
                return Err(format!("spot cutoff angle {cutoff_degrees} is out of range (0, 180] degrees"));
            }
            if !(*beam_degrees >= 0.0 && beam_degrees.is_finite()) {
                return Err(format!("spot beam width {beam_degrees} must be finite and at least 0"));
            }
            Ok(())
        }
        LightKind::Directional { direction, irradiance } => {
            direction_of(*direction, "direction")?;
            color(*irradiance, "irradiance")
        }
        LightKind::Constant { radiance } => color(*radiance, "radiance"),
        LightKind::EnvMap { scale, to_world, texels: t, .. } => {
            if !(*scale >= 0.0 && scale.is_finite()) {
                return Err(format!("envmap scale {scale} must be finite and at least 0"));
            }
            t.as_ref().map_or(Ok(()), texels)?;
            matrix(to_world, "to_world")
        }
        LightKind::TexturedSpot { to_world, intensity, cutoff_degrees, beam_degrees, .. } => {
            matrix(to_world, "to_world")?;
            color(*intensity, "intensity")?;
            // Below 90 degrees: the texture is laid over tan(cutoff).
            if !(*cutoff_degrees > 0.0 && *cutoff_degrees < 90.0) {
                return Err(format!("textured spot cutoff angle {cutoff_degrees} is out of range (0, 90) degrees"));
            }
            if !(*beam_degrees >= 0.0 && beam_degrees.is_finite()) {
                return Err(format!("spot beam width {beam_degrees} must be finite and at least 0"));
            }
            Ok(())
        }
        LightKind::Projector { to_world, scale, fov_degrees, .. } => {
            matrix(to_world, "to_world")?;
            if !(*scale >= 0.0 && scale.is_finite()) {
                return Err(format!("projector scale {scale} must be finite and at least 0"));
            }
            if !(*fov_degrees > 0.0 && *fov_degrees < 180.0) {
                return Err(format!("projector fov {fov_degrees} is out of range (0, 180) degrees"));
            }
            Ok(())
        }
    }
}

fn vector(v: Vec3, what: &str) -> Result<(), String> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(format!("{what} ({}, {}, {}) is not finite", v.x, v.y, v.z))
    }
}

fn direction_of(v: Vec3, what: &str) -> Result<(), String> {
    vector(v, what)?;
    if v.length_squared() > 0.0 && v.normalize().is_finite() {
        Ok(())
    } else {
        Err(format!("{what} is zero"))
    }
}

fn matrix(m: &Matrix4, what: &str) -> Result<(), String> {
    // Checked as f32 too: the world is f32, and 1e39 is a finite f64 but infinite as f32.
    if m.iter().flatten().all(|v| v.is_finite() && (*v as f32).is_finite()) {
        Ok(())
    } else {
        Err(format!("{what}: the matrix has a NaN or infinite entry (or one beyond f32's range)"))
    }
}

/// The scale a transform applies along each axis (the length of each column of its linear
/// part) must keep squared lengths within f32's normal range, where the world is traced:
/// beyond, a shape's points, normals or areas overflow or vanish and it renders black. A
/// scale of exactly 0 (a shape flattened on purpose) is left to the build.
fn axis_scales(m: &Matrix4, what: &str) -> Result<(), String> {
    let (lo, hi) = ((f32::MIN_POSITIVE as f64).sqrt(), (f32::MAX as f64).sqrt());
    for c in 0..3 {
        let len = m[..3].iter().map(|row| row[c] * row[c]).sum::<f64>().sqrt();
        if len != 0.0 && !(lo..=hi).contains(&len) {
            return Err(format!(
                "{what}: a scale of {len:.3e} along an axis is degenerate (glint traces in f32: scales from {lo:.1e} to {hi:.1e})"
            ));
        }
    }
    Ok(())
}
