//! `glint rays`: writes benchmark ray sets. Primary rays come from a pinhole camera that
//! frames the mesh (or from `--eye`/`--look-at`); diffuse rays start at the surface points
//! that primary rays hit and leave in cosine-distributed directions around the normal that
//! faces the camera, as a path tracer's second bounce does.
//!
//! A ray file is little-endian float32 records `(ox, oy, oz, tmin, dx, dy, dz, tmax)`.

use crate::meshsrc;
use clap::Args;
use glint::accel::BvhSplit;
use glint::geometry::TriangleMesh;
use glint::math::{offset_origin, Frame, Ray, Transform, Vec3};
use glint::sampling::{warp, Rng};
use std::path::{Path, PathBuf};

#[derive(Args)]
pub struct RaysArgs {
    /// Mesh file (.obj, .ply) or synthetic:TRIANGLES.
    #[arg(long)]
    mesh: String,
    /// primary or diffuse.
    #[arg(long, value_parser = ["primary", "diffuse"])]
    kind: String,
    /// Number of rays.
    #[arg(long, default_value_t = 1 << 20)]
    count: usize,
    /// Camera position (x,y,z); default: in front of the mesh on +z.
    #[arg(long, value_parser = parse_vec3)]
    eye: Option<Vec3>,
    /// Camera target (x,y,z); default: the centre of the mesh's bounds.
    #[arg(long, value_parser = parse_vec3)]
    look_at: Option<Vec3>,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Ray file to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Also write the triangles (float32 x 9 per triangle) for the Embree harness.
    #[arg(long)]
    triangles_out: Option<PathBuf>,
}

pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> =
        s.split(',').map(|c| c.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v.as_slice() {
        [x, y, z] => Ok(Vec3 { x: *x, y: *y, z: *z }),
        _ => Err(format!("'{s}': expected x,y,z")),
    }
}

/// Most rays `glint rays` writes in one file, and so `glint bench` reads (32 bytes each:
/// 2 GiB): bounds the allocation that `--count` or a ray file asks for.
pub const MAX_RAYS: usize = 1 << 26;

pub fn read_rays(path: &Path) -> Result<Vec<Ray>, String> {
    let bytes = glint::io::read_file_bounded(path, (MAX_RAYS * 32) as u64)?;
    if bytes.len() % 32 != 0 {
        return Err(format!(
            "{}: size {} is not a multiple of 32 bytes (8 float32 per ray)",
            path.display(),
            bytes.len()
        ));
    }
    let f = |c: &[u8], i: usize| f32::from_le_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]]);
    Ok(bytes
        .chunks_exact(32)
        .map(|c| Ray {
            origin: Vec3 { x: f(c, 0), y: f(c, 1), z: f(c, 2) },
            t_min: f(c, 3),
            dir: Vec3 { x: f(c, 4), y: f(c, 5), z: f(c, 6) },
            t_max: f(c, 7),
        })
        .collect())
}

pub fn write_rays(rays: &[Ray], path: &Path) -> Result<(), String> {
    let mut bytes = Vec::with_capacity(rays.len() * 32);
    for r in rays {
        for v in [r.origin.x, r.origin.y, r.origin.z, r.t_min, r.dir.x, r.dir.y, r.dir.z, r.t_max] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

pub fn rays_cmd(a: RaysArgs) -> Result<(), String> {
    if a.count == 0 || a.count > MAX_RAYS {
        return Err(format!("--count {}: must be from 1 to {MAX_RAYS}", a.count));
    }
    let flat = meshsrc::load(&a.mesh)?;
    if let Some(p) = &a.triangles_out {
        meshsrc::write_triangles(&flat, p)?;
    }
    let mesh = TriangleMesh::new(flat.positions, None, None, flat.indices, BvhSplit::Sah)?;
    let bounds = mesh.bounds();
    let target = a.look_at.unwrap_or(bounds.center());
    let radius = bounds.extent().length() * 0.5;
    let eye = a.eye.unwrap_or(bounds.center() + Vec3 { x: 0.0, y: 0.0, z: radius * 1.8 });
    let cam = Transform::look_at(eye, target, Vec3::Y).ok_or("camera: eye and target coincide")?;
    // A square image of about `count` pixels, one jittered ray each, 45 degree field of view.
    let tan_half = (22.5f32).to_radians().tan();
    let mut rng = Rng::new(a.seed, 0);
    let primary = |rng: &mut Rng, i: usize, side: usize| -> Ray {
        let (px, py) = ((i % side) as f32, (i / side) as f32);
        let [jx, jy] = rng.next_2d();
        let nx = (px + jx) / side as f32 * 2.0 - 1.0;
        let ny = (py + jy) / side as f32 * 2.0 - 1.0;
        let d = cam.vector(Vec3 { x: -nx * tan_half, y: -ny * tan_half, z: 1.0 }).normalize();
        Ray::new(eye, d)
    };
    let side = (a.count as f64).sqrt().ceil() as usize;
    let mut rays = Vec::with_capacity(a.count);
    match a.kind.as_str() {
        "primary" => {
            for i in 0..a.count {
                rays.push(primary(&mut rng, i % (side * side), side));
            }
        }
        _ => {
            let mut i = 0usize;
            let mut misses = 0usize;
            while rays.len() < a.count {
                let mut r = primary(&mut rng, i % (side * side), side);
                i += 1;
                let Some((tri, h)) = mesh.intersect(&mut r) else {
                    misses += 1;
                    if misses > 100 * a.count.max(1000) {
                        return Err("the camera sees no surface: no diffuse rays can be made".into());
                    }
                    continue;
                };
                let [p0, p1, p2] = mesh.vertices(tri as usize);
                let mut n = (p1 - p0).cross(p2 - p0).normalize();
                if n.dot(r.dir) > 0.0 {
                    n = -n;
                }
                let p = p0 * (1.0 - h.b1 - h.b2) + p1 * h.b1 + p2 * h.b2;
                let d = Frame::from_normal(n).to_world(warp::cosine_hemisphere(rng.next_2d())).normalize();
                if !d.is_finite() {
                    continue;
                }
                rays.push(Ray::new(offset_origin(p, n, d), d));
            }
        }
    }
    write_rays(&rays, &a.output)?;
    eprintln!(
        "glint rays: {} {} rays over {} triangles -> {}",
        rays.len(),
        a.kind,
        mesh.indices.len(),
        a.output.display()
    );
    Ok(())
}
