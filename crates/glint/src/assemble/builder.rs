//! The world builder: places meshes, spheres, materials and lights, loads each mesh file
//! once, folds transforms and creates area lights. `build` drives it from a description;
//! tests drive it directly to make small worlds in code.

use crate::accel::BvhSplit;
use crate::camera::Camera;
use crate::geometry::{CurveBasis, Curves, Cylinder, SdfGrid, SdfGridData, SdfNormals, Sphere, TriangleMesh};
use crate::io::{obj, ply, serialized};
use crate::lights::LightSelection;
use crate::lights::{scene_radius, AreaEmission, EnvMap, Light, MeshEmitter};
use crate::materials::Black;
use crate::materials::{
    Bitmap, ConductorMaterial, DielectricMaterial, DiffuseMaterial, Material, MaterialKind, PhongMaterial, Texture,
};
use crate::math::{vec3, Aabb, Rgb, Transform, Vec3};
use crate::media::{Medium, MediumBoundary};
use crate::world::{Instance, ShapeRef, World};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Lights that need the finished scene's bounds, created in `finish`.
enum PendingLight {
    Ready(Light),
    Directional { direction: Vec3, irradiance: Rgb },
    Constant { radiance: Rgb },
    EnvMap { image: Bitmap, scale: f32, to_world: Transform },
}

/// A mesh loaded from a file: one per material group.
#[derive(Clone, Debug)]
pub struct LoadedGroup {
    pub mesh: Arc<TriangleMesh>,
    /// `usemtl` name for OBJ groups, empty otherwise.
    pub material: String,
    /// That material as the OBJ's MTL file defines it, if it does.
    pub mtl: Option<obj::MtlMaterial>,
}

impl LoadedGroup {
    pub fn primitive(mesh: TriangleMesh) -> LoadedGroup {
        LoadedGroup { mesh: Arc::new(mesh), material: String::new(), mtl: None }
    }
}

/// Reads an OBJ (one group per material) or PLY file and builds each group's BVH;
/// `reverse_winding` (glTF primitives only) reverses each triangle's vertex order.
pub fn read_mesh_file(
    path: &Path,
    face_normals: bool,
    shape_index: u32,
    reverse_winding: bool,
    split: BvhSplit,
) -> Result<Vec<LoadedGroup>, String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if reverse_winding && !matches!(ext.as_str(), "gltf" | "glb") {
        return Err(format!("{}: only glTF primitives are read with reversed winding", path.display()));
    }
    match ext.as_str() {
        "serialized" => {
            let m = serialized::read_serialized(path, shape_index)?;
            // Mitsuba computes smooth normals for a serialized mesh that stores none.
            let normals = match (face_normals, m.normals) {
                (true, _) => None,
                (false, Some(n)) => Some(n),
                (false, None) => Some(serialized::angle_weighted_normals(&m.positions, &m.indices)),
            };
            let mesh = TriangleMesh::new(m.positions, normals, m.uvs, m.indices, split)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            Ok(vec![LoadedGroup::primitive(mesh)])
        }
        "obj" => {
            let f = obj::read_obj(path)?;
            let mut out = Vec::new();
            for g in f.groups {
                let normals = if face_normals { None } else { g.normals };
                let mesh = TriangleMesh::new(g.positions, normals, g.uvs, g.indices, split)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                let mtl = f.materials.iter().find(|m| m.name == g.material).cloned();
                out.push(LoadedGroup { mesh: Arc::new(mesh), material: g.material, mtl });
            }
            Ok(out)
        }
        "ply" => {
            let m = ply::read_ply(path)?;
            let normals = if face_normals { None } else { m.normals };
            let mesh = TriangleMesh::new(m.positions, normals, m.uvs, m.indices, split)
                .and_then(|mesh| mesh.with_attributes(m.attributes))
                .map_err(|e| format!("{}: {e}", path.display()))?;
            Ok(vec![LoadedGroup::primitive(mesh)])
        }
        "gltf" | "glb" => {
            Ok(vec![LoadedGroup::primitive(gltf_primitive(path, shape_index, face_normals, reverse_winding, split)?)])
        }
        _ => Err(format!("{}: unknown mesh format (expected .obj, .ply or .serialized)", path.display())),
    }
}

