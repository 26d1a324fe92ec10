//! `Scene`: a loaded scene, its built world and mesh cache (a library session).

use crate::convert::{guard, scene_error};
use glint::describe::{Geometry, MeshData, Texels};
use glint::formats::{Define, ReadOptions};
use glint::materials::SceneDesc;
use glint::math::{Rgb, Vec3};
use glint::session::{Param, ParamValue, Session};
use numpy::{IntoPyArray, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use std::collections::HashMap;
use std::path::PathBuf;

/// A loaded scene: its description and, once rendered, its built world. Made by
/// `glint.load_file` or `glint.load_dict`; edited through `glint.traverse`.
#[pyclass(module = "glint._glint")]
pub struct Scene {
    pub(crate) session: Session,
}

impl Scene {
    /// The scene's file name (or "scene" for one made from a dict), a preview's title.
    pub fn title(&self) -> String {
        let d = self.session.description();
        d.source.as_ref().and_then(|p| p.file_name()).map_or("scene".into(), |n| n.to_string_lossy().into_owned())
    }
}

/// Reads a scene file; `defines` are (name, value) Mitsuba `<default>` overrides; `camera`
/// picks a glTF camera by index or name.
#[pyfunction]
#[pyo3(signature = (path, defines, camera=None))]
pub fn load_file(
    py: Python<'_>,
    path: PathBuf,
    defines: Vec<(String, String)>,
    camera: Option<String>,
) -> PyResult<Scene> {
    guard(|| {
        let defines = defines.into_iter().map(|(name, value)| Define { name, value }).collect();
        let opts = ReadOptions { defines, camera };
        let session = py.detach(|| Session::open(&path, &opts)).map_err(|e| scene_error(py, e))?;
        Ok(Scene { session })
    })
}

/// A mesh given as arrays (a dict), for shape `index` of a JSON scene.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct MeshArrays<'py> {
    index: usize,
    positions: PyReadonlyArray2<'py, f32>,
    indices: PyReadonlyArray2<'py, u32>,
    normals: Option<PyReadonlyArray2<'py, f32>>,
    uvs: Option<PyReadonlyArray2<'py, f32>>,
}

fn vec3s(name: &str, a: &PyReadonlyArray2<'_, f32>) -> PyResult<Vec<Vec3>> {
    if a.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!("{name}: expected shape (N, 3), got {:?}", a.shape())));
    }
    Ok(a.as_array().outer_iter().map(|r| Vec3 { x: r[0], y: r[1], z: r[2] }).collect())
}

impl MeshArrays<'_> {
    fn data(&self) -> PyResult<MeshData> {
        let i = &self.indices;
        if i.shape()[1] != 3 {
            return Err(PyValueError::new_err(format!("indices: expected shape (M, 3), got {:?}", i.shape())));
        }
        let uvs = match &self.uvs {
            Some(u) if u.shape()[1] != 2 => {
                return Err(PyValueError::new_err(format!("uvs: expected shape (N, 2), got {:?}", u.shape())))
            }
            Some(u) => Some(u.as_array().outer_iter().map(|r| [r[0], r[1]]).collect()),
            None => None,
        };
        Ok(MeshData {
            positions: vec3s("positions", &self.positions)?,
            indices: i.as_array().outer_iter().map(|r| [r[0], r[1], r[2]]).collect(),
            normals: self.normals.as_ref().map(|n| vec3s("normals", n)).transpose()?,
            uvs,
        })
    }
}

/// Reads a scene from JSON text as if from `path` (relative files resolve beside it); each
/// of `meshes` replaces the geometry of its shape (a placeholder in the text).
#[pyfunction]
pub fn load_json(py: Python<'_>, text: &str, path: PathBuf, meshes: Vec<MeshArrays<'_>>) -> PyResult<Scene> {
    guard(|| {
        let mut desc = glint::formats::json::read(&path, text).map_err(|e| scene_error(py, e))?;
        for m in &meshes {
            let n = desc.shapes.len();
            let shape = desc
                .shapes
                .get_mut(m.index)
                .ok_or_else(|| PyValueError::new_err(format!("mesh for shape {} of {n}", m.index)))?;
            shape.geometry = Geometry::Mesh(m.data()?);
        }
        Ok(Scene { session: Session::from_description(desc) })
    })
}

