//! Description → world: the one place where a scene description becomes the render-ready
//! [`World`]. It loads each mesh file once (in parallel), creates textures, materials,
//! shapes and lights in a fixed order (materials, meshes, shapes, lights, camera), owns the
//! tessellation of every primitive and every default, and reports errors at the entity's
//! source location.

mod builder;
mod validate;

pub use builder::{LoadedGroup, WorldBuilder};

use crate::accel::BvhSplit;
use crate::bsdf::Microfacet;
use crate::camera::Camera;
use crate::describe::{
    CameraDesc, Geometry, LightKind, MaterialModel, MaterialRef, Matrix4, Roughness, SceneDesc, ShapeDesc, TextureDesc,
};
use crate::error::{Error, SourceLoc};
use crate::geometry::{cube_mesh, disk_mesh, rectangle_mesh, TriangleMesh};
use crate::lights::Light;
use crate::materials::{Bitmap, Material, MaterialKind, Texture};
use crate::math::{Frame, Mat4, Transform, Vec3};
use crate::world::World;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// Choices that shape the built world but are not part of the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildOptions {
    pub bvh_split: BvhSplit,
}

/// Builds the world a description describes.
pub fn build(desc: &SceneDesc, opts: &BuildOptions) -> Result<World, Error> {
    validate::check(desc)?;
    let mut b = WorldBuilder::new(opts.bvh_split);
    let mut textures = TextureCache::default();

    let mut material_ids = Vec::with_capacity(desc.materials.len());
    for m in &desc.materials {
        let kind = material_kind(&m.model, &mut textures).map_err(|e| e.or_at(&m.loc))?;
        material_ids.push(b.add_material(Material::new(m.name.clone(), kind, m.two_sided)));
    }

    // Every mesh file, loaded and its BVH built in parallel, before any shape is placed.
    let mut files: Vec<(PathBuf, bool)> = Vec::new();
    for m in &desc.meshes {
        files.push((m.file.clone(), m.face_normals));
    }
    for s in &desc.shapes {
        if let Geometry::MeshFile { file, face_normals } = &s.geometry {
            files.push((file.clone(), *face_normals));
        }
    }
    files.sort();
    files.dedup();
    let start = std::time::Instant::now();
    let loaded: Vec<Result<Vec<LoadedGroup>, String>> = files
        .par_iter()
        .map(|(file, face_normals)| builder::read_mesh_file(file, *face_normals, opts.bvh_split))
        .collect();
    b.build_seconds += start.elapsed().as_secs_f64();
    let mut groups_of: HashMap<(PathBuf, bool), Vec<LoadedGroup>> = HashMap::new();
    for (key, result) in files.into_iter().zip(loaded) {
        match result {
            Ok(g) => {
                groups_of.insert(key, g);
            }
            Err(e) => {
                let loc = mesh_loc(desc, &key.0);
                return Err(Error::at(&loc, e));
            }
        }
    }
    for s in &desc.shapes {
        add_shape(&mut b, desc, s, &material_ids, &groups_of).map_err(|e| e.or_at(&s.loc))?;
    }

    for l in &desc.lights {
        add_light(&mut b, &l.light, &mut textures).map_err(|e| e.or_at(&l.loc))?;
    }

    let camera = camera(desc, &b).map_err(|e| e.or_at(&desc.camera.loc))?;
    let origin = desc.source.as_deref().map(SourceLoc::file).unwrap_or_default();
    b.finish(camera, desc.light_selection).map_err(|e| Error::at(&origin, e))
}

/// Where a mesh file is named, for errors found while reading it.
fn mesh_loc(desc: &SceneDesc, file: &PathBuf) -> SourceLoc {
    let in_meshes = desc.meshes.iter().find(|m| &m.file == file).map(|m| m.loc.clone());
    let in_shapes = || {
        desc.shapes
            .iter()
            .find(|s| matches!(&s.geometry, Geometry::MeshFile { file: f, .. } if f == file))
            .map(|s| s.loc.clone())
    };
    in_meshes.or_else(in_shapes).unwrap_or_default()
}

