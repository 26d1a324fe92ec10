//! Mitsuba 3 scene XML, read into a [`SceneDesc`]. `xml` reads the file into a tree
//! (includes, defaults, `$name` substitution, 0.x upgrades), `props` reads typed parameters,
//! and this module maps each plugin onto the description. What glint supports, plugin by
//! plugin and parameter by parameter, is listed in docs/mitsuba-support.md; anything else is
//! an error that names the plugin, the file and the line.

mod bsdfs;
mod hair;
mod instances;
mod media;
mod polarized;
mod projected;
mod props;
mod roughness;
mod spectrum;
mod surface;
pub mod xml;

use super::Define;
use crate::describe::{
    Aov, CameraDesc, CurveBasisDesc, Emission, FilmDesc, Geometry, IntegratorDesc, LightDesc, LightKind, MaterialRef,
    MediumDesc, PathSettings, SamplerDesc, SdfNormalsDesc, ShapeDesc, ShapeMedia, TextureDesc, VolpathSettings,
};
use crate::describe::{CropWindow, FovAxis, PixelFilter, Projection, SamplerKind, SpotFalloff};
use crate::error::{Error, SourceLoc};
use crate::materials::{MaterialDesc, SceneDesc};
use crate::math::{Rgb, Transform, Vec3};
use props::{color_of, Props};
use spectrum::SpectrumUse;
use std::collections::HashMap;
use std::path::Path;
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

struct Reader<'a> {
    /// Named top-level objects (`id`), for `<ref>`.
    named: HashMap<String, &'a Element>,
    /// Materials already described, by the element that defines them.
    material_index: HashMap<*const Element, usize>,
    materials: Vec<MaterialDesc>,
    shapes: Vec<ShapeDesc>,
    lights: Vec<LightDesc>,
    /// Mesh files placed by `instance`s of shape groups, each loaded once.
    meshes: Vec<crate::describe::MeshFileDesc>,
    warnings: Vec<String>,
    /// Errors found so far: a scene's unsupported features are all reported, one a line.
    errors: Vec<Error>,
    /// The scene's tree, for resolving file names through its search path.
    tree: &'a xml::SceneTree,
    source: xml::IncludeSource<'a>,
    /// Media already described, by the element that defines them.
    medium_index: HashMap<*const Element, usize>,
    media: Vec<MediumDesc>,
    /// Layers an `aov` integrator asks for.
    aovs: Vec<Aov>,
}

pub fn read(path: &Path, defines: &[Define]) -> Result<SceneDesc, Error> {
    let defines: Vec<(String, String)> = defines.iter().map(|d| (d.name.clone(), d.value.clone())).collect();
    describe_tree(path, &xml::load_tree(path, &defines)?, xml::IncludeSource::Disk)
}

/// Reads a Mitsuba scene given as text (for fuzzing and in-memory scenes); `path` names it.
pub fn read_str(text: &str, path: &Path, defines: &[Define]) -> Result<SceneDesc, Error> {
    let defines: Vec<(String, String)> = defines.iter().map(|d| (d.name.clone(), d.value.clone())).collect();
    describe_tree(path, &xml::load_tree_str(text, path, &defines, xml::IncludeSource::Disk)?, xml::IncludeSource::Disk)
}

/// [`read_str`] with `<include>`s read from `files` (path to text) instead of the disk: a
/// path that is not a key does not exist.
pub fn read_str_with_includes(
    text: &str,
    path: &Path,
    defines: &[Define],
    files: &HashMap<std::path::PathBuf, String>,
) -> Result<SceneDesc, Error> {
    let defines: Vec<(String, String)> = defines.iter().map(|d| (d.name.clone(), d.value.clone())).collect();
    let source = xml::IncludeSource::Memory(files);
    describe_tree(path, &xml::load_tree_str(text, path, &defines, source)?, source)
}

