//! The build driver: [`build_cached`] builds a world from a description, reusing what an
//! earlier build of the same session made. Every mesh BVH (of a mesh file, an
//! in-description mesh, a primitive, or a copy with its transform baked in) is kept in a
//! [`MeshCache`], so building the world again after an edit builds only what the edit
//! changed: nothing geometric after a material, light or camera edit (those are patched into
//! the built world by [`patch_appearance`]), and only the top-level BVH after a transform
//! edit (the shape is then traced through its transform instead of being baked).
//! [`BuildCounters`] count what was built, so tests and users can see it.

use super::builder::{bake, environment_lights, read_mesh_file};
use super::{add_light, camera, material_id, mesh_loc, transform_of, validate};
use super::{BuildOptions, LoadedGroup, WorldBuilder};
use crate::accel::BvhSplit;
use crate::describe::{CurveBasisDesc, Emission, Geometry, MaterialRef, Matrix4, SdfNormalsDesc, ShapeDesc};
use crate::error::{Error, SourceLoc};
use crate::geometry::{cube_mesh, disk_mesh, rectangle_mesh, CurveBasis, SdfNormals, TriangleMesh};
use crate::lights::{AreaEmission, Light};
use crate::materials::{Material, TextureCache};
use crate::materials::{MaterialDesc, MaterialModel, SceneDesc};
use crate::math::Transform;
use crate::world::World;
use rayon::prelude::*;
use std::collections::hash_map::DefaultHasher;
use std::collections::{BTreeSet, HashMap, HashSet};
use std::hash::{Hash, Hasher};
use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;

/// How many BVHs the builds of one cache made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildCounters {
    /// Bottom-level (per-mesh) BVHs built.
    pub mesh_bvh_builds: u64,
    /// Top-level BVHs (over instances) built: one per world built.
    pub top_level_builds: u64,
}

/// Where a shape's object-space meshes come from.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Source {
    File {
        file: PathBuf,
        face_normals: bool,
        shape_index: u32,
        reverse_winding: bool,
    },
    /// An in-description mesh or a primitive, by shape index and a hash of its geometry (so
    /// a shape whose geometry was replaced is not served a stale mesh).
    Shape {
        index: usize,
        geometry: u64,
    },
}

/// A baked copy: one group of a source under one transform (its matrix's bits).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct BakedKey {
    /// Two shapes of one file and transform still get a copy each, as an uncached build
    /// gives them.
    shape: usize,
    source: Source,
    group: usize,
    to_world: [u64; 16],
}

/// The meshes of earlier builds, with their BVHs.
#[derive(Default)]
pub struct MeshCache {
    /// The split every cached BVH was built with; another split empties the cache.
    split: Option<BvhSplit>,
    groups: HashMap<Source, Vec<LoadedGroup>>,
    baked: HashMap<BakedKey, Arc<TriangleMesh>>,
    pub counters: BuildCounters,
}

/// What a build used, so that entries no longer used are dropped after it.
#[derive(Default)]
struct Used {
    groups: HashSet<Source>,
    baked: HashSet<BakedKey>,
}

/// Which instances and lights of a built world came from which entities of its
/// description: what an in-place edit needs to find them.
#[derive(Clone, Debug, Default)]
pub struct WorldLayout {
    /// The instances each shape placed.
    pub shape_instances: Vec<Range<u32>>,
    /// Lights made by emitting shapes; the description's lights follow them in order.
    pub shape_lights: u32,
    /// The description's materials are the world's first materials, in order.
    pub materials: u32,
}

/// A built world and its layout.
pub struct Built {
    pub world: World,
    pub layout: WorldLayout,
}

