//! The scene description: what a scene file says, as plain data.
//!
//! Readers (`formats`) produce a [`SceneDesc`]; `assemble` turns it into the render-ready
//! world. Nothing here loads a mesh or an image or builds a BVH: files are named by path,
//! names are resolved to indices, and every entity carries the [`SourceLoc`] it came from so
//! that an error found while building still names the file and line. A description is what
//! the Python API builds from a dict and what a render farm ships to its workers (it
//! serialises with serde), and overrides (`--width`, `--spp`, a parameter edit) are edits of
//! it, made before the build.

use crate::error::SourceLoc;
use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

mod aov;
mod camera;
pub mod checks;
mod gltf;
mod integrator;
pub mod limits;
mod medium;
mod sampling;
pub mod slots;
pub use aov::Aov;
pub use camera::{CropWindow, FovAxis, Projection};
pub use gltf::{GltfTextureDesc, GltfWrap};
pub use integrator::{DirectSettings, PathSettings, Strategy, VolpathSettings, WhittedSettings};
pub use medium::{GridFilter, GridVolumeDesc, GridWrap, MediumDesc, PhaseDesc, VolumeDesc};
pub use sampling::{LightSelection, PixelFilter, SamplerKind};

/// A 4x4 row-major object-to-world matrix (column vectors: `p' = M p`).
pub type Matrix4 = [[f64; 4]; 4];

pub const IDENTITY: Matrix4 = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];

/// What a description needs of the materials it holds: their textures (the files they read,
/// and their paths to rewrite). The material set itself is the `materials` module's: a
/// description is generic over it so that `describe` depends on nothing but `math` and
/// `error` (`materials::SceneDesc` is the description with glint's materials).
pub trait MaterialSet {
    /// Every texture the material reads, in a fixed order.
    fn textures(&self) -> Vec<&TextureDesc>;

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc>;
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneDesc<M> {
    /// The file the description was read from (`None` when built in code).
    pub source: Option<PathBuf>,
    /// Files the scene file included (Mitsuba's `<include>`).
    pub includes: Vec<PathBuf>,
    pub camera: CameraDesc,
    pub film: FilmDesc,
    pub integrator: IntegratorDesc,
    pub sampler: SamplerDesc,
    pub light_selection: LightSelection,
    pub materials: Vec<MaterialDesc<M>>,
    /// Mesh files placed by [`Geometry::Instance`] shapes, loaded once each.
    pub meshes: Vec<MeshFileDesc>,
    pub shapes: Vec<ShapeDesc>,
    pub lights: Vec<LightDesc>,
    /// What the reader accepted but cannot honour exactly (the CLI prints these).
    pub warnings: Vec<String>,
    /// Participating media, referred to by index from shapes and the camera.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub media: Vec<MediumDesc>,
    /// What the reader read, one line each, for `glint info` (a glTF file's nodes,
    /// meshes, triangles, ...); empty for formats that say nothing more than the world.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub summary: Vec<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraDesc {
    /// Camera to world (+z forward, +y up, +x left, as Mitsuba). `None`: frame the scene's
    /// bounds from the front (the preview of a bare mesh file).
    pub to_world: Option<Matrix4>,
    pub fov_degrees: f32,
    pub fov_axis: FovAxis,
    /// Thin lens; 0 is a pinhole.
    pub lens_radius: f32,
    pub focus_distance: f32,
    pub near_clip: f32,
    /// `f32::MAX` for none (JSON has no infinity).
    pub far_clip: f32,
    pub loc: SourceLoc,
    /// The medium the camera sits in (index into [`SceneDesc::media`]); `None` is vacuum.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<usize>,
    /// Perspective (the field of view and lens above) or orthographic (they are unused).
    #[serde(default)]
    pub projection: Projection,
    /// The file's id for the sensor (Mitsuba's `<sensor id>`), by which Mitsuba's names of
    /// its parameters are accepted as aliases (see `session::edit`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FilmDesc {
    pub width: u32,
    pub height: u32,
    pub filter: PixelFilter,
    pub loc: SourceLoc,
    /// Render only this part of the `width` x `height` image (Mitsuba's crop window).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crop: Option<CropWindow>,
    /// Layers the scene asks for beside the image (a Mitsuba `aov` integrator's, a JSON
    /// film's `aovs`); a film keeps those its caller asks for, then these
    /// (`Session::film_aovs`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub aovs: Vec<Aov>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorDesc {
    Whitted(WhittedSettings),
    Path(PathSettings),
    Direct(DirectSettings),
    Volpath(VolpathSettings),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SamplerDesc {
    pub kind: SamplerKind,
    pub spp: u32,
    pub seed: u64,
}

impl Default for SamplerDesc {
    fn default() -> Self {
        SamplerDesc { kind: SamplerKind::Sobol, spp: 16, seed: 0 }
    }
}

/// A named material; `model` is one of the material set's descriptions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaterialDesc<M> {
    pub name: String,
    pub model: M,
    /// Scatters on both faces (else the back face is black, Mitsuba's default).
    pub two_sided: bool,
    pub loc: SourceLoc,
}

/// A microfacet distribution of normals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum MicrofacetKind {
    Ggx,
    Beckmann,
}

