//! glTF 2.0 (`.gltf` with its buffers and images, or `.glb`) as a scene description: the
//! default scene's node hierarchy (meshes as shared instances, `EXT_mesh_gpu_instancing`),
//! materials (metallic-roughness and the KHR extensions Blender writes), cameras, emissive
//! surfaces and `KHR_lights_punctual`. The file's bytes are read through `io::gltf`; each
//! primitive becomes one mesh of [`SceneDesc::meshes`] (the build loads it from the file),
//! so a mesh placed by several nodes is stored once. See docs/gltf-support.md.

mod camera;
mod lights;
mod material;
mod scene;

use crate::describe::{CameraDesc, FilmDesc, IntegratorDesc, Matrix4, PixelFilter, VolpathSettings, IDENTITY};

use crate::error::{Error, SourceLoc};
use crate::io::gltf::GltfFile;
use crate::materials::SceneDesc;
use serde_json::Value;
use std::path::Path;

/// The extensions glint reads (`KHR_materials_pbrSpecularGlossiness` approximately: its
/// diffuse colour and glossiness become a dielectric base colour and roughness).
pub const SUPPORTED_EXTENSIONS: [&str; 13] = [
    "KHR_materials_emissive_strength",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_volume",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_unlit",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_texture_transform",
    "KHR_lights_punctual",
    "KHR_mesh_quantization",
    "EXT_mesh_gpu_instancing",
];

fn supported(ext: &str) -> bool {
    SUPPORTED_EXTENSIONS.contains(&ext)
}

/// Reads a glTF file as a whole scene; `camera` picks a camera by name or index.
pub fn read(path: &Path, camera: Option<&str>) -> Result<SceneDesc, Error> {
    let loc = SourceLoc::file(path);
    let file = crate::io::gltf::open_cached(path).map_err(|e| Error::at(&loc, e))?;
    describe(&file, path, camera).map_err(|e| Error::at(&loc, e))
}

/// Reads a glTF file as a group of shapes placed by `to_world` in a scene of another file
/// (JSON): its nodes and lights all move with it; its cameras are not used.
pub fn read_placed(path: &Path, to_world: &Matrix4) -> Result<SceneDesc, Error> {
    let loc = SourceLoc::file(path);
    let file = crate::io::gltf::open_cached(path).map_err(|e| Error::at(&loc, e))?;
    describe_placed(&file, path, None, to_world).map_err(|e| Error::at(&loc, e))
}

/// The description of an open glTF file (the fuzz target calls this on bytes).
pub fn describe(file: &GltfFile, path: &Path, camera: Option<&str>) -> Result<SceneDesc, String> {
    describe_placed(file, path, Some(camera), &IDENTITY)
}

/// `camera`: `None` for a placed group (no camera chosen), else the whole scene's choice.
fn describe_placed(
    file: &GltfFile,
    path: &Path,
    camera: Option<Option<&str>>,
    to_world: &Matrix4,
) -> Result<SceneDesc, String> {
    let loc = SourceLoc::file(path);
    let mut warnings = check_extensions(file)?;
    let cam = CameraDesc { loc: loc.clone(), ..CameraDesc::default() };
    let film =
        FilmDesc { width: 640, height: 480, filter: PixelFilter::Box, loc: loc.clone(), crop: None, aovs: Vec::new() };
    let mut d = SceneDesc::empty(cam, film);
    d.source = Some(path.to_path_buf());
    let materials = material::materials(file, path, &mut d)?;
    let walk = scene::place(file, path, to_world, &mut d, &materials, &mut warnings)?;
    if let Some(camera) = camera {
        camera::choose(file, &walk, camera, &mut d, &mut warnings)?;
        // Absorbing volumes (KHR_materials_volume attenuation) are media: rendered by the
        // volumetric path tracer, which is the path tracer where there are none.
        if !d.media.is_empty() {
            d.integrator = IntegratorDesc::Volpath(VolpathSettings::default());
        }
    }
    lights::punctual(file, &walk, &mut d)?;
    d.summary = walk.summary(file, &d, &warnings);
    d.warnings.extend(warnings);
    Ok(d)
}

/// An unsupported required extension is an error; an unsupported optional one a warning.
fn check_extensions(file: &GltfFile) -> Result<Vec<String>, String> {
    let names = |key: &str| -> Vec<String> {
        file.json
            .get(key)
            .and_then(Value::as_array)
            .map_or(Vec::new(), |a| a.iter().filter_map(Value::as_str).map(str::to_string).collect())
    };
    let required = names("extensionsRequired");
    if let Some(bad) = required.iter().find(|e| !supported(e)) {
        return Err(format!("extensionsRequired: {bad} is not supported by glint"));
    }
    Ok(names("extensionsUsed")
        .into_iter()
        .filter(|e| !supported(e))
        .map(|e| format!("glTF extension {e} is not supported; ignored"))
        .collect())
}

/// A 4x4 row-major matrix product.
pub(crate) fn mul(a: &crate::describe::Matrix4, b: &crate::describe::Matrix4) -> crate::describe::Matrix4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

#[cfg(test)]
mod tests;