/// Builds the world, taking every mesh BVH it can from `cache` and adding those it builds.
/// Shapes in `instanced` are traced through their transform rather than baked (their
/// transform can then change without building a mesh BVH). With an empty cache and no
/// instanced shapes this is exactly [`super::build`].
pub fn build_cached(
    desc: &SceneDesc,
    opts: &BuildOptions,
    cache: &mut MeshCache,
    instanced: &BTreeSet<usize>,
) -> Result<Built, Error> {
    validate::check(desc)?;
    if cache.split != Some(opts.bvh_split) {
        let counters = cache.counters;
        *cache = MeshCache { split: Some(opts.bvh_split), counters, ..MeshCache::default() };
    }
    let mut b = WorldBuilder::new(opts.bvh_split);
    let mut textures = TextureCache::default();
    let mut used = Used::default();

    let mut material_ids = Vec::with_capacity(desc.materials.len());
    for m in &desc.materials {
        material_ids.push(b.add_material(material(m, &mut textures)?));
    }
    load_files(desc, opts.bvh_split, cache, &mut b)?;
    for m in super::media::media(desc)? {
        b.add_medium(m);
    }
    b.set_camera_medium(desc.camera.medium.map(|i| i as u32));

    let mut layout = WorldLayout { materials: desc.materials.len() as u32, ..WorldLayout::default() };
    for (index, s) in desc.shapes.iter().enumerate() {
        let first = b.instance_count() as u32;
        let place = Placement { index, instanced: instanced.contains(&index) };
        add_shape(&mut b, desc, s, &place, &material_ids, cache, &mut used, &mut textures)
            .map_err(|e| e.or_at(&s.loc))?;
        b.set_media_since(first as usize, super::media::boundary(&s.media));
        layout.shape_instances.push(first..b.instance_count() as u32);
    }
    layout.shape_lights = b.light_count() as u32;

    for l in &desc.lights {
        add_light(&mut b, &l.light, &mut textures).map_err(|e| e.or_at(&l.loc))?;
    }
    let camera = camera(desc, &b.bounds()).map_err(|e| e.or_at(&desc.camera.loc))?;
    let origin = desc.source.as_deref().map(SourceLoc::file).unwrap_or_default();
    let world = b.finish(camera, desc.light_selection).map_err(|e| Error::at(&origin, e))?;
    cache.counters.top_level_builds += 1;
    cache.groups.retain(|k, _| used.groups.contains(k));
    cache.baked.retain(|k, _| used.baked.contains(k));
    Ok(Built { world, layout })
}

/// Loads the mesh files not yet cached, in parallel, each once.
fn load_files(desc: &SceneDesc, split: BvhSplit, cache: &mut MeshCache, b: &mut WorldBuilder) -> Result<(), Error> {
    let mut files: Vec<(PathBuf, bool, u32, bool)> =
        desc.meshes.iter().map(|m| (m.file.clone(), m.face_normals, m.shape_index, m.reverse_winding)).collect();
    for s in &desc.shapes {
        if let Geometry::MeshFile { file, face_normals, shape_index } = &s.geometry {
            files.push((file.clone(), *face_normals, *shape_index, false));
        }
    }
    files.sort();
    files.dedup();
    files.retain(|(file, face_normals, shape_index, reverse_winding)| {
        !cache.groups.contains_key(&Source::File {
            file: file.clone(),
            face_normals: *face_normals,
            shape_index: *shape_index,
            reverse_winding: *reverse_winding,
        })
    });
    let start = std::time::Instant::now();
    let loaded: Vec<Result<Vec<LoadedGroup>, String>> = files
        .par_iter()
        .map(|(file, face_normals, shape_index, reverse)| {
            read_mesh_file(file, *face_normals, *shape_index, *reverse, split)
        })
        .collect();
    b.build_seconds += start.elapsed().as_secs_f64();
    for ((file, face_normals, shape_index, reverse_winding), result) in files.into_iter().zip(loaded) {
        let groups = result.map_err(|e| Error::at(&mesh_loc(desc, &file), e))?;
        cache.counters.mesh_bvh_builds += groups.len() as u64;
        cache.groups.insert(Source::File { file, face_normals, shape_index, reverse_winding }, groups);
    }
    Ok(())
}