/// A microfacet roughness. `alpha` runs along the surface's dp/du (Mitsuba's `alpha_u`);
/// `alpha_v`, along dp/dv, makes it anisotropic, and is `alpha` when absent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Roughness {
    pub distribution: MicrofacetKind,
    pub alpha: ScalarTexture,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha_v: Option<ScalarTexture>,
}

impl Roughness {
    pub fn isotropic(distribution: MicrofacetKind, alpha: f32) -> Roughness {
        Roughness { distribution, alpha: ScalarTexture::Value(alpha), alpha_v: None }
    }

    /// The roughness values that are textures.
    pub fn textures(&self) -> Vec<&TextureDesc> {
        self.alpha_v.iter().chain([&self.alpha]).filter_map(ScalarTexture::texture).collect()
    }

    pub fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        let v = self.alpha_v.iter_mut().chain([&mut self.alpha]);
        v.filter_map(|s| match s {
            ScalarTexture::Texture(t) => Some(t),
            ScalarTexture::Value(_) => None,
        })
        .collect()
    }
}

/// A number, or a texture read as one (its luminance, as Mitsuba's `eval_1`). In JSON a
/// plain number or a texture object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ScalarTexture {
    Value(f32),
    Texture(TextureDesc),
}

impl ScalarTexture {
    pub fn texture(&self) -> Option<&TextureDesc> {
        match self {
            ScalarTexture::Texture(t) => Some(t),
            ScalarTexture::Value(_) => None,
        }
    }
}

/// An image's texels given as data (by an edit, such as an optimiser's step), replacing
/// those of its file: linear RGB, `width * height` of them, rows from the top.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Texels {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<Rgb>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum TextureDesc {
    Constant {
        color: Rgb,
    },
    /// An image file; PNG/JPEG are sRGB-decoded unless `raw`. `texels`, where set, replace
    /// the file's.
    Bitmap {
        file: PathBuf,
        raw: bool,
        uv_scale: [f32; 2],
        uv_offset: [f32; 2],
        loc: SourceLoc,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texels: Option<Texels>,
    },
    Checkerboard {
        color0: Rgb,
        color1: Rgb,
        uv_scale: [f32; 2],
        uv_offset: [f32; 2],
    },
    /// A per-vertex (`vertex_NAME`) or per-face (`face_NAME`) attribute of the mesh it is
    /// used on, times `scale` (Mitsuba's `mesh_attribute`).
    #[serde(rename = "mesh_attribute")]
    MeshAttribute {
        name: String,
        scale: f32,
        loc: SourceLoc,
    },
    /// An image of a glTF file with its sampler and texture coordinate set.
    Gltf(GltfTextureDesc),
}

impl TextureDesc {
    /// The file the build reads for this texture, if any.
    pub fn file(&self) -> Option<&PathBuf> {
        match self {
            TextureDesc::Bitmap { file, .. } | TextureDesc::Gltf(GltfTextureDesc { file, .. }) => Some(file),
            TextureDesc::Constant { .. } | TextureDesc::Checkerboard { .. } | TextureDesc::MeshAttribute { .. } => None,
        }
    }