/// Makes a scene from a description (`Scene.description_json`) whose build inputs were
/// shipped elsewhere: `files` maps each path the description names to the copy to read
/// instead (a path it lacks is an error, so nothing is read from the sender's folders), and
/// `instanced` lists the shapes traced through their transforms (`Scene._instanced`).
#[pyfunction]
pub fn load_description(
    py: Python<'_>,
    json: &str,
    files: HashMap<PathBuf, PathBuf>,
    instanced: Vec<usize>,
) -> PyResult<Scene> {
    guard(|| {
        let mut desc: SceneDesc =
            serde_json::from_str(json).map_err(|e| PyValueError::new_err(format!("not a scene description: {e}")))?;
        desc.map_build_inputs(&mut |p| {
            files.get(p).cloned().ok_or_else(|| {
                glint::Error::new(format!("{}: not among the files shipped with the scene", p.display()))
            })
        })
        .map_err(|e| scene_error(py, e))?;
        let mut session = Session::from_description(desc);
        session.set_instanced_shapes(&instanced).map_err(|e| scene_error(py, e))?;
        Ok(Scene { session })
    })
}

fn value_to_py<'py>(py: Python<'py>, v: &ParamValue) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        ParamValue::Float(x) => (*x as f64).into_pyobject(py)?.into_any(),
        ParamValue::Color(c) => ("color", vec![c.r, c.g, c.b]).into_pyobject(py)?.into_any(),
        ParamValue::Matrix(m) => {
            ("matrix", m.iter().map(|r| r.to_vec()).collect::<Vec<_>>()).into_pyobject(py)?.into_any()
        }
        ParamValue::Image(t) => {
            let flat: Vec<f32> = t.pixels.iter().flat_map(|p| p.to_array()).collect();
            let array = numpy::ndarray::Array3::from_shape_vec((t.height, t.width, 3), flat)
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            ("image", array.into_pyarray(py)).into_pyobject(py)?.into_any()
        }
    })
}

#[pymethods]
impl Scene {
    /// Image width in pixels.
    #[getter]
    fn width(&self) -> u32 {
        self.session.description().film.width
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> u32 {
        self.session.description().film.height
    }

    /// The samples per pixel the scene asks for.
    #[getter]
    fn spp(&self) -> u32 {
        self.session.description().sampler.spp
    }

    /// What the reader accepted but cannot honour exactly.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.session.description().warnings.clone()
    }

    /// The scene description as JSON text (glint's plain-data `SceneDesc`).
    fn description_json(&self) -> String {
        serde_json::to_string(self.session.description()).unwrap_or_default()
    }

    /// The files the build reads (meshes, textures, environment maps), each once; the
    /// scene file and its includes are not among them (the description holds them).
    fn build_inputs(&self) -> Vec<PathBuf> {
        self.session.description().build_inputs()
    }

