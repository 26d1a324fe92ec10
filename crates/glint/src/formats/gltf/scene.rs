//! The default scene's node hierarchy: world transforms (TRS or matrices), each mesh
//! primitive placed as an instance of a shared mesh (`EXT_mesh_gpu_instancing` adding one
//! per instance), and the cameras and lights the walk meets, in depth-first order.

use super::material::Materials;
use super::mul;
use crate::describe::{Emission, Geometry, MaterialRef, Matrix4, MeshFileDesc, ShapeDesc, IDENTITY};
use crate::error::SourceLoc;
use crate::io::gltf::{read_accessor, read_primitive, triangle_mode, GltfFile, Node, PrimitiveMode};
use crate::materials::SceneDesc;
use crate::math::Aabb;
use serde_json::Value;
use std::collections::HashMap;
use std::path::Path;

/// Most instances one scene may place (nodes times GPU instances): each is a shape of the
/// description and an instance of the top-level BVH.
pub const MAX_INSTANCES: usize = 1 << 22;

/// What the walk found besides shapes.
#[derive(Default)]
pub struct Walk {
    /// (node, camera index, world matrix) in depth-first order.
    pub cameras: Vec<(usize, usize, Matrix4)>,
    /// (node, light index, world matrix).
    pub lights: Vec<(usize, usize, Matrix4)>,
    pub nodes: usize,
    pub primitives: usize,
    pub triangles: u64,
    pub bounds: Option<Aabb>,
}

impl Walk {
    /// What `glint info` prints about the file.
    pub fn summary(&self, file: &GltfFile, d: &SceneDesc, warnings: &[String]) -> Vec<String> {
        let images = file.array("images").len();
        let mut out = vec![
            format!("glTF nodes       {} in the default scene ({} in the file)", self.nodes, file.array("nodes").len()),
            format!("glTF meshes      {} ({} triangle primitives placed)", file.array("meshes").len(), self.primitives),
            format!("glTF triangles   {}", self.triangles),
            format!("glTF materials   {}", file.array("materials").len()),
            format!("glTF textures    {} ({images} images)", file.array("textures").len()),
            format!("glTF cameras     {} ({} placed)", file.array("cameras").len(), self.cameras.len()),
            format!(
                "glTF lights      {} punctual, {} emissive shapes",
                self.lights.len(),
                d.shapes.iter().filter(|s| s.emission.is_some()).count()
            ),
        ];
        if let Some(b) = &self.bounds {
            out.push(format!(
                "glTF bounds      ({:.4}, {:.4}, {:.4}) to ({:.4}, {:.4}, {:.4})",
                b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
            ));
        }
        let ignored: Vec<&str> = warnings
            .iter()
            .filter_map(|w| w.strip_prefix("glTF extension "))
            .filter_map(|w| w.split(' ').next())
            .collect();
        out.push(format!(
            "glTF ignored     {}",
            if ignored.is_empty() { "none".to_string() } else { ignored.join(", ") }
        ));
        out
    }
}

/// A node's local matrix (row-major, from the file's column-major `matrix` or its TRS).
pub fn local_matrix(n: &Node) -> Result<Matrix4, String> {
    if let Some(m) = n.numbers("matrix", 16)? {
        let mut out = [[0.0; 4]; 4];
        for (c, col) in m.chunks_exact(4).enumerate() {
            for (r, v) in col.iter().enumerate() {
                out[r][c] = *v;
            }
        }
        return Ok(out);
    }
    let t = n.numbers("translation", 3)?.unwrap_or(vec![0.0; 3]);
    let r = n.numbers("rotation", 4)?.unwrap_or(vec![0.0, 0.0, 0.0, 1.0]);
    let s = n.numbers("scale", 3)?.unwrap_or(vec![1.0; 3]);
    Ok(trs(&t, &r, &s))
}