/// Primitive `flat` of a glTF file (see [`crate::io::gltf::GltfFile::primitive_at`]), with
/// its second texture coordinate set, vertex colours and tangents as mesh attributes; `reverse` gives
/// each triangle the opposite winding (for a placement by a mirroring transform).
fn gltf_primitive(
    path: &Path,
    flat: u32,
    face_normals: bool,
    reverse: bool,
    split: BvhSplit,
) -> Result<TriangleMesh, String> {
    use crate::geometry::{AttributeScope, MeshAttribute};
    use crate::materials::{
        ALPHA_ATTRIBUTE, COLOR_ATTRIBUTE, TANGENT_ATTRIBUTE, TANGENT_SIGN_ATTRIBUTE, UV1_ATTRIBUTE,
    };
    let at = |e: String| format!("{}: {e}", path.display());
    let f = crate::io::gltf::open_cached(path).map_err(at)?;
    let (mesh, prim) = f.primitive_at(flat as usize).ok_or_else(|| at(format!("no primitive {flat}")))?;
    let mut p = crate::io::gltf::read_primitive(&f, mesh, prim).map_err(at)?;
    if reverse {
        for t in &mut p.indices {
            t.swap(1, 2);
        }
    }
    let attribute = |name: &str, dim: usize, values: Vec<f32>| MeshAttribute {
        name: name.into(),
        scope: AttributeScope::Vertex,
        dim,
        values,
    };
    let mut attributes = Vec::new();
    if let Some(uv1) = &p.uv1 {
        attributes.push(attribute(UV1_ATTRIBUTE, 3, uv1.iter().flat_map(|t| [t[0], t[1], 0.0]).collect()));
    }
    if let Some(c) = &p.colors {
        attributes.push(attribute(COLOR_ATTRIBUTE, 3, c.iter().flat_map(|c| [c[0], c[1], c[2]]).collect()));
        attributes.push(attribute(ALPHA_ATTRIBUTE, 1, c.iter().map(|c| c[3]).collect()));
    }
    if let Some(t) = &p.tangents {
        attributes.push(attribute(TANGENT_ATTRIBUTE, 3, t.iter().flat_map(|t| [t[0], t[1], t[2]]).collect()));
        attributes.push(attribute(TANGENT_SIGN_ATTRIBUTE, 1, t.iter().map(|t| t[3]).collect()));
    }
    let normals = if face_normals { None } else { p.normals };
    let ctx = format!("meshes[{mesh}].primitives[{prim}]");
    TriangleMesh::new(p.positions, normals, p.uv0, p.indices, split)
        .and_then(|m| m.with_attributes(attributes))
        .map_err(|e| at(format!("{ctx}: {e}")))
}

/// Material for an MTL entry (used when an OBJ shape names no material).
fn material_from_mtl(m: &obj::MtlMaterial) -> Material {
    let kind = if m.illum == 7 || m.dissolve < 1.0 {
        MaterialKind::Dielectric(DielectricMaterial::smooth(m.ni.max(1.0001), Rgb::WHITE, Rgb::WHITE))
    } else if m.illum == 5 {
        MaterialKind::Conductor(ConductorMaterial { eta: Rgb::BLACK, k: Rgb::WHITE, specular: m.ks, roughness: None })
    } else if m.ks.max_component() > 0.0 && m.ns > 0.0 {
        MaterialKind::Phong(PhongMaterial { kd: Texture::Constant(m.kd), ks: m.ks, exponent: m.ns })
    } else {
        MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(m.kd) })
    };
    Material::new(format!("mtl:{}", m.name), kind, true)
}