pub(crate) fn transform_of(m: &Matrix4) -> Result<Transform, Error> {
    Transform::from_matrix(Mat4(*m)).ok_or_else(|| Error::new("the transform is not invertible"))
}

#[derive(Default)]
struct TextureCache {
    bitmaps: HashMap<(PathBuf, bool), Arc<Bitmap>>,
}

impl TextureCache {
    fn bitmap(&mut self, file: &PathBuf, raw: bool, loc: &SourceLoc) -> Result<Arc<Bitmap>, Error> {
        if let Some(b) = self.bitmaps.get(&(file.clone(), raw)) {
            return Ok(b.clone());
        }
        let bm = Arc::new(Bitmap::load(file, raw).map_err(|e| Error::at(loc, e))?);
        self.bitmaps.insert((file.clone(), raw), bm.clone());
        Ok(bm)
    }

    fn texture(&mut self, t: &TextureDesc) -> Result<Texture, Error> {
        Ok(match t {
            TextureDesc::Constant { color } => Texture::Constant(*color),
            TextureDesc::Bitmap { file, raw, uv_scale, uv_offset, loc } => {
                Texture::Bitmap { image: self.bitmap(file, *raw, loc)?, uv_scale: *uv_scale, uv_offset: *uv_offset }
            }
            TextureDesc::Checkerboard { color0, color1, uv_scale, uv_offset } => {
                Texture::Checkerboard { color0: *color0, color1: *color1, uv_scale: *uv_scale, uv_offset: *uv_offset }
            }
        })
    }
}

fn microfacet(r: &Roughness) -> Microfacet {
    Microfacet::new(r.distribution, r.alpha)
}

fn material_kind(m: &MaterialModel, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
    Ok(match m {
        MaterialModel::Diffuse { reflectance } => MaterialKind::Diffuse { reflectance: textures.texture(reflectance)? },
        MaterialModel::Phong { kd, ks, exponent } => {
            MaterialKind::Phong { kd: textures.texture(kd)?, ks: *ks, exponent: *exponent }
        }
        MaterialModel::Conductor { eta, k, specular, roughness } => match roughness {
            None => MaterialKind::Conductor { eta: *eta, k: *k, specular: *specular },
            Some(r) => MaterialKind::RoughConductor { dist: microfacet(r), eta: *eta, k: *k, specular: *specular },
        },
        MaterialModel::Dielectric { eta, reflect, transmit, roughness, thin } => {
            let (eta, reflect, transmit) = (*eta, *reflect, *transmit);
            match (thin, roughness) {
                (true, _) => MaterialKind::ThinDielectric { eta, reflect, transmit },
                (false, None) => MaterialKind::Dielectric { eta, reflect, transmit },
                (false, Some(r)) => MaterialKind::RoughDielectric { dist: microfacet(r), eta, reflect, transmit },
            }
        }
        MaterialModel::Plastic { diffuse, specular, eta, roughness } => {
            Material::plastic(textures.texture(diffuse)?, *specular, *eta, roughness.as_ref().map(microfacet))
        }
        MaterialModel::Black => MaterialKind::Black,
    })
}

fn material_id(b: &mut WorldBuilder, r: MaterialRef, ids: &[u32]) -> Result<u32, Error> {
    Ok(match r {
        MaterialRef::Index(i) => *ids
            .get(i)
            .ok_or_else(|| Error::new(format!("material index {i} is out of range ({} materials)", ids.len())))?,
        MaterialRef::DefaultDiffuse => b.default_material(),
        MaterialRef::Black => b.black_material(),
    })
}