/// T R S with the rotation a quaternion (x, y, z, w), normalised.
pub fn trs(t: &[f64], q: &[f64], s: &[f64]) -> Matrix4 {
    let len = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let (x, y, z, w) = if len > 0.0 { (q[0] / len, q[1] / len, q[2] / len, q[3] / len) } else { (0.0, 0.0, 0.0, 1.0) };
    let r = [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
    ];
    let mut m = IDENTITY;
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = r[i][j] * s[j];
        }
        m[i][3] = t[i];
    }
    m
}

/// The default scene (`scene`), else the first; `None` when the file has no scenes.
fn default_scene(file: &GltfFile) -> Result<Option<usize>, String> {
    let root = Node::new(&file.json, "");
    match root.index("scene").map_err(|e| e.trim_start_matches('.').to_string())? {
        Some(s) => {
            file.item("scenes", s, "scene")?;
            Ok(Some(s))
        }
        None => Ok(if file.array("scenes").is_empty() { None } else { Some(0) }),
    }
}

/// The per-instance matrices of a node's `EXT_mesh_gpu_instancing` (none: one identity).
fn gpu_instances(file: &GltfFile, node: &Value, path: &str) -> Result<Vec<Matrix4>, String> {
    let Some(ext) = node.get("extensions").and_then(|e| e.get("EXT_mesh_gpu_instancing")) else {
        return Ok(vec![IDENTITY]);
    };
    let ep = format!("{path}.extensions.EXT_mesh_gpu_instancing.attributes");
    let attrs = ext.get("attributes").ok_or_else(|| format!("{ep}: missing"))?;
    let read = |name: &str, comps: usize| -> Result<Option<Vec<f64>>, String> {
        let Some(i) = attrs.get(name) else { return Ok(None) };
        let p = format!("{ep}.{name}");
        let i = i.as_u64().ok_or_else(|| format!("{p}: expected an accessor index"))? as usize;
        let a = read_accessor(file, i, &p)?;
        if a.comps != comps {
            return Err(format!("{p}: accessor {i} has {} components (expected {comps})", a.comps));
        }
        Ok(Some(a.values.iter().map(|&v| v as f64).collect()))
    };
    let (t, r, s) = (read("TRANSLATION", 3)?, read("ROTATION", 4)?, read("SCALE", 3)?);
    let count = [t.as_ref().map(|v| v.len() / 3), r.as_ref().map(|v| v.len() / 4), s.as_ref().map(|v| v.len() / 3)];
    let n = count.iter().flatten().copied().max().unwrap_or(0);
    if count.iter().flatten().any(|&c| c != n) {
        return Err(format!("{ep}: the attributes have different counts"));
    }
    Ok((0..n)
        .map(|i| {
            let tt = t.as_ref().map_or(vec![0.0; 3], |v| v[3 * i..3 * i + 3].to_vec());
            let rr = r.as_ref().map_or(vec![0.0, 0.0, 0.0, 1.0], |v| v[4 * i..4 * i + 4].to_vec());
            let ss = s.as_ref().map_or(vec![1.0; 3], |v| v[3 * i..3 * i + 3].to_vec());
            trs(&tt, &rr, &ss)
        })
        .collect())
}

/// A mesh's primitives, read once each: (mode, flat index, object-space bounds,
/// triangles, material); points and lines are kept to be skipped with a warning.
struct PrimitiveInfo {
    flat: usize,
    mode: PrimitiveMode,
    /// The vertices the triangles use (for the scene's exact world bounds).
    points: Vec<crate::math::Vec3>,
    triangles: usize,
    material: Option<usize>,
    /// The description's mesh of this primitive, as in the file and with its winding
    /// reversed (for placements by a mirroring transform), once placed so.
    desc_mesh: [Option<usize>; 2],
}