/// A shape's place in the description and how it is to be placed.
struct Placement {
    index: usize,
    /// Traced through its transform (not baked) even where the description would bake it.
    instanced: bool,
}

#[allow(clippy::too_many_arguments)]
fn add_shape(
    b: &mut WorldBuilder,
    desc: &SceneDesc,
    s: &ShapeDesc,
    place: &Placement,
    material_ids: &[u32],
    cache: &mut MeshCache,
    used: &mut Used,
    textures: &mut TextureCache,
) -> Result<(), Error> {
    let to_world = transform_of(&s.to_world)?;
    let material = material_id(b, s.material, material_ids)?;
    let emission = area_emission(s.emission.as_ref(), textures)?;
    let (source, instanced) = match &s.geometry {
        Geometry::MeshFile { file, face_normals, shape_index } => {
            let (file, face_normals, shape_index) = (file.clone(), *face_normals, *shape_index);
            (Source::File { file, face_normals, shape_index, reverse_winding: false }, false)
        }
        Geometry::Instance { mesh } => {
            let m = desc.meshes.get(*mesh).ok_or_else(|| {
                Error::new(format!("mesh index {mesh} is out of range ({} meshes)", desc.meshes.len()))
            })?;
            let (file, face_normals, shape_index) = (m.file.clone(), m.face_normals, m.shape_index);
            (Source::File { file, face_normals, shape_index, reverse_winding: m.reverse_winding }, true)
        }
        Geometry::Sphere { center, radius } => {
            check_attributes(desc, s, None)?;
            return Ok(b.add_sphere(*center, *radius, &to_world, material, emission, s.flip_normals)?);
        }
        Geometry::Cylinder { p0, p1, radius } => {
            check_attributes(desc, s, None)?;
            return Ok(b.add_cylinder(*p0, *p1, *radius, &to_world, material, emission, s.flip_normals)?);
        }
        Geometry::SdfGrid { file, normals } => {
            check_attributes(desc, s, None)?;
            return b
                .add_sdf_grid(
                    file,
                    match normals {
                        SdfNormalsDesc::Analytic => SdfNormals::Analytic,
                        SdfNormalsDesc::Smooth => SdfNormals::Smooth,
                    },
                    &to_world,
                    material,
                    emission,
                )
                .map_err(|e| Error::at(&s.loc, e));
        }
        Geometry::Curves { file, basis } => {
            check_attributes(desc, s, None)?;
            let basis = match basis {
                CurveBasisDesc::Linear => CurveBasis::Linear,
                CurveBasisDesc::BSpline => CurveBasis::BSpline,
            };
            if emission.is_some() || s.flip_normals {
                return Err(Error::at(&s.loc, "curves can neither emit light nor flip their normals"));
            }
            return b.add_curves(file, basis, &to_world, material).map_err(|e| Error::at(&s.loc, e));
        }
        g => (Source::Shape { index: place.index, geometry: geometry_hash(g) }, false),
    };
    if !cache.groups.contains_key(&source) {
        let mesh = match &s.geometry {
            Geometry::Mesh(data) => TriangleMesh::new(
                data.positions.clone(),
                data.normals.clone(),
                data.uvs.clone(),
                data.indices.clone(),
                b.split,
            )?,
            Geometry::Rectangle => rectangle_mesh(b.split),
            Geometry::Cube => cube_mesh(b.split),
            Geometry::Disk => disk_mesh(b.split),
            _ => unreachable!("mesh files are loaded before shapes are placed"),
        };
        cache.counters.mesh_bvh_builds += 1;
        cache.groups.insert(source.clone(), vec![LoadedGroup::primitive(mesh)]);
    }
    let groups = cache.groups[&source].clone();
    for g in &groups {
        check_attributes(desc, s, Some(&g.mesh))?;
    }
    used.groups.insert(source.clone());
    let instanced = instanced || place.instanced;
    for (group, g) in groups.iter().enumerate() {
        let m = if s.use_mtl && !g.material.is_empty() { b.mtl_material(g).unwrap_or(material) } else { material };
        if instanced || to_world.is_identity() {
            b.add_mesh_instance(&g.mesh, &to_world, instanced, m, emission.clone(), s.flip_normals)?;
        } else {
            // Baked here rather than by the builder so that the copy is cached; placed with
            // the identity, exactly as the builder places its own baked copies.
            let key =
                BakedKey { shape: place.index, source: source.clone(), group, to_world: matrix_bits(&s.to_world) };
            let mesh = match cache.baked.get(&key) {
                Some(m) => m.clone(),
                None => {
                    let start = std::time::Instant::now();
                    let m = Arc::new(bake(&g.mesh, &to_world, b.split)?);
                    b.build_seconds += start.elapsed().as_secs_f64();
                    cache.counters.mesh_bvh_builds += 1;
                    cache.baked.insert(key.clone(), m.clone());
                    m
                }
            };
            used.baked.insert(key);
            b.add_mesh_instance(&mesh, &Transform::IDENTITY, false, m, emission.clone(), s.flip_normals)?;
        }
    }
    Ok(())
}