fn describe_tree<'a>(
    path: &Path,
    tree: &'a xml::SceneTree,
    source: xml::IncludeSource<'a>,
) -> Result<SceneDesc, Error> {
    let root = &tree.root;
    let mut r = Reader {
        tree,
        source,
        named: HashMap::new(),
        material_index: HashMap::new(),
        materials: Vec::new(),
        shapes: Vec::new(),
        lights: Vec::new(),
        meshes: Vec::new(),
        warnings: tree.warnings.clone(),
        errors: Vec::new(),
        medium_index: HashMap::new(),
        media: Vec::new(),
        aovs: Vec::new(),
    };
    for c in &root.children {
        if let Some(id) = c.attr("id") {
            if r.named.insert(id.to_string(), c).is_some() {
                return Err(c.err(format!("two objects have the id '{id}'")));
            }
        }
    }
    let mut sensor = None;
    let mut integrator_el = None;
    // Each object that fails adds its error and the reader goes on, so that one run reports
    // every unsupported feature of the scene.
    for c in &root.children {
        let result = match c.tag.as_str() {
            "shape" => r.shape(c),
            // A named area emitter is described when a shape refers to it.
            "emitter" if c.attr("type") == Some("area") && c.attr("id").is_some() => Ok(()),
            "emitter" => r.emitter(c),
            "sensor" => {
                sensor = Some(c);
                Ok(())
            }
            "integrator" => {
                integrator_el = Some(c);
                Ok(())
            }
            // Named BSDFs and textures are described when a shape refers to them, samplers
            // and films when the sensor does (an unreferenced one is ignored, as by Mitsuba).
            // Media too, when a shape or the sensor does.
            "bsdf" | "texture" | "sampler" | "film" | "medium" => Ok(()),
            "phase" | "volume" => {
                Err(c.err(format!("<{}> at scene level is not supported (nest it in its <medium>)", c.tag)))
            }
            other => Err(c.err(format!("unexpected element <{other}> in <scene>"))),
        };
        r.note(result);
    }
    let described = r.describe_sensor(path, sensor, integrator_el);
    let described = r.note(described);
    if let Some(e) = Error::many(std::mem::take(&mut r.errors)) {
        return Err(e);
    }
    let (camera, film, seed, spp, integrator) = described.expect("no errors, so described");
    let mut desc = SceneDesc::empty(camera, film);
    desc.source = Some(path.to_path_buf());
    desc.includes = tree.included.clone();
    desc.integrator = integrator;
    desc.film.aovs = std::mem::take(&mut r.aovs);
    desc.sampler = SamplerDesc { kind: SamplerKind::Sobol, spp, seed };
    desc.materials = r.materials;
    desc.shapes = r.shapes;
    desc.meshes = r.meshes;
    desc.lights = r.lights;
    if (!desc.media.is_empty() || !r.media.is_empty()) && !matches!(desc.integrator, IntegratorDesc::Volpath(_)) {
        r.warnings.push(format!(
                "{}: the scene has media, which only the volpath integrator renders (they are ignored, as Mitsuba's other integrators ignore them)",
                path.display()
            ));
    }
    desc.media = r.media;
    desc.warnings = r.warnings;
    Ok(desc)
}

impl<'a> Reader<'a> {
    /// The most errors one run reports.
    const MAX_ERRORS: usize = 100;

    /// Keeps an error (once: a BSDF shared by several shapes fails once) and goes on.
    fn note<T>(&mut self, result: Result<T, Error>) -> Option<T> {
        match result {
            Ok(v) => Some(v),
            Err(e) => {
                if self.errors.len() < Self::MAX_ERRORS && !self.errors.contains(&e) {
                    self.errors.push(e);
                } else if self.errors.len() == Self::MAX_ERRORS {
                    self.errors.push(Error::new(format!("(more errors; the first {} are shown)", Self::MAX_ERRORS)));
                }
                None
            }
        }
    }

    /// The camera, film, seed, samples per pixel and integrator.
    #[allow(clippy::type_complexity)]
    fn describe_sensor(
        &mut self,
        path: &Path,
        sensor: Option<&'a Element>,
        integrator_el: Option<&'a Element>,
    ) -> Result<(CameraDesc, FilmDesc, u64, u32, IntegratorDesc), Error> {
        let root = &self.tree.root;
        let sensor = sensor.ok_or_else(|| Error::at(&SourceLoc::file(path), "the scene has no <sensor>"))?;
        let sampler_el = self.sensor_child(sensor, "sampler")?;
        let film_el = self.sensor_child(sensor, "film")?;
        for c in &root.children {
            let used = [sampler_el, film_el].iter().flatten().any(|u| std::ptr::eq(*u, c));
            if matches!(c.tag.as_str(), "sampler" | "film") && !used {
                self.warnings.push(
                    c.err(format!(
                        "<{}> at scene level is not used by the sensor (it would need a <ref id> there) and was ignored, as Mitsuba ignores it",
                        c.tag
                    ))
                    .to_string(),
                );
            }
        }
        let (camera, film, seed) = self.sensor(sensor, film_el, sampler_el)?;
        let integrator = match integrator_el {
            Some(e) => self.integrator(e)?,
            None => IntegratorDesc::Path(PathSettings::default()),
        };
        Ok((camera, film, seed, settings_spp(sampler_el)?.unwrap_or(16), integrator))
    }
}