fn mesh_primitives(file: &GltfFile, mesh: usize, first_flat: usize) -> Result<Vec<PrimitiveInfo>, String> {
    let mp = format!("meshes[{mesh}]");
    let m = file.item("meshes", mesh, &mp)?;
    let prims = m.get("primitives").and_then(Value::as_array).ok_or_else(|| format!("{mp}.primitives: missing"))?;
    let mut out = Vec::new();
    for (k, pv) in prims.iter().enumerate() {
        let pp = format!("{mp}.primitives[{k}]");
        let n = Node::new(pv, &pp);
        let mode = triangle_mode(&n)?;
        let material = n.index("material")?;
        if let Some(mi) = material {
            file.item("materials", mi, &format!("{pp}.material"))?;
        }
        let (points, triangles) = if mode == PrimitiveMode::PointsOrLines {
            (Vec::new(), 0)
        } else {
            let data = read_primitive(file, mesh, k)?;
            if let Some(i) =
                data.positions.iter().position(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
            {
                return Err(format!("{pp}.attributes.POSITION: vertex {i} is not finite"));
            }
            let mut used = vec![false; data.positions.len()];
            for t in &data.indices {
                for &v in t {
                    used[v as usize] = true;
                }
            }
            let points = data.positions.iter().zip(used).filter(|(_, u)| *u).map(|(p, _)| *p).collect();
            (points, data.indices.len())
        };
        out.push(PrimitiveInfo { flat: first_flat + k, mode, points, triangles, material, desc_mesh: [None; 2] });
    }
    Ok(out)
}

/// Whether `m` mirrors (its linear part has a negative determinant). glTF then keeps each
/// face's front on the side the mirrored normal points to (the winding in world space turns
/// clockwise), where glint orients a face by its winding in world space: such a placement
/// uses the primitive with its winding reversed.
fn mirrors(m: &Matrix4) -> bool {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    det < 0.0
}

/// The world bounds of points under `m`.
fn transform_bounds(points: &[crate::math::Vec3], m: &Matrix4) -> Aabb {
    let mut out = Aabb::EMPTY;
    for p in points {
        let c = [p.x as f64, p.y as f64, p.z as f64];
        let w = |r: usize| (m[r][0] * c[0] + m[r][1] * c[1] + m[r][2] * c[2] + m[r][3]) as f32;
        out = out.grow(crate::math::vec3(w(0), w(1), w(2)));
    }
    out
}

/// Walks the default scene from `root` (the identity for a whole scene), adding a shape
/// for every placed primitive.
pub fn place(
    file: &GltfFile,
    path: &Path,
    root: &Matrix4,
    d: &mut SceneDesc,
    materials: &Materials,
    warnings: &mut Vec<String>,
) -> Result<Walk, String> {
    let mut walk = Walk::default();
    let Some(scene) = default_scene(file)? else {
        warnings.push("the glTF file has no scene: nothing to render".into());
        return Ok(walk);
    };
    let nodes = file.array("nodes");
    let sp = format!("scenes[{scene}]");
    let roots = Node::new(&file.array("scenes")[scene], &sp);
    let mut stack: Vec<(usize, Matrix4, String)> = Vec::new();
    for (i, r) in
        roots.get("nodes").and_then(Value::as_array).map(Vec::as_slice).unwrap_or(&[]).iter().enumerate().rev()
    {
        let p = format!("{sp}.nodes[{i}]");
        let n = r
            .as_u64()
            .filter(|&n| (n as usize) < nodes.len())
            .ok_or_else(|| format!("{p}: {r} is not a node index ({} nodes)", nodes.len()))?;
        stack.push((n as usize, *root, p));
    }
    let mut seen = vec![false; nodes.len()];
    let mut first_flat = Vec::with_capacity(file.array("meshes").len());
    let mut total = 0usize;
    for m in file.array("meshes") {
        first_flat.push(total);
        total += m.get("primitives").and_then(Value::as_array).map_or(0, Vec::len);
    }
    let mut prims: HashMap<usize, Vec<PrimitiveInfo>> = HashMap::new();
    let mut warned_lines = false;
    let loc = SourceLoc::file(path);
    while let Some((ni, parent, refp)) = stack.pop() {
        let np = format!("nodes[{ni}]");
        if std::mem::replace(&mut seen[ni], true) {
            return Err(format!("{refp}: node {ni} appears twice in the scene (glTF nodes form a tree)"));
        }
        walk.nodes += 1;
        let node = Node::new(&nodes[ni], &np);
        let world = mul(&parent, &local_matrix(&node)?);
        if let Some(c) = node.index("camera")? {
            file.item("cameras", c, &format!("{np}.camera"))?;
            walk.cameras.push((ni, c, world));
        }
        if let Some(l) = node.get("extensions").and_then(|e| e.get("KHR_lights_punctual")) {
            let lp = format!("{np}.extensions.KHR_lights_punctual");
            let li = Node::new(l, &lp).required_index("light")?;
            walk.lights.push((ni, li, world));
        }
        if let Some(mesh) = node.index("mesh")? {
            file.item("meshes", mesh, &format!("{np}.mesh"))?;
            if let std::collections::hash_map::Entry::Vacant(e) = prims.entry(mesh) {
                e.insert(mesh_primitives(file, mesh, first_flat[mesh])?);
            }
            let instances = gpu_instances(file, &nodes[ni], &np)?;
            let list = prims.get_mut(&mesh).expect("inserted above");
            for info in list.iter_mut() {
                if info.mode == PrimitiveMode::PointsOrLines {
                    if !warned_lines {
                        warnings.push("glTF points and lines are skipped (a path tracer has no lines)".into());
                        warned_lines = true;
                    }
                    continue;
                }
                if info.triangles == 0 {
                    continue;
                }
                let (material, emission, interior) = match info.material {
                    Some(m) => {
                        (MaterialRef::Index(materials.index[m]), materials.emission[m].clone(), materials.interior[m])
                    }
                    None => (MaterialRef::Index(materials.default_material(d)), None, None),
                };
                for inst in &instances {
                    if d.shapes.len() >= MAX_INSTANCES {
                        return Err(format!("{np}: more than {MAX_INSTANCES} instances in the scene"));
                    }
                    let to_world = mul(&world, inst);
                    let reversed = mirrors(&to_world);
                    let mesh_index = *info.desc_mesh[reversed as usize].get_or_insert_with(|| {
                        let prim = info.flat - first_flat[mesh];
                        d.meshes.push(MeshFileDesc {
                            name: format!("mesh {mesh} primitive {prim}{}", if reversed { " (mirrored)" } else { "" }),
                            file: path.to_path_buf(),
                            face_normals: false,
                            loc: loc.clone(),
                            shape_index: info.flat as u32,
                            reverse_winding: reversed,
                        });
                        d.meshes.len() - 1
                    });
                    let mut s = shape(mesh_index, to_world, material, emission.clone(), &loc);
                    // The node's name, for `traverse` (shared by a node's primitives and
                    // instances, which are then named by index).
                    s.id = node.get("name").and_then(Value::as_str).map(str::to_string);
                    // A volume's absorbing medium inside; outside, none (vacuum).
                    s.media.interior = interior;
                    d.shapes.push(s);
                    walk.primitives += 1;
                    walk.triangles += info.triangles as u64;
                    let wb = transform_bounds(&info.points, &to_world);
                    walk.bounds = Some(walk.bounds.map_or(wb, |a| a.union(wb)));
                }
            }
        }
        if let Some(children) = node.get("children") {
            let a = children.as_array().ok_or_else(|| format!("{np}.children: expected an array"))?;
            for (i, c) in a.iter().enumerate().rev() {
                let p = format!("{np}.children[{i}]");
                let c = c
                    .as_u64()
                    .filter(|&c| (c as usize) < nodes.len())
                    .ok_or_else(|| format!("{p}: not a node index ({} nodes)", nodes.len()))?;
                stack.push((c as usize, world, p));
            }
        }
    }
    Ok(walk)
}

fn shape(
    mesh: usize,
    to_world: Matrix4,
    material: MaterialRef,
    emission: Option<Emission>,
    loc: &SourceLoc,
) -> ShapeDesc {
    ShapeDesc {
        geometry: Geometry::Instance { mesh },
        to_world,
        material,
        use_mtl: false,
        emission,
        flip_normals: false,
        loc: loc.clone(),
        media: Default::default(),
        id: None,
    }
}
