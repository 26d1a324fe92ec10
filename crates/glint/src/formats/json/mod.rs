//! glint's native JSON scene format (documented in docs/scene-format.md), read into a
//! [`SceneDesc`]. The serde structures below mirror the file's scene structure (camera,
//! film, shapes, lights); each material's object is read by its type's function in
//! `materials`, straight into the material's description. `read` turns them into the
//! description. Structural errors come from serde_json with their line and column; the
//! others (an unknown material name, say) point at the offending value, found by its path
//! in the document (`json_spans`), never by searching the text.

mod materials;

use super::json_spans::Spans;
use crate::describe::{
    Aov, CameraDesc, DirectSettings, Emission, FilmDesc, Geometry, IntegratorDesc, LightDesc, LightKind, MaterialRef,
    Matrix4, MediumDesc, MeshFileDesc, PathSettings, PhaseDesc, Roughness, SamplerDesc, ScalarTexture, ShapeDesc,
    ShapeMedia, Strategy, TextureDesc, VolpathSettings, WhittedSettings,
};
use crate::describe::{CropWindow, FovAxis, LightSelection, MicrofacetKind, PixelFilter, Projection, SamplerKind};
use crate::error::{Error, SourceLoc};
use crate::materials::SceneDesc;
use crate::math::{Mat4, Rgb, Transform, Vec3};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

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
    /// Each material's object, read by its type's function in `materials`.
    materials: BTreeMap<String, serde_json::Value>,
    #[serde(default)]
    meshes: BTreeMap<String, JsonMeshFile>,
    #[serde(default)]
    shapes: Vec<JsonShape>,
    #[serde(default)]
    lights: Vec<JsonLight>,
    #[serde(default)]
    media: BTreeMap<String, JsonMedium>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonMedium {
    #[serde(default, rename = "type")]
    kind: Option<String>,
    #[serde(default)]
    sigma_t: Option<JsonColor>,
    #[serde(default)]
    albedo: Option<JsonColor>,
    #[serde(default)]
    scale: Option<f32>,
    #[serde(default)]
    phase: Option<PhaseDesc>,
    #[serde(default)]
    sample_emitters: Option<bool>,
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
    #[serde(default)]
    medium: Option<String>,
    /// `perspective` (default) or `orthographic`.
    #[serde(default)]
    projection: Option<String>,
    /// Orthographic: half the width of the view, in scene units (default 1).
    #[serde(default)]
    ortho_half_width: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonFilm {
    width: u64,
    height: u64,
    #[serde(default)]
    filter: Option<String>,
    /// Render only [offset_x, offset_y, width, height] of the image.
    #[serde(default)]
    crop: Option<[u64; 4]>,
    /// Layers beside the image ("albedo", "depth", ...), as `--aov` names them.
    #[serde(default)]
    aovs: Vec<Aov>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum JsonIntegrator {
    Whitted {
        #[serde(default)]
        max_depth: Option<u64>,
        #[serde(default)]
        background: Option<[f32; 3]>,
    },
    Path {
        #[serde(default)]
        max_depth: Option<i64>,
        #[serde(default)]
        rr_depth: Option<u64>,
        #[serde(default)]
        rr_probability: Option<f32>,
        #[serde(default)]
        strategy: Option<Strategy>,
        #[serde(default)]
        light_selection: Option<String>,
        #[serde(default)]
        hide_emitters: bool,
    },
    Direct {
        #[serde(default)]
        emitter_samples: Option<u64>,
        #[serde(default)]
        bsdf_samples: Option<u64>,
        #[serde(default)]
        light_selection: Option<String>,
        #[serde(default)]
        hide_emitters: bool,
    },
    Volpath {
        #[serde(default)]
        max_depth: Option<i64>,
        #[serde(default)]
        rr_depth: Option<u64>,
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
    spp: Option<u64>,
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
    /// A mesh attribute (`vertex_...` or `face_...`) of the shape the material is used on.
    Attribute {
        attribute: String,
        #[serde(default)]
        scale: Option<f32>,
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
    emission: Option<JsonTexture>,
    #[serde(default)]
    two_sided_emission: bool,
    #[serde(default)]
    flip_normals: bool,
    #[serde(default)]
    face_normals: bool,
    #[serde(default)]
    interior: Option<String>,
    #[serde(default)]
    exterior: Option<String>,
    p0: Option<[f32; 3]>,
    #[serde(default)]
    p1: Option<[f32; 3]>,
    /// Names the shape's parameters in `traverse`.
    #[serde(default)]
    id: Option<String>,
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
        /// Projected over the cone (Mitsuba's spot `texture`); `up` turns it.
        #[serde(default)]
        texture: Option<JsonTexture>,
        #[serde(default = "default_up")]
        up: [f32; 3],
    },
    /// Mitsuba's `projector`.
    Projector {
        position: [f32; 3],
        target: [f32; 3],
        #[serde(default = "default_up")]
        up: [f32; 3],
        fov: f32,
        irradiance: JsonTexture,
        #[serde(default)]
        scale: Option<f32>,
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

struct Ctx<'a> {
    path: &'a Path,
    spans: Spans,
    dir: PathBuf,
}

impl Ctx<'_> {
    /// The location of the value at a document path.
    fn loc(&self, json_path: &str) -> SourceLoc {
        let p = self.spans.get(json_path);
        SourceLoc::new(self.path, p.line, p.col)
    }
    fn err(&self, json_path: &str, msg: impl Into<String>) -> Error {
        Error::at(&self.loc(json_path), msg)
    }
    fn resolve(&self, p: &str) -> PathBuf {
        self.dir.join(p)
    }
}

/// A whole number from the file, checked against its range before it is narrowed.
fn narrow(ctx: &Ctx, json_path: &str, what: &str, v: u64, min: u64, max: u64) -> Result<u32, Error> {
    if v < min || v > max {
        return Err(ctx.err(json_path, format!("{what} {v} is out of range ({min} to {max})")));
    }
    Ok(v as u32)
}

fn transform_of(ops: &[JsonTransformOp]) -> Result<Matrix4, String> {
    let mut t = Transform::IDENTITY;
    for op in ops {
        let step = match op {
            JsonTransformOp::Translate(v) => Transform::translate(Vec3::from_array(*v)),
            JsonTransformOp::Scale(s) => {
                let s = s.rgb();
                Transform::scale(Vec3 { x: s.r, y: s.g, z: s.b }).ok_or("a scale of zero is not invertible")?
            }
            JsonTransformOp::Rotate { axis, angle } => {
                if !(Vec3::from_array(*axis).length_squared() > 0.0) {
                    return Err("rotate: the axis is zero".into());
                }
                Transform::rotate(Vec3::from_array(*axis), *angle)
            }
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
    Ok(t.m.0)
}

/// A light's placement: at `position`, its +z towards `target`, +y towards `up`.
fn json_look_at(
    ctx: &Ctx,
    at: &str,
    position: &[f32; 3],
    target: &[f32; 3],
    up: &[f32; 3],
) -> Result<crate::describe::Matrix4, Error> {
    let (p, t, u) = (Vec3::from_array(*position), Vec3::from_array(*target), Vec3::from_array(*up));
    Transform::look_at(p, t, u)
        .map(|x| x.m.0)
        .ok_or_else(|| ctx.err(at, "the light's target equals its position, or its up is along its axis"))
}

fn texture_of(ctx: &Ctx, json_path: &str, t: &JsonTexture) -> TextureDesc {
    match t {
        JsonTexture::Color(c) => TextureDesc::constant(c.rgb()),
        JsonTexture::Bitmap { texture, raw, uv_scale } => TextureDesc::Bitmap {
            file: ctx.resolve(texture),
            raw: *raw,
            uv_scale: uv_scale.unwrap_or([1.0, 1.0]),
            uv_offset: [0.0, 0.0],
            loc: ctx.loc(json_path),
            texels: None,
        },
        JsonTexture::Checker { checkerboard, uv_scale } => TextureDesc::Checkerboard {
            color0: checkerboard[0].rgb(),
            color1: checkerboard[1].rgb(),
            uv_scale: uv_scale.unwrap_or([1.0, 1.0]),
            uv_offset: [0.0, 0.0],
        },
        JsonTexture::Attribute { attribute, scale } => {
            TextureDesc::MeshAttribute { name: attribute.clone(), scale: scale.unwrap_or(1.0), loc: ctx.loc(json_path) }
        }
    }
}

/// A roughness from `alpha` (a number or a texture; along dp/du when `alpha_v` is given).
/// A constant `alpha` of 0 or less with no `alpha_v` means a smooth surface.
fn roughness(
    ctx: &Ctx,
    at: &str,
    name: &Option<String>,
    alpha: &Option<JsonTexture>,
    alpha_v: &Option<JsonTexture>,
) -> Result<Option<Roughness>, Error> {
    let scalar = |field: &str, t: &JsonTexture| match texture_of(ctx, &format!("{at}/{field}"), t) {
        TextureDesc::Constant { color } if color.r == color.g && color.g == color.b => ScalarTexture::Value(color.r),
        other => ScalarTexture::Texture(other),
    };
    let Some(alpha) = alpha.as_ref().map(|a| scalar("alpha", a)) else {
        if alpha_v.is_some() {
            return Err(ctx.err(&format!("{at}/alpha_v"), "alpha_v needs alpha (the roughness along u) too"));
        }
        return Ok(None);
    };
    let alpha_v = alpha_v.as_ref().map(|a| scalar("alpha_v", a));
    if let (ScalarTexture::Value(a), None) = (&alpha, &alpha_v) {
        if !(*a > 0.0 || a.is_nan()) {
            return Ok(None);
        }
    }
    let distribution = match name.as_deref().unwrap_or("ggx") {
        "ggx" => MicrofacetKind::Ggx,
        "beckmann" => MicrofacetKind::Beckmann,
        other => {
            return Err(ctx.err(
                &format!("{at}/distribution"),
                format!("unknown microfacet distribution '{other}' (ggx or beckmann)"),
            ))
        }
    };
    Ok(Some(Roughness { distribution, alpha, alpha_v }))
}

/// Reads a JSON scene (`text` is the file's contents) into a description.
pub fn read(path: &Path, text: &str) -> Result<SceneDesc, Error> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let file: JsonScene = serde_json::from_str(text).map_err(|e| {
        if e.line() > 0 {
            Error::at(&SourceLoc::new(path, e.line() as u32, e.column() as u32), strip_position(&e.to_string()))
        } else {
            Error::at(&SourceLoc::file(path), e.to_string())
        }
    })?;
    let ctx = Ctx { path, spans: Spans::scan(text), dir: path.parent().unwrap_or(Path::new(".")).to_path_buf() };
    if let Some((key_path, pos)) = ctx.spans.first_duplicate() {
        let key = key_path.rsplit('/').next().unwrap_or(key_path);
        return Err(Error::at(
            &SourceLoc::new(path, pos.line, pos.col),
            format!("'{key}' is given twice in the same object ({key_path})"),
        ));
    }

    let camera = camera_of(&ctx, &file.camera)?;
    let film = film_of(&ctx, &file.film)?;
    let mut desc = SceneDesc::empty(camera, film);
    desc.source = Some(path.to_path_buf());

    desc.integrator = integrator_of(&ctx, file.integrator.as_ref(), &mut desc.light_selection)?;
    for (name, m) in &file.media {
        desc.media.push(medium_of(&ctx, name, m)?);
    }
    let medium_ref = |name: &Option<String>, at: &str| -> Result<Option<usize>, Error> {
        match name {
            None => Ok(None),
            Some(n) => match file.media.keys().position(|k| k == n) {
                Some(i) => Ok(Some(i)),
                None => Err(ctx.err(at, format!("unknown medium '{n}'"))),
            },
        }
    };
    desc.camera.medium = medium_ref(&file.camera.medium, "camera/medium")?;
    desc.sampler = sampler_of(&ctx, &file.sampler)?;

    for (name, m) in &file.materials {
        desc.materials.push(materials::material_of(&ctx, name, m)?);
    }
    for (name, m) in &file.meshes {
        desc.meshes.push(MeshFileDesc {
            name: name.clone(),
            file: ctx.resolve(&m.file),
            face_normals: m.face_normals,
            loc: ctx.loc(&format!("meshes/{name}")),
            shape_index: 0,
            reverse_winding: false,
        });
    }

    let json_media = desc.media.len();
    for (i, s) in file.shapes.iter().enumerate() {
        if s.kind == "gltf" {
            let (gltf, part) = gltf_group(&ctx, i, s)?;
            desc.append_parts(part);
            if !desc.includes.contains(&gltf) {
                desc.includes.push(gltf);
            }
            continue;
        }
        let shape = shape_of(&ctx, &desc, i, s, &medium_ref)?;
        desc.shapes.push(shape);
    }

    if desc.media.len() > json_media {
        // A placed glTF file brought absorbing volumes (KHR_materials_volume): without an
        // integrator of its own the scene gets the volumetric path tracer, which renders them.
        match (&file.integrator, &desc.integrator) {
            (None, _) => desc.integrator = IntegratorDesc::Volpath(VolpathSettings::default()),
            (Some(_), IntegratorDesc::Volpath(_)) => {}
            (Some(_), IntegratorDesc::Path(_) | IntegratorDesc::Direct(_) | IntegratorDesc::Whitted(_)) => {
                desc.warnings.push(format!(
                    "{}: a glTF file's absorbing volumes (KHR_materials_volume attenuation) are rendered only by the volpath integrator; the {} integrator ignores them",
                    path.display(),
                    desc.integrator.name()
                ))
            }
        }
    }
    for (i, l) in file.lights.iter().enumerate() {
        let at = format!("lights/{i}");
        desc.lights.push(LightDesc { light: light_of(&ctx, &at, l)?, name: None, loc: ctx.loc(&at) });
    }
    Ok(desc)
}

fn camera_of(ctx: &Ctx, cam: &JsonCamera) -> Result<CameraDesc, Error> {
    let to_world =
        Transform::look_at(Vec3::from_array(cam.position), Vec3::from_array(cam.look_at), Vec3::from_array(cam.up))
            .ok_or_else(|| {
                ctx.err("camera", "camera: position equals look_at, or up is parallel to the view direction")
            })?;
    let fov_axis: FovAxis = match &cam.fov_axis {
        Some(a) => a.parse().map_err(|e: String| ctx.err("camera/fov_axis", e))?,
        None => FovAxis::Y,
    };
    let focus_distance = match cam.focus_distance {
        Some(f) => f,
        None => (Vec3::from_array(cam.look_at) - Vec3::from_array(cam.position)).length(),
    };
    let projection = match cam.projection.as_deref() {
        None | Some("perspective") => Projection::Perspective,
        Some("orthographic") => Projection::Orthographic,
        Some(other) => {
            return Err(
                ctx.err("camera/projection", format!("unknown projection '{other}' (perspective, orthographic)"))
            )
        }
    };
    let to_world = match (projection, cam.ortho_half_width) {
        (Projection::Orthographic, Some(s)) => {
            let scale = Transform::scale(Vec3 { x: s, y: s, z: 1.0 }).filter(|_| s > 0.0 && s.is_finite());
            let scale = scale.ok_or_else(|| {
                ctx.err("camera/ortho_half_width", format!("ortho_half_width {s} must be positive and finite"))
            })?;
            to_world.then_after(&scale)
        }
        _ => to_world,
    };
    Ok(CameraDesc {
        to_world: Some(to_world.m.0),
        fov_degrees: cam.fov,
        fov_axis,
        lens_radius: cam.aperture_radius,
        focus_distance,
        near_clip: 0.0,
        far_clip: f32::MAX,
        loc: ctx.loc("camera"),
        medium: None,
        projection,
        id: None,
    })
}

fn film_of(ctx: &Ctx, f: &JsonFilm) -> Result<FilmDesc, Error> {
    let filter = match f.filter.as_deref() {
        None | Some("box") => PixelFilter::Box,
        Some("tent") => PixelFilter::Tent { radius: 1.0 },
        Some("gaussian") => PixelFilter::Gaussian { stddev: 0.5 },
        Some(other) => return Err(ctx.err("film/filter", format!("unknown filter '{other}' (box, tent, gaussian)"))),
    };
    let (width, height) = (f.width.min(u32::MAX as u64) as u32, f.height.min(u32::MAX as u64) as u32);
    crate::describe::limits::check_resolution(width, height).map_err(|e| ctx.err("film", e))?;
    Ok(FilmDesc {
        width,
        height,
        filter,
        loc: ctx.loc("film"),
        crop: f.crop.map(|[x, y, w, h]| {
            let n = |v: u64| v.min(u32::MAX as u64) as u32;
            CropWindow { offset_x: n(x), offset_y: n(y), width: n(w), height: n(h) }
        }),
        aovs: f.aovs.clone(),
    })
}

/// The integrator, and into `selection` the light selection it names (which the
/// description keeps beside it).
fn integrator_of(
    ctx: &Ctx,
    integrator: Option<&JsonIntegrator>,
    selection: &mut LightSelection,
) -> Result<IntegratorDesc, Error> {
    Ok(match integrator {
        None => IntegratorDesc::Path(PathSettings::default()),
        Some(JsonIntegrator::Whitted { max_depth, background }) => IntegratorDesc::Whitted(WhittedSettings {
            max_depth: match max_depth {
                Some(d) => narrow(
                    ctx,
                    "integrator/max_depth",
                    "max_depth",
                    *d,
                    1,
                    crate::describe::limits::MAX_WHITTED_DEPTH as u64,
                )?,
                None => 5,
            },
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
                *selection = ls.parse::<LightSelection>().map_err(|e| ctx.err("integrator/light_selection", e))?;
            }
            let max_depth = match max_depth {
                Some(d) if *d < 0 => None,
                Some(d) => Some(narrow(ctx, "integrator/max_depth", "max_depth", *d as u64, 0, u32::MAX as u64 - 1)?),
                None => None,
            };
            IntegratorDesc::Path(PathSettings {
                max_depth,
                rr_depth: match rr_depth {
                    Some(d) => narrow(ctx, "integrator/rr_depth", "rr_depth", *d, 1, u32::MAX as u64 - 1)?,
                    None => 5,
                },
                rr_probability: *rr_probability,
                strategy: strategy.unwrap_or(Strategy::Mis),
                hide_emitters: *hide_emitters,
            })
        }
        Some(JsonIntegrator::Direct { emitter_samples, bsdf_samples, light_selection, hide_emitters }) => {
            if let Some(ls) = light_selection {
                *selection = ls.parse::<LightSelection>().map_err(|e| ctx.err("integrator/light_selection", e))?;
            }
            let max = crate::describe::limits::MAX_DIRECT_SAMPLES as u64;
            let count = |v: &Option<u64>, name: &str| -> Result<u32, Error> {
                match v {
                    Some(n) => narrow(ctx, &format!("integrator/{name}"), name, *n, 0, max),
                    None => Ok(1),
                }
            };
            IntegratorDesc::Direct(DirectSettings {
                emitter_samples: count(emitter_samples, "emitter_samples")?,
                bsdf_samples: count(bsdf_samples, "bsdf_samples")?,
                hide_emitters: *hide_emitters,
            })
        }
        Some(JsonIntegrator::Volpath { max_depth, rr_depth, light_selection, hide_emitters }) => {
            if let Some(ls) = light_selection {
                *selection = ls.parse::<LightSelection>().map_err(|e| ctx.err("integrator/light_selection", e))?;
            }
            IntegratorDesc::Volpath(VolpathSettings {
                max_depth: match max_depth {
                    Some(d) if *d < 0 => None,
                    Some(d) => {
                        Some(narrow(ctx, "integrator/max_depth", "max_depth", *d as u64, 0, u32::MAX as u64 - 1)?)
                    }
                    None => None,
                },
                rr_depth: match rr_depth {
                    Some(d) => narrow(ctx, "integrator/rr_depth", "rr_depth", *d, 1, u32::MAX as u64 - 1)?,
                    None => 5,
                },
                hide_emitters: *hide_emitters,
            })
        }
    })
}

fn sampler_of(ctx: &Ctx, s: &JsonSampler) -> Result<SamplerDesc, Error> {
    Ok(SamplerDesc {
        kind: match s.kind.as_deref() {
            None => SamplerKind::default(),
            Some(k) => k.parse().map_err(|e: String| ctx.err("sampler/type", e))?,
        },
        spp: match s.spp {
            Some(n) => narrow(ctx, "sampler/spp", "spp", n, 1, crate::describe::limits::MAX_SPP as u64)?,
            None => 16,
        },
        seed: s.seed.unwrap_or(0),
    })
}

/// Resolves a medium's name (at a path in the document) to its index.
type MediumRef<'a> = dyn Fn(&Option<String>, &str) -> Result<Option<usize>, Error> + 'a;

fn shape_of(ctx: &Ctx, desc: &SceneDesc, i: usize, s: &JsonShape, medium_ref: &MediumRef) -> Result<ShapeDesc, Error> {
    let at = format!("shapes/{i}");
    let here = |msg: String| ctx.err(&at, format!("shape {i} ({}): {msg}", s.kind));
    let to_world = transform_of(&s.transform).map_err(|e| ctx.err(&format!("{at}/transform"), e))?;
    let emission = s
        .emission
        .as_ref()
        .map(|e| Emission { radiance: texture_of(ctx, &format!("{at}/emission"), e), two_sided: s.two_sided_emission });
    let material = match &s.material {
        Some(name) => MaterialRef::Index(
            desc.material_index(name)
                .ok_or_else(|| ctx.err(&format!("{at}/material"), format!("shape {i}: unknown material '{name}'")))?,
        ),
        None if emission.is_some() => MaterialRef::Black,
        None => MaterialRef::DefaultDiffuse,
    };
    let geometry = match s.kind.as_str() {
        "obj" | "ply" => {
            let file = s.file.as_ref().ok_or_else(|| here("needs 'file'".into()))?;
            Geometry::MeshFile { file: ctx.resolve(file), face_normals: s.face_normals, shape_index: 0 }
        }
        "instance" => {
            let name = s.mesh.as_ref().ok_or_else(|| here("needs 'mesh'".into()))?;
            let mesh = desc
                .meshes
                .iter()
                .position(|m| &m.name == name)
                .ok_or_else(|| ctx.err(&format!("{at}/mesh"), format!("unknown mesh '{name}'")))?;
            Geometry::Instance { mesh }
        }
        "sphere" => {
            Geometry::Sphere { center: Vec3::from_array(s.center.unwrap_or([0.0; 3])), radius: s.radius.unwrap_or(1.0) }
        }
        "rectangle" => Geometry::Rectangle,
        "cube" => Geometry::Cube,
        "disk" => Geometry::Disk,
        "cylinder" => Geometry::Cylinder {
            p0: Vec3::from_array(s.p0.unwrap_or([0.0; 3])),
            p1: Vec3::from_array(s.p1.unwrap_or([0.0, 0.0, 1.0])),
            radius: s.radius.unwrap_or(1.0),
        },
        other => {
            return Err(ctx.err(
                &format!("{at}/type"),
                format!(
                "shape {i}: unknown shape type '{other}' (obj, ply, gltf, instance, sphere, rectangle, cube, disk, cylinder)"
            ),
            ))
        }
    };
    let use_mtl = s.material.is_none() && matches!(geometry, Geometry::MeshFile { .. } | Geometry::Instance { .. });
    Ok(ShapeDesc {
        geometry,
        to_world,
        material,
        use_mtl,
        emission,
        flip_normals: s.flip_normals,
        loc: ctx.loc(&at),
        media: ShapeMedia {
            interior: medium_ref(&s.interior, &format!("{at}/interior"))?,
            exterior: medium_ref(&s.exterior, &format!("{at}/exterior"))?,
        },
        id: s.id.clone(),
    })
}

/// A glTF file placed as a group of shapes: its default scene's meshes, materials and
/// lights, moved by the shape's `transform` (the only other key it takes).
fn gltf_group(ctx: &Ctx, i: usize, s: &JsonShape) -> Result<(PathBuf, SceneDesc), Error> {
    let at = format!("shapes/{i}");
    let given = [
        ("mesh", s.mesh.is_some()),
        ("center", s.center.is_some()),
        ("radius", s.radius.is_some()),
        ("material", s.material.is_some()),
        ("emission", s.emission.is_some()),
        ("two_sided_emission", s.two_sided_emission),
        ("flip_normals", s.flip_normals),
        ("face_normals", s.face_normals),
        ("interior", s.interior.is_some()),
        ("exterior", s.exterior.is_some()),
        ("p0", s.p0.is_some()),
        ("p1", s.p1.is_some()),
        ("id", s.id.is_some()),
    ];
    if let Some((key, _)) = given.iter().find(|(_, set)| *set) {
        return Err(ctx.err(
            &format!("{at}/{key}"),
            format!("shape {i} (gltf): '{key}' does not apply (a glTF file brings its own materials; it takes 'file' and 'transform')"),
        ));
    }
    let file = s.file.as_ref().ok_or_else(|| ctx.err(&at, format!("shape {i} (gltf): needs 'file'")))?;
    let to_world = transform_of(&s.transform).map_err(|e| ctx.err(&format!("{at}/transform"), e))?;
    let path = ctx.resolve(file);
    let part = crate::formats::gltf::read_placed(&path, &to_world)?;
    Ok((path, part))
}

fn light_of(ctx: &Ctx, at: &str, l: &JsonLight) -> Result<LightKind, Error> {
    Ok(match l {
        JsonLight::Point { position, intensity } => {
            LightKind::Point { position: Vec3::from_array(*position), intensity: intensity.rgb() }
        }
        JsonLight::Spot { position, target, intensity, cutoff_angle, beam_width, texture: Some(t), up } => {
            let cutoff = cutoff_angle.unwrap_or(20.0);
            LightKind::TexturedSpot {
                to_world: json_look_at(ctx, at, position, target, up)?,
                intensity: intensity.rgb(),
                cutoff_degrees: cutoff,
                beam_degrees: beam_width.unwrap_or(cutoff * 0.75),
                texture: texture_of(ctx, &format!("{at}/texture"), t),
            }
        }
        JsonLight::Projector { position, target, up, fov, irradiance, scale } => LightKind::Projector {
            to_world: json_look_at(ctx, at, position, target, up)?,
            irradiance: texture_of(ctx, &format!("{at}/irradiance"), irradiance),
            scale: scale.unwrap_or(1.0),
            fov_degrees: *fov,
            fov_axis: FovAxis::X,
        },
        JsonLight::Spot { position, target, intensity, cutoff_angle, beam_width, .. } => {
            let cutoff = cutoff_angle.unwrap_or(20.0);
            LightKind::Spot {
                position: Vec3::from_array(*position),
                direction: Vec3::from_array(*target) - Vec3::from_array(*position),
                intensity: intensity.rgb(),
                cutoff_degrees: cutoff,
                beam_degrees: beam_width.unwrap_or(cutoff * 0.75),
                falloff: crate::describe::SpotFalloff::Linear,
            }
        }
        JsonLight::Directional { direction, irradiance } => {
            LightKind::Directional { direction: Vec3::from_array(*direction), irradiance: irradiance.rgb() }
        }
        JsonLight::Constant { radiance } => LightKind::Constant { radiance: radiance.rgb() },
        JsonLight::Envmap { file, scale, transform } => LightKind::EnvMap {
            file: ctx.resolve(file),
            scale: scale.unwrap_or(1.0),
            to_world: transform_of(transform).map_err(|e| ctx.err(&format!("{at}/transform"), e))?,
            texels: None,
        },
    })
}

fn medium_of(ctx: &Ctx, name: &str, m: &JsonMedium) -> Result<MediumDesc, Error> {
    let at = format!("media/{name}");
    if let Some(k) = m.kind.as_deref().filter(|k| *k != "homogeneous") {
        return Err(ctx.err(&format!("{at}/type"), format!("medium '{name}': unknown type '{k}' (homogeneous)")));
    }
    Ok(MediumDesc {
        name: name.to_string(),
        sigma_t: m.sigma_t.map_or(Rgb::WHITE, |c| c.rgb()),
        albedo: m.albedo.map_or(Rgb::splat(0.75), |c| c.rgb()).into(),
        scale: m.scale.unwrap_or(1.0),
        phase: m.phase.unwrap_or_default(),
        sample_emitters: m.sample_emitters.unwrap_or(true),
        density: None,
        absorbing_only: false,
        loc: ctx.loc(&at),
    })
}

/// serde_json appends " at line L column C"; the location is already at the front.
fn strip_position(msg: &str) -> String {
    match msg.rfind(" at line ") {
        Some(i) => msg[..i].to_string(),
        None => msg.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use crate::materials::SceneDesc;
    use std::path::Path;

    /// A scene of one shape object (given as JSON text).
    fn read(shape: &str) -> Result<SceneDesc, String> {
        let text = format!(
            "{{\n\"camera\": {{\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"fov\": 40}},\n\
             \"film\": {{\"width\": 4, \"height\": 4}},\n\
             \"shapes\": [\n{shape}\n]\n}}"
        );
        super::read(Path::new("s.json"), &text).map_err(|e| e.to_string())
    }

    #[test]
    fn a_shape_keeps_its_id() {
        let d = read(r#"{"type": "sphere", "id": "ball"}"#).unwrap();
        assert_eq!(d.shapes[0].id.as_deref(), Some("ball"));
        assert_eq!(read(r#"{"type": "sphere"}"#).unwrap().shapes[0].id, None);
    }

    #[test]
    fn an_id_that_is_not_a_string_is_one_line_where_it_is() {
        let e = read("{\"type\": \"sphere\",\n \"id\": 3}").unwrap_err();
        // The key is on the shape's second line, the file's sixth.
        assert!(e.starts_with("s.json:6:") && e.contains("expected a string"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        let e = read(r#"{"type": "gltf", "file": "a.glb", "id": "x"}"#).unwrap_err();
        assert!(e.contains("'id' does not apply"), "{e}");
    }
}
