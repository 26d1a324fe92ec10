//! Description → world: the one place where a scene description becomes the render-ready
//! [`World`]. It loads each mesh file once (in parallel), creates textures, materials,
//! shapes and lights in a fixed order (materials, meshes, shapes, lights, camera), owns the
//! tessellation of every primitive and every default, and reports errors at the entity's
//! source location.

mod builder;
mod driver;
mod gltf;
mod media;
mod validate;

pub use builder::{LoadedGroup, WorldBuilder};
pub(crate) use driver::patch_appearance;
pub use driver::{build_cached, BuildCounters, Built, MeshCache, WorldLayout};

use crate::accel::BvhSplit;
use crate::bsdf::PrincipledRates;
use crate::bsdf::{HairBsdf, Microfacet};
use crate::camera::Camera;
use crate::describe::ScalarTexture as DescScalar;
use crate::describe::{
    CameraDesc, Geometry, LightKind, MaterialModel, MaterialRef, Matrix4, Roughness, SceneDesc, TextureDesc,
};
use crate::error::{Error, SourceLoc};
use crate::lights::{Light, ProjectedKind, ProjectedLight};
use crate::materials::{
    Bitmap, BlendMaterial, BlendMaterialPart, Material, MaterialKind, PrincipledMaterial, RoughnessMap, ScalarTexture,
    Texture,
};
use crate::math::{Aabb, Frame, Mat4, Transform, Vec3};
use crate::world::World;
use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
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

#[derive(Default)]
struct TextureCache {
    bitmaps: HashMap<(PathBuf, bool), Arc<Bitmap>>,
    /// glTF images by file, image index and whether sRGB-decoded.
    gltf_images: HashMap<(PathBuf, usize, bool), Arc<crate::io::gltf::RgbaImage>>,
}

impl TextureCache {
    fn bitmap(&mut self, file: &Path, raw: bool, loc: &SourceLoc) -> Result<Arc<Bitmap>, Error> {
        if let Some(b) = self.bitmaps.get(&(file.to_path_buf(), raw)) {
            return Ok(b.clone());
        }
        let bm = Arc::new(Bitmap::load(file, raw).map_err(|e| Error::at(loc, e))?);
        self.bitmaps.insert((file.to_path_buf(), raw), bm.clone());
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
            TextureDesc::MeshAttribute { name, scale, .. } => {
                Texture::MeshAttribute { name: name.clone(), scale: *scale }
            }
            TextureDesc::Gltf(d) => Texture::Gltf(self.gltf_texture(d)?),
        })
    }
}

/// The roughness of a material: constant, or read from its textures at each hit.
fn roughness_map(r: &Roughness, textures: &mut TextureCache) -> Result<RoughnessMap, Error> {
    let alpha_u = &r.alpha;
    let alpha_v = r.alpha_v.as_ref().unwrap_or(alpha_u);
    Ok(match (alpha_u, alpha_v) {
        (DescScalar::Value(u), DescScalar::Value(v)) => {
            RoughnessMap::Constant(Microfacet::anisotropic(r.distribution, *u, *v))
        }
        _ => {
            let mut tex = |s: &DescScalar| -> Result<Texture, Error> {
                match s {
                    DescScalar::Value(v) => Ok(Texture::Constant(crate::math::Rgb::splat(*v))),
                    DescScalar::Texture(t) => Ok(scalar_checker_parity(textures.texture(t)?)),
                }
            };
            RoughnessMap::Textured { kind: r.distribution, alpha_u: tex(alpha_u)?, alpha_v: tex(alpha_v)? }
        }
    })
}

/// Mitsuba's checkerboard read as a number (`eval_1`, what roughness reads) puts `color1`
/// where its colour lookup (`eval`) puts `color0`, and the reverse; glint follows it, so a
/// checkerboard of roughness lands where Mitsuba puts it.
fn scalar_checker_parity(t: Texture) -> Texture {
    match t {
        Texture::Checkerboard { color0, color1, uv_scale, uv_offset } => {
            Texture::Checkerboard { color0: color1, color1: color0, uv_scale, uv_offset }
        }
        other => other,
    }
}

/// A roughness that must be one number (plastics, whose coating tables are precomputed).
fn constant_microfacet(r: &Roughness) -> Result<Microfacet, Error> {
    match (&r.alpha, &r.alpha_v) {
        (DescScalar::Value(a), None) => Ok(Microfacet::new(r.distribution, *a)),
        (DescScalar::Value(a), Some(DescScalar::Value(b))) if a == b => Ok(Microfacet::new(r.distribution, *a)),
        _ => Err(Error::new("this material's roughness must be one number (isotropic, untextured), as in Mitsuba")),
    }
}

