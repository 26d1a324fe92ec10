//! Mitsuba 3 scene XML. `xml` reads the file into a tree (includes, defaults, `$name`
//! substitution, 0.x upgrades), `props` reads typed parameters, and this module maps each
//! plugin onto the [`SceneBuilder`]. What glint supports, plugin by plugin and parameter by
//! parameter, is listed in docs/mitsuba-support.md; anything else is an error that names the
//! plugin, the file and the line.

mod props;
pub mod xml;

use super::builder::{Emission, SceneBuilder};
use super::{LightSelection, LoadOptions, LoadedScene};
use crate::bsdf::{Microfacet, MicrofacetKind};
use crate::camera::{Camera, FovAxis};
use crate::integrators::{Integrator, PathSettings};
use crate::lights::Light;
use crate::materials::{conductor_preset, Bitmap, Material, MaterialKind, Texture};
use crate::math::{Frame, Rgb, Vec3};
use crate::render::{PixelFilter, RenderSettings};
use crate::sampling::SamplerKind;
use props::{color_of, Props};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use xml::Element;

/// Refractive indices Mitsuba accepts by name.
fn named_ior(name: &str) -> Option<f32> {
    Some(match name {
        "vacuum" => 1.0,
        "helium" => 1.000036,
        "hydrogen" => 1.000132,
        "air" => 1.000277,
        "carbon dioxide" => 1.00045,
        "water" => 1.3330,
        "acetone" => 1.36,
        "ethanol" => 1.361,
        "carbon tetrachloride" => 1.461,
        "glycerol" => 1.4729,
        "benzene" => 1.501,
        "silicone oil" => 1.52045,
        "bromine" => 1.661,
        "water ice" => 1.31,
        "fused quartz" => 1.458,
        "pyrex" => 1.470,
        "acrylic glass" => 1.49,
        "polypropylene" => 1.49,
        "bk7" => 1.5046,
        "sodium chloride" => 1.544,
        "amber" => 1.55,
        "pet" => 1.5750,
        "diamond" => 2.419,
        _ => return None,
    })
}

struct Loader<'a> {
    b: SceneBuilder,
    opts: &'a LoadOptions,
    /// Named top-level objects (`id`), for `<ref>`.
    named: HashMap<String, &'a Element>,
    materials: HashMap<*const Element, u32>,
    warnings: Vec<String>,
}

pub fn load(path: &Path, opts: &LoadOptions) -> Result<LoadedScene, String> {
    let root = xml::load_tree(path, &opts.defines)?;
    let mut l = Loader {
        b: SceneBuilder::new(opts.bvh_split),
        opts,
        named: HashMap::new(),
        materials: HashMap::new(),
        warnings: Vec::new(),
    };
    for c in &root.children {
        if let Some(id) = c.attr("id") {
            l.named.insert(id.to_string(), c);
        }
    }
    let mut sensor = None;
    let mut integrator_el = None;
    for c in &root.children {
        match c.tag.as_str() {
            "shape" => l.shape(c)?,
            "emitter" => l.emitter(c)?,
            "sensor" => sensor = Some(c),
            "integrator" => integrator_el = Some(c),
            // Named BSDFs and textures are built when a shape refers to them.
            "bsdf" | "texture" => {}
            "medium" | "phase" | "volume" => {
                return Err(c.err(format!("<{}> (participating media) is not supported", c.tag)))
            }
            other => return Err(c.err(format!("unexpected element <{other}> in <scene>"))),
        }
    }
    let sensor = sensor.ok_or_else(|| format!("{}: the scene has no <sensor>", path.display()))?;
    let (camera, mut settings) = l.sensor(sensor)?;
    let integrator = match integrator_el {
        Some(e) => l.integrator(e)?,
        None => Integrator::Path(PathSettings::default()),
    };
    if let Some(spp) = settings_spp(sensor)? {
        settings.spp = spp;
    }
    let mut scene = l.b.finish(camera, LightSelection::Power).map_err(|e| format!("{}: {e}", path.display()))?;
    scene.set_light_selection(LightSelection::Power);
    Ok(LoadedScene { scene, integrator, settings, warnings: l.warnings })
}

fn settings_spp(sensor: &Element) -> Result<Option<u32>, String> {
    for c in sensor.children.iter().filter(|c| c.tag == "sampler") {
        let p = Props::new(c);
        let n = p.int("sample_count", 4)?;
        if n < 1 {
            return Err(c.err("sample_count must be at least 1"));
        }
        return Ok(Some(n as u32));
    }
    Ok(None)
}

