//! What a surface does before its BSDF scatters: normal and bump maps tilt the shading
//! frame, masks let light through. Shared by the integrators.

use super::Counters;
use crate::materials::{flip_invalid, normal_map_frame, ShadedBsdf};
use crate::materials::{Perturbation, TexturePoint, TANGENT_ATTRIBUTE, TANGENT_SIGN_ATTRIBUTE};
use crate::math::{offset_origin, Frame, Ray, Vec3};
use crate::sampling::Sampler;
use crate::world::{SurfaceInteraction, World};

/// The most masked surfaces one ray passes through; a ray that meets more (a stack of
/// coincident cut-outs) stops at the next one, as if it were opaque.
pub(crate) const MAX_MASK_PASSES: u32 = 256;

/// Where textures are looked up for `si`.
pub(crate) fn texture_point<'a>(scene: &'a World, si: &SurfaceInteraction) -> TexturePoint<'a> {
    scene.texture_point(si)
}

/// The probability that light travelling along `dir` and meeting the surface at `si`
/// scatters there: 1 unless masked, and 0 at the back face of a material whose back faces
/// are culled (single-sided glTF): the face whose geometric normal `si.ng` (after the
/// instance's transform, counter-clockwise winding in front) points along `dir`.
pub(crate) fn opacity(scene: &World, si: &SurfaceInteraction, dir: Vec3) -> f32 {
    let mat = &scene.materials[si.material as usize];
    if mat.cull_back_faces && si.ng.dot(dir) > 0.0 {
        return 0.0;
    }
    if !mat.is_masked() {
        return 1.0;
    }
    mat.opacity(&texture_point(scene, si))
}

/// Whether a ray along `dir` that met the surface at `si` after `passes` earlier passes goes
/// on through it unscattered: a masked surface (or a culled back face, of opacity 0) lets it
/// pass with probability 1 - opacity (one random number per masked surface met), up to
/// [`MAX_MASK_PASSES`] times along one path segment.
#[inline]
pub(crate) fn passes_mask(scene: &World, si: &SurfaceInteraction, dir: Vec3, passes: u32, rng: &mut Sampler) -> bool {
    if !scene.has_masks || passes >= MAX_MASK_PASSES {
        return false;
    }
    let o = opacity(scene, si, dir);
    o < 1.0 && rng.next_f32() >= o
}

/// The fraction of light that gets along a shadow ray: 1 when nothing blocks it, 0 when an
/// opaque surface does, the product of (1 − opacity) over the masked surfaces (and culled
/// back faces) it crosses otherwise (the expected value of passing each one, as Mitsuba's
/// volumetric path tracer counts null surfaces; its `path` integrator stops shadow rays at
/// every surface).
pub(crate) fn transmittance(scene: &World, ray: &Ray, c: &mut Counters) -> f32 {
    transmittance_if_blocked(scene, ray, scene.occluded(ray), c)
}

/// [`transmittance`] of a ray whose occlusion query has already answered `blocked`.
pub(crate) fn transmittance_if_blocked(scene: &World, ray: &Ray, blocked: bool, c: &mut Counters) -> f32 {
    if !blocked {
        return 1.0;
    }
    if !scene.has_masks {
        return 0.0;
    }
    let mut r = *ray;
    let mut t = 1.0f32;
    for _ in 0..MAX_MASK_PASSES {
        let Some(hit) = scene.intersect(&r) else { return t };
        let si = scene.interaction(&r, &hit);
        t *= 1.0 - opacity(scene, &si, r.dir);
        if !(t > 0.0) {
            return 0.0;
        }
        c.shadow_rays += 1;
        // Carry on from just past the surface, to the same end point (or to infinity).
        let o = offset_origin(si.p, si.ng, r.dir);
        let t_max = if r.t_max.is_finite() {
            let along = (r.at(r.t_max) - o).dot(r.dir) / r.dir.length_squared();
            if !(along > 0.0) {
                return t;
            }
            along
        } else {
            f32::INFINITY
        };
        r = Ray { origin: o, dir: r.dir, t_min: 0.0, t_max };
    }
    0.0
}