/// A private copy of `mesh` with `to_world` baked into its vertices (and its own BVH).
pub(crate) fn bake(mesh: &TriangleMesh, to_world: &Transform, split: BvhSplit) -> Result<TriangleMesh, String> {
    let positions = mesh.positions.iter().map(|&p| to_world.point(p)).collect();
    let normals = mesh.normals.as_ref().map(|ns| ns.iter().map(|&n| to_world.normal(n).normalize()).collect());
    // Indices are kept: as in Mitsuba, a mirroring transform reverses the winding and so
    // flips the face normal.
    TriangleMesh::new(positions, normals, mesh.uvs.clone(), mesh.indices.clone(), split)?
        .with_attributes(mesh.attributes.clone())
}

pub struct WorldBuilder {
    pub split: BvhSplit,
    meshes: Vec<Arc<TriangleMesh>>,
    spheres: Vec<Sphere>,
    cylinders: Vec<Cylinder>,
    sdf_grids: Vec<SdfGrid>,
    curves: Vec<Curves>,
    /// SDF grids by file, loaded once however often they are placed.
    sdf_data: HashMap<std::path::PathBuf, Arc<SdfGridData>>,
    instances: Vec<Instance>,
    materials: Vec<Material>,
    material_names: HashMap<String, u32>,
    lights: Vec<PendingLight>,
    mesh_ids: HashMap<*const TriangleMesh, u32>,
    pub build_seconds: f64,
    media: Vec<Medium>,
    camera_medium: Option<u32>,
}

impl WorldBuilder {
    pub fn new(split: BvhSplit) -> WorldBuilder {
        WorldBuilder {
            split,
            meshes: Vec::new(),
            spheres: Vec::new(),
            cylinders: Vec::new(),
            sdf_grids: Vec::new(),
            curves: Vec::new(),
            sdf_data: HashMap::new(),
            instances: Vec::new(),
            materials: Vec::new(),
            material_names: HashMap::new(),
            lights: Vec::new(),
            mesh_ids: HashMap::new(),
            build_seconds: 0.0,
            media: Vec::new(),
            camera_medium: None,
        }
    }

    pub fn add_material(&mut self, m: Material) -> u32 {
        let id = self.materials.len() as u32;
        self.material_names.insert(m.name.clone(), id);
        self.materials.push(m);
        id
    }

    pub fn material_id(&self, name: &str) -> Option<u32> {
        self.material_names.get(name).copied()
    }

    /// A black, one-sided material for emitters declared without one.
    pub fn black_material(&mut self) -> u32 {
        if let Some(id) = self.material_id("__black") {
            return id;
        }
        self.add_material(Material::new("__black", MaterialKind::Black(Black), false))
    }

    /// A default diffuse material (Mitsuba's: reflectance 0.5), for shapes without one.
    pub fn default_material(&mut self) -> u32 {
        if let Some(id) = self.material_id("__default") {
            return id;
        }
        self.add_material(Material::new(
            "__default",
            MaterialKind::Diffuse(DiffuseMaterial { reflectance: Texture::Constant(Rgb::splat(0.5)) }),
            false,
        ))
    }

    /// The material of an OBJ group's `usemtl` entry (created on first use), if the MTL
    /// file defines it.
    pub fn mtl_material(&mut self, group: &LoadedGroup) -> Option<u32> {
        let mtl = group.mtl.as_ref()?;
        let key = format!("mtl:{}", mtl.name);
        if let Some(id) = self.material_id(&key) {
            return Some(id);
        }
        Some(self.add_material(material_from_mtl(mtl)))
    }

    fn mesh_id(&mut self, mesh: &Arc<TriangleMesh>) -> u32 {
        let key = Arc::as_ptr(mesh);
        if let Some(&id) = self.mesh_ids.get(&key) {
            return id;
        }
        let id = self.meshes.len() as u32;
        self.meshes.push(mesh.clone());
        self.mesh_ids.insert(key, id);
        id
    }