    /// The files building the world reads with their bytes, each once: the build inputs
    /// and what reading them reads besides them (an OBJ file's material libraries; bytes
    /// None for a missing one, which its reader goes on without). What a render farm ships.
    fn build_files<'py>(&self, py: Python<'py>) -> PyResult<Vec<(PathBuf, Option<Bound<'py, PyBytes>>)>> {
        guard(|| {
            let s = &self.session;
            let files = py.detach(|| s.build_files()).map_err(|e| scene_error(py, e))?;
            Ok(files.into_iter().map(|f| (f.path, f.bytes.map(|b| PyBytes::new(py, &b)))).collect())
        })
    }

    /// Shapes traced through their transforms since an in-place edit of them.
    fn _instanced(&self) -> Vec<usize> {
        self.session.instanced_shapes()
    }

    /// Editable parameters as (name, value) pairs; a colour is ("color", [r, g, b]), a
    /// matrix ("matrix", rows), a number a float, an image ("image", None): its texels are
    /// read by `_param`, when asked for.
    fn _params<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let items = self
            .session
            .param_listing()
            .iter()
            .map(|(name, value)| match value {
                Some(v) => Ok((name.clone(), value_to_py(py, v)?)),
                None => Ok((name.clone(), ("image", py.None()).into_pyobject(py)?.into_any())),
            })
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, items)
    }

    /// One parameter's value, as `_params` gives it (an image's texels included).
    fn _param<'py>(&mut self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let value = self.session.param(name).map_err(|e| PyKeyError::new_err(e.to_string()))?;
        value_to_py(py, &value)
    }

    /// The name `_params` gives a parameter named `name` or by an alias of it (Mitsuba's
    /// key); KeyError, its message one line, for an unknown or ambiguous one.
    fn _param_name(&mut self, name: &str) -> PyResult<String> {
        guard(|| self.session.param_name(name).map_err(|e| PyKeyError::new_err(e.to_string())))
    }

    /// Sets parameters given as (name, kind, values) with kind "float" (one value),
    /// "color" (3) or "matrix" (16, row-major), and images as (name, array (H, W, 3)), all
    /// at once.
    #[pyo3(signature = (edits, images=Vec::new()))]
    fn _set_params(
        &mut self,
        py: Python<'_>,
        edits: Vec<(String, String, Vec<f64>)>,
        images: Vec<(String, PyReadonlyArray3<'_, f32>)>,
    ) -> PyResult<()> {
        guard(|| {
            let mut params = Vec::with_capacity(edits.len() + images.len());
            for (name, a) in images {
                let [height, width, channels] = [a.shape()[0], a.shape()[1], a.shape()[2]];
                if channels != 3 {
                    return Err(PyTypeError::new_err(format!("{name}: an image has 3 channels, not {channels}")));
                }
                let view = a.as_array();
                let pixels = view
                    .outer_iter()
                    .flat_map(|row| row.outer_iter().map(|p| Rgb { r: p[0], g: p[1], b: p[2] }).collect::<Vec<_>>())
                    .collect();
                let texels = Texels { width, height, pixels };
                params.push(Param { name, value: ParamValue::Image(texels) });
            }
            for (name, kind, v) in edits {
                let value = match (kind.as_str(), v.len()) {
                    ("float", 1) => ParamValue::Float(v[0] as f32),
                    ("color", 3) => ParamValue::Color(Rgb { r: v[0] as f32, g: v[1] as f32, b: v[2] as f32 }),
                    ("matrix", 16) => {
                        let mut m = [[0.0; 4]; 4];
                        for (i, x) in v.iter().enumerate() {
                            m[i / 4][i % 4] = *x;
                        }
                        ParamValue::Matrix(m)
                    }
                    _ => return Err(PyTypeError::new_err(format!("{name}: {} values for a {kind}", v.len()))),
                };
                params.push(Param { name, value });
            }
            self.session.set_params(&params).map_err(|e| scene_error(py, e))
        })
    }

    /// How many BVHs the builds of this scene made so far: `mesh_bvh_builds` (bottom
    /// level) and `top_level_builds`.
    pub(crate) fn build_counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.session.build_counters();
        let d = PyDict::new(py);
        d.set_item("mesh_bvh_builds", c.mesh_bvh_builds)?;
        d.set_item("top_level_builds", c.top_level_builds)?;
        Ok(d)
    }

    /// Builds the world now (rendering builds it when needed).
    fn build(&mut self, py: Python<'_>) -> PyResult<()> {
        guard(|| {
            let s = &mut self.session;
            py.detach(|| s.world().map(|_| ())).map_err(|e| scene_error(py, e))
        })
    }

    fn __repr__(&self) -> String {
        let d = self.session.description();
        let source = d.source.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "<dict>".into());
        format!(
            "<glint.Scene {source}: {}x{}, {} shapes, {} lights, {} spp>",
            d.film.width,
            d.film.height,
            d.shapes.len(),
            d.lights.len(),
            d.sampler.spp
        )
    }
}