fn material_kind(m: &MaterialModel, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
    Ok(match m {
        MaterialModel::Diffuse { reflectance } => MaterialKind::Diffuse { reflectance: textures.texture(reflectance)? },
        MaterialModel::Phong { kd, ks, exponent } => {
            MaterialKind::Phong { kd: textures.texture(kd)?, ks: *ks, exponent: *exponent }
        }
        MaterialModel::Conductor { eta, k, specular, roughness } => match roughness {
            None => MaterialKind::Conductor { eta: *eta, k: *k, specular: *specular },
            Some(r) => MaterialKind::RoughConductor {
                dist: roughness_map(r, textures)?,
                eta: *eta,
                k: *k,
                specular: *specular,
            },
        },
        MaterialModel::Dielectric { eta, reflect, transmit, roughness, thin } => {
            let (eta, reflect, transmit) = (*eta, *reflect, *transmit);
            match (thin, roughness) {
                (true, _) => MaterialKind::ThinDielectric { eta, reflect, transmit },
                (false, None) => MaterialKind::Dielectric { eta, reflect, transmit },
                (false, Some(r)) => {
                    MaterialKind::RoughDielectric { dist: roughness_map(r, textures)?, eta, reflect, transmit }
                }
            }
        }
        MaterialModel::Plastic { diffuse, specular, eta, roughness, nonlinear } => {
            let dist = roughness.as_ref().map(constant_microfacet).transpose()?;
            let diffuse = textures.texture(diffuse)?;
            if *nonlinear {
                Material::nonlinear_plastic(diffuse, *specular, *eta, dist)
            } else {
                Material::plastic(diffuse, *specular, *eta, dist)
            }
        }
        MaterialModel::Black => MaterialKind::Black,
        MaterialModel::NormalMap { normals, nested } => MaterialKind::NormalMap {
            normals: textures.texture(normals)?,
            nested: Box::new(material_kind(nested, textures)?),
        },
        MaterialModel::BumpMap { height, scale, nested } => MaterialKind::BumpMap {
            height: textures.texture(height)?,
            scale: *scale,
            nested: Box::new(material_kind(nested, textures)?),
        },
        MaterialModel::Mask { opacity, nested } => MaterialKind::Mask {
            opacity: textures.texture(opacity)?,
            nested: Box::new(material_kind(nested, textures)?),
        },
        MaterialModel::Null => MaterialKind::Null,
        MaterialModel::Principled(p) => principled_kind(p, textures)?,
        MaterialModel::Blend(b) => {
            let mut part = |p: &crate::describe::BlendPartDesc| -> Result<BlendMaterialPart, Error> {
                Ok(BlendMaterialPart { kind: material_kind(&p.model, textures)?, two_sided: p.two_sided })
            };
            let (first, second) = (part(&b.first)?, part(&b.second)?);
            MaterialKind::Blend(BlendMaterial::new(ScalarTexture::new(textures.texture(&b.weight)?), first, second))
        }
        MaterialModel::PPlastic { diffuse, specular, eta, roughness } => {
            let diffuse = textures.texture(diffuse)?;
            let (d, s) = (diffuse.mean().average(), specular.average());
            let specular_probability = if d + s > 0.0 { s / (d + s) } else { 0.5 };
            MaterialKind::PPlastic {
                diffuse,
                specular: *specular,
                eta: *eta,
                dist: roughness_map(roughness, textures)?,
                specular_probability,
            }
        }
        MaterialModel::Hair(h) => MaterialKind::Hair(HairBsdf::new(
            h.sigma_a,
            h.eta,
            h.longitudinal_roughness,
            h.azimuthal_roughness,
            h.scale_tilt,
        )),
        MaterialModel::Gltf(g) => gltf::gltf_kind(g, textures)?,
    })
}

fn principled_kind(p: &crate::describe::PrincipledDesc, textures: &mut TextureCache) -> Result<MaterialKind, Error> {
    let mut scalar = |t: &TextureDesc| -> Result<ScalarTexture, Error> { Ok(ScalarTexture::new(textures.texture(t)?)) };
    Ok(MaterialKind::Principled(PrincipledMaterial {
        roughness: scalar(&p.roughness)?,
        anisotropic: scalar(&p.anisotropic)?,
        metallic: scalar(&p.metallic)?,
        spec_trans: scalar(&p.spec_trans)?,
        eta: p.eta,
        spec_tint: scalar(&p.spec_tint)?,
        sheen: scalar(&p.sheen)?,
        sheen_tint: scalar(&p.sheen_tint)?,
        flatness: scalar(&p.flatness)?,
        clearcoat: scalar(&p.clearcoat)?,
        clearcoat_gloss: scalar(&p.clearcoat_gloss)?,
        base_color: textures.texture(&p.base_color)?,
        rates: PrincipledRates {
            diffuse: p.diffuse_sampling_rate,
            specular: p.specular_sampling_rate,
            clearcoat: p.clearcoat_sampling_rate,
        },
    }))
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
        LightKind::EnvMap { file, scale, to_world } => {
            let image = textures.bitmap(file, true, &SourceLoc::default())?;
            b.add_envmap((*image).clone(), *scale, transform_of(to_world)?);
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