    pub fn file_mut(&mut self) -> Option<&mut PathBuf> {
        match self {
            TextureDesc::Bitmap { file, .. } | TextureDesc::Gltf(GltfTextureDesc { file, .. }) => Some(file),
            TextureDesc::Constant { .. } | TextureDesc::Checkerboard { .. } | TextureDesc::MeshAttribute { .. } => None,
        }
    }

    pub fn constant(color: Rgb) -> TextureDesc {
        TextureDesc::Constant { color }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshFileDesc {
    pub name: String,
    pub file: PathBuf,
    pub face_normals: bool,
    pub loc: SourceLoc,
    /// Which mesh of a `.serialized` file (Mitsuba's `shape_index`); 0 for other files.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub shape_index: u32,
    /// The triangles are read with their winding reversed: a glTF primitive placed by a
    /// mirroring transform (glTF keeps a face's front where the determinant is negative;
    /// glint orients faces by their winding in world space). glTF files only.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reverse_winding: bool,
}

/// Which material a shape uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum MaterialRef {
    /// Index into [`SceneDesc::materials`].
    Index(usize),
    /// Mitsuba's default: diffuse, reflectance 0.5.
    DefaultDiffuse,
    /// Absorbs everything (the JSON format's default for emitters).
    Black,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShapeDesc {
    pub geometry: Geometry,
    pub to_world: Matrix4,
    pub material: MaterialRef,
    /// For OBJ files: groups with a `usemtl` material take it from the MTL file when the
    /// shape names no material (`material` is then the fallback).
    pub use_mtl: bool,
    pub emission: Option<Emission>,
    pub flip_normals: bool,
    pub loc: SourceLoc,
    /// The media inside (behind the normal) and outside the shape, as indices into
    /// [`SceneDesc::media`]; a shape with neither leaves the medium of a ray unchanged.
    #[serde(default, skip_serializing_if = "ShapeMedia::is_none")]
    pub media: ShapeMedia,
    /// The file's id for the shape (Mitsuba's `<shape id>`, JSON's `id`), by which
    /// `traverse` names its parameters; `None` where the file gives none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
}

/// The media on the two sides of a shape (Mitsuba's `interior` and `exterior`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeMedia {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interior: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exterior: Option<usize>,
}

impl ShapeMedia {
    pub fn is_none(&self) -> bool {
        self.interior.is_none() && self.exterior.is_none()
    }
}

/// What an area light emits: radiance, a colour or a texture read at the surface's uv (as
/// Mitsuba's `area` emitter reads its `radiance`), on the side the normal faces or on both.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Emission {
    pub radiance: TextureDesc,
    pub two_sided: bool,
}

impl Emission {
    /// A uniform radiance on the front side.
    pub fn constant(radiance: Rgb) -> Emission {
        Emission { radiance: TextureDesc::constant(radiance), two_sided: false }
    }

