//! Light sources. Every light answers the same questions:
//! - `sample_li(ref_p, u)`: a direction towards the light from a reference point, the
//!   radiance arriving along it, its solid-angle density, and the distance for the shadow ray;
//! - `pdf_li(...)`: that density for a direction found another way (a BSDF sample that hit
//!   the light), so that multiple importance sampling can weigh the two;
//! - `power()`: an estimate of emitted flux, for choosing among lights.
//!
//! Area lights emit a radiance texture read at the surface's uv (Mitsuba's `area` emitter
//! with a textured `radiance`). A bitmap radiance on a sphere, a cylinder, a rectangle whose
//! uvs span it once, or a disk (the fan of triangles `geometry::disk_mesh` makes, with its
//! polar uvs, told by `MeshEmitter::uv_disk`) is sampled by its texels (`texel`: the
//! filtered luminance times the area Jacobian, mapped onto the surface: on the disk the
//! Jacobian, u, enters exactly, so the density per unit area is the luminance itself), as
//! Mitsuba samples it by its texels in uv; other textures and other meshes (general meshes
//! with uvs) are sampled by the shape's geometry alone (by solid angle where the shape
//! allows it, by area otherwise) and the texture is read at the point sampled. Either way
//! `pdf_li` gives the density the sampler used, so light sampling and rays that hit the
//! light are weighed alike. Their power (for light selection) uses the texture's mean.
//!
//! Delta lights (point, spot, directional) have a density of 1 by convention and are never
//! hit by BSDF-sampled rays.

mod envmap;
mod projected;
mod rectangle;
mod sphere;
mod texel;
mod tree;
pub use crate::describe::LightSelection;
pub use envmap::EnvMap;
pub use projected::{ProjectedKind, ProjectedLight};
pub use rectangle::Rectangle;
pub use texel::{DiskImportance, RectangleImportance, TexelImportance, UvDisk, UvJacobian, UvRectangle};
pub use tree::{by_triangle, LightTree, TreeSample};

use rectangle::SphericalRectangle;
use texel::SPHERE_UV_JACOBIAN;

use crate::geometry::{Cylinder, Sphere, TriangleMesh};
use crate::materials::{Texture, TexturePoint};
use crate::math::{Aabb, Frame, Rgb, Vec3, PI};
use crate::sampling::{warp, Distribution1d};
use std::sync::Arc;

#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the reference point towards the light.
    pub wi: Vec3,
    /// Radiance arriving at the reference point along `wi` (for delta lights: intensity / d²).
    pub radiance: Rgb,
    /// Solid-angle density of `wi` (1 for delta lights).
    pub pdf: f32,
    /// Distance to the light sample (infinity for infinite lights).
    pub dist: f32,
    pub delta: bool,
}

/// What an area light emits (see the module doc): a radiance texture on the front side (the
/// way the normal faces) or on both.
#[derive(Clone, Debug)]
pub struct AreaEmission {
    pub radiance: Texture,
    pub two_sided: bool,
}

impl AreaEmission {
    /// A uniform radiance on the front side.
    pub fn constant(radiance: Rgb) -> AreaEmission {
        AreaEmission { radiance: Texture::Constant(radiance), two_sided: false }
    }
}

/// The radiance a texture gives at a point found by `at` (only looked for when the texture
/// varies).
#[inline]
fn radiance_at<'a>(t: &Texture, at: impl FnOnce() -> TexturePoint<'a>) -> Rgb {
    match t {
        Texture::Constant(c) => *c,
        t => t.eval_at(&at()),
    }
}