    /// Places a mesh. With `instanced` the mesh is shared and traced through its transform;
    /// otherwise the transform is baked into a private copy of the vertices (faster to trace).
    pub fn add_mesh_instance(
        &mut self,
        mesh: &Arc<TriangleMesh>,
        to_world: &Transform,
        instanced: bool,
        material: u32,
        emission: Option<AreaEmission>,
        flip_normals: bool,
    ) -> Result<(), String> {
        let (mesh, xf) = if instanced || to_world.is_identity() {
            (mesh.clone(), if to_world.is_identity() { None } else { Some(*to_world) })
        } else {
            let start = Instant::now();
            let m = bake(mesh, to_world, self.split)?;
            self.build_seconds += start.elapsed().as_secs_f64();
            (Arc::new(m), None)
        };
        let id = self.mesh_id(&mesh);
        let bounds = match &xf {
            None => mesh.bounds(),
            Some(t) => t.aabb(&mesh.bounds()),
        };
        let instance = self.instances.len() as u32;
        let light = emission.map(|e| {
            let triangles: Vec<[Vec3; 3]> = (0..mesh.indices.len())
                .map(|t| {
                    let v = mesh.vertices(t);
                    match &xf {
                        None => v,
                        Some(x) => [x.point(v[0]), x.point(v[1]), x.point(v[2])],
                    }
                })
                .map(|[a, b, c]| if flip_normals { [a, c, b] } else { [a, b, c] })
                .collect();
            (triangles, e)
        });
        let light = match light {
            Some((triangles, e)) => {
                let Some(emitter) = MeshEmitter::of_mesh(triangles, mesh.clone(), flip_normals) else {
                    return Err("an emitting mesh has zero area".into());
                };
                self.lights.push(PendingLight::Ready(Light::mesh(
                    instance,
                    Arc::new(emitter),
                    e.radiance,
                    e.two_sided,
                )));
                Some(self.lights.len() as u32 - 1)
            }
            None => None,
        };
        self.instances.push(Instance {
            shape: ShapeRef::Mesh(id),
            to_world: xf,
            material,
            light,
            flip_normals,
            bounds,
            media: MediumBoundary::default(),
        });
        Ok(())
    }