    /// The mesh attributes the radiance reads (a shape must have them).
    pub fn mesh_attributes(&self) -> Vec<(&str, &SourceLoc)> {
        match &self.radiance {
            TextureDesc::MeshAttribute { name, loc, .. } => vec![(name.as_str(), loc)],
            _ => vec![],
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Geometry {
    /// An OBJ, PLY or Mitsuba `.serialized` file, its transform baked into the vertices.
    MeshFile {
        file: PathBuf,
        face_normals: bool,
        /// Which mesh of a `.serialized` file (Mitsuba's `shape_index`); 0 for other files.
        #[serde(default, skip_serializing_if = "is_zero")]
        shape_index: u32,
    },
    /// A mesh of [`SceneDesc::meshes`] placed by its transform (shared, not copied).
    Instance {
        mesh: usize,
    },
    /// A mesh given in the description itself (from Python, say).
    Mesh(MeshData),
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// The square [-1, 1]^2 in the z = 0 plane, facing +z.
    Rectangle,
    /// The cube [-1, 1]^3.
    Cube,
    /// The unit disk in the z = 0 plane, facing +z.
    Disk,
    /// An open tube (no end caps) of `radius` around the segment `p0` to `p1`, its normals
    /// outward (Mitsuba's `cylinder`).
    Cylinder {
        p0: Vec3,
        p1: Vec3,
        radius: f32,
    },
    /// A signed distance grid (Mitsuba's `sdfgrid`): a one-channel `.vol` file sampled at the
    /// vertices of a regular grid over the unit cube; the surface is the zero level set of
    /// its trilinear interpolant. The file's bounding box is ignored (as in Mitsuba).
    SdfGrid {
        file: PathBuf,
        normals: SdfNormalsDesc,
    },
    /// Round curves read from a Mitsuba curve file (x y z radius per line, a blank line
    /// between curves); the transform moves the points, not the radii.
    Curves {
        file: PathBuf,
        basis: CurveBasisDesc,
    },
}

/// How a curve file's control points make curves (Mitsuba's plugin).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CurveBasisDesc {
    /// `linearcurve`: straight segments, round joints and caps.
    Linear,
    /// `bsplinecurve`: a uniform cubic B-spline, open ends.
    BSpline,
}

/// How an SDF grid's shading normals are computed (Mitsuba's `normals`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SdfNormalsDesc {
    /// The gradient of the hit voxel's trilinear interpolant.
    Analytic,
    /// Blended gradients of the neighbouring voxels (Mitsuba's default).
    Smooth,
}

fn is_zero(v: &u32) -> bool {
    *v == 0
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightDesc {
    pub light: LightKind,
    /// The file's name for the light (a glTF light's `name`, a Mitsuba emitter's `id`), by
    /// which `traverse` names its parameters; `None` where the format names none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub loc: SourceLoc,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum LightKind {
    Point {
        position: Vec3,
        intensity: Rgb,
    },
    /// Cone angles in degrees; `beam_degrees` is where the falloff starts.
    Spot {
        position: Vec3,
        direction: Vec3,
        intensity: Rgb,
        cutoff_degrees: f32,
        beam_degrees: f32,
        /// How the intensity falls between the cones (Mitsuba's unless a glTF file says).
        #[serde(default, skip_serializing_if = "SpotFalloff::is_linear")]
        falloff: SpotFalloff,
    },
    /// `direction` is where the light travels.
    Directional {
        direction: Vec3,
        irradiance: Rgb,
    },
    /// A uniform sky.
    Constant {
        radiance: Rgb,
    },
    /// A latitude-longitude environment map.
    /// `texels`, where set, replace the file's.
    EnvMap {
        file: PathBuf,
        scale: f32,
        to_world: Matrix4,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texels: Option<Texels>,
    },
    /// A spot light projecting a texture (Mitsuba's `spot` with `texture`), at the origin
    /// of `to_world` looking along its +z; its rotation about that axis turns the texture.
    TexturedSpot {
        to_world: Matrix4,
        intensity: Rgb,
        cutoff_degrees: f32,
        beam_degrees: f32,
        texture: TextureDesc,
    },
    /// Mitsuba's `projector`: a pinhole projecting `irradiance` with the field of view of
    /// a camera whose film has the texture's aspect ratio.
    Projector {
        to_world: Matrix4,
        irradiance: TextureDesc,
        scale: f32,
        fov_degrees: f32,
        fov_axis: FovAxis,
    },
}

/// How a spot light's intensity falls from the beam's cone to the cutoff's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SpotFalloff {
    /// Linear in the angle (Mitsuba's `spot`).
    #[default]
    Linear,
    /// `KHR_lights_punctual`'s: linear in the cosine between the cones, then squared.
    Gltf,
}

impl SpotFalloff {
    pub fn is_linear(&self) -> bool {
        *self == SpotFalloff::Linear
    }
}

impl<M: MaterialSet> SceneDesc<M> {
    /// A description with nothing in it but a camera and film; readers and code fill it.
    pub fn empty(camera: CameraDesc, film: FilmDesc) -> SceneDesc<M> {
        SceneDesc {
            source: None,
            includes: Vec::new(),
            camera,
            film,
            integrator: IntegratorDesc::Path(PathSettings::default()),
            sampler: SamplerDesc::default(),
            light_selection: LightSelection::Power,
            materials: Vec::new(),
            meshes: Vec::new(),
            shapes: Vec::new(),
            lights: Vec::new(),
            warnings: Vec::new(),
            media: Vec::new(),
            summary: Vec::new(),
        }
    }