fn settings_spp(sampler: Option<&Element>) -> Result<Option<u32>, Error> {
    if let Some(c) = sampler {
        let p = Props::new(c);
        let n = p.int("sample_count", 4)?;
        let max = crate::describe::limits::MAX_SPP as i64;
        if n < 1 || n > max {
            return Err(c.err(format!("sample_count {n} is out of range (1 to {max})")));
        }
        return Ok(Some(n as u32));
    }
    Ok(None)
}

/// `hdrfilm`'s crop window (`crop_offset_x/y`, default 0; `crop_width/height`, default the
/// rest of the film), checked as Mitsuba checks it; `None` when it is the whole film.
fn film_crop(fp: &Props, width: u32, height: u32) -> Result<Option<CropWindow>, Error> {
    let (ox, oy) = (fp.int("crop_offset_x", 0)?, fp.int("crop_offset_y", 0)?);
    let (cw, ch) = (fp.int("crop_width", width as i64 - ox)?, fp.int("crop_height", height as i64 - oy)?);
    let fits = |o: i64, s: i64, full: u32| o >= 0 && s >= 1 && o + s <= full as i64;
    if !fits(ox, cw, width) || !fits(oy, ch, height) {
        return Err(fp.el.err(format!(
            "the crop window ({cw}x{ch} at {ox}, {oy}) must be at least one pixel and lie within the {width}x{height} film"
        )));
    }
    let crop = CropWindow { offset_x: ox as u32, offset_y: oy as u32, width: cw as u32, height: ch as u32 };
    Ok((crop != CropWindow { offset_x: 0, offset_y: 0, width, height }).then_some(crop))
}

fn matrix(t: &Transform) -> crate::describe::Matrix4 {
    t.m.0
}