/// A described material, built: its kind with textures loaded, its sides.
pub(crate) fn material(m: &MaterialDesc, textures: &mut TextureCache) -> Result<Material, Error> {
    let kind = m.model.build(textures).map_err(|e| e.or_at(&m.loc))?;
    let mut out = Material::new(m.name.clone(), kind, m.two_sided);
    if let MaterialModel::Gltf(g) = &m.model {
        out.cull_back_faces = g.culls_back_faces();
    }
    Ok(out)
}

/// What a shape emits, its texture made (or found in the cache).
fn area_emission(e: Option<&Emission>, textures: &mut TextureCache) -> Result<Option<AreaEmission>, Error> {
    e.map(|e| Ok(AreaEmission { radiance: textures.texture(&e.radiance)?, two_sided: e.two_sided })).transpose()
}

/// Every mesh attribute the shape's material and emitted radiance read must be one its mesh
/// has (spheres and cylinders have none), with a value size a texture can use.
fn check_attributes(desc: &SceneDesc, s: &ShapeDesc, mesh: Option<&TriangleMesh>) -> Result<(), Error> {
    let material = match s.material {
        MaterialRef::Index(i) => desc.materials.get(i),
        _ => None,
    };
    let mut reads: Vec<(String, &str)> = Vec::new();
    if let Some(m) = material {
        let what = format!("material '{}'", m.name);
        reads.extend(m.model.mesh_attributes().into_iter().map(|(name, _)| (what.clone(), name)));
    }
    if let Some(e) = &s.emission {
        reads.extend(e.mesh_attributes().into_iter().map(|(name, _)| ("the emitted radiance".to_string(), name)));
    }
    for (what, name) in reads {
        if mesh.is_some_and(|mesh| mesh.attribute(name).is_some()) {
            continue;
        }
        let have: Vec<&str> = mesh.map_or(vec![], |m| m.attributes.iter().map(|a| a.name.as_str()).collect());
        let have = if have.is_empty() { "none".to_string() } else { have.join(", ") };
        return Err(Error::new(format!(
            "{what} reads mesh attribute '{name}', which this shape does not have (it has: {have})"
        )));
    }
    Ok(())
}

fn matrix_bits(m: &Matrix4) -> [u64; 16] {
    let mut out = [0; 16];
    for (i, v) in m.iter().flatten().enumerate() {
        out[i] = v.to_bits();
    }
    out
}