/// Barycentrics (b1, b2) of `q` in the triangle `[a, b, c]` (q = a + b1 (b - a) + b2 (c - a)
/// when q lies in its plane).
fn barycentric([a, b, c]: [Vec3; 3], q: Vec3) -> [f32; 2] {
    let (e1, e2, d) = (b - a, c - a, q - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1, d2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if !(det > 0.0) {
        return [0.0, 0.0];
    }
    [(d22 * d1 - d12 * d2) / det, (d11 * d2 - d12 * d1) / det]
}

/// A triangle-mesh emitter, with its triangles in world space and a distribution
/// proportional to their area (the paper's choice: pick a triangle by area, then a uniform
/// point on it). A mesh that is one rectangle is sampled by solid angle instead, from the
/// points where that works (see `rectangle`), and elsewhere by area through the linear map of
/// the square onto the rectangle.
#[derive(Clone, Debug)]
pub struct MeshEmitter {
    pub triangles: Vec<[Vec3; 3]>,
    pub areas: Distribution1d,
    pub total_area: f32,
    pub rectangle: Option<Rectangle>,
    /// The mesh the triangles were made from (triangle `i` is its triangle `i`), for the uvs
    /// and attributes a radiance texture reads; `None`: uvs are the barycentrics.
    pub mesh: Option<Arc<TriangleMesh>>,
    /// The triangles' second and third corners are swapped from the mesh's (flipped normals).
    pub flipped: bool,
}

impl MeshEmitter {
    /// `None` when the triangles have no area.
    pub fn new(triangles: Vec<[Vec3; 3]>) -> Option<MeshEmitter> {
        let areas: Vec<f32> = triangles.iter().map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length()).collect();
        let total_area = areas.iter().sum();
        let areas = Distribution1d::new(&areas)?;
        let rectangle = Rectangle::from_triangles(&triangles);
        Some(MeshEmitter { triangles, areas, total_area, rectangle, mesh: None, flipped: false })
    }

    /// The emitter of `mesh`'s triangles, given in world space (with their second and third
    /// corners swapped when `flipped`).
    pub fn of_mesh(triangles: Vec<[Vec3; 3]>, mesh: Arc<TriangleMesh>, flipped: bool) -> Option<MeshEmitter> {
        let e = MeshEmitter::new(triangles)?;
        Some(MeshEmitter { mesh: Some(mesh), flipped, ..e })
    }

    /// Where a texture is read at the point of barycentrics `e` (in the emitter's corner
    /// order) on triangle `tri`: the mesh's interpolated uv, as a hit there reads it.
    fn texture_point(&self, tri: usize, e: [f32; 2]) -> TexturePoint<'_> {
        let bary = if self.flipped { [e[1], e[0]] } else { e };
        let Some(mesh) = self.mesh.as_deref() else { return TexturePoint::uv(bary) };
        let uv = match (mesh.uvs.as_ref(), mesh.indices.get(tri)) {
            (Some(t), Some(&[i0, i1, i2])) => {
                let (t0, t1, t2) = (t[i0 as usize], t[i1 as usize], t[i2 as usize]);
                let b0 = 1.0 - bary[0] - bary[1];
                [t0[0] * b0 + t1[0] * bary[0] + t2[0] * bary[1], t0[1] * b0 + t1[1] * bary[0] + t2[1] * bary[1]]
            }
            _ => bary,
        };
        TexturePoint { uv, prim: tri as u32, bary, mesh: Some(mesh) }
    }

    /// The triangle holding `q` (a point of the emitter) and its barycentrics there: the
    /// triangle `q` lies deepest inside.
    fn locate(&self, q: Vec3) -> (usize, [f32; 2]) {
        let mut best = (0, [0.0, 0.0], f32::NEG_INFINITY);
        for (i, t) in self.triangles.iter().enumerate() {
            let b = barycentric(*t, q);
            let inside = b[0].min(b[1]).min(1.0 - b[0] - b[1]);
            if inside > best.2 {
                best = (i, b, inside);
            }
        }
        (best.0, best.1)
    }

    /// The uv map of a rectangle emitter whose uvs are affine over it and span the unit
    /// square once, for importance-sampling a bitmap on it; `None` for other meshes.
    pub fn uv_rectangle(&self) -> Option<UvRectangle> {
        let r = self.rectangle.as_ref()?;
        let uvs = |tri: usize| [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]].map(|e| self.texture_point(tri, e).uv);
        // Triangle 0's affine map from uv to space: q = a + E M⁻¹ (uv - uv_a).
        let [a, b, c] = self.triangles[0];
        let [ta, tb, tc] = uvs(0);
        let (m00, m01, m10, m11) = (tb[0] - ta[0], tc[0] - ta[0], tb[1] - ta[1], tc[1] - ta[1]);
        let det = m00 * m11 - m01 * m10;
        if !(det.abs() > 1e-12) {
            return None;
        }
        let q = |t: [f32; 2]| {
            let (x, y) = (t[0] - ta[0], t[1] - ta[1]);
            let (b1, b2) = ((m11 * x - m01 * y) / det, (m00 * y - m10 * x) / det);
            a + (b - a) * b1 + (c - a) * b2
        };
        let origin = q([0.0, 0.0]);
        let map = UvRectangle { origin, du: q([1.0, 0.0]) - origin, dv: q([0.0, 1.0]) - origin, area: r.area() };
        let tol = 1e-4 * (r.ex.length() + r.ey.length());
        let close = |p: Vec3, q: Vec3| (p - q).length() <= tol;
        // Both triangles follow the same map, ...
        let same_map = (0..2).all(|tri| {
            let t = uvs(tri);
            (0..3).all(|k| close(q(t[k]), self.triangles[tri][k]))
        });
        // ... which takes the unit square onto the rectangle.
        let corners = [r.corner, r.corner + r.ex, r.corner + r.ey, r.corner + r.ex + r.ey];
        let square = [map.origin, map.origin + map.du, map.origin + map.dv, map.origin + map.du + map.dv];
        let onto = square.iter().all(|&p| corners.iter().any(|&c| close(p, c)));
        (same_map && onto).then_some(map)
    }

    /// The uv map of a disk emitter made as `geometry::disk_mesh` makes it (under any affine
    /// map, normals flipped or not), for importance-sampling a bitmap on it; `None` for other
    /// meshes. What is checked is what the map relies on: triangle k is the centre and rim
    /// vertices k and k + 1 with the polar uvs (0, (k + ½)/N), (1, k/N), (1, (k + 1)/N), and
    /// the rim lies on an ellipse at those azimuths.
    pub fn uv_disk(&self) -> Option<UvDisk> {
        let mesh = self.mesh.as_deref()?;
        let uvs = mesh.uvs.as_ref()?;
        let n = self.triangles.len();
        if n < 4 || mesh.indices.len() != n {
            return None;
        }
        let centre = self.triangles[0][0];
        let tol = 1e-4 * (self.triangles[0][1] - centre).length();
        let mut edges = Vec::with_capacity(n);
        for (k, (tri, idx)) in self.triangles.iter().zip(&mesh.indices).enumerate() {
            let expected =
                [[0.0, (k as f32 + 0.5) / n as f32], [1.0, k as f32 / n as f32], [1.0, (k + 1) as f32 / n as f32]];
            let same_uv = |i: u32, e: [f32; 2]| {
                uvs.get(i as usize).is_some_and(|t| (t[0] - e[0]).abs() <= 1e-6 && (t[1] - e[1]).abs() <= 1e-6)
            };
            if !(0..3).all(|c| same_uv(idx[c], expected[c])) || !((tri[0] - centre).length() <= tol) {
                return None;
            }
            // The emitter's corners 1 and 2 are the mesh's 2 and 1 when the normals are flipped.
            edges.push(if self.flipped { [tri[2], tri[1]] } else { [tri[1], tri[2]] });
        }
        UvDisk::new(centre, edges)
    }

    /// Whether light samples seen from `p` are drawn by solid angle (otherwise by area).
    pub fn samples_by_solid_angle(&self, p: Vec3) -> bool {
        self.spherical_rectangle(p).is_some()
    }

    /// The solid-angle parametrization to sample from `p`, where it applies.
    fn spherical_rectangle(&self, p: Vec3) -> Option<SphericalRectangle> {
        self.rectangle.as_ref().and_then(|r| SphericalRectangle::new(r, p))
    }
}