impl<'a> Reader<'a> {
    fn warn_unused(&mut self, p: &Props) {
        // Shapes and sensors read their media themselves.
        if !matches!(p.el.tag.as_str(), "shape" | "sensor") {
            for c in &p.el.children {
                if self.is_medium(c) {
                    self.note::<()>(Err(c.err(format!(
                        "a <medium> inside a <{}> is not supported (media attach to shapes and sensors)",
                        p.el.tag
                    ))));
                }
            }
        }
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

    /// A plugin's `filename`, found through the scene's search path (`<path>`).
    fn resolve_file(&self, el: &Element, name: &str) -> std::path::PathBuf {
        self.tree.resolve(el, name, self.source)
    }

    /// Follows `<ref id>` to the named object.
    fn resolve(&self, el: &'a Element) -> Result<&'a Element, Error> {
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

    fn texture(&self, p: &Props<'a>, name: &str, default: Rgb) -> Result<TextureDesc, Error> {
        let Some(e) = p.find(name) else { return Ok(TextureDesc::constant(default)) };
        self.texture_element(e)
    }

    /// The texture (or colour) an element gives.
    fn texture_element(&self, e: &'a Element) -> Result<TextureDesc, Error> {
        let e = self.resolve(e)?;
        if e.tag != "texture" {
            return Ok(TextureDesc::constant(color_of(e, SpectrumUse::Reflectance)?));
        }
        let tp = Props::new(e);
        let to_uv = tp.transform("to_uv")?;
        // Only scale and translation of uv are meaningful for glint's textures.
        let o = to_uv.point(Vec3::ZERO);
        let sx = to_uv.vector(Vec3::X).x;
        let sy = to_uv.vector(Vec3::Y).y;
        let (uv_scale, uv_offset) = ([sx, sy], [o.x, o.y]);
        match e.attr("type").unwrap_or("") {
            "bitmap" => {
                let file = tp.string("filename").ok_or_else(|| e.err("bitmap texture needs 'filename'"))?;
                let path = self.resolve_file(e, file);
                let raw = tp.bool("raw", false)?;
                let _ = tp.string("filter_type");
                let _ = tp.string("wrap_mode");
                Ok(TextureDesc::Bitmap { file: path, raw, uv_scale, uv_offset, loc: e.loc(), texels: None })
            }
            "checkerboard" => Ok(TextureDesc::Checkerboard {
                color0: tp.rgb("color0", Rgb::splat(0.4))?,
                color1: tp.rgb("color1", Rgb::splat(0.2))?,
                uv_scale,
                uv_offset,
            }),
            "mesh_attribute" => self.mesh_attribute(e, &tp),
            other => {
                Err(e.err(format!("texture plugin '{other}' is not supported (bitmap, checkerboard, mesh_attribute)")))
            }
        }
    }

    fn shape(&mut self, el: &'a Element) -> Result<(), Error> {
        match el.attr("type").unwrap_or("") {
            "shapegroup" => self.shape_group(el),
            "instance" => self.instance(el),
            _ => self.placed_shape(el, None),
        }
    }

    /// A shape, placed by its `to_world` and then (inside a shape group) by the instance's.
    fn placed_shape(&mut self, el: &'a Element, instance_to_world: Option<&Transform>) -> Result<(), Error> {
        let p = Props::new(el);
        let ty = el.attr("type").unwrap_or("");
        let own_to_world = p.transform("to_world")?;
        let to_world = match instance_to_world {
            Some(t) => t.then_after(&own_to_world),
            None => own_to_world,
        };
        let flip_normals = p.bool("flip_normals", false)?;
        // BSDF: a nested <bsdf> or a <ref> to one.
        let mut material = None;
        let mut emission = None;
        let mut media = ShapeMedia::default();
        // Each child's error is kept and the next child read, so that a shape with several
        // unsupported features reports them all.
        let errors_before = self.errors.len();
        for c in &el.children {
            let result = match c.tag.as_str() {
                "bsdf" => self.material(c).map(|m| material = Some(m)),
                "ref" => self.resolve(c).and_then(|target| match target.tag.as_str() {
                    "bsdf" => self.material(target).map(|m| material = Some(m)),
                    "medium" => self.shape_medium(c, &mut media),
                    // A named area emitter at scene level, as Mitsuba allows.
                    "emitter" => self.area_emitter(target).map(|e| emission = Some(e)),
                    other => Err(c.err(format!("a shape cannot refer to a <{other}>"))),
                }),
                "emitter" => self.area_emitter(c).map(|e| emission = Some(e)),
                "medium" => self.shape_medium(c, &mut media),
                _ => Ok(()),
            };
            self.note(result);
        }
        if ty == "sdfgrid" {
            if emission.is_some() {
                self.note::<()>(Err(el.err("an sdfgrid cannot emit light (as in Mitsuba)")));
            }
            if media != ShapeMedia::default() {
                self.note::<()>(Err(el.err("sdfgrid: interior/exterior media are not supported")));
            }
            if flip_normals {
                self.note::<()>(Err(el.err("sdfgrid: flip_normals is not supported (Mitsuba ignores it)")));
            }
        }
        if ty == "linearcurve" || ty == "bsplinecurve" {
            if emission.is_some() {
                self.note::<()>(Err(el.err(format!("{ty}: emitting curves are not supported"))));
            }
            if media != ShapeMedia::default() {
                self.note::<()>(Err(el.err(format!("{ty}: interior/exterior media are not supported"))));
            }
            if flip_normals {
                self.note::<()>(Err(el.err(format!("{ty}: flip_normals is not supported"))));
            }
        }
        // Mitsuba gives a shape without a BSDF a diffuse 0.5 one, and an emitting shape a
        // black one (its light does not reflect light).
        let material = match (material, &emission) {
            (Some(m), _) => MaterialRef::Index(m),
            (None, Some(_)) => MaterialRef::Black,
            (None, None) => MaterialRef::DefaultDiffuse,
        };
        let geometry = match ty {
            "obj" | "ply" => {
                let file = p.string("filename").ok_or_else(|| el.err(format!("shape '{ty}' needs 'filename'")))?;
                let path = self.resolve_file(el, file);
                Geometry::MeshFile { file: path, face_normals: p.bool("face_normals", false)?, shape_index: 0 }
            }
            "cylinder" => Geometry::Cylinder {
                p0: p.point("p0")?.unwrap_or(Vec3::ZERO),
                p1: p.point("p1")?.unwrap_or(Vec3::Z),
                radius: p.float("radius", 1.0)?,
            },
            "serialized" => {
                let file = p.string("filename").ok_or_else(|| el.err("shape 'serialized' needs 'filename'"))?;
                let path = self.resolve_file(el, file);
                if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("serialized")) {
                    return Err(
                        el.err(format!("serialized: glint reads these meshes from .serialized files, not '{file}'"))
                    );
                }
                let index = p.int("shape_index", 0)?;
                if !(0..=u32::MAX as i64).contains(&index) {
                    return Err(el.err(format!("serialized: shape_index {index} must be 0 or more")));
                }
                Geometry::MeshFile {
                    file: path,
                    face_normals: p.bool("face_normals", false)?,
                    shape_index: index as u32,
                }
            }
            "sphere" => {
                Geometry::Sphere { center: p.point("center")?.unwrap_or(Vec3::ZERO), radius: p.float("radius", 1.0)? }
            }
            "rectangle" => Geometry::Rectangle,
            "cube" => Geometry::Cube,
            "disk" => Geometry::Disk,
            "sdfgrid" => {
                // Mitsuba's `grid` (a tensor) can only be given from Python or C++.
                let file = p.string("filename").ok_or_else(|| el.err("shape 'sdfgrid' needs 'filename'"))?;
                let normals = match p.string("normals").unwrap_or("smooth") {
                    "smooth" => SdfNormalsDesc::Smooth,
                    "analytic" => SdfNormalsDesc::Analytic,
                    other => {
                        let at = p.find("normals").unwrap_or(el);
                        return Err(at.err(format!("sdfgrid: normals '{other}' must be 'analytic' or 'smooth'")));
                    }
                };
                Geometry::SdfGrid { file: self.resolve_file(el, file), normals }
            }
            "linearcurve" | "bsplinecurve" => {
                let file = p.string("filename").ok_or_else(|| el.err(format!("shape '{ty}' needs 'filename'")))?;
                let basis = if ty == "linearcurve" { CurveBasisDesc::Linear } else { CurveBasisDesc::BSpline };
                Geometry::Curves { file: self.resolve_file(el, file), basis }
            }
            other => return Err(el.err(format!("shape plugin '{other}' is not supported"))),
        };
        self.warn_unused(&p);
        if self.errors.len() > errors_before {
            return Ok(());
        }
        // Meshes of a shape group are loaded once and traced through each instance's
        // transform (as Mitsuba shares a group's BVH among its instances).
        let geometry = match (instance_to_world, geometry) {
            (Some(_), Geometry::MeshFile { file, face_normals, shape_index }) => {
                Geometry::Instance { mesh: self.shared_mesh(el, file, face_normals, shape_index) }
            }
            (_, g) => g,
        };
        self.shapes.push(ShapeDesc {
            geometry,
            to_world: matrix(&to_world),
            material,
            use_mtl: false,
            emission,
            flip_normals,
            loc: el.loc(),
            media,
            // A group's shape is drawn once per instance: its id names none of them.
            id: if instance_to_world.is_none() { el.attr("id").map(str::to_string) } else { None },
        });
        Ok(())
    }

    fn area_emitter(&mut self, c: &'a Element) -> Result<Emission, Error> {
        if c.attr("type") != Some("area") {
            return Err(c.err(format!(
                "emitter '{}' cannot be attached to a shape (only 'area')",
                c.attr("type").unwrap_or("")
            )));
        }
        let ep = Props::new(c);
        // A colour, or any texture glint reads, taken at the surface's uv as Mitsuba does.
        let radiance = match ep.find("radiance").map(|e| self.resolve(e)).transpose()? {
            Some(e) if e.tag == "texture" => self.texture_element(e)?,
            _ => TextureDesc::constant(ep.rgb_as("radiance", Rgb::WHITE, SpectrumUse::Emission)?),
        };
        let emission = Emission { radiance, two_sided: false };
        self.warn_unused(&ep);
        Ok(emission)
    }

    fn emitter(&mut self, el: &'a Element) -> Result<(), Error> {
        let p = Props::new(el);
        let to_world = p.transform("to_world")?;
        let light = match el.attr("type").unwrap_or("") {
            "point" => LightKind::Point {
                position: match p.point("position")? {
                    Some(v) => v,
                    None => to_world.point(Vec3::ZERO),
                },
                intensity: p.rgb_as("intensity", Rgb::WHITE, SpectrumUse::Emission)?,
            },
            "spot" if p.find("texture").is_some() => self.textured_spot(&p, &to_world)?,
            "projector" => self.projector(&p, &to_world)?,
            "spot" => {
                let cutoff = p.float("cutoff_angle", 20.0)?;
                LightKind::Spot {
                    position: to_world.point(Vec3::ZERO),
                    direction: to_world.vector(Vec3::Z),
                    intensity: p.rgb_as("intensity", Rgb::WHITE, SpectrumUse::Emission)?,
                    cutoff_degrees: cutoff,
                    beam_degrees: p.float("beam_width", cutoff * 0.75)?,
                    falloff: SpotFalloff::Linear,
                }
            }
            "directional" => LightKind::Directional {
                direction: match p.point("direction")? {
                    Some(v) => v,
                    None => to_world.vector(Vec3::Z),
                },
                irradiance: p.rgb_as("irradiance", Rgb::WHITE, SpectrumUse::Emission)?,
            },
            "constant" => LightKind::Constant { radiance: p.rgb_as("radiance", Rgb::WHITE, SpectrumUse::Emission)? },
            "envmap" => {
                let file = p.string("filename").ok_or_else(|| el.err("envmap needs 'filename'"))?;
                LightKind::EnvMap {
                    file: self.resolve_file(el, file),
                    scale: p.float("scale", 1.0)?,
                    to_world: matrix(&to_world),
                    texels: None,
                }
            }
            "area" => return Err(el.err("an area emitter must be nested inside a <shape>")),
            other => return Err(el.err(format!("emitter plugin '{other}' is not supported"))),
        };
        self.warn_unused(&p);
        self.lights.push(LightDesc { light, name: el.attr("id").map(str::to_string), loc: el.loc() });
        Ok(())
    }

    /// The sensor's `<film>` or `<sampler>`: nested, or a `<ref id>` to one at scene level
    /// (Mitsuba accepts both); two are an error, as in Mitsuba.
    fn sensor_child(&self, sensor: &'a Element, tag: &str) -> Result<Option<&'a Element>, Error> {
        let mut found = None;
        for c in &sensor.children {
            let target = if c.tag == "ref" { self.resolve(c)? } else { c };
            if target.tag == tag {
                if found.is_some() {
                    return Err(c.err(format!("only one <{tag}> can be given per sensor")));
                }
                found = Some(target);
            }
        }
        Ok(found)
    }

    /// The camera, the film and the sampler's seed.
    fn sensor(
        &mut self,
        el: &'a Element,
        film_el: Option<&'a Element>,
        sampler_el: Option<&'a Element>,
    ) -> Result<(CameraDesc, FilmDesc, u64), Error> {
        let ty = el.attr("type").unwrap_or("");
        if !matches!(ty, "perspective" | "thinlens" | "orthographic") {
            return Err(el.err(format!("sensor plugin '{ty}' is not supported (perspective, thinlens, orthographic)")));
        }
        let p = Props::new(el);
        let to_world = p.transform("to_world")?;
        let orthographic = ty == "orthographic";
        // An orthographic camera has no field of view (its fov is an unused placeholder).
        let fov_given = if orthographic { (Some(45.0), None) } else { (p.opt_float("fov")?, p.string("focal_length")) };
        let fov = match fov_given {
            (Some(f), _) => f,
            (None, Some(fl)) => {
                let mm: f32 =
                    fl.trim_end_matches("mm").parse().map_err(|_| el.err(format!("bad focal_length '{fl}'")))?;
                // 35 mm film: 36 mm wide, fov along the diagonal of 36x24.
                2.0 * (43.266_615 / (2.0 * mm)).atan().to_degrees()
            }
            (None, None) => 2.0 * (43.266_615f32 / (2.0 * 50.0)).atan().to_degrees(),
        };
        let fov_axis: FovAxis = match (orthographic, p.string("fov_axis")) {
            (true, _) => FovAxis::X,
            (false, Some(a)) => a.parse().map_err(|e: String| el.err(e))?,
            (false, None) if p.opt_float("fov")?.is_some() => FovAxis::X,
            (false, None) => FovAxis::Diagonal,
        };
        let mut film = FilmDesc {
            width: 768,
            height: 576,
            filter: PixelFilter::Gaussian { stddev: 0.5 },
            loc: el.loc(),
            crop: None,
            aovs: Vec::new(),
        };
        if let Some(f) = film_el {
            if f.attr("type") != Some("hdrfilm") {
                return Err(f.err(format!("film plugin '{}' is not supported (hdrfilm)", f.attr("type").unwrap_or(""))));
            }
            let fp = Props::new(f);
            let side = |name: &str, default: i64| -> Result<u32, Error> {
                let v = fp.int(name, default)?;
                let max = crate::describe::limits::MAX_SIDE as i64;
                if v < 1 || v > max {
                    return Err(f.err(format!("film {name} {v} is out of range (1 to {max})")));
                }
                Ok(v as u32)
            };
            film.width = side("width", 768)?;
            film.height = side("height", 576)?;
            film.loc = f.loc();
            let _ = fp.string("pixel_format");
            let _ = fp.string("component_format");
            let _ = fp.string("file_format");
            let _ = fp.bool("banner", false);
            if let Some(rf) = f.children.iter().find(|c| c.tag == "rfilter") {
                let rp = Props::new(rf);
                film.filter = match rf.attr("type").unwrap_or("") {
                    "box" => PixelFilter::Box,
                    "tent" => PixelFilter::Tent { radius: rp.float("radius", 1.0)? },
                    "gaussian" => PixelFilter::Gaussian { stddev: rp.float("stddev", 0.5)? },
                    other => return Err(rf.err(format!("rfilter '{other}' is not supported (box, tent, gaussian)"))),
                };
            }
            film.crop = film_crop(&fp, film.width, film.height)?;
            self.warn_unused(&fp);
        }
        let mut camera = CameraDesc {
            to_world: Some(matrix(&to_world)),
            fov_degrees: fov,
            fov_axis,
            lens_radius: 0.0,
            focus_distance: 1.0,
            near_clip: p.float("near_clip", 1e-2)?,
            far_clip: p.float("far_clip", 1e4)?,
            loc: el.loc(),
            medium: self.sensor_medium(el)?,
            projection: if orthographic { Projection::Orthographic } else { Projection::Perspective },
            id: el.attr("id").map(str::to_string),
        };
        // Perspective cameras accept (and, like Mitsuba, ignore) a focus distance.
        let _ = p.opt_float("focus_distance")?;
        if ty == "thinlens" {
            camera.lens_radius = p.float("aperture_radius", 0.0)?;
            camera.focus_distance = p.float("focus_distance", 0.0)?;
            if !(camera.focus_distance > 0.0) {
                return Err(el.err("thinlens needs a positive focus_distance"));
            }
        }
        let mut seed = 0;
        if let Some(s) = sampler_el {
            let sp = Props::new(s);
            let v = sp.int("seed", 0)?;
            if v < 0 {
                return Err(s.err(format!("seed {v} must not be negative")));
            }
            seed = v as u64;
        }
        self.warn_unused(&p);
        Ok((camera, film, seed))
    }

    fn integrator(&mut self, el: &'a Element) -> Result<IntegratorDesc, Error> {
        let p = Props::new(el);
        let ty = el.attr("type").unwrap_or("");
        let depth = |p: &Props, default: i64| -> Result<Option<u32>, Error> {
            let d = p.int("max_depth", default)?;
            if d >= u32::MAX as i64 {
                return Err(
                    el.err(format!("max_depth {d} is out of range (-1 for unbounded, or 0 to {})", u32::MAX - 1))
                );
            }
            Ok(if d < 0 { None } else { Some(d as u32) })
        };
        let rr_depth = |p: &Props| -> Result<u32, Error> {
            let d = p.int("rr_depth", 5)?;
            if !(1..u32::MAX as i64).contains(&d) {
                return Err(el.err(format!("rr_depth {d} is out of range (1 to {})", u32::MAX - 1)));
            }
            Ok(d as u32)
        };
        if ty == "direct" {
            return self.direct_integrator(el, &p);
        }
        if ty == "aov" {
            return self.aov_integrator(el, &p);
        }
        // volpathmis is volpath with spectral MIS, which glint's volpath always uses; Mitsuba's
        // prbvolpath renders (its primal image) what volpath does, with the same parameters.
        if ty == "volpath" || ty == "volpathmis" || ty == "prbvolpath" {
            let settings = VolpathSettings {
                max_depth: depth(&p, -1)?,
                rr_depth: rr_depth(&p)?,
                hide_emitters: p.bool("hide_emitters", false)?,
            };
            self.warn_unused(&p);
            return Ok(IntegratorDesc::Volpath(settings));
        }
        // prb and prb_basic (path replay backpropagation, with and without next-event
        // estimation) render the image path does, with the same parameters.
        let settings = match ty {
            "path" | "prb" | "prb_basic" => PathSettings {
                max_depth: depth(&p, -1)?,
                rr_depth: rr_depth(&p)?,
                hide_emitters: p.bool("hide_emitters", false)?,
                ..Default::default()
            },
            other => {
                self.warnings
                    .push(el.err(format!("integrator '{other}' is not supported; using 'path' instead")).to_string());
                PathSettings {
                    max_depth: depth(&p, -1)?,
                    rr_depth: rr_depth(&p)?,
                    hide_emitters: p.bool("hide_emitters", false)?,
                    ..Default::default()
                }
            }
        };
        if matches!(ty, "path" | "prb" | "prb_basic") {
            self.warn_unused(&p);
        }
        Ok(IntegratorDesc::Path(settings))
    }

    /// Mitsuba's `aov`: the image of its (first) nested integrator, and the layers its
    /// `aovs` names ("name:type, ..."), those glint's film has: `albedo`, `depth`,
    /// `position`, and `sh_normal` as `normal`. They keep glint's names (`depth.Z`, ...), not
    /// the file's; a type glint has no layer for is a warning.
    fn aov_integrator(&mut self, el: &'a Element, p: &Props<'a>) -> Result<IntegratorDesc, Error> {
        let mut nested = el.children.iter().filter(|c| c.tag == "integrator");
        let Some(first) = nested.next() else {
            return Err(el.err("aov: give the integrator that renders the image as a nested <integrator>"));
        };
        if nested.next().is_some() {
            self.warnings.push(el.err("aov: only the first nested integrator is rendered").to_string());
        }
        let mut missing = Vec::new();
        for entry in p.string("aovs").unwrap_or("").split(',').map(str::trim).filter(|e| !e.is_empty()) {
            let Some((_, ty)) = entry.split_once(':') else {
                return Err(el.err(format!("aov: '{entry}' in aovs is not name:type")));
            };
            let aov = match ty.trim() {
                "albedo" => Aov::Albedo,
                "depth" => Aov::Depth,
                "position" => Aov::Position,
                "sh_normal" => Aov::Normal,
                _ => {
                    missing.push(entry);
                    continue;
                }
            };
            if !self.aovs.contains(&aov) {
                self.aovs.push(aov);
            }
        }
        if !missing.is_empty() {
            self.warnings.push(
                el.err(format!(
                    "aov: no layer for {} (glint has albedo, depth, position, sh_normal)",
                    missing.join(", ")
                ))
                .to_string(),
            );
        }
        self.integrator(first)
    }

    /// Mitsuba's `direct`: `shading_samples` (default 1) sets both counts unless
    /// `emitter_samples` or `bsdf_samples` is given (giving both kinds is an error there too).
    fn direct_integrator(&mut self, el: &'a Element, p: &Props<'a>) -> Result<IntegratorDesc, Error> {
        let max = crate::describe::limits::MAX_DIRECT_SAMPLES;
        let count = |name: &str, default: u32| -> Result<u32, Error> {
            let v = p.int(name, default as i64)?;
            if !(0..=max as i64).contains(&v) {
                return Err(el.err(format!("{name} {v} is out of range (0 to {max})")));
            }
            Ok(v as u32)
        };
        let split = p.find("emitter_samples").is_some() || p.find("bsdf_samples").is_some();
        if split && p.find("shading_samples").is_some() {
            return Err(el.err("give either shading_samples or emitter_samples/bsdf_samples, not both"));
        }
        let shading = count("shading_samples", 1)?;
        let settings = crate::describe::DirectSettings {
            emitter_samples: count("emitter_samples", shading)?,
            bsdf_samples: count("bsdf_samples", shading)?,
            hide_emitters: p.bool("hide_emitters", false)?,
        };
        if settings.emitter_samples == 0 && settings.bsdf_samples == 0 {
            return Err(el.err("direct needs at least one emitter or BSDF sample"));
        }
        self.warn_unused(p);
        Ok(IntegratorDesc::Direct(settings))
    }
}