    /// Places a sphere; its transform must be a similarity (uniform scale).
    pub fn add_sphere(
        &mut self,
        center: Vec3,
        radius: f32,
        to_world: &Transform,
        material: u32,
        emission: Option<AreaEmission>,
        flip_normals: bool,
    ) -> Result<(), String> {
        let c = to_world.point(center);
        let axes = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| to_world.vector(a).length());
        if (axes[0] - axes[1]).abs() > 1e-4 * axes[0] || (axes[0] - axes[2]).abs() > 1e-4 * axes[0] {
            return Err("a sphere's transform must scale all axes equally".into());
        }
        let r = radius * axes[0];
        if !(r > 0.0 && r.is_finite()) {
            return Err(format!("sphere radius must be positive, got {r}"));
        }
        // The rotation (or reflection) part of the transform orients the sphere's uvs.
        let axes = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| to_world.vector(a).normalize());
        let sphere = Sphere { center: c, radius: r, axes };
        let id = self.spheres.len() as u32;
        self.spheres.push(sphere);
        let instance = self.instances.len() as u32;
        let light = emission.map(|e| {
            // A sphere emits on the side its normal faces (Mitsuba has no two-sided area light).
            self.lights.push(PendingLight::Ready(Light::sphere(instance, sphere, e.radiance, flip_normals)));
            self.lights.len() as u32 - 1
        });
        self.instances.push(Instance {
            shape: ShapeRef::Sphere(id),
            to_world: None,
            material,
            light,
            flip_normals,
            bounds: sphere.bounds(),
            media: MediumBoundary::default(),
        });
        Ok(())
    }

    /// Places an open cylinder (Mitsuba's `p0`, `p1`, `radius`, then `to_world`).
    #[allow(clippy::too_many_arguments)]
    pub fn add_cylinder(
        &mut self,
        p0: Vec3,
        p1: Vec3,
        radius: f32,
        to_world: &Transform,
        material: u32,
        emission: Option<AreaEmission>,
        flip_normals: bool,
    ) -> Result<(), String> {
        let cylinder = Cylinder::new(p0, p1, radius, to_world)
            .ok_or("a cylinder needs a positive radius, distinct end points and an invertible transform")?;
        if emission.is_some() && !(cylinder.area() > 0.0 && cylinder.area().is_finite()) {
            return Err("an emitting cylinder has no finite area".into());
        }
        let id = self.cylinders.len() as u32;
        self.cylinders.push(cylinder);
        let instance = self.instances.len() as u32;
        // Emits on the side its normal faces, as a sphere.
        let light = emission.map(|e| {
            self.lights.push(PendingLight::Ready(Light::cylinder(instance, cylinder, e.radiance, flip_normals)));
            self.lights.len() as u32 - 1
        });
        self.instances.push(Instance {
            shape: ShapeRef::Cylinder(id),
            to_world: None,
            material,
            light,
            flip_normals,
            bounds: cylinder.bounds(),
            media: MediumBoundary::default(),
        });
        Ok(())
    }

    /// Places the signed distance grid of a Mitsuba `.vol` file (one channel) over the unit
    /// cube mapped by `to_world`; the file's bounding box is ignored, as in Mitsuba.
    pub fn add_sdf_grid(
        &mut self,
        file: &std::path::Path,
        normals: SdfNormals,
        to_world: &Transform,
        material: u32,
        emission: Option<AreaEmission>,
    ) -> Result<(), String> {
        if emission.is_some() {
            return Err("an emitting sdfgrid is not supported (Mitsuba's cannot emit either)".into());
        }
        let data = match self.sdf_data.get(file) {
            Some(d) => d.clone(),
            None => {
                let start = Instant::now();
                let grid = crate::io::vol::read_vol(file)?;
                if grid.channels != 1 {
                    return Err(format!(
                        "{}: an SDF grid has 1 channel, this one has {}",
                        file.display(),
                        grid.channels
                    ));
                }
                let data = Arc::new(
                    SdfGridData::new(grid.resolution, grid.data, self.split)
                        .map_err(|e| format!("{}: {e}", file.display()))?,
                );
                self.build_seconds += start.elapsed().as_secs_f64();
                self.sdf_data.insert(file.to_path_buf(), data.clone());
                data
            }
        };
        let grid = SdfGrid::new(data, to_world, normals).ok_or("an sdfgrid needs an invertible, finite transform")?;
        let id = self.sdf_grids.len() as u32;
        let bounds = grid.bounds();
        self.sdf_grids.push(grid);
        self.instances.push(Instance {
            shape: ShapeRef::SdfGrid(id),
            to_world: None,
            material,
            light: None,
            flip_normals: false,
            bounds,
            media: MediumBoundary::default(),
        });
        Ok(())
    }

    /// Places the curves of a Mitsuba curve file: `to_world` moves the control points, not
    /// their radii (as in Mitsuba).
    pub fn add_curves(
        &mut self,
        file: &std::path::Path,
        basis: CurveBasis,
        to_world: &Transform,
        material: u32,
    ) -> Result<(), String> {
        let start = Instant::now();
        let data = crate::io::curves::read_curves(file, basis)?;
        let points = data
            .points
            .iter()
            .map(|p| {
                let q = to_world.point(vec3(p[0], p[1], p[2]));
                [q.x, q.y, q.z, p[3]]
            })
            .collect();
        let curves = Curves::new(basis, points, data.curve_starts, self.split)
            .map_err(|e| format!("{}: {e}", file.display()))?;
        self.build_seconds += start.elapsed().as_secs_f64();
        let id = self.curves.len() as u32;
        let bounds = curves.bounds();
        self.curves.push(curves);
        self.instances.push(Instance {
            shape: ShapeRef::Curves(id),
            to_world: None,
            material,
            light: None,
            flip_normals: false,
            bounds,
            media: MediumBoundary::default(),
        });
        Ok(())
    }

    pub fn add_light(&mut self, light: Light) {
        self.lights.push(PendingLight::Ready(light));
    }
    pub fn add_directional(&mut self, direction: Vec3, irradiance: Rgb) {
        self.lights.push(PendingLight::Directional { direction: direction.normalize(), irradiance });
    }
    pub fn add_constant_environment(&mut self, radiance: Rgb) {
        self.lights.push(PendingLight::Constant { radiance });
    }
    pub fn add_envmap(&mut self, image: Bitmap, scale: f32, to_world: Transform) {
        self.lights.push(PendingLight::EnvMap { image, scale, to_world });
    }

    /// Adds a medium; its index is what [`MediumBoundary`] and the camera refer to.
    pub fn add_medium(&mut self, m: Medium) -> u32 {
        self.media.push(m);
        self.media.len() as u32 - 1
    }

    /// Puts the camera in a medium (by index).
    pub fn set_camera_medium(&mut self, medium: Option<u32>) {
        self.camera_medium = medium;
    }

    /// Makes the instances placed since `first` (one shape's) bound the given media.
    pub fn set_media_since(&mut self, first: usize, media: MediumBoundary) {
        for inst in &mut self.instances[first..] {
            inst.media = media;
        }
    }

    pub fn light_count(&self) -> usize {
        self.lights.len()
    }

    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// The bounds of everything placed so far.
    pub fn bounds(&self) -> Aabb {
        self.instances.iter().fold(Aabb::EMPTY, |a, i| a.union(i.bounds))
    }

    pub fn finish(self, camera: Camera, selection: LightSelection) -> Result<World, String> {
        let start = Instant::now();
        let bounds = self.instances.iter().fold(Aabb::EMPTY, |a, i| a.union(i.bounds));
        let lights = finish_lights(self.lights, scene_radius(&bounds))?;
        let environment_lights = environment_lights(&lights);
        let mut scene = World {
            meshes: self.meshes,
            spheres: self.spheres,
            cylinders: self.cylinders,
            sdf_grids: self.sdf_grids,
            curves: self.curves,
            instances: self.instances,
            top: Default::default(),
            materials: self.materials,
            lights,
            environment_lights,
            camera,
            bounds,
            light_distribution: None,
            light_tree: None,
            light_selection: selection,
            bvh_split: self.split,
            bvh_build_seconds: 0.0,
            has_masks: false,
            has_passage_materials: false,
            prefetch_hits: false,
            media: self.media,
            camera_medium: self.camera_medium,
        };
        scene.finish(selection);
        scene.bvh_build_seconds = self.build_seconds + start.elapsed().as_secs_f64();
        Ok(scene)
    }

    /// The lights placed so far, finished for a scene of the given bounds (a session that
    /// edits lights in a built world makes them this way).
    pub(crate) fn into_lights(self, bounds: &Aabb) -> Result<Vec<Light>, String> {
        finish_lights(self.lights, scene_radius(bounds))
    }
}

fn finish_lights(pending: Vec<PendingLight>, radius: f32) -> Result<Vec<Light>, String> {
    let mut lights = Vec::with_capacity(pending.len());
    for l in pending {
        lights.push(match l {
            PendingLight::Ready(l) => l,
            PendingLight::Directional { direction, irradiance } => {
                Light::Directional { direction, irradiance, scene_radius: radius }
            }
            PendingLight::Constant { radiance } => Light::Constant { radiance, scene_radius: radius },
            PendingLight::EnvMap { image, scale, to_world } => {
                Light::EnvMap(Arc::new(EnvMap::new(image, scale, to_world, radius)?))
            }
        });
    }
    Ok(lights)
}

/// Indices of the lights an escaping ray sees.
pub(crate) fn environment_lights(lights: &[Light]) -> Vec<u32> {
    (0..lights.len() as u32)
        .filter(|&i| matches!(lights[i as usize], Light::Constant { .. } | Light::EnvMap(_)))
        .collect()
}