/// How a mesh light's bitmap radiance is sampled by its texels: over a rectangle whose uvs
/// are affine, or over a disk's polar uvs.
#[derive(Clone, Debug)]
pub enum MeshImportance {
    Rectangle(RectangleImportance),
    Disk(DiskImportance),
}

#[derive(Clone, Debug)]
// Unboxed on purpose: lights are read on every light sample, and a box is a pointer chase.
#[allow(clippy::large_enum_variant)]
pub enum Light {
    Point {
        position: Vec3,
        intensity: Rgb,
    },
    /// Cone light; falloff is linear in angle between `cos_beam` and `cos_cutoff` (Mitsuba's),
    /// or with `gltf_falloff` the square of the linear ramp in the cosine (glTF's).
    Spot {
        position: Vec3,
        frame: Frame,
        intensity: Rgb,
        cutoff: f32,
        beam: f32,
        gltf_falloff: bool,
    },
    /// Light from direction `-direction` (i.e. travelling along `direction`) with irradiance
    /// `irradiance` on a perpendicular surface.
    Directional {
        direction: Vec3,
        irradiance: Rgb,
        scene_radius: f32,
    },
    /// Area light on a triangle mesh instance.
    Mesh {
        instance: u32,
        emitter: Arc<MeshEmitter>,
        radiance: Texture,
        two_sided: bool,
        /// A bitmap radiance on a rectangle or a disk, sampled by its texels (see `texel`).
        importance: Option<Arc<MeshImportance>>,
    },
    /// Area light on a sphere; sampled by the solid angle it subtends.
    Sphere {
        instance: u32,
        sphere: Sphere,
        radiance: Texture,
        /// Normals flipped: the sphere emits into its inside only (otherwise outside only).
        inward: bool,
        /// A bitmap radiance, sampled by its texels over the whole sphere.
        importance: Option<Arc<TexelImportance>>,
    },
    /// Area light on an open cylinder; sampled uniformly by area (as Mitsuba samples it).
    Cylinder {
        instance: u32,
        cylinder: Cylinder,
        radiance: Texture,
        /// Normals flipped: the tube emits towards its axis only (otherwise outward only).
        inward: bool,
        /// A bitmap radiance, sampled by its texels.
        importance: Option<Arc<TexelImportance>>,
    },
    /// Uniform radiance from every direction.
    Constant {
        radiance: Rgb,
        scene_radius: f32,
    },
    /// Environment map, importance-sampled by luminance.
    EnvMap(Arc<EnvMap>),
    /// A point light projecting a texture (a textured spot, or a projector).
    Projected(Arc<ProjectedLight>),
}

impl Light {
    /// An area light on a mesh; a bitmap radiance on a rectangle whose uvs span it once, or
    /// on a disk with its polar uvs, is importance-sampled by its texels.
    pub fn mesh(instance: u32, emitter: Arc<MeshEmitter>, radiance: Texture, two_sided: bool) -> Light {
        let importance = match emitter.uv_rectangle() {
            Some(map) => TexelImportance::new(&radiance, UvJacobian::Uniform)
                .map(|texels| MeshImportance::Rectangle(RectangleImportance { texels, map })),
            // Only a bitmap can be sampled by its texels: other meshes are not looked at.
            None if matches!(radiance, Texture::Bitmap { .. }) => emitter.uv_disk().and_then(|map| {
                let texels = TexelImportance::new(&radiance, UvJacobian::LinearU)?;
                Some(MeshImportance::Disk(DiskImportance { texels, map }))
            }),
            None => None,
        };
        Light::Mesh { instance, emitter, radiance, two_sided, importance: importance.map(Arc::new) }
    }

    /// An area light on a sphere; a bitmap radiance is importance-sampled by its texels.
    pub fn sphere(instance: u32, sphere: Sphere, radiance: Texture, inward: bool) -> Light {
        let importance = TexelImportance::new(&radiance, UvJacobian::SinPiV).map(Arc::new);
        Light::Sphere { instance, sphere, radiance, inward, importance }
    }

