//! Checks a description before anything is built: every number that enters the world is
//! finite and in its range, so that no NaN or infinity reaches the BVH or the integrators.
//! Each error names the entity's source location and the allowed range.

use crate::describe::{
    CameraDesc, FilmDesc, Geometry, IntegratorDesc, LightKind, MaterialModel, Matrix4, PixelFilter, SceneDesc,
    TextureDesc,
};
use crate::error::{Error, SourceLoc};
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
        material(&m.model).map_err(|e| Error::at(&m.loc, format!("material '{}': {e}", m.name)))?;
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

/// A texture's colours (named `what` when constant), uv transform and attribute name.
fn texture(t: &TextureDesc, what: &str) -> Result<(), String> {
    match t {
        TextureDesc::Constant { color: c } => color(*c, what)?,
        TextureDesc::Checkerboard { color0, color1, uv_scale, uv_offset } => {
            color(*color0, "color0")?;
            color(*color1, "color1")?;
            uv(uv_scale, uv_offset)?;
        }
        TextureDesc::Bitmap { uv_scale, uv_offset, .. } => uv(uv_scale, uv_offset)?,
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

fn material(m: &MaterialModel) -> Result<(), String> {
    for t in m.textures() {
        texture(t, "colour")?;
    }
    let alpha = |r: &Option<crate::describe::Roughness>| -> Result<(), String> {
        let Some(r) = r else { return Ok(()) };
        // A constant alpha must be positive (0 is a smooth surface, described as such); a
        // textured one may reach 0 where it is checked as a colour, and is clamped, as
        // Mitsuba clamps it, to 1e-4.
        for (name, value) in [("alpha", Some(&r.alpha)), ("alpha_v", r.alpha_v.as_ref())] {
            if let Some(crate::describe::ScalarTexture::Value(a)) = value {
                if !(*a > 0.0 && a.is_finite()) {
                    return Err(format!("roughness {name} {a} must be positive and finite"));
                }
            }
        }
        Ok(())
    };
    let eta_ok = |eta: f32| -> Result<(), String> {
        if eta > 0.0 && eta.is_finite() {
            Ok(())
        } else {
            Err(format!("index of refraction {eta} must be positive and finite"))
        }
    };
    match m {
        MaterialModel::Phong { ks, exponent, .. } => {
            color(*ks, "ks")?;
            if !(*exponent >= 0.0 && exponent.is_finite()) {
                return Err(format!("Phong exponent {exponent} must be finite and at least 0"));
            }
        }
        MaterialModel::Conductor { eta, k, specular, roughness } => {
            color(*eta, "eta")?;
            color(*k, "k")?;
            color(*specular, "specular reflectance")?;
            alpha(roughness)?;
        }
        MaterialModel::Dielectric { eta, reflect, transmit, roughness, .. } => {
            eta_ok(*eta)?;
            color(*reflect, "specular reflectance")?;
            color(*transmit, "specular transmittance")?;
            alpha(roughness)?;
        }
        MaterialModel::Plastic { specular, eta, roughness, .. } => {
            eta_ok(*eta)?;
            color(*specular, "specular reflectance")?;
            alpha(roughness)?;
        }
        MaterialModel::PPlastic { specular, eta, roughness, .. } => {
            eta_ok(*eta)?;
            color(*specular, "specular reflectance")?;
            alpha(&Some(roughness.clone()))?;
        }
        MaterialModel::Diffuse { .. } | MaterialModel::Black | MaterialModel::Null => {}
        MaterialModel::Hair(h) => {
            eta_ok(h.eta)?;
            if !(h.sigma_a.r >= 0.0
                && h.sigma_a.g >= 0.0
                && h.sigma_a.b >= 0.0
                && h.sigma_a.max_component().is_finite())
            {
                return Err(format!("hair absorption {:?} must be finite and not negative", h.sigma_a));
            }
            for (name, v) in
                [("longitudinal_roughness", h.longitudinal_roughness), ("azimuthal_roughness", h.azimuthal_roughness)]
            {
                if !(0.0..=1.0).contains(&v) {
                    return Err(format!("hair {name} {v} must be in [0, 1]"));
                }
            }
            if !h.scale_tilt.is_finite() {
                return Err(format!("hair scale_tilt {} must be finite", h.scale_tilt));
            }
        }
        MaterialModel::BumpMap { scale, nested, .. } => {
            if !scale.is_finite() {
                return Err(format!("bump map scale {scale} must be finite"));
            }
            material(nested)?;
        }
        MaterialModel::NormalMap { nested, .. } | MaterialModel::Mask { nested, .. } => material(nested)?,
        MaterialModel::Principled(p) => principled(p, eta_ok)?,
        MaterialModel::Gltf(g) => gltf_material(g, eta_ok)?,
        MaterialModel::Blend(b) => {
            // Each part is checked as a material of its own (its textures included).
            material(&b.first.model).map_err(|e| format!("blend, first part: {e}"))?;
            material(&b.second.model).map_err(|e| format!("blend, second part: {e}"))?;
        }
    }
    Ok(())
}

/// A glTF material's factors: the specification's ranges ([0, 1] but for the index of
/// refraction and the attenuation distance), so that a BSDF never sees a value it has no
/// meaning for.
fn gltf_material(
    g: &crate::describe::GltfMaterialDesc,
    eta_ok: impl Fn(f32) -> Result<(), String>,
) -> Result<(), String> {
    eta_ok(g.ior)?;
    for (name, c) in [
        ("baseColorFactor", g.base_color),
        ("specularColorFactor", g.specular_color),
        ("sheenColorFactor", g.sheen_color),
        ("attenuationColor", g.attenuation_color),
    ] {
        color(c, name)?;
    }
    for (name, v) in [
        ("alpha", g.base_alpha),
        ("metallicFactor", g.metallic),
        ("roughnessFactor", g.roughness),
        ("specularFactor", g.specular),
        ("transmissionFactor", g.transmission),
        ("clearcoatFactor", g.clearcoat),
        ("clearcoatRoughnessFactor", g.clearcoat_roughness),
        ("sheenRoughnessFactor", g.sheen_roughness),
    ] {
        if !(0.0..=1.0).contains(&v) {
            return Err(format!("glTF material: {name} {v} must lie in [0, 1]"));
        }
    }
    if !g.normal_scale.is_finite() {
        return Err(format!("glTF material: normalTexture.scale {} must be finite", g.normal_scale));
    }
    if !(g.attenuation_distance > 0.0) {
        return Err(format!("glTF material: attenuationDistance {} must be positive", g.attenuation_distance));
    }
    Ok(())
}

/// Mitsuba documents every principled parameter but `eta` and the sampling rates as lying
/// in [0, 1]; out of it the model has no meaning (anisotropic above 1/0.9 is a NaN).
fn principled(p: &crate::describe::PrincipledDesc, eta_ok: impl Fn(f32) -> Result<(), String>) -> Result<(), String> {
    eta_ok(p.eta)?;
    for (name, t) in p.textures() {
        let unit = |c: Rgb| -> Result<(), String> {
            if name != "base_color" && c.to_array().iter().any(|v| *v > 1.0) {
                return Err(format!("principled: {name} ({}, {}, {}) must lie in [0, 1]", c.r, c.g, c.b));
            }
            Ok(())
        };
        match t {
            TextureDesc::Constant { color: c } => unit(*c)?,
            TextureDesc::Checkerboard { color0, color1, .. } => {
                unit(*color0)?;
                unit(*color1)?;
            }
            // Images are clamped to [0, 1] by their formats or read as given (EXR).
            TextureDesc::Bitmap { .. } | TextureDesc::MeshAttribute { .. } | TextureDesc::Gltf(_) => {}
        }
    }
    for (rate, name) in [
        (p.diffuse_sampling_rate, "diffuse_reflectance_sampling_rate"),
        (p.specular_sampling_rate, "main_specular_sampling_rate"),
        (p.clearcoat_sampling_rate, "clearcoat_sampling_rate"),
    ] {
        if !(rate >= 0.0 && rate.is_finite()) {
            return Err(format!("principled: {name} {rate} must be finite and not negative"));
        }
    }
    if !(p.specular_sampling_rate > 0.0) {
        // The main lobe must be sampleable: it is the only one seen from inside.
        return Err("principled: main_specular_sampling_rate must be positive".to_string());
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
        LightKind::EnvMap { scale, to_world, .. } => {
            if !(*scale >= 0.0 && scale.is_finite()) {
                return Err(format!("envmap scale {scale} must be finite and at least 0"));
            }
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

fn color(c: Rgb, what: &str) -> Result<(), String> {
    if c.to_array().iter().all(|v| v.is_finite() && *v >= 0.0) {
        Ok(())
    } else {
        Err(format!("{what} ({}, {}, {}) must be finite and not negative", c.r, c.g, c.b))
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

fn uv(scale: &[f32; 2], offset: &[f32; 2]) -> Result<(), String> {
    if scale.iter().chain(offset).all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err("uv scale and offset must be finite".into())
    }
}
