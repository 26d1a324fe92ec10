//! Description → world: the one place where a scene description becomes the render-ready
//! [`World`]. It loads each mesh file once (in parallel), creates textures, materials,
//! shapes and lights in a fixed order (materials, meshes, shapes, lights, camera), owns the
//! tessellation of every primitive and every default, and reports errors at the entity's
//! source location.

mod builder;
mod driver;
mod media;
mod validate;

pub use builder::{LoadedGroup, WorldBuilder};
pub use driver::{build_cached, BuildCounters, Built, MeshCache, WorldLayout};
pub(crate) use driver::{material as build_material, patch_appearance};

use crate::accel::BvhSplit;
use crate::camera::Camera;
use crate::describe::{CameraDesc, Geometry, LightKind, MaterialRef, Matrix4};
use crate::error::{Error, SourceLoc};
use crate::lights::{Light, ProjectedKind, ProjectedLight};
use crate::materials::SceneDesc;
use crate::materials::{Bitmap, Texture, TextureCache};
use crate::math::{Aabb, Frame, Mat4, Transform, Vec3};
use crate::world::World;
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::sync::Arc;

/// Choices that shape the built world but are not part of the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildOptions {
    pub bvh_split: BvhSplit,
}

/// Builds the world a description describes.
pub fn build(desc: &SceneDesc, opts: &BuildOptions) -> Result<World, Error> {
    Ok(build_cached(desc, opts, &mut MeshCache::default(), &BTreeSet::new())?.world)
}

/// Checks every number of a description, as a build does first.
pub(crate) fn validate_description(desc: &SceneDesc) -> Result<(), Error> {
    validate::check(desc)
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

fn material_id(b: &mut WorldBuilder, r: MaterialRef, ids: &[u32]) -> Result<u32, Error> {
    Ok(match r {
        MaterialRef::Index(i) => *ids
            .get(i)
            .ok_or_else(|| Error::new(format!("material index {i} is out of range ({} materials)", ids.len())))?,
        MaterialRef::DefaultDiffuse => b.default_material(),
        MaterialRef::Black => b.black_material(),
    })
}

fn add_light(b: &mut WorldBuilder, l: &LightKind, textures: &mut TextureCache) -> Result<(), Error> {
    match l {
        LightKind::Point { position, intensity } => {
            b.add_light(Light::Point { position: *position, intensity: *intensity })
        }
        LightKind::Spot { position, direction, intensity, cutoff_degrees, beam_degrees, falloff } => {
            b.add_light(Light::Spot {
                gltf_falloff: *falloff == crate::describe::SpotFalloff::Gltf,
                position: *position,
                frame: Frame::from_normal(direction.normalize()),
                intensity: *intensity,
                cutoff: cutoff_degrees.to_radians(),
                beam: beam_degrees.min(*cutoff_degrees).to_radians(),
            });
        }
        LightKind::Directional { direction, irradiance } => b.add_directional(*direction, *irradiance),
        LightKind::Constant { radiance } => b.add_constant_environment(*radiance),
        LightKind::EnvMap { file, scale, to_world, texels } => {
            let image = match texels {
                Some(t) => Bitmap::of_texels(t),
                None => (*textures.bitmap(file, true, &SourceLoc::default())?).clone(),
            };
            b.add_envmap(image, *scale, transform_of(to_world)?);
        }
        LightKind::TexturedSpot { to_world, intensity, cutoff_degrees, beam_degrees, texture } => {
            b.add_light(Light::Projected(Arc::new(ProjectedLight {
                to_world: transform_of(to_world)?,
                texture: textures.texture(texture)?,
                kind: ProjectedKind::Spot {
                    intensity: *intensity,
                    cutoff: cutoff_degrees.to_radians(),
                    beam: beam_degrees.min(*cutoff_degrees).to_radians(),
                },
            })));
        }
        LightKind::Projector { to_world, irradiance, scale, fov_degrees, fov_axis } => {
            let texture = textures.texture(irradiance)?;
            // The field of view is taken over the texture's shape, as a camera's over its film.
            let (w, h) = match &texture {
                Texture::Bitmap { image, .. } => (image.width as u32, image.height as u32),
                _ => (1, 1),
            };
            let lens = Camera::new(Transform::IDENTITY, w, h, *fov_degrees, *fov_axis);
            b.add_light(Light::Projected(Arc::new(ProjectedLight {
                to_world: transform_of(to_world)?,
                texture,
                kind: ProjectedKind::Projector {
                    scale: *scale,
                    tan_half_x: lens.tan_half_x,
                    aspect: w as f32 / h as f32,
                },
            })));
        }
    }
    Ok(())
}

fn camera(desc: &SceneDesc, bounds: &Aabb) -> Result<Camera, Error> {
    let c: &CameraDesc = &desc.camera;
    let to_world = match &c.to_world {
        Some(m) => transform_of(m)?,
        None => frame_bounds(bounds)?,
    };
    let mut camera = Camera::new(to_world, desc.film.width, desc.film.height, c.fov_degrees, c.fov_axis);
    camera.lens_radius = c.lens_radius;
    camera.focus_distance = c.focus_distance;
    camera.near_clip = c.near_clip;
    camera.far_clip = c.far_clip;
    camera.projection = c.projection;
    if let Some(crop) = desc.film.crop {
        camera.set_crop(crop);
    }
    Ok(camera)
}

/// A camera in front of (+z) the scene's bounds, looking at their centre (mesh previews).
fn frame_bounds(bounds: &Aabb) -> Result<Transform, Error> {
    let centre = bounds.center();
    let radius = bounds.extent().length() * 0.5;
    let eye = centre + Vec3 { x: 0.0, y: 0.0, z: radius * 2.8 };
    Transform::look_at(eye, centre, Vec3::Y).ok_or_else(|| Error::new("the scene is empty: nothing to frame"))
}