impl<'a> Loader<'a> {
    fn warn_unused(&mut self, p: &Props) {
        for (name, line) in p.unused() {
            self.warnings.push(format!(
                "{}:{}: <{} type=\"{}\">: parameter '{name}' is not supported and was ignored",
                p.el.file.display(),
                line,
                p.el.tag,
                p.el.attr("type").unwrap_or("")
            ));
        }
    }

    /// Follows `<ref id>` to the named object.
    fn resolve(&self, el: &'a Element) -> Result<&'a Element, String> {
        if el.tag == "ref" {
            let id = el.required("id")?;
            return self
                .named
                .get(id)
                .copied()
                .ok_or_else(|| el.err(format!("<ref id=\"{id}\">: no object has that id")));
        }
        Ok(el)
    }

    fn texture(&self, p: &Props<'a>, name: &str, default: Rgb) -> Result<Texture, String> {
        let Some(e) = p.find(name) else { return Ok(Texture::Constant(default)) };
        let e = self.resolve(e)?;
        if e.tag != "texture" {
            return Ok(Texture::Constant(color_of(e)?));
        }
        let tp = Props::new(e);
        let to_uv = tp.transform("to_uv")?;
        // Only scale and translation of uv are meaningful for glint's textures.
        let o = to_uv.point(Vec3::ZERO);
        let sx = to_uv.vector(Vec3::X).x;
        let sy = to_uv.vector(Vec3::Y).y;
        let (scale, offset) = ([sx, sy], [o.x, o.y]);
        match e.attr("type").unwrap_or("") {
            "bitmap" => {
                let file = tp.string("filename").ok_or_else(|| e.err("bitmap texture needs 'filename'"))?;
                let path = e.file.parent().unwrap_or(Path::new(".")).join(file);
                let raw = tp.bool("raw", false)?;
                let bm = Bitmap::load(&path, raw).map_err(|err| e.err(err))?;
                let _ = tp.string("filter_type");
                let _ = tp.string("wrap_mode");
                Ok(Texture::Bitmap { image: Arc::new(bm), uv_scale: scale, uv_offset: offset })
            }
            "checkerboard" => Ok(Texture::Checkerboard {
                color0: tp.rgb("color0", Rgb::splat(0.4))?,
                color1: tp.rgb("color1", Rgb::splat(0.2))?,
                uv_scale: scale,
                uv_offset: offset,
            }),
            other => Err(e.err(format!("texture plugin '{other}' is not supported (bitmap, checkerboard)"))),
        }
    }

    fn ior(&self, p: &Props, name: &str, default: f32) -> Result<f32, String> {
        match p.find(name) {
            None => Ok(default),
            Some(e) if e.tag == "string" => {
                let v = e.required("value")?;
                named_ior(v).ok_or_else(|| e.err(format!("unknown index of refraction '{v}'")))
            }
            Some(e) => props::parse_float(e, e.required("value")?),
        }
    }

    fn microfacet(&self, p: &Props) -> Result<Microfacet, String> {
        let kind = match p.string("distribution").unwrap_or("beckmann") {
            "beckmann" => MicrofacetKind::Beckmann,
            "ggx" => MicrofacetKind::Ggx,
            other => return Err(p.el.err(format!("unknown microfacet distribution '{other}'"))),
        };
        let alpha = match (p.opt_float("alpha_u")?, p.opt_float("alpha_v")?) {
            (Some(u), Some(v)) if (u - v).abs() > 1e-6 => {
                return Err(p.el.err("anisotropic roughness (alpha_u != alpha_v) is not supported"))
            }
            (Some(u), _) => u,
            _ => p.float("alpha", 0.1)?,
        };
        let _ = p.bool("sample_visible", true)?;
        Ok(Microfacet::new(kind, alpha))
    }

    fn conductor_ior(&self, p: &Props) -> Result<(Rgb, Rgb), String> {
        let (eta_el, k_el) = (p.find("eta"), p.find("k"));
        if eta_el.is_some() || k_el.is_some() {
            return Ok((p.rgb("eta", Rgb::BLACK)?, p.rgb("k", Rgb::WHITE)?));
        }
        let name = p.string("material").unwrap_or("none");
        conductor_preset(name)
            .ok_or_else(|| p.el.err(format!("conductor material '{name}' is not known (Au, Ag, Cu, Al, Cr, none)")))
    }

    /// Builds (once) the material of a `<bsdf>` element.
    fn material(&mut self, el: &'a Element) -> Result<u32, String> {
        let el = self.resolve(el)?;
        if let Some(&id) = self.materials.get(&(el as *const Element)) {
            return Ok(id);
        }
        if el.tag != "bsdf" {
            return Err(el.err(format!("expected a <bsdf>, found <{}>", el.tag)));
        }
        let (kind, two_sided) = self.material_kind(el)?;
        let name = el.attr("id").map_or_else(|| format!("bsdf@{}:{}", el.file.display(), el.line), str::to_string);
        let id = self.b.add_material(Material::new(name, kind, two_sided));
        self.materials.insert(el as *const Element, id);
        Ok(id)
    }

    fn material_kind(&mut self, el: &'a Element) -> Result<(MaterialKind, bool), String> {
        let ty = el.attr("type").unwrap_or("");
        let p = Props::new(el);
        let kind = match ty {
            "twosided" => {
                let inner: Vec<&Element> = el.children.iter().filter(|c| c.tag == "bsdf" || c.tag == "ref").collect();
                if inner.len() != 1 {
                    return Err(
                        el.err("twosided: give exactly one nested <bsdf> (different BSDFs per side are not supported)")
                    );
                }
                let inner = self.resolve(inner[0])?;
                let (k, _) = self.material_kind(inner)?;
                return Ok((k, true));
            }
            "diffuse" => MaterialKind::Diffuse { reflectance: self.texture(&p, "reflectance", Rgb::splat(0.5))? },
            "conductor" => {
                let (eta, k) = self.conductor_ior(&p)?;
                MaterialKind::Conductor { eta, k, specular: p.rgb("specular_reflectance", Rgb::WHITE)? }
            }
            "roughconductor" => {
                let dist = self.microfacet(&p)?;
                let (eta, k) = self.conductor_ior(&p)?;
                MaterialKind::RoughConductor { dist, eta, k, specular: p.rgb("specular_reflectance", Rgb::WHITE)? }
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                let eta = self.ior(&p, "int_ior", 1.5046)? / self.ior(&p, "ext_ior", 1.000277)?;
                let reflect = p.rgb("specular_reflectance", Rgb::WHITE)?;
                let transmit = p.rgb("specular_transmittance", Rgb::WHITE)?;
                match ty {
                    "dielectric" => MaterialKind::Dielectric { eta, reflect, transmit },
                    "thindielectric" => MaterialKind::ThinDielectric { eta, reflect, transmit },
                    _ => {
                        let dist = self.microfacet(&p)?;
                        MaterialKind::RoughDielectric { dist, eta, reflect, transmit }
                    }
                }
            }
            "plastic" | "roughplastic" => {
                let eta = self.ior(&p, "int_ior", 1.49)? / self.ior(&p, "ext_ior", 1.000277)?;
                let diffuse = self.texture(&p, "diffuse_reflectance", Rgb::splat(0.5))?;
                let specular = p.rgb("specular_reflectance", Rgb::WHITE)?;
                if p.bool("nonlinear", false)? {
                    return Err(el.err(format!("{ty}: nonlinear=true is not supported")));
                }
                let dist = if ty == "roughplastic" { Some(self.microfacet(&p)?) } else { None };
                Material::plastic(diffuse, specular, eta, dist)
            }
            other => return Err(el.err(format!("bsdf plugin '{other}' is not supported"))),
        };
        self.warn_unused(&p);
        Ok((kind, false))
    }

    fn shape(&mut self, el: &'a Element) -> Result<(), String> {
        let p = Props::new(el);
        let ty = el.attr("type").unwrap_or("");
        let to_world = p.transform("to_world")?;
        let flip = p.bool("flip_normals", false)?;
        // BSDF: a nested <bsdf> or a <ref> to one.
        let mut material = None;
        let mut emission = None;
        for c in &el.children {
            match c.tag.as_str() {
                "bsdf" => material = Some(self.material(c)?),
                "ref" => {
                    let target = self.resolve(c)?;
                    match target.tag.as_str() {
                        "bsdf" => material = Some(self.material(target)?),
                        other => return Err(c.err(format!("a shape cannot refer to a <{other}>"))),
                    }
                }
                "emitter" => {
                    if c.attr("type") != Some("area") {
                        return Err(c.err(format!(
                            "emitter '{}' cannot be attached to a shape (only 'area')",
                            c.attr("type").unwrap_or("")
                        )));
                    }
                    let ep = Props::new(c);
                    emission = Some(Emission { radiance: ep.rgb("radiance", Rgb::WHITE)?, two_sided: false });
                    self.warn_unused(&ep);
                }
                _ => {}
            }
        }
        let material = match material {
            Some(m) => m,
            None => self.b.default_material(),
        };
        let here = |e: String| el.err(format!("shape '{ty}': {e}"));
        match ty {
            "obj" | "ply" => {
                let file = p.string("filename").ok_or_else(|| el.err(format!("shape '{ty}' needs 'filename'")))?;
                let path = el.file.parent().unwrap_or(Path::new(".")).join(file);
                if !path.exists() {
                    return Err(el.err(format!("mesh file '{}' does not exist", path.display())));
                }
                let face_normals = p.bool("face_normals", false)?;
                let groups = self.b.load_mesh_file(&path, face_normals).map_err(|e| el.err(e))?;
                for g in &groups {
                    self.b.add_mesh_instance(&g.mesh, &to_world, false, material, emission, flip).map_err(here)?;
                }
            }
            "sphere" => {
                let c = p.point("center")?.unwrap_or(Vec3::ZERO);
                let r = p.float("radius", 1.0)?;
                self.b.add_sphere(c, r, &to_world, material, emission, flip).map_err(here)?;
            }
            "rectangle" | "cube" | "disk" => {
                let split = self.opts.bvh_split;
                let mesh = match ty {
                    "rectangle" => crate::geometry::quad_mesh(
                        [
                            Vec3 { x: -1.0, y: -1.0, z: 0.0 },
                            Vec3 { x: 1.0, y: -1.0, z: 0.0 },
                            Vec3 { x: 1.0, y: 1.0, z: 0.0 },
                            Vec3 { x: -1.0, y: 1.0, z: 0.0 },
                        ],
                        split,
                    ),
                    "cube" => crate::geometry::cube_mesh(split),
                    _ => crate::geometry::disk_mesh(256, split),
                };
                self.b.add_mesh_instance(&Arc::new(mesh), &to_world, false, material, emission, flip).map_err(here)?;
            }
            other => return Err(el.err(format!("shape plugin '{other}' is not supported"))),
        }
        self.warn_unused(&p);
        Ok(())
    }

    fn emitter(&mut self, el: &'a Element) -> Result<(), String> {
        let p = Props::new(el);
        let to_world = p.transform("to_world")?;
        match el.attr("type").unwrap_or("") {
            "point" => {
                let pos = match p.point("position")? {
                    Some(v) => v,
                    None => to_world.point(Vec3::ZERO),
                };
                self.b.add_light(Light::Point { position: pos, intensity: p.rgb("intensity", Rgb::WHITE)? });
            }
            "spot" => {
                let cutoff = p.float("cutoff_angle", 20.0)?;
                let beam = p.float("beam_width", cutoff * 0.75)?;
                let dir = to_world.vector(Vec3::Z).normalize();
                self.b.add_light(Light::Spot {
                    position: to_world.point(Vec3::ZERO),
                    frame: Frame::from_normal(dir),
                    intensity: p.rgb("intensity", Rgb::WHITE)?,
                    cutoff: cutoff.to_radians(),
                    beam: beam.min(cutoff).to_radians(),
                });
                if p.find("texture").is_some() {
                    return Err(el.err("spot: projected textures are not supported"));
                }
            }
            "directional" => {
                let d = match p.point("direction")? {
                    Some(v) => v,
                    None => to_world.vector(Vec3::Z),
                };
                self.b.add_directional(d, p.rgb("irradiance", Rgb::WHITE)?);
            }
            "constant" => self.b.add_constant_environment(p.rgb("radiance", Rgb::WHITE)?),
            "envmap" => {
                let file = p.string("filename").ok_or_else(|| el.err("envmap needs 'filename'"))?;
                let path = el.file.parent().unwrap_or(Path::new(".")).join(file);
                let img = Bitmap::load(&path, true).map_err(|e| el.err(e))?;
                self.b.add_envmap(img, p.float("scale", 1.0)?, to_world);
            }
            "area" => return Err(el.err("an area emitter must be nested inside a <shape>")),
            other => return Err(el.err(format!("emitter plugin '{other}' is not supported"))),
        }
        self.warn_unused(&p);
        Ok(())
    }

    fn sensor(&mut self, el: &'a Element) -> Result<(Camera, RenderSettings), String> {
        let ty = el.attr("type").unwrap_or("");
        if ty != "perspective" && ty != "thinlens" {
            return Err(el.err(format!("sensor plugin '{ty}' is not supported (perspective, thinlens)")));
        }
        let p = Props::new(el);
        let to_world = p.transform("to_world")?;
        let fov = match (p.opt_float("fov")?, p.string("focal_length")) {
            (Some(f), _) => f,
            (None, Some(fl)) => {
                let mm: f32 =
                    fl.trim_end_matches("mm").parse().map_err(|_| el.err(format!("bad focal_length '{fl}'")))?;
                // 35 mm film: 36 mm wide, fov along the diagonal of 36x24.
                2.0 * (43.266_615 / (2.0 * mm)).atan().to_degrees()
            }
            (None, None) => 2.0 * (43.266_615f32 / (2.0 * 50.0)).atan().to_degrees(),
        };
        let axis: FovAxis = match p.string("fov_axis") {
            Some(a) => a.parse().map_err(|e| el.err(e))?,
            None if p.opt_float("fov")?.is_some() => FovAxis::X,
            None => FovAxis::Diagonal,
        };
        let film = el.children.iter().find(|c| c.tag == "film");
        let (mut w, mut h, mut filter) = (768u32, 576u32, PixelFilter::Gaussian { stddev: 0.5 });
        if let Some(f) = film {
            if f.attr("type") != Some("hdrfilm") {
                return Err(f.err(format!("film plugin '{}' is not supported (hdrfilm)", f.attr("type").unwrap_or(""))));
            }
            let fp = Props::new(f);
            w = fp.int("width", 768)?.clamp(0, u32::MAX as i64) as u32;
            h = fp.int("height", 576)?.clamp(0, u32::MAX as i64) as u32;
            let _ = fp.string("pixel_format");
            let _ = fp.string("component_format");
            let _ = fp.string("file_format");
            let _ = fp.bool("banner", false);
            if let Some(rf) = f.children.iter().find(|c| c.tag == "rfilter") {
                let rp = Props::new(rf);
                filter = match rf.attr("type").unwrap_or("") {
                    "box" => PixelFilter::Box,
                    "tent" => PixelFilter::Tent { radius: rp.float("radius", 1.0)? },
                    "gaussian" => PixelFilter::Gaussian { stddev: rp.float("stddev", 0.5)? },
                    other => return Err(rf.err(format!("rfilter '{other}' is not supported (box, tent, gaussian)"))),
                };
            }
            if fp.find("crop_width").is_some() || fp.find("crop_offset_x").is_some() {
                return Err(f.err("film cropping is not supported"));
            }
            self.warn_unused(&fp);
        }
        let (w, h) = (self.opts.width.unwrap_or(w), self.opts.height.unwrap_or(h));
        super::json::check_resolution(w, h).map_err(|e| el.err(e))?;
        let mut camera = Camera::new(to_world, w, h, fov, axis);
        camera.near_clip = p.float("near_clip", 1e-2)?;
        camera.far_clip = p.float("far_clip", 1e4)?;
        // Perspective cameras accept (and, like Mitsuba, ignore) a focus distance.
        let _ = p.opt_float("focus_distance")?;
        if ty == "thinlens" {
            camera.lens_radius = p.float("aperture_radius", 0.0)?;
            camera.focus_distance = p.float("focus_distance", 0.0)?;
            if camera.focus_distance <= 0.0 {
                return Err(el.err("thinlens needs a positive focus_distance"));
            }
        }
        let mut settings = RenderSettings { filter, sampler: SamplerKind::Sobol, ..Default::default() };
        if let Some(s) = el.children.iter().find(|c| c.tag == "sampler") {
            let sp = Props::new(s);
            settings.seed = sp.int("seed", 0)?.max(0) as u64;
        }
        self.warn_unused(&p);
        Ok((camera, settings))
    }

    fn integrator(&mut self, el: &'a Element) -> Result<Integrator, String> {
        let p = Props::new(el);
        let ty = el.attr("type").unwrap_or("");
        let depth = |p: &Props, default: i64| -> Result<Option<u32>, String> {
            let d = p.int("max_depth", default)?;
            Ok(if d < 0 { None } else { Some(d as u32) })
        };
        let settings = match ty {
            "path" => PathSettings {
                max_depth: depth(&p, -1)?,
                rr_depth: p.int("rr_depth", 5)?.max(1) as u32,
                hide_emitters: p.bool("hide_emitters", false)?,
                ..Default::default()
            },
            "direct" => {
                let _ = p.int("emitter_samples", 1)?;
                let _ = p.int("bsdf_samples", 1)?;
                PathSettings {
                    max_depth: Some(2),
                    hide_emitters: p.bool("hide_emitters", false)?,
                    ..Default::default()
                }
            }
            other => {
                self.warnings.push(el.err(format!("integrator '{other}' is not supported; using 'path' instead")));
                PathSettings {
                    max_depth: depth(&p, -1)?,
                    rr_depth: p.int("rr_depth", 5)?.max(1) as u32,
                    hide_emitters: p.bool("hide_emitters", false)?,
                    ..Default::default()
                }
            }
        };
        if ty == "path" || ty == "direct" {
            self.warn_unused(&p);
        }
        Ok(Integrator::Path(settings))
    }
}