/// A hash of an in-description mesh or primitive (its kind and every number of its data).
fn geometry_hash(g: &Geometry) -> u64 {
    let mut h = DefaultHasher::new();
    std::mem::discriminant(g).hash(&mut h);
    if let Geometry::Mesh(d) = g {
        for p in &d.positions {
            [p.x, p.y, p.z].map(f32::to_bits).hash(&mut h);
        }
        d.indices.hash(&mut h);
        for n in d.normals.iter().flatten() {
            [n.x, n.y, n.z].map(f32::to_bits).hash(&mut h);
        }
        for uv in d.uvs.iter().flatten() {
            uv.map(f32::to_bits).hash(&mut h);
        }
        (d.normals.is_some(), d.uvs.is_some()).hash(&mut h);
    }
    h.finish()
}

/// Makes a built world show the materials, emission, lights and camera of `desc`, which
/// must differ from the description it was built from in nothing else. Builds no BVH.
/// Returns `false`, changing nothing, where that cannot be done in place (a shape started
/// or stopped emitting, lights were added or removed): the world must be built again.
pub(crate) fn patch_appearance(world: &mut World, desc: &SceneDesc, layout: &WorldLayout) -> Result<bool, Error> {
    validate::check(desc)?;
    if layout.shape_instances.len() != desc.shapes.len()
        || layout.materials as usize != desc.materials.len()
        || world.lights.len() != layout.shape_lights as usize + desc.lights.len()
    {
        return Ok(false);
    }
    // Everything is made first, so that an error leaves the world as it was.
    let mut textures = TextureCache::default();
    let mut materials = Vec::with_capacity(desc.materials.len());
    for m in &desc.materials {
        materials.push(material(m, &mut textures)?);
    }
    let mut b = WorldBuilder::new(world.bvh_split);
    for l in &desc.lights {
        add_light(&mut b, &l.light, &mut textures).map_err(|e| e.or_at(&l.loc))?;
    }
    let lights = b.into_lights(&world.bounds).map_err(Error::new)?;
    let camera = camera(desc, &world.bounds).map_err(|e| e.or_at(&desc.camera.loc))?;
    let mut emission = Vec::new();
    for (s, instances) in desc.shapes.iter().zip(&layout.shape_instances) {
        for i in instances.clone() {
            match (world.instances[i as usize].light, &s.emission) {
                (Some(light), Some(e)) => {
                    let e = area_emission(Some(e), &mut textures).map_err(|err| err.or_at(&s.loc))?;
                    emission.extend(e.map(|e| (light as usize, e)));
                }
                (None, None) => {}
                _ => return Ok(false),
            }
        }
    }

    for (i, m) in materials.into_iter().enumerate() {
        world.materials[i] = m;
    }
    world.update_material_flags();
    // Made again from the new radiance: a textured one's importance sampling follows it.
    for (light, e) in emission {
        let l = &mut world.lights[light];
        match l {
            Light::Mesh { instance, emitter, .. } => {
                *l = Light::mesh(*instance, emitter.clone(), e.radiance, e.two_sided)
            }
            Light::Sphere { instance, sphere, inward, .. } => {
                *l = Light::sphere(*instance, *sphere, e.radiance, *inward)
            }
            Light::Cylinder { instance, cylinder, inward, .. } => {
                *l = Light::cylinder(*instance, *cylinder, e.radiance, *inward)
            }
            Light::Point { .. }
            | Light::Spot { .. }
            | Light::Directional { .. }
            | Light::Constant { .. }
            | Light::EnvMap(_)
            | Light::Projected(_) => unreachable!("an instance's light is an area light"),
        }
    }
    let first = layout.shape_lights as usize;
    world.lights.truncate(first);
    world.lights.extend(lights);
    world.environment_lights = environment_lights(&world.lights);
    world.camera = camera;
    world.media = super::media::media(desc)?;
    world.camera_medium = desc.camera.medium.map(|i| i as u32);
    for (s, instances) in desc.shapes.iter().zip(&layout.shape_instances) {
        for i in instances.clone() {
            world.instances[i as usize].media = super::media::boundary(&s.media);
        }
    }
    // Light powers changed: the light-selection distribution follows them.
    world.set_light_selection(desc.light_selection);
    Ok(true)
}