    /// Every file the scene reads (the scene file, its includes, meshes, textures,
    /// environment maps), each once: what a checkpoint hashes.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = Vec::new();
        for p in self.source.iter().chain(&self.includes).cloned().chain(self.build_inputs()) {
            if !out.contains(&p) {
                out.push(p);
            }
        }
        out
    }

    /// The files the build reads (meshes, textures, environment maps), each once; not the
    /// scene file and its includes, whose content the description already holds. With
    /// the description, what a render farm ships to its workers.
    pub fn build_inputs(&self) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = Vec::new();
        let mut add = |p: &PathBuf| {
            if !out.contains(p) {
                out.push(p.clone());
            }
        };
        for m in &self.materials {
            for t in m.model.textures() {
                if let Some(file) = t.file() {
                    add(file);
                }
            }
        }
        for m in &self.meshes {
            add(&m.file);
        }
        for s in &self.shapes {
            if let Geometry::MeshFile { file, .. } | Geometry::SdfGrid { file, .. } | Geometry::Curves { file, .. } =
                &s.geometry
            {
                add(file);
            }
            if let Some(file) = s.emission.as_ref().and_then(|e| e.radiance.file()) {
                add(file);
            }
        }
        for l in &self.lights {
            match &l.light {
                LightKind::EnvMap { file, .. } => add(file),
                LightKind::TexturedSpot { texture, .. } | LightKind::Projector { irradiance: texture, .. } => {
                    if let TextureDesc::Bitmap { file, .. } = texture {
                        add(file);
                    }
                }
                LightKind::Point { .. }
                | LightKind::Spot { .. }
                | LightKind::Directional { .. }
                | LightKind::Constant { .. } => {}
            }
        }
        for m in &self.media {
            if let VolumeDesc::Grid(g) = &m.albedo {
                add(&g.file);
            }
            if let Some(g) = &m.density {
                add(&g.file);
            }
        }
        out
    }

    /// Rewrites every path of [`SceneDesc::build_inputs`] (a worker that received the
    /// files points the description at its own copies); `f` may refuse a path.
    pub fn map_build_inputs<E>(&mut self, f: &mut dyn FnMut(&Path) -> Result<PathBuf, E>) -> Result<(), E> {
        let mut map = |p: &mut PathBuf| -> Result<(), E> {
            *p = f(p)?;
            Ok(())
        };
        for m in &mut self.materials {
            for t in m.model.textures_mut() {
                if let Some(file) = t.file_mut() {
                    map(file)?;
                }
            }
        }
        for m in &mut self.meshes {
            map(&mut m.file)?;
        }
        for s in &mut self.shapes {
            if let Geometry::MeshFile { file, .. } | Geometry::SdfGrid { file, .. } | Geometry::Curves { file, .. } =
                &mut s.geometry
            {
                map(file)?;
            }
            if let Some(file) = s.emission.as_mut().and_then(|e| e.radiance.file_mut()) {
                map(file)?;
            }
        }
        for l in &mut self.lights {
            match &mut l.light {
                LightKind::EnvMap { file, .. } => map(file)?,
                LightKind::TexturedSpot { texture, .. } | LightKind::Projector { irradiance: texture, .. } => {
                    if let TextureDesc::Bitmap { file, .. } = texture {
                        map(file)?;
                    }
                }
                LightKind::Point { .. }
                | LightKind::Spot { .. }
                | LightKind::Directional { .. }
                | LightKind::Constant { .. } => {}
            }
        }
        for m in &mut self.media {
            if let VolumeDesc::Grid(g) = &mut m.albedo {
                map(&mut g.file)?;
            }
            if let Some(g) = &mut m.density {
                map(&mut g.file)?;
            }
        }
        Ok(())
    }

    /// The index of the material called `name`.
    pub fn material_index(&self, name: &str) -> Option<usize> {
        self.materials.iter().position(|m| m.name == name)
    }

    /// Adds what `part` places in the world (materials, meshes, shapes, lights, media), its
    /// references re-indexed to follow this description's own; its camera, film, integrator
    /// and sampler are dropped. How a scene composes a file of another format (a glTF file
    /// placed from JSON) as one group of shapes.
    pub fn append_parts(&mut self, part: SceneDesc<M>) {
        let (materials, meshes, media) = (self.materials.len(), self.meshes.len(), self.media.len());
        self.materials.extend(part.materials);
        self.meshes.extend(part.meshes);
        self.media.extend(part.media);
        for mut s in part.shapes {
            match &mut s.material {
                MaterialRef::Index(i) => *i += materials,
                MaterialRef::DefaultDiffuse | MaterialRef::Black => {}
            }
            if let Geometry::Instance { mesh } = &mut s.geometry {
                *mesh += meshes;
            }
            for m in [&mut s.media.interior, &mut s.media.exterior].into_iter().flatten() {
                *m += media;
            }
            self.shapes.push(s);
        }
        self.lights.extend(part.lights);
        self.warnings.extend(part.warnings);
        self.summary.extend(part.summary);
    }
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc {
            to_world: None,
            fov_degrees: 45.0,
            fov_axis: FovAxis::Y,
            lens_radius: 0.0,
            focus_distance: 1.0,
            near_clip: 0.0,
            far_clip: f32::MAX,
            loc: SourceLoc::default(),
            medium: None,
            projection: Projection::Perspective,
            id: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A material set of one textured material: all these tests need of one (the
    /// description is generic over glint's own set, which lives above `describe`).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    struct Textured {
        reflectance: TextureDesc,
    }

    impl MaterialSet for Textured {
        fn textures(&self) -> Vec<&TextureDesc> {
            vec![&self.reflectance]
        }

        fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
            vec![&mut self.reflectance]
        }
    }

    type SceneDesc = super::SceneDesc<Textured>;
    type MaterialDesc = super::MaterialDesc<Textured>;

    fn small_film(aovs: Vec<Aov>) -> FilmDesc {
        FilmDesc { width: 4, height: 3, filter: PixelFilter::Box, loc: SourceLoc::default(), crop: None, aovs }
    }

    #[test]
    fn round_trips_through_json() {
        let mut d = SceneDesc::empty(CameraDesc::default(), small_film(vec![Aov::Depth, Aov::Albedo]));
        d.shapes.push(ShapeDesc {
            geometry: Geometry::Sphere { center: Vec3::ZERO, radius: 1.0 },
            to_world: IDENTITY,
            material: MaterialRef::DefaultDiffuse,
            use_mtl: false,
            emission: Some(Emission::constant(Rgb::splat(2.0))),
            flip_normals: false,
            loc: SourceLoc::new("a.json", 3, 5),
            media: ShapeMedia::default(),
            id: Some("ball".into()),
        });
        let text = serde_json::to_string(&d).unwrap();
        let back: SceneDesc = serde_json::from_str(&text).unwrap();
        assert_eq!(back, d);
    }

    fn desc_with_files() -> SceneDesc {
        let mut d = SceneDesc::empty(CameraDesc::default(), small_film(Vec::new()));
        d.source = Some("scene.xml".into());
        d.includes.push("part.xml".into());
        let bitmap = |f: &str| TextureDesc::Bitmap {
            file: f.into(),
            raw: false,
            uv_scale: [1.0; 2],
            uv_offset: [0.0; 2],
            loc: SourceLoc::default(),
            texels: None,
        };
        d.materials.push(MaterialDesc {
            name: "wood".into(),
            model: Textured { reflectance: bitmap("wood.png") },
            two_sided: false,
            loc: SourceLoc::default(),
        });
        d.meshes.push(MeshFileDesc {
            name: "m".into(),
            file: "bunny.ply".into(),
            face_normals: false,
            loc: SourceLoc::default(),
            shape_index: 0,
            reverse_winding: false,
        });
        for file in ["box.obj", "bunny.ply"] {
            d.shapes.push(ShapeDesc {
                geometry: Geometry::MeshFile { file: file.into(), face_normals: false, shape_index: 0 },
                to_world: IDENTITY,
                material: MaterialRef::DefaultDiffuse,
                use_mtl: false,
                emission: None,
                flip_normals: false,
                loc: SourceLoc::default(),
                media: ShapeMedia::default(),
                id: None,
            });
        }
        d.lights.push(LightDesc {
            light: LightKind::EnvMap { file: "sky.exr".into(), scale: 1.0, to_world: IDENTITY, texels: None },
            name: None,
            loc: SourceLoc::default(),
        });
        d.shapes.push(ShapeDesc {
            geometry: Geometry::Sphere { center: Vec3::ZERO, radius: 1.0 },
            to_world: IDENTITY,
            material: MaterialRef::DefaultDiffuse,
            use_mtl: false,
            emission: Some(Emission { radiance: bitmap("glow.png"), two_sided: false }),
            flip_normals: false,
            loc: SourceLoc::default(),
            media: ShapeMedia::default(),
            id: None,
        });
        d.lights.push(LightDesc {
            light: LightKind::TexturedSpot {
                to_world: IDENTITY,
                intensity: Rgb::WHITE,
                cutoff_degrees: 20.0,
                beam_degrees: 15.0,
                texture: bitmap("slide.png"),
            },
            name: None,
            loc: SourceLoc::default(),
        });
        d.lights.push(LightDesc {
            light: LightKind::Projector {
                to_world: IDENTITY,
                irradiance: bitmap("beamer.png"),
                scale: 1.0,
                fov_degrees: 30.0,
                fov_axis: FovAxis::X,
            },
            name: None,
            loc: SourceLoc::default(),
        });
        d
    }

    #[test]
    fn build_inputs_are_the_files_less_the_scene_text_and_map_in_place() {
        let mut d = desc_with_files();
        let inputs: Vec<PathBuf> =
            ["wood.png", "bunny.ply", "box.obj", "glow.png", "sky.exr", "slide.png", "beamer.png"]
                .iter()
                .map(PathBuf::from)
                .collect();
        assert_eq!(d.build_inputs(), inputs);
        let mut files = vec![PathBuf::from("scene.xml"), "part.xml".into()];
        files.extend(inputs.clone());
        assert_eq!(d.files(), files);
        // Every path the build reads is visited (the shared mesh once per place it is named).
        let mut seen = Vec::new();
        d.map_build_inputs(&mut |p| {
            seen.push(p.to_path_buf());
            Ok::<_, ()>(Path::new("copies").join(p))
        })
        .unwrap();
        assert_eq!(seen.len(), inputs.len() + 1);
        let mut unique: Vec<PathBuf> = Vec::new();
        for p in seen {
            if !unique.contains(&p) {
                unique.push(p);
            }
        }
        assert_eq!(unique, inputs, "map_build_inputs and build_inputs visit different files");
        assert_eq!(d.build_inputs(), inputs.iter().map(|p| Path::new("copies").join(p)).collect::<Vec<_>>());
        assert_eq!(d.source, Some("scene.xml".into()));
        assert_eq!(d.map_build_inputs(&mut |_| Err("refused")), Err("refused"));
    }

    #[test]
    fn numbers_round_trip_through_json_exactly() {
        // A render farm ships the description as JSON: a number that came back one bit off
        // would change the image. 0.1 + 0.2 needs 17 digits.
        let mut d = desc_with_files();
        let awkward = [0.1 + 0.2, std::f64::consts::PI / 7.0, 1.0 / 3.0, -2.0f64.sqrt() * 1e-7, 123456.789e10];
        d.shapes[0].to_world[0] = [awkward[0], awkward[1], awkward[2], awkward[3]];
        d.shapes[0].to_world[1][3] = awkward[4];
        d.camera.fov_degrees = (1.0f32 / 3.0) * 100.0;
        d.camera.lens_radius = f32::MIN_POSITIVE * 3.0;
        let text = serde_json::to_string(&d).unwrap();
        let back: SceneDesc = serde_json::from_str(&text).unwrap();
        assert_eq!(back, d);
    }
}
