//! glint's native JSON scene format (documented in docs/scene-format.md). The serde
//! structures below are the scene *description*, as parsed; `load` turns them into a
//! render-ready [`Scene`] through the [`SceneBuilder`]. Structural errors come from serde
//! with their line and column; semantic ones (an unknown material name, say) are located by
//! finding the offending text in the file.

use super::builder::{Emission, SceneBuilder};
use super::{LoadOptions, LoadedScene};
use crate::bsdf::{Microfacet, MicrofacetKind};
use crate::camera::{Camera, FovAxis};
use crate::integrators::{Integrator, PathSettings, Strategy, WhittedSettings};
use crate::lights::Light;
use crate::materials::{conductor_preset, Bitmap, Material, MaterialKind, Texture};
use crate::math::{Frame, Mat4, Rgb, Transform, Vec3};
use crate::render::{PixelFilter, RenderSettings};
use crate::sampling::SamplerKind;
use crate::scene::LightSelection;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonScene {
    camera: JsonCamera,
    film: JsonFilm,
    #[serde(default)]
    integrator: Option<JsonIntegrator>,
    #[serde(default)]
    sampler: JsonSampler,
    #[serde(default)]
    materials: BTreeMap<String, JsonMaterial>,
    #[serde(default)]
    meshes: BTreeMap<String, JsonMeshFile>,
    #[serde(default)]
    shapes: Vec<JsonShape>,
    #[serde(default)]
    lights: Vec<JsonLight>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonCamera {
    position: [f32; 3],
    look_at: [f32; 3],
    #[serde(default = "default_up")]
    up: [f32; 3],
    fov: f32,
    #[serde(default)]
    fov_axis: Option<String>,
    #[serde(default)]
    aperture_radius: f32,
    #[serde(default)]
    focus_distance: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonFilm {
    width: u32,
    height: u32,
    #[serde(default)]
    filter: Option<String>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum JsonIntegrator {
    Whitted {
        #[serde(default)]
        max_depth: Option<u32>,
        #[serde(default)]
        background: Option<[f32; 3]>,
    },
    Path {
        #[serde(default)]
        max_depth: Option<i64>,
        #[serde(default)]
        rr_depth: Option<u32>,
        #[serde(default)]
        rr_probability: Option<f32>,
        #[serde(default)]
        strategy: Option<Strategy>,
        #[serde(default)]
        light_selection: Option<String>,
        #[serde(default)]
        hide_emitters: bool,
    },
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct JsonSampler {
    #[serde(default, rename = "type")]
    kind: Option<String>,
    #[serde(default)]
    spp: Option<u32>,
    #[serde(default)]
    seed: Option<u64>,
}

/// A colour: one number (grey) or three.
#[derive(Deserialize, Clone, Copy)]
#[serde(untagged)]
enum JsonColor {
    Grey(f32),
    Rgb([f32; 3]),
}

impl JsonColor {
    fn rgb(self) -> Rgb {
        match self {
            JsonColor::Grey(v) => Rgb::splat(v),
            JsonColor::Rgb(a) => Rgb::from_array(a),
        }
    }
}

#[derive(Deserialize, Clone)]
#[serde(untagged)]
enum JsonTexture {
    Color(JsonColor),
    Bitmap {
        texture: String,
        #[serde(default)]
        raw: bool,
        #[serde(default)]
        uv_scale: Option<[f32; 2]>,
    },
    Checker {
        checkerboard: [JsonColor; 2],
        #[serde(default)]
        uv_scale: Option<[f32; 2]>,
    },
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum JsonMaterial {
    Diffuse {
        reflectance: JsonTexture,
        #[serde(default)]
        two_sided: Option<bool>,
    },
    Phong {
        kd: JsonTexture,
        #[serde(default)]
        ks: Option<JsonColor>,
        #[serde(default)]
        exponent: Option<f32>,
        #[serde(default)]
        two_sided: Option<bool>,
    },
    /// A perfect mirror: conductor with reflectance 1 (or `specular`).
    Mirror {
        #[serde(default)]
        specular: Option<JsonColor>,
    },
    Conductor {
        #[serde(default)]
        metal: Option<String>,
        #[serde(default)]
        eta: Option<JsonColor>,
        #[serde(default)]
        k: Option<JsonColor>,
        #[serde(default)]
        specular: Option<JsonColor>,
        #[serde(default)]
        alpha: Option<f32>,
        #[serde(default)]
        distribution: Option<String>,
    },
    Dielectric {
        #[serde(default)]
        ior: Option<f32>,
        #[serde(default)]
        alpha: Option<f32>,
        #[serde(default)]
        distribution: Option<String>,
        #[serde(default)]
        thin: bool,
    },
    Plastic {
        diffuse: JsonTexture,
        #[serde(default)]
        ior: Option<f32>,
        #[serde(default)]
        alpha: Option<f32>,
        #[serde(default)]
        distribution: Option<String>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonMeshFile {
    file: String,
    #[serde(default)]
    face_normals: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonShape {
    #[serde(rename = "type")]
    kind: String,
    #[serde(default)]
    file: Option<String>,
    #[serde(default)]
    mesh: Option<String>,
    #[serde(default)]
    center: Option<[f32; 3]>,
    #[serde(default)]
    radius: Option<f32>,
    #[serde(default)]
    material: Option<String>,
    #[serde(default)]
    transform: Vec<JsonTransformOp>,
    #[serde(default)]
    emission: Option<JsonColor>,
    #[serde(default)]
    two_sided_emission: bool,
    #[serde(default)]
    flip_normals: bool,
    #[serde(default)]
    face_normals: bool,
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
enum JsonTransformOp {
    Translate([f32; 3]),
    Scale(JsonColor),
    Rotate { axis: [f32; 3], angle: f32 },
    Matrix([f32; 16]),
    LookAt { origin: [f32; 3], target: [f32; 3], up: [f32; 3] },
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum JsonLight {
    Point {
        position: [f32; 3],
        intensity: JsonColor,
    },
    Spot {
        position: [f32; 3],
        target: [f32; 3],
        intensity: JsonColor,
        #[serde(default)]
        cutoff_angle: Option<f32>,
        #[serde(default)]
        beam_width: Option<f32>,
    },
    Directional {
        direction: [f32; 3],
        irradiance: JsonColor,
    },
    Constant {
        radiance: JsonColor,
    },
    Envmap {
        file: String,
        #[serde(default)]
        scale: Option<f32>,
        #[serde(default)]
        transform: Vec<JsonTransformOp>,
    },
}

/// Line (1-based) of the first occurrence of `needle` in `text`, for error messages.
fn line_of(text: &str, needle: &str) -> usize {
    text.find(needle).map_or(1, |i| text[..i].matches('\n').count() + 1)
}

struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
    dir: PathBuf,
}

impl Ctx<'_> {
    /// "file:line: message", the line found by searching for `needle`.
    fn err(&self, needle: &str, msg: impl std::fmt::Display) -> String {
        format!("{}:{}: {}", self.path.display(), line_of(self.text, needle), msg)
    }
    fn resolve(&self, p: &str) -> PathBuf {
        self.dir.join(p)
    }
}

fn transform_of(ops: &[JsonTransformOp]) -> Result<Transform, String> {
    let mut t = Transform::IDENTITY;
    for op in ops {
        let step = match op {
            JsonTransformOp::Translate(v) => Transform::translate(Vec3::from_array(*v)),
            JsonTransformOp::Scale(s) => {
                let s = s.rgb();
                Transform::scale(Vec3 { x: s.r, y: s.g, z: s.b }).ok_or("a scale of zero is not invertible")?
            }
            JsonTransformOp::Rotate { axis, angle } => Transform::rotate(Vec3::from_array(*axis), *angle),
            JsonTransformOp::Matrix(m) => {
                let mut a = [[0.0f64; 4]; 4];
                for (i, v) in m.iter().enumerate() {
                    a[i / 4][i % 4] = *v as f64;
                }
                Transform::from_matrix(Mat4(a)).ok_or("the matrix is not invertible")?
            }
            JsonTransformOp::LookAt { origin, target, up } => {
                Transform::look_at(Vec3::from_array(*origin), Vec3::from_array(*target), Vec3::from_array(*up))
                    .ok_or("look_at: degenerate direction or up vector")?
            }
        };
        // Later operations apply after earlier ones.
        t = step.then_after(&t);
    }
    Ok(t)
}

fn texture_of(ctx: &Ctx, t: &JsonTexture) -> Result<Texture, String> {
    Ok(match t {
        JsonTexture::Color(c) => Texture::Constant(c.rgb()),
        JsonTexture::Bitmap { texture, raw, uv_scale } => {
            let bm = Bitmap::load(&ctx.resolve(texture), *raw).map_err(|e| ctx.err(texture, e))?;
            Texture::Bitmap { image: Arc::new(bm), uv_scale: uv_scale.unwrap_or([1.0, 1.0]), uv_offset: [0.0, 0.0] }
        }
        JsonTexture::Checker { checkerboard, uv_scale } => Texture::Checkerboard {
            color0: checkerboard[0].rgb(),
            color1: checkerboard[1].rgb(),
            uv_scale: uv_scale.unwrap_or([1.0, 1.0]),
            uv_offset: [0.0, 0.0],
        },
    })
}

fn distribution(ctx: &Ctx, name: &Option<String>, alpha: f32) -> Result<Microfacet, String> {
    let kind = match name.as_deref().unwrap_or("ggx") {
        "ggx" => MicrofacetKind::Ggx,
        "beckmann" => MicrofacetKind::Beckmann,
        other => return Err(ctx.err(other, format!("unknown microfacet distribution '{other}' (ggx or beckmann)"))),
    };
    Ok(Microfacet::new(kind, alpha))
}

fn material_of(ctx: &Ctx, name: &str, m: &JsonMaterial) -> Result<Material, String> {
    let needle = format!("\"{name}\"");
    let (kind, two_sided) = match m {
        JsonMaterial::Diffuse { reflectance, two_sided } => {
            (MaterialKind::Diffuse { reflectance: texture_of(ctx, reflectance)? }, two_sided.unwrap_or(true))
        }
        JsonMaterial::Phong { kd, ks, exponent, two_sided } => (
            MaterialKind::Phong {
                kd: texture_of(ctx, kd)?,
                ks: ks.map_or(Rgb::BLACK, |c| c.rgb()),
                exponent: exponent.unwrap_or(32.0),
            },
            two_sided.unwrap_or(true),
        ),
        JsonMaterial::Mirror { specular } => (
            MaterialKind::Conductor {
                eta: Rgb::BLACK,
                k: Rgb::WHITE,
                specular: specular.map_or(Rgb::WHITE, |c| c.rgb()),
            },
            true,
        ),
        JsonMaterial::Conductor { metal, eta, k, specular, alpha, distribution: d } => {
            let (e, kk) = match (metal, eta, k) {
                (Some(mname), None, None) => conductor_preset(mname)
                    .ok_or_else(|| ctx.err(mname, format!("unknown metal '{mname}' (Au, Ag, Cu, Al, Cr)")))?,
                (None, Some(e), Some(k)) => (e.rgb(), k.rgb()),
                (None, None, None) => (Rgb::BLACK, Rgb::WHITE),
                _ => {
                    return Err(
                        ctx.err(&needle, format!("material '{name}': give either 'metal' or both 'eta' and 'k'"))
                    )
                }
            };
            let specular = specular.map_or(Rgb::WHITE, |c| c.rgb());
            let kind = match alpha {
                Some(a) if *a > 0.0 => {
                    MaterialKind::RoughConductor { dist: distribution(ctx, d, *a)?, eta: e, k: kk, specular }
                }
                _ => MaterialKind::Conductor { eta: e, k: kk, specular },
            };
            (kind, true)
        }
        JsonMaterial::Dielectric { ior, alpha, distribution: d, thin } => {
            let eta = ior.unwrap_or(1.5);
            if !(eta > 0.0) {
                return Err(ctx.err(&needle, format!("material '{name}': ior must be positive")));
            }
            let (reflect, transmit) = (Rgb::WHITE, Rgb::WHITE);
            let kind = if *thin {
                MaterialKind::ThinDielectric { eta, reflect, transmit }
            } else {
                match alpha {
                    Some(a) if *a > 0.0 => {
                        MaterialKind::RoughDielectric { dist: distribution(ctx, d, *a)?, eta, reflect, transmit }
                    }
                    _ => MaterialKind::Dielectric { eta, reflect, transmit },
                }
            };
            (kind, false)
        }
        JsonMaterial::Plastic { diffuse, ior, alpha, distribution: d } => {
            let dist = match alpha {
                Some(a) if *a > 0.0 => Some(distribution(ctx, d, *a)?),
                _ => None,
            };
            (Material::plastic(texture_of(ctx, diffuse)?, Rgb::WHITE, ior.unwrap_or(1.49), dist), true)
        }
    };
    Ok(Material::new(name, kind, two_sided))
}

/// Material for an MTL entry (used when an OBJ shape names no material).
fn material_from_mtl(m: &crate::io::obj::MtlMaterial) -> Material {
    let kind = if m.illum == 7 || m.dissolve < 1.0 {
        MaterialKind::Dielectric { eta: m.ni.max(1.0001), reflect: Rgb::WHITE, transmit: Rgb::WHITE }
    } else if m.illum == 5 {
        MaterialKind::Conductor { eta: Rgb::BLACK, k: Rgb::WHITE, specular: m.ks }
    } else if m.ks.max_component() > 0.0 && m.ns > 0.0 {
        MaterialKind::Phong { kd: Texture::Constant(m.kd), ks: m.ks, exponent: m.ns }
    } else {
        MaterialKind::Diffuse { reflectance: Texture::Constant(m.kd) }
    };
    Material::new(format!("mtl:{}", m.name), kind, true)
}

pub fn load(path: &Path, text: &str, opts: &LoadOptions) -> Result<LoadedScene, String> {
    let desc: JsonScene = serde_json::from_str(text).map_err(|e| {
        if e.line() > 0 {
            format!("{}:{}:{}: {}", path.display(), e.line(), e.column(), strip_position(&e.to_string()))
        } else {
            format!("{}: {e}", path.display())
        }
    })?;
    let ctx = Ctx { path, text, dir: path.parent().unwrap_or(Path::new(".")).to_path_buf() };
    let mut b = SceneBuilder::new(opts.bvh_split);

    for (name, m) in &desc.materials {
        let mat = material_of(&ctx, name, m)?;
        b.add_material(mat);
    }

    // Named meshes for instancing, loaded once each.
    let mut named_meshes = BTreeMap::new();
    for (name, m) in &desc.meshes {
        let groups = b.load_mesh_file(&ctx.resolve(&m.file), m.face_normals).map_err(|e| ctx.err(&m.file, e))?;
        named_meshes.insert(name.clone(), groups);
    }

    for (i, s) in desc.shapes.iter().enumerate() {
        let shape_needle = s.file.as_deref().or(s.mesh.as_deref()).unwrap_or(&s.kind).to_string();
        let here = |msg: String| ctx.err(&shape_needle, format!("shape {i} ({}): {msg}", s.kind));
        let to_world = transform_of(&s.transform).map_err(&here)?;
        let emission = s.emission.map(|e| Emission { radiance: e.rgb(), two_sided: s.two_sided_emission });
        let material = match &s.material {
            Some(name) => Some(b.material_id(name).ok_or_else(|| {
                ctx.err(&format!("\"material\": \"{name}\""), format!("shape {i}: unknown material '{name}'"))
            })?),
            None => None,
        };
        let mat_or_default = |b: &mut SceneBuilder| match material {
            Some(m) => m,
            None if emission.is_some() => b.black_material(),
            None => b.default_material(),
        };
        match s.kind.as_str() {
            "obj" | "ply" | "instance" => {
                let (groups, instanced) = if s.kind == "instance" {
                    let name = s.mesh.as_ref().ok_or_else(|| here("needs 'mesh'".into()))?;
                    let g = named_meshes
                        .get(name)
                        .ok_or_else(|| ctx.err(&format!("\"{name}\""), format!("unknown mesh '{name}'")))?;
                    (g.clone(), true)
                } else {
                    let file = s.file.as_ref().ok_or_else(|| here("needs 'file'".into()))?;
                    (b.load_mesh_file(&ctx.resolve(file), s.face_normals).map_err(|e| ctx.err(file, e))?, false)
                };
                for g in &groups {
                    let m = match material {
                        Some(m) => m,
                        None if !g.material.is_empty() => {
                            let key = format!("mtl:{}", g.material);
                            match b.material_id(&key) {
                                Some(id) => id,
                                None => match b.mtl_materials.get(&g.material).cloned() {
                                    Some(mtl) => b.add_material(material_from_mtl(&mtl)),
                                    None => mat_or_default(&mut b),
                                },
                            }
                        }
                        None => mat_or_default(&mut b),
                    };
                    b.add_mesh_instance(&g.mesh, &to_world, instanced, m, emission, s.flip_normals).map_err(&here)?;
                }
            }
            "sphere" => {
                let c = Vec3::from_array(s.center.unwrap_or([0.0; 3]));
                let m = mat_or_default(&mut b);
                b.add_sphere(c, s.radius.unwrap_or(1.0), &to_world, m, emission, s.flip_normals).map_err(&here)?;
            }
            "rectangle" | "cube" | "disk" => {
                let mesh = match s.kind.as_str() {
                    "rectangle" => crate::geometry::quad_mesh(
                        [
                            Vec3 { x: -1.0, y: -1.0, z: 0.0 },
                            Vec3 { x: 1.0, y: -1.0, z: 0.0 },
                            Vec3 { x: 1.0, y: 1.0, z: 0.0 },
                            Vec3 { x: -1.0, y: 1.0, z: 0.0 },
                        ],
                        opts.bvh_split,
                    ),
                    "cube" => crate::geometry::cube_mesh(opts.bvh_split),
                    _ => crate::geometry::disk_mesh(128, opts.bvh_split),
                };
                let m = mat_or_default(&mut b);
                b.add_mesh_instance(&Arc::new(mesh), &to_world, false, m, emission, s.flip_normals).map_err(&here)?;
            }
            other => {
                return Err(ctx.err(
                    &format!("\"{other}\""),
                    format!(
                        "shape {i}: unknown shape type '{other}' (obj, ply, instance, sphere, rectangle, cube, disk)"
                    ),
                ))
            }
        }
    }

    for l in &desc.lights {
        match l {
            JsonLight::Point { position, intensity } => {
                b.add_light(Light::Point { position: Vec3::from_array(*position), intensity: intensity.rgb() })
            }
            JsonLight::Spot { position, target, intensity, cutoff_angle, beam_width } => {
                let p = Vec3::from_array(*position);
                let dir = (Vec3::from_array(*target) - p).normalize();
                let cutoff = cutoff_angle.unwrap_or(20.0);
                let beam = beam_width.unwrap_or(cutoff * 0.75);
                b.add_light(Light::Spot {
                    position: p,
                    frame: Frame::from_normal(dir),
                    intensity: intensity.rgb(),
                    cutoff: cutoff.to_radians(),
                    beam: beam.min(cutoff).to_radians(),
                });
            }
            JsonLight::Directional { direction, irradiance } => {
                b.add_directional(Vec3::from_array(*direction), irradiance.rgb())
            }
            JsonLight::Constant { radiance } => b.add_constant_environment(radiance.rgb()),
            JsonLight::Envmap { file, scale, transform } => {
                let img = Bitmap::load(&ctx.resolve(file), true).map_err(|e| ctx.err(file, e))?;
                let t = transform_of(transform).map_err(|e| ctx.err(file, e))?;
                b.add_envmap(img, scale.unwrap_or(1.0), t);
            }
        }
    }

    // Camera and film.
    let cam = &desc.camera;
    let (w, h) = (opts.width.unwrap_or(desc.film.width), opts.height.unwrap_or(desc.film.height));
    check_resolution(w, h).map_err(|e| ctx.err("\"film\"", e))?;
    let to_world =
        Transform::look_at(Vec3::from_array(cam.position), Vec3::from_array(cam.look_at), Vec3::from_array(cam.up))
            .ok_or_else(|| {
                ctx.err("\"camera\"", "camera: position equals look_at, or up is parallel to the view direction")
            })?;
    if !(cam.fov > 0.0 && cam.fov < 180.0) {
        return Err(ctx.err("\"fov\"", format!("camera: fov must be in (0, 180) degrees, got {}", cam.fov)));
    }
    let axis: FovAxis = match &cam.fov_axis {
        Some(a) => a.parse().map_err(|e| ctx.err("\"fov_axis\"", e))?,
        None => FovAxis::Y,
    };
    let mut camera = Camera::new(to_world, desc.film.width, desc.film.height, cam.fov, axis);
    if (w, h) != (desc.film.width, desc.film.height) {
        camera.set_resolution(w, h);
    }
    if cam.aperture_radius > 0.0 {
        camera.lens_radius = cam.aperture_radius;
        camera.focus_distance = cam
            .focus_distance
            .unwrap_or_else(|| (Vec3::from_array(cam.look_at) - Vec3::from_array(cam.position)).length());
    }
    let filter = match desc.film.filter.as_deref() {
        None | Some("box") => PixelFilter::Box,
        Some("tent") => PixelFilter::Tent { radius: 1.0 },
        Some("gaussian") => PixelFilter::Gaussian { stddev: 0.5 },
        Some(other) => return Err(ctx.err(other, format!("unknown filter '{other}' (box, tent, gaussian)"))),
    };

    let mut selection = LightSelection::Power;
    let integrator = match &desc.integrator {
        None => Integrator::Path(PathSettings::default()),
        Some(JsonIntegrator::Whitted { max_depth, background }) => Integrator::Whitted(WhittedSettings {
            max_depth: max_depth.unwrap_or(5),
            background: background.unwrap_or([0.0; 3]),
        }),
        Some(JsonIntegrator::Path {
            max_depth,
            rr_depth,
            rr_probability,
            strategy,
            light_selection,
            hide_emitters,
        }) => {
            if let Some(ls) = light_selection {
                selection = ls.parse().map_err(|e| ctx.err(ls, e))?;
            }
            Integrator::Path(PathSettings {
                max_depth: max_depth.and_then(|d| if d < 0 { None } else { Some(d as u32) }),
                rr_depth: rr_depth.unwrap_or(5),
                rr_probability: *rr_probability,
                strategy: strategy.unwrap_or_default(),
                hide_emitters: *hide_emitters,
            })
        }
    };
    let settings = RenderSettings {
        spp: desc.sampler.spp.unwrap_or(16),
        seed: desc.sampler.seed.unwrap_or(0),
        filter,
        sampler: match desc.sampler.kind.as_deref() {
            None => SamplerKind::default(),
            Some(k) => k.parse().map_err(|e| ctx.err(k, e))?,
        },
        ..Default::default()
    };
    let scene = b.finish(camera, selection).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(LoadedScene { scene, integrator, settings, warnings: Vec::new() })
}

/// serde_json appends " at line L column C"; the location is already at the front.
fn strip_position(msg: &str) -> String {
    match msg.rfind(" at line ") {
        Some(i) => msg[..i].to_string(),
        None => msg.to_string(),
    }
}

/// Rejects zero and absurd resolutions (more than 2^28 pixels or a side over 65536).
pub fn check_resolution(w: u32, h: u32) -> Result<(), String> {
    if w == 0 || h == 0 {
        return Err(format!("resolution {w}x{h}: width and height must be at least 1"));
    }
    if w > 65536 || h > 65536 || (w as u64) * (h as u64) > (1 << 28) {
        return Err(format!("resolution {w}x{h} is too large (at most 65536 per side and 2^28 pixels)"));
    }
    Ok(())
}
