//! A bare OBJ or PLY file as a scene: the mesh in grey, lit by a grey sky and a sun, seen by
//! a camera that frames it from the front (for `glint info mesh.obj` and quick previews).

use crate::describe::{
    CameraDesc, FilmDesc, FovAxis, Geometry, LightDesc, LightKind, MaterialRef, PixelFilter, ShapeDesc, TextureDesc,
    IDENTITY,
};
use crate::materials::DiffuseDesc;

use crate::error::{Error, SourceLoc};
use crate::materials::{MaterialDesc, MaterialModel, SceneDesc};
use crate::math::{Rgb, Vec3};
use std::path::Path;

pub fn describe(path: &Path) -> Result<SceneDesc, Error> {
    let loc = SourceLoc::file(path);
    if !path.is_file() {
        return Err(Error::at(&loc, "no such file"));
    }
    let camera =
        CameraDesc { to_world: None, fov_degrees: 45.0, fov_axis: FovAxis::Y, loc: loc.clone(), ..Default::default() };
    let film =
        FilmDesc { width: 512, height: 512, filter: PixelFilter::Box, loc: loc.clone(), crop: None, aovs: Vec::new() };
    let mut d = SceneDesc::empty(camera, film);
    d.source = Some(path.to_path_buf());
    d.materials.push(MaterialDesc {
        name: "grey".into(),
        model: MaterialModel::Diffuse(DiffuseDesc { reflectance: TextureDesc::constant(Rgb::splat(0.6)) }),
        two_sided: true,
        loc: loc.clone(),
    });
    d.shapes.push(ShapeDesc {
        geometry: Geometry::MeshFile { file: path.to_path_buf(), face_normals: false, shape_index: 0 },
        to_world: IDENTITY,
        material: MaterialRef::Index(0),
        use_mtl: false,
        emission: None,
        flip_normals: false,
        loc: loc.clone(),
        media: Default::default(),
        id: None,
    });
    d.lights.push(LightDesc { light: LightKind::Constant { radiance: Rgb::splat(0.4) }, name: None, loc: loc.clone() });
    d.lights.push(LightDesc {
        light: LightKind::Directional { direction: Vec3 { x: 1.0, y: -2.0, z: -1.5 }, irradiance: Rgb::splat(2.5) },
        name: None,
        loc,
    });
    Ok(d)
}