fn add_shape(
    b: &mut WorldBuilder,
    desc: &SceneDesc,
    s: &ShapeDesc,
    material_ids: &[u32],
    groups_of: &HashMap<(PathBuf, bool), Vec<LoadedGroup>>,
) -> Result<(), Error> {
    let to_world = transform_of(&s.to_world)?;
    let material = material_id(b, s.material, material_ids)?;
    let (groups, instanced) = match &s.geometry {
        Geometry::MeshFile { file, face_normals } => (groups_of[&(file.clone(), *face_normals)].clone(), false),
        Geometry::Instance { mesh } => {
            let m = desc.meshes.get(*mesh).ok_or_else(|| {
                Error::new(format!("mesh index {mesh} is out of range ({} meshes)", desc.meshes.len()))
            })?;
            (groups_of[&(m.file.clone(), m.face_normals)].clone(), true)
        }
        Geometry::Mesh(data) => {
            let mesh = TriangleMesh::new(
                data.positions.clone(),
                data.normals.clone(),
                data.uvs.clone(),
                data.indices.clone(),
                b.split,
            )?;
            (vec![LoadedGroup::primitive(mesh)], false)
        }
        Geometry::Sphere { center, radius } => {
            return Ok(b.add_sphere(*center, *radius, &to_world, material, s.emission, s.flip_normals)?);
        }
        Geometry::Rectangle => (vec![LoadedGroup::primitive(rectangle_mesh(b.split))], false),
        Geometry::Cube => (vec![LoadedGroup::primitive(cube_mesh(b.split))], false),
        Geometry::Disk => (vec![LoadedGroup::primitive(disk_mesh(b.split))], false),
    };
    for g in &groups {
        let m = if s.use_mtl && !g.material.is_empty() { b.mtl_material(g).unwrap_or(material) } else { material };
        b.add_mesh_instance(&g.mesh, &to_world, instanced, m, s.emission, s.flip_normals)?;
    }
    Ok(())
}

fn add_light(b: &mut WorldBuilder, l: &LightKind, textures: &mut TextureCache) -> Result<(), Error> {
    match l {
        LightKind::Point { position, intensity } => {
            b.add_light(Light::Point { position: *position, intensity: *intensity })
        }
        LightKind::Spot { position, direction, intensity, cutoff_degrees, beam_degrees } => {
            b.add_light(Light::Spot {
                position: *position,
                frame: Frame::from_normal(direction.normalize()),
                intensity: *intensity,
                cutoff: cutoff_degrees.to_radians(),
                beam: beam_degrees.min(*cutoff_degrees).to_radians(),
            });
        }
        LightKind::Directional { direction, irradiance } => b.add_directional(*direction, *irradiance),
        LightKind::Constant { radiance } => b.add_constant_environment(*radiance),
        LightKind::EnvMap { file, scale, to_world } => {
            let image = textures.bitmap(file, true, &SourceLoc::default())?;
            b.add_envmap((*image).clone(), *scale, transform_of(to_world)?);
        }
    }
    Ok(())
}

fn camera(desc: &SceneDesc, b: &WorldBuilder) -> Result<Camera, Error> {
    let c: &CameraDesc = &desc.camera;
    let to_world = match &c.to_world {
        Some(m) => transform_of(m)?,
        None => frame_bounds(b)?,
    };
    let mut camera = Camera::new(to_world, desc.film.width, desc.film.height, c.fov_degrees, c.fov_axis);
    camera.lens_radius = c.lens_radius;
    camera.focus_distance = c.focus_distance;
    camera.near_clip = c.near_clip;
    camera.far_clip = c.far_clip;
    Ok(camera)
}

/// A camera in front of (+z) the scene's bounds, looking at their centre (mesh previews).
fn frame_bounds(b: &WorldBuilder) -> Result<Transform, Error> {
    let bounds = b.bounds();
    let centre = bounds.center();
    let radius = bounds.extent().length() * 0.5;
    let eye = centre + Vec3 { x: 0.0, y: 0.0, z: radius * 2.8 };
    Transform::look_at(eye, centre, Vec3::Y).ok_or_else(|| Error::new("the scene is empty: nothing to frame"))
}