/// The BSDF at a hit and the frame to evaluate it in (see [`super::shading`]): the frame
/// faces the viewer for two-sided materials, and a normal or bump map tilts the BSDF
/// within it.
pub(crate) fn shade(scene: &World, si: &SurfaceInteraction, wo_world: Vec3) -> (ShadedBsdf, Frame) {
    let mat = &scene.materials[si.material as usize];
    let p = texture_point(scene, si);
    let bsdf = mat.bsdf_at(&p);
    let mut frame = si.frame;
    if mat.two_sided && !mat.is_transmissive() && frame.n.dot(wo_world) < 0.0 {
        // Mirrored in the tangent plane, as Mitsuba's `twosided` mirrors directions.
        frame = Frame { s: frame.s, t: frame.t, n: -frame.n };
    }
    let Some(perturbation) = mat.perturbation() else { return (bsdf.into(), frame) };
    let wo = frame.to_local(wo_world);
    let tilt = match perturbation {
        Perturbation::NormalMap { normals } => {
            let c = normals.eval_at(&p);
            let v = Vec3 { x: 2.0 * c.r - 1.0, y: 2.0 * c.g - 1.0, z: 2.0 * c.b - 1.0 };
            normal_map_frame(mesh_tangent_space(scene, si, &p, v), wo)
        }
        Perturbation::BumpMap { height, scale } => bump_frame(si, height.luminance_gradient(si.uv), scale, wo),
    };
    (ShadedBsdf { bsdf, tilt }, frame)
}

/// A tangent-space normal `v` in the surface's shading frame. Where the mesh carries
/// tangents of its own (glTF's `TANGENT`), `v` is in their frame: the tangent's xyz
/// interpolated by the barycentrics, moved to world space and made orthogonal to the shading
/// normal `n`, and the bitangent sign(w) n x t (w's sign turned where the instance's
/// transform mirrors, so that the bitangent moves with the surface). Elsewhere, and where the
/// file's tangent is degenerate there, `v` is already in the shading frame, whose `s` is
/// dp/du: MikkTSpace's tangent of the triangle before its per-vertex averaging. Either way
/// the result is in the unmirrored frame's coordinates, which a two-sided material's mirrored
/// frame then reads as it reads `v`.
fn mesh_tangent_space(scene: &World, si: &SurfaceInteraction, p: &TexturePoint, v: Vec3) -> Vec3 {
    let Some(mesh) = p.mesh else { return v };
    let (Some(ta), Some(wa)) = (mesh.attribute(TANGENT_ATTRIBUTE), mesh.attribute(TANGENT_SIGN_ATTRIBUTE)) else {
        return v;
    };
    let Some(&tri) = mesh.indices.get(p.prim as usize) else { return v };
    let c = ta.eval(tri, p.prim, p.bary);
    let mut t = Vec3 { x: c.r, y: c.g, z: c.b };
    let mut sign = if wa.eval(tri, p.prim, p.bary).r < 0.0 { -1.0 } else { 1.0 };
    if let Some(x) = scene.instances.get(si.instance as usize).and_then(|i| i.to_world.as_ref()) {
        t = x.vector(t);
        if x.swaps_handedness() {
            sign = -sign;
        }
    }
    let n = si.frame.n;
    let t = t - n * n.dot(t);
    let len = t.length();
    if !(len > 1e-12) || !len.is_finite() {
        return v;
    }
    let t = t / len;
    let b = n.cross(t) * sign;
    si.frame.to_local(t * v.x + b * v.y + n * v.z)
}

/// Mitsuba's bump-mapped frame, in the surface's shading frame: dp/du and dp/dv moved along
/// the shading normal by the height's gradient, their cross product turned to the side of
/// the geometric normal. Computed on the unmirrored surface (the mirror of a two-sided
/// material applies to it as to directions).
fn bump_frame(si: &SurfaceInteraction, grad: [f32; 2], scale: f32, wo: Vec3) -> Option<Frame> {
    let n = si.frame.n;
    let dpdu = si.dpdu + n * (scale * grad[0] - n.dot(si.dpdu));
    let dpdv = si.dpdv + n * (scale * grad[1] - n.dot(si.dpdv));
    let mut nb = dpdu.cross(dpdv).normalize();
    if !nb.is_finite() {
        return None;
    }
    if si.ng.dot(nb) < 0.0 {
        nb = -nb;
    }
    let local = flip_invalid(si.frame.to_local(nb), wo);
    let len = local.length();
    if !(len > 0.0) || !len.is_finite() {
        return None;
    }
    let local = local / len;
    Some(Frame::from_normal_tangent(local, si.frame.to_local(si.dpdu)))
}