    /// An area light on a cylinder; a bitmap radiance is importance-sampled by its texels.
    pub fn cylinder(instance: u32, cylinder: Cylinder, radiance: Texture, inward: bool) -> Light {
        let importance = TexelImportance::new(&radiance, UvJacobian::Uniform).map(Arc::new);
        Light::Cylinder { instance, cylinder, radiance, inward, importance }
    }

    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } | Light::Projected(_))
    }

    pub fn is_infinite(&self) -> bool {
        matches!(self, Light::Directional { .. } | Light::Constant { .. } | Light::EnvMap(_))
    }

    /// Surface area of an area light (0 for the others).
    pub fn area(&self) -> f32 {
        match self {
            Light::Mesh { emitter, .. } => emitter.total_area,
            Light::Sphere { sphere, .. } => sphere.area(),
            Light::Cylinder { cylinder, .. } => cylinder.area(),
            Light::Point { .. }
            | Light::Spot { .. }
            | Light::Directional { .. }
            | Light::Constant { .. }
            | Light::EnvMap(_)
            | Light::Projected(_) => 0.0,
        }
    }

    /// Emitted flux (luminance-weighted) for power-proportional light selection.
    pub fn power(&self) -> f32 {
        match self {
            Light::Point { intensity, .. } => 4.0 * PI * intensity.luminance(),
            Light::Spot { intensity, cutoff, beam, .. } => {
                // Solid angle of the cone, counting the falloff band at half weight.
                let mid = 0.5 * (cutoff + beam);
                2.0 * PI * (1.0 - mid.cos()) * intensity.luminance()
            }
            Light::Directional { irradiance, scene_radius, .. } => {
                PI * scene_radius * scene_radius * irradiance.luminance()
            }
            Light::Mesh { emitter, radiance, two_sided, .. } => {
                let sides = if *two_sided { 2.0 } else { 1.0 };
                sides * PI * emitter.total_area * radiance.mean().luminance()
            }
            Light::Sphere { sphere, radiance, .. } => PI * sphere.area() * radiance.mean().luminance(),
            Light::Cylinder { cylinder, radiance, .. } => PI * cylinder.area() * radiance.mean().luminance(),
            Light::Constant { radiance, scene_radius } => {
                4.0 * PI * PI * scene_radius * scene_radius * radiance.luminance()
            }
            Light::EnvMap(env) => 4.0 * PI * PI * env.scene_radius * env.scene_radius * env.mean_luminance(),
            Light::Projected(l) => l.power(),
        }
    }

    /// Samples a direction towards the light as seen from `p`. `None` when the light sends
    /// nothing towards `p` for this sample.
    pub fn sample_li(&self, p: Vec3, u: [f32; 2]) -> Option<LightSample> {
        match self {
            Light::Point { position, intensity } => {
                let d = *position - p;
                let dist2 = d.length_squared();
                let dist = dist2.sqrt();
                Some(LightSample { wi: d / dist, radiance: *intensity / dist2, pdf: 1.0, dist, delta: true })
            }
            Light::Spot { position, frame, intensity, cutoff, beam, gltf_falloff } => {
                let d = *position - p;
                let dist2 = d.length_squared();
                let dist = dist2.sqrt();
                let wi = d / dist;
                let cos_t = frame.to_local(-wi).z;
                let falloff = if *gltf_falloff {
                    gltf_spot_falloff(cos_t, *cutoff, *beam)
                } else {
                    spot_falloff(cos_t, *cutoff, *beam)
                };
                if falloff <= 0.0 {
                    return None;
                }
                Some(LightSample { wi, radiance: *intensity * (falloff / dist2), pdf: 1.0, dist, delta: true })
            }
            Light::Directional { direction, irradiance, .. } => {
                Some(LightSample { wi: -*direction, radiance: *irradiance, pdf: 1.0, dist: f32::INFINITY, delta: true })
            }
            Light::Mesh { emitter, radiance, two_sided, importance: Some(imp), .. } => match &**imp {
                MeshImportance::Rectangle(imp) => {
                    let (uv, pdf_uv) = imp.texels.sample(u)?;
                    let n = emitter.rectangle.as_ref()?.normal;
                    let le = radiance_at(radiance, || TexturePoint::uv(uv));
                    area_sample(p, imp.map.point(uv), n, *two_sided, pdf_uv / imp.map.area, le)
                }
                MeshImportance::Disk(imp) => {
                    let (uv, pdf_uv) = imp.texels.sample(u)?;
                    let (q, k, t) = imp.map.point(uv);
                    let [a, b, c] = emitter.triangles[k];
                    let n = (b - a).cross(c - a).normalize();
                    // Read where a ray hitting q reads it: the mesh's interpolated uv at q's
                    // barycentrics on triangle k (rim vertex k weighs u(1 - t), k + 1 weighs ut).
                    let rim = [uv[0] * (1.0 - t), uv[0] * t];
                    let bary = if emitter.flipped { [rim[1], rim[0]] } else { rim };
                    let le = radiance_at(radiance, || emitter.texture_point(k, bary));
                    area_sample(p, q, n, *two_sided, imp.map.area_density(pdf_uv, uv, k), le)
                }
            },
            Light::Mesh { emitter, radiance, two_sided, importance: None, .. } => {
                let by_solid_angle = emitter.spherical_rectangle(p);
                let (q, n, at) = match &by_solid_angle {
                    Some(sr) => (sr.sample(u), emitter.rectangle.as_ref()?.normal, None),
                    // A rectangle by area: the square mapped linearly onto it, as Mitsuba's
                    // `rectangle` does, so a stratified `u` stays stratified along both edges.
                    // (Picking one of its two triangles with `u[0]` left each triangle, which
                    // spans the whole length, half the strata: on thin lights 1.5-3x the error
                    // of Mitsuba's at 16 spp.) Same density: uniform over the same area.
                    None if emitter.rectangle.is_some() => {
                        let r = emitter.rectangle.as_ref()?;
                        (r.corner + r.ex * u[0] + r.ey * u[1], r.normal, None)
                    }
                    None => {
                        let pick = emitter.areas.sample(u[0]);
                        let [a, b, c] = emitter.triangles[pick.index];
                        let bary = warp::uniform_triangle([pick.remapped, u[1]]);
                        let q = a * (1.0 - bary[0] - bary[1]) + b * bary[0] + c * bary[1];
                        (q, (b - a).cross(c - a).normalize(), Some((pick.index, bary)))
                    }
                };
                let d = q - p;
                let dist2 = d.length_squared();
                if dist2 == 0.0 {
                    return None;
                }
                let dist = dist2.sqrt();
                let wi = d / dist;
                let cos_l = -n.dot(wi);
                if cos_l == 0.0 || (!two_sided && cos_l < 0.0) {
                    return None;
                }
                let pdf = match &by_solid_angle {
                    Some(sr) => sr.pdf(),
                    None => dist2 / (cos_l.abs() * emitter.total_area),
                };
                let radiance = radiance_at(radiance, || {
                    let (tri, bary) = at.unwrap_or_else(|| emitter.locate(q));
                    emitter.texture_point(tri, bary)
                });
                Some(LightSample { wi, radiance, pdf, dist, delta: false })
            }
            Light::Sphere { sphere, radiance, inward, importance: Some(imp), .. } => {
                let (uv, pdf_uv) = imp.sample(u)?;
                let (st, ct) = (PI * uv[1]).sin_cos();
                let (sp, cp) = (2.0 * PI * uv[0]).sin_cos();
                let dir = sphere.axes[0] * (st * cp) + sphere.axes[1] * (st * sp) + sphere.axes[2] * ct;
                let n = if *inward { -dir } else { dir };
                let jacobian = SPHERE_UV_JACOBIAN * sphere.radius * sphere.radius * st;
                if !(jacobian > 0.0) {
                    return None;
                }
                let le = radiance_at(radiance, || TexturePoint::uv(uv));
                area_sample(p, sphere.center + dir * sphere.radius, n, false, pdf_uv / jacobian, le)
            }
            Light::Sphere { sphere, radiance, inward, importance: None, .. } => {
                let mut ls = sphere::sample(sphere, Rgb::WHITE, *inward, p, u)?;
                ls.radiance = radiance_at(radiance, || {
                    let n = (p + ls.wi * ls.dist - sphere.center).normalize();
                    TexturePoint::uv(sphere.uv(n))
                });
                Some(ls)
            }
            Light::Cylinder { cylinder, radiance, inward, importance: Some(imp), .. } => {
                let (uv, pdf_uv) = imp.sample(u)?;
                let q = cylinder.sample(uv);
                let n = if *inward { -q.n } else { q.n };
                let le = radiance_at(radiance, || TexturePoint::uv(uv));
                area_sample(p, q.p, n, false, pdf_uv / cylinder.area(), le)
            }
            Light::Cylinder { cylinder, radiance, inward, importance: None, .. } => {
                let q = cylinder.sample(u);
                let n = if *inward { -q.n } else { q.n };
                let d = q.p - p;
                let dist2 = d.length_squared();
                if !(dist2 > 0.0) {
                    return None;
                }
                let dist = dist2.sqrt();
                let wi = d / dist;
                let cos_l = -n.dot(wi);
                if !(cos_l > 0.0) {
                    return None;
                }
                let pdf = dist2 / (cos_l * cylinder.area());
                let radiance = radiance_at(radiance, || TexturePoint::uv(q.uv));
                Some(LightSample { wi, radiance, pdf, dist, delta: false })
            }
            Light::Constant { radiance, .. } => {
                let wi = warp::uniform_sphere(u);
                Some(LightSample {
                    wi,
                    radiance: *radiance,
                    pdf: warp::UNIFORM_SPHERE_PDF,
                    dist: f32::INFINITY,
                    delta: false,
                })
            }
            Light::EnvMap(env) => env.sample(u),
            Light::Projected(l) => l.sample_li(p),
        }
    }

    /// Samples a point uniformly on triangle `t` of a mesh light (the light tree chooses the
    /// triangles of large meshes one by one); `None` for other lights.
    pub fn sample_li_triangle(&self, p: Vec3, t: usize, u: [f32; 2]) -> Option<LightSample> {
        let Light::Mesh { emitter, radiance, two_sided, .. } = self else { return None };
        let [a, b, c] = *emitter.triangles.get(t)?;
        let bary = warp::uniform_triangle(u);
        let q = a * (1.0 - bary[0] - bary[1]) + b * bary[0] + c * bary[1];
        let n = (b - a).cross(c - a);
        let area = 0.5 * n.length();
        if !(area > 0.0) {
            return None;
        }
        let le = radiance_at(radiance, || emitter.texture_point(t, bary));
        area_sample(p, q, n / (2.0 * area), *two_sided, 1.0 / area, le)
    }

    /// The density of `sample_li_triangle` on triangle `t` from `p` producing `q` (normal `n`).
    pub fn pdf_li_triangle(&self, p: Vec3, wi: Vec3, q: Vec3, n: Vec3, t: usize) -> f32 {
        let Light::Mesh { emitter, .. } = self else { return 0.0 };
        let Some([a, b, c]) = emitter.triangles.get(t) else { return 0.0 };
        let area = 0.5 * (*b - *a).cross(*c - *a).length();
        if !(area > 0.0) {
            return 0.0;
        }
        solid_angle_pdf(p, wi, q, n, 1.0 / area)
    }

    /// Solid-angle density of `sample_li` from `p` producing the point `q` (normal `n`) on an
    /// area light, or direction `wi` for an infinite light.
    pub fn pdf_li(&self, p: Vec3, wi: Vec3, q: Vec3, n: Vec3) -> f32 {
        match self {
            Light::Mesh { importance: Some(imp), .. } => match &**imp {
                MeshImportance::Rectangle(imp) => {
                    solid_angle_pdf(p, wi, q, n, imp.texels.pdf(imp.map.uv(q)) / imp.map.area)
                }
                MeshImportance::Disk(imp) => {
                    let (uv, k, _) = imp.map.uv(q);
                    solid_angle_pdf(p, wi, q, n, imp.map.area_density(imp.texels.pdf(uv), uv, k))
                }
            },
            Light::Sphere { sphere, importance: Some(imp), .. } => {
                let dir = (q - sphere.center).normalize();
                let st = (1.0 - sphere.to_local(dir).z.powi(2)).max(0.0).sqrt();
                let jacobian = SPHERE_UV_JACOBIAN * sphere.radius * sphere.radius * st;
                if !(jacobian > 0.0) {
                    return 0.0;
                }
                solid_angle_pdf(p, wi, q, n, imp.pdf(sphere.uv(dir)) / jacobian)
            }
            Light::Cylinder { cylinder, importance: Some(imp), .. } => {
                solid_angle_pdf(p, wi, q, n, imp.pdf(cylinder.uv_at(q)) / cylinder.area())
            }
            Light::Mesh { emitter, importance: None, .. } => {
                if let Some(sr) = emitter.spherical_rectangle(p) {
                    return sr.pdf();
                }
                let dist2 = (q - p).length_squared();
                let cos_l = n.dot(wi).abs();
                if cos_l == 0.0 {
                    return 0.0;
                }
                dist2 / (cos_l * emitter.total_area)
            }
            Light::Sphere { sphere, importance: None, .. } => sphere::pdf(sphere, p, q, n, wi),
            Light::Cylinder { cylinder, importance: None, .. } => {
                let cos_l = n.dot(wi).abs();
                if cos_l == 0.0 {
                    return 0.0;
                }
                (q - p).length_squared() / (cos_l * cylinder.area())
            }
            Light::Constant { .. } => warp::UNIFORM_SPHERE_PDF,
            Light::EnvMap(env) => env.pdf(wi),
            Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } | Light::Projected(_) => 0.0,
        }
    }

    /// Radiance leaving an area light at the point `at` (where its texture is read), of
    /// geometric normal `n`, towards `-wi` (`wi` is the direction the ray travelled).
    pub fn emitted(&self, at: &TexturePoint, n: Vec3, wi: Vec3) -> Rgb {
        match self.emitting_texture(n, wi) {
            Some(radiance) => radiance_at(radiance, || *at),
            None => Rgb::BLACK,
        }
    }

    /// The radiance texture of an area light whose surface, of normal `n`, emits along `wi`
    /// (None for other lights, and for the side that does not emit).
    pub fn emitting_texture(&self, n: Vec3, wi: Vec3) -> Option<&Texture> {
        let (radiance, two_sided) = match self {
            Light::Mesh { radiance, two_sided, .. } => (radiance, *two_sided),
            Light::Sphere { radiance, .. } | Light::Cylinder { radiance, .. } => (radiance, false),
            Light::Point { .. }
            | Light::Spot { .. }
            | Light::Directional { .. }
            | Light::Constant { .. }
            | Light::EnvMap(_)
            | Light::Projected(_) => return None,
        };
        (two_sided || n.dot(wi) < 0.0).then_some(radiance)
    }

    /// Radiance from an infinite light arriving along a ray that escaped with direction `dir`.
    pub fn environment(&self, dir: Vec3) -> Rgb {
        match self {
            Light::Constant { radiance, .. } => *radiance,
            Light::EnvMap(env) => env.eval(dir),
            Light::Point { .. }
            | Light::Spot { .. }
            | Light::Directional { .. }
            | Light::Mesh { .. }
            | Light::Sphere { .. }
            | Light::Cylinder { .. }
            | Light::Projected(_) => Rgb::BLACK,
        }
    }
}

/// A light sample at `q` on an area light (normal `n` on its emitting side; either side when
/// `two_sided`), drawn with density `pdf_area` per unit area, seen from `p`.
fn area_sample(p: Vec3, q: Vec3, n: Vec3, two_sided: bool, pdf_area: f32, radiance: Rgb) -> Option<LightSample> {
    let d = q - p;
    let dist2 = d.length_squared();
    if !(dist2 > 0.0) {
        return None;
    }
    let dist = dist2.sqrt();
    let wi = d / dist;
    let cos_l = -n.dot(wi);
    if !(cos_l > 0.0 || (two_sided && cos_l < 0.0)) {
        return None;
    }
    let pdf = pdf_area * dist2 / cos_l.abs();
    Some(LightSample { wi, radiance, pdf, dist, delta: false })
}

/// The solid-angle density at `p` of direction `wi` reaching `q` (normal `n`), from a
/// density per unit area.
fn solid_angle_pdf(p: Vec3, wi: Vec3, q: Vec3, n: Vec3, pdf_area: f32) -> f32 {
    let cos_l = n.dot(wi).abs();
    if !(cos_l > 0.0) {
        return 0.0;
    }
    pdf_area * (q - p).length_squared() / cos_l
}

/// `KHR_lights_punctual`'s spot falloff, as its reference code computes it: the cosine's
/// place between the outer (`cutoff`) and inner (`beam`) cones, clamped to [0, 1], squared.
pub(crate) fn gltf_spot_falloff(cos_t: f32, cutoff: f32, beam: f32) -> f32 {
    let (cos_outer, cos_inner) = (cutoff.cos(), beam.cos());
    let scale = 1.0 / (cos_inner - cos_outer).max(0.001);
    let t = (cos_t * scale - cos_outer * scale).clamp(0.0, 1.0);
    t * t
}

fn spot_falloff(cos_t: f32, cutoff: f32, beam: f32) -> f32 {
    if cos_t <= cutoff.cos() {
        return 0.0;
    }
    if cos_t >= beam.cos() {
        return 1.0;
    }
    ((cutoff - cos_t.clamp(-1.0, 1.0).acos()) / (cutoff - beam)).clamp(0.0, 1.0)
}

/// Radius of a sphere that bounds the scene, for infinite lights' power estimates.
pub fn scene_radius(bounds: &Aabb) -> f32 {
    if bounds.is_empty() {
        1.0
    } else {
        (bounds.extent().length() * 0.5).max(1e-3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    #[test]
    fn gltf_spot_falloff_is_the_squared_ramp_in_the_cosine() {
        let (outer, inner) = (0.6f32, 0.2f32);
        assert_eq!(gltf_spot_falloff(1.0, outer, inner), 1.0);
        assert_eq!(gltf_spot_falloff(outer.cos() - 0.01, outer, inner), 0.0);
        // Half-way in cosine between the cones: a quarter.
        let mid = 0.5 * (outer.cos() + inner.cos());
        assert!((gltf_spot_falloff(mid, outer, inner) - 0.25).abs() < 1e-5);
    }

    #[test]
    fn sphere_lights_are_sampled_only_from_the_side_they_light() {
        let sphere = Sphere::new(Vec3::ZERO, 1.0);
        let light = |inward| Light::sphere(0, sphere, Texture::Constant(Rgb::WHITE), inward);
        let (outside, inside) = (vec3(0.0, 0.0, 3.0), vec3(0.2, 0.1, 0.0));
        for u in [[0.1, 0.2], [0.5, 0.5], [0.9, 0.7]] {
            assert!(light(false).sample_li(outside, u).is_some());
            assert!(light(false).sample_li(inside, u).is_none());
            assert!(light(true).sample_li(outside, u).is_none());
            assert!(light(true).sample_li(inside, u).is_some());
        }
    }

    /// A thin rectangle, 2 x 0.2, facing down at height 2.8, as two triangles.
    fn thin_rectangle() -> Light {
        let (a, b, c, d) = (vec3(-1.0, -0.1, 2.8), vec3(1.0, -0.1, 2.8), vec3(1.0, 0.1, 2.8), vec3(-1.0, 0.1, 2.8));
        let emitter = MeshEmitter::new(vec![[a, c, b], [a, d, c]]).unwrap();
        assert!(emitter.rectangle.is_some());
        Light::mesh(0, Arc::new(emitter), Texture::Constant(Rgb::WHITE), false)
    }

    #[test]
    fn rectangles_sampled_by_area_keep_the_strata_of_the_square() {
        // Below the light's middle area sampling is used (the light looks nearly uniform in
        // solid angle), by the linear map of the square onto the rectangle: a 4 x 4
        // stratified set of u lands one point in each of the rectangle's 4 x 4 cells (cells
        // along its edges, whichever corner the map starts from). Picking a triangle with
        // u[0] first, as for other meshes, would not.
        let light = thin_rectangle();
        let p = vec3(0.0, 0.0, 0.0);
        let Light::Mesh { emitter, .. } = &light else { unreachable!() };
        assert!(!emitter.samples_by_solid_angle(p));
        let mut cells = [[0u32; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                let u = [(i as f32 + 0.37) / 4.0, (j as f32 + 0.61) / 4.0];
                let ls = light.sample_li(p, u).unwrap();
                let q = p + ls.wi * ls.dist;
                assert!((q.z - 2.8).abs() < 1e-4 && q.x.abs() <= 1.0 + 1e-5 && q.y.abs() <= 0.1 + 1e-6, "{q:?}");
                let cx = (((q.x + 1.0) / 2.0 * 4.0) as usize).min(3);
                let cy = (((q.y + 0.1) / 0.2 * 4.0) as usize).min(3);
                cells[cx][cy] += 1;
                // The density is area sampling's, and what pdf_li says for the same point.
                let n = vec3(0.0, 0.0, -1.0);
                let expected = ls.dist * ls.dist / (-n.dot(ls.wi) * 0.4);
                assert!((ls.pdf / expected - 1.0).abs() < 1e-4, "{} vs {expected}", ls.pdf);
                assert!((light.pdf_li(p, ls.wi, q, n) / ls.pdf - 1.0).abs() < 1e-4);
            }
        }
        assert_eq!(cells, [[1; 4]; 4]);
    }

    /// An 8 × 4 bitmap with a hot texel, so that the density varies 100× over the disk.
    fn hot_bitmap() -> Texture {
        let pixels = (0..32).map(|k| {
            if k == 13 {
                crate::math::rgb(90.0, 60.0, 30.0)
            } else {
                Rgb::splat(0.3 + 0.1 * (k % 3) as f32)
            }
        });
        Texture::Bitmap {
            image: Arc::new(crate::materials::Bitmap { width: 8, height: 4, pixels: pixels.collect() }),
            uv_scale: [1.0; 2],
            uv_offset: [0.0; 2],
        }
    }

    /// The unit disk's fan placed by `xf`, as the builder hands it to a light.
    fn disk_emitter(mesh: TriangleMesh, xf: &crate::math::Transform, flipped: bool) -> MeshEmitter {
        let tris = (0..mesh.indices.len())
            .map(|t| mesh.vertices(t).map(|v| xf.point(v)))
            .map(|[a, b, c]| if flipped { [a, c, b] } else { [a, b, c] })
            .collect();
        MeshEmitter::of_mesh(tris, Arc::new(mesh), flipped).unwrap()
    }

    fn placed() -> crate::math::Transform {
        use crate::math::Transform;
        Transform::translate(vec3(0.3, 1.5, -0.2))
            .then_after(&Transform::rotate(vec3(1.0, 0.2, 0.0).normalize(), 100.0))
            .then_after(&Transform::scale(vec3(0.7, 0.4, 1.0)).unwrap())
    }

    fn importance_of(l: &Light) -> Option<&MeshImportance> {
        match l {
            Light::Mesh { importance, .. } => importance.as_deref(),
            _ => None,
        }
    }

    #[test]
    fn bitmaps_on_disks_are_sampled_by_their_texels_at_the_density_pdf_li_gives() {
        // From points on both sides of a turned, squashed disk, one- and two-sided, normals
        // flipped or not: every sample's density is what pdf_li gives the same point, and its
        // radiance is the texture read where a ray hitting that point reads it.
        use crate::accel::BvhSplit;
        use crate::geometry::disk_mesh;
        let xf = placed();
        let mut rng = crate::sampling::Rng::new(17, 3);
        let mut checked = 0;
        for (flipped, two_sided) in [(false, false), (true, false), (false, true)] {
            let emitter = Arc::new(disk_emitter(disk_mesh(BvhSplit::Sah), &xf, flipped));
            let light = Light::mesh(0, emitter.clone(), hot_bitmap(), two_sided);
            assert!(matches!(importance_of(&light), Some(MeshImportance::Disk(_))));
            let centre = xf.point(Vec3::ZERO);
            let normal = xf.normal(Vec3::Z).normalize();
            for side in [1.0, -1.0] {
                let p = centre + normal * (0.6 * side) + vec3(0.2, -0.1, 0.15);
                for _ in 0..5000 {
                    let Some(ls) = light.sample_li(p, [rng.next_f32(), rng.next_f32()]) else { continue };
                    let q = p + ls.wi * ls.dist;
                    let pdf = light.pdf_li(p, ls.wi, q, normal);
                    assert!((pdf / ls.pdf - 1.0).abs() < 1e-3, "{q:?}: pdf_li {pdf} vs the sample's {}", ls.pdf);
                    // The mesh's uv there: u, and v between the centre's (k + ½)/N and the
                    // rim's (k + t)/N in proportion to u (barycentrics in these thin
                    // triangles, as `locate` finds them, are too coarse to check against).
                    let Some(MeshImportance::Disk(d)) = importance_of(&light) else { unreachable!() };
                    let ([u, _], k, t) = d.map.uv(q);
                    let n = emitter.triangles.len() as f32;
                    let v = (1.0 - u) * (k as f32 + 0.5) / n + u * (k as f32 + t) / n;
                    let expected = hot_bitmap().eval([u, v]);
                    let (got, want) =
                        ([ls.radiance.r, ls.radiance.g, ls.radiance.b], [expected.r, expected.g, expected.b]);
                    assert!((0..3).all(|c| (got[c] - want[c]).abs() <= 1e-3 * want[c]), "{q:?}: {got:?} vs {want:?}");
                    checked += 1;
                }
            }
        }
        // One-sided lights are sampled from their emitting side only.
        assert!(checked > 5000 * 3, "{checked}");
    }

    #[test]
    fn only_bitmaps_on_a_true_disk_fan_are_sampled_by_texels() {
        use crate::accel::BvhSplit;
        use crate::geometry::disk_mesh;
        let xf = placed();
        let light = |mesh: TriangleMesh, radiance: Texture| {
            Light::mesh(0, Arc::new(disk_emitter(mesh, &xf, false)), radiance, false)
        };
        let importance = |l: &Light| importance_of(l).cloned();
        let disk = light(disk_mesh(BvhSplit::Sah), hot_bitmap());
        assert!(matches!(importance(&disk), Some(MeshImportance::Disk(_))));
        // Not a bitmap.
        assert!(importance(&light(disk_mesh(BvhSplit::Sah), Texture::Constant(Rgb::WHITE))).is_none());
        // Uvs that are not the disk's polar ones (one rim vertex's azimuth moved).
        let mut m = disk_mesh(BvhSplit::Sah);
        m.uvs.as_mut().unwrap()[4][1] += 0.01;
        assert!(importance(&light(m, hot_bitmap())).is_none());
        // A rim vertex pulled off the ellipse.
        let mut m = disk_mesh(BvhSplit::Sah);
        m.positions[7] *= 0.9;
        assert!(importance(&light(m, hot_bitmap())).is_none());
        // The rectangle keeps its own.
        let quad = crate::geometry::rectangle_mesh(BvhSplit::Sah);
        assert!(matches!(importance(&light(quad, hot_bitmap())), Some(MeshImportance::Rectangle(_))));
    }
}
