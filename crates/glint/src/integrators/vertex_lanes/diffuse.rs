//! The Lambertian vertex in lanes: for lanes of untransformed meshes the interaction's
//! normals and frame (`mesh_frames`), then the BSDF towards the light, the MIS weight, the
//! shadow ray, the cosine sample and the next ray (`diffuse_lanes`), as
//! `PathState::scatter` computes them for `Bsdf::Diffuse`.

use super::columns::{Lobe, SharedColumns};
use super::lane_math::*;
use super::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use super::{flag, put3, Column, Column3, MeshHit};
use crate::integrators::path::PathState;
use crate::lights::LightSample;
use crate::math::lanes::Lanes;
use crate::math::{Frame, Rgb, Vec3, INV_PI};
use crate::sampling::Sampler;
use crate::world::SurfaceInteraction;

/// Up to [`MAX_LANES`] diffuse vertices, one per lane: what the scalar code gathered, and what
/// the kernel leaves. Flags are 1.0 (true) or 0.0.
#[derive(Clone, Copy, Default)]
pub(crate) struct DiffuseChunk {
    /// The vertex, its light sample and random numbers, and the continuation.
    pub(super) shared: SharedColumns,
    /// In: the reflectance.
    pub(super) reflectance: Column3,
    // In, for lanes whose interaction the kernel computes (`from_mesh` 1): the hit triangle of
    // an untransformed mesh, its barycentrics, vertex normals and uvs where the mesh has them,
    // and the instance's and material's flags. The kernel then writes `ng`, `n`, `s`, `t`.
    pub(super) from_mesh: Column,
    pub(super) corners: [Column3; 3],
    pub(super) bary: Column3,
    pub(super) has_normals: Column,
    pub(super) normals: [Column3; 3],
    pub(super) has_uvs: Column,
    pub(super) uvs: [[Column; 2]; 3],
    pub(super) flip_normals: Column,
    pub(super) two_sided: Column,
}

impl DiffuseChunk {
    /// Adds a path's vertex as the next lane, its interaction and frame computed by the scalar
    /// code, drawing its random numbers from `rng` as `PathState::scatter` does (see
    /// [`DiffuseChunk::push_common`]).
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        path_index: u32,
        path: &PathState,
        si: &SurfaceInteraction,
        frame: &Frame,
        reflectance: Rgb,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.push_common(path_index, path, si.p, reflectance, light, rng);
        self.from_mesh[i] = 0.0;
        self.shared.v.put_frame(i, si.ng, frame);
    }

    /// Adds a path's vertex on an untransformed mesh as the next lane, its interaction and
    /// frame left to the kernel (`p` is the hit point `World::interaction` gives).
    #[allow(clippy::too_many_arguments)]
    pub fn push_mesh(
        &mut self,
        path_index: u32,
        path: &PathState,
        hit: &MeshHit,
        p: Vec3,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) {
        let i = self.push_common(path_index, path, p, hit.reflectance, light, rng);
        self.from_mesh[i] = 1.0;
        for (k, v) in hit.corners.iter().enumerate() {
            put3(&mut self.corners[k], i, [v.x, v.y, v.z]);
        }
        put3(&mut self.bary, i, hit.bary);
        self.has_normals[i] = flag(hit.normals.is_some());
        for (k, v) in hit.normals.unwrap_or([Vec3::ZERO; 3]).iter().enumerate() {
            put3(&mut self.normals[k], i, [v.x, v.y, v.z]);
        }
        self.has_uvs[i] = flag(hit.uvs.is_some());
        for (k, uv) in hit.uvs.unwrap_or([[0.0; 2]; 3]).iter().enumerate() {
            self.uvs[k][0][i] = uv[0];
            self.uvs[k][1][i] = uv[1];
        }
        self.flip_normals[i] = flag(hit.flip_normals);
        self.two_sided[i] = flag(hit.two_sided);
    }

    /// `SharedColumns::push` and the reflectance (a Lambertian BSDF reads no lobe number, drawn
    /// all the same). Returns the lane.
    fn push_common(
        &mut self,
        path_index: u32,
        path: &PathState,
        p: Vec3,
        reflectance: Rgb,
        light: Option<(LightSample, f32)>,
        rng: &mut Sampler,
    ) -> usize {
        let i = self.shared.push(path_index, path, p, light, Lobe::Unread, rng);
        put3(&mut self.reflectance, i, reflectance.to_array());
        i
    }
}

lane_kernel!(DiffuseChunk, diffuse_lanes);

/// One vector of the chunk's lanes, from `base`: `PathState::scatter` for a Lambertian BSDF.
#[inline(always)]
fn diffuse_lanes<L: Lanes>(l: L, c: &mut DiffuseChunk, base: usize, _live: u32, light_only: bool) {
    mesh_frames(l, c, base);
    let zero = l.splat(0.0);
    let inv_pi = l.splat(INV_PI);
    let dir = load3(l, &c.shared.v.dir, base);
    let n = load3(l, &c.shared.v.n, base);
    let refl = load3(l, &c.reflectance, base);
    let thr = load3(l, &c.shared.throughput, base);
    // `frame.to_local(-ray.dir).z`: the Lambertian BSDF reads only the normal component.
    let wo_z = dot(l, V3 { x: l.neg(dir.x), y: l.neg(dir.y), z: l.neg(dir.z) }, n);
    let wo_below = l.le(wo_z, zero);

    // Next-event estimation: `Diffuse::eval` and `pdf` towards the light, then what
    // `NextEventColumns::lanes` makes of them.
    let light_wi = load3(l, &c.shared.ne.light_wi, base);
    let wi_z = dot(l, light_wi, n);
    let black = l.or(wo_below, l.le(wi_z, zero));
    let k = l.mul(inv_pi, wi_z);
    let f = V3 {
        x: l.select(black, zero, l.mul(refl.x, k)),
        y: l.select(black, zero, l.mul(refl.y, k)),
        z: l.select(black, zero, l.mul(refl.z, k)),
    };
    // `cosine_hemisphere_pdf(wi.z)`, where `wi.z` is above 0 or NaN.
    let bsdf_pdf = l.select(black, zero, cosine_hemisphere_pdf(l, wi_z));
    c.shared.ne.lanes(l, base, &c.shared.v, thr, f, bsdf_pdf, light_only);

    // `Diffuse::sample`: `cosine_hemisphere(u)`.
    let u0 = l.load(&c.shared.u[0][base..]);
    let u1 = l.load(&c.shared.u[1][base..]);
    let d = cosine_hemisphere(l, u0, u1);
    let z = d.z;
    // `Diffuse::sample`'s weight is the reflectance.
    let kept = l.and_not(l.not(wo_below), l.le(z, zero));
    c.shared.store_next(l, base, kept, refl, cosine_hemisphere_pdf(l, z), d);
}

/// For the lanes of untransformed meshes: `World::interaction`'s geometric normal and
/// shading frame (interpolated normals, dp/du from the uvs), then `shading`'s turn of a
/// two-sided material's frame towards the viewer, written to the `ng`, `n`, `s`, `t` columns;
/// the other lanes keep theirs.
#[inline(always)]
fn mesh_frames<L: Lanes>(l: L, c: &mut DiffuseChunk, base: usize) {
    let zero = l.splat(0.0);
    let yes = |col: &Column| l.gt(l.load(&col[base..]), zero);
    let from_mesh = yes(&c.from_mesh);
    if l.bits(from_mesh) == 0 {
        return;
    }
    let [a, b, cc] = c.corners.each_ref().map(|k| load3(l, k, base));
    let [b0, b1, b2] = [0, 1, 2].map(|k| l.load(&c.bary[k][base..]));
    let e1 = sub3(l, b, a);
    let e2 = sub3(l, cc, a);
    let ng_obj = cross(l, e1, e2);
    // dp/du: from the uvs (`triangle_dpduv`), else the edge b - a.
    let [t0, t1, t2] = c.uvs.each_ref().map(|uv| (l.load(&uv[0][base..]), l.load(&uv[1][base..])));
    let (du0, dv0) = (l.sub(t1.0, t0.0), l.sub(t1.1, t0.1));
    let (du1, dv1) = (l.sub(t2.0, t0.0), l.sub(t2.1, t0.1));
    let det = l.sub(l.mul(du0, dv1), l.mul(dv0, du1));
    let inv = l.div(l.splat(1.0), det);
    let dpdu_uv = scale(l, sub3(l, scale(l, e1, dv1), scale(l, e2, dv0)), inv);
    let dpdv_uv = scale(l, sub3(l, scale(l, e2, du0), scale(l, e1, du1)), inv);
    let uv_ok = l.and(l.ne(det, zero), l.and(finite3(l, dpdu_uv), finite3(l, dpdv_uv)));
    let (fallback_s, _) = frame_from_normal(l, normalize(l, ng_obj));
    let dpdu_mesh = select3(l, uv_ok, dpdu_uv, fallback_s);
    let dpdu = select3(l, yes(&c.has_uvs), dpdu_mesh, e1);
    // The geometric normal, and the shading normal: the interpolated one where the mesh
    // has normals and it is not zero, else the geometric one; the geometric one again where
    // that is not finite.
    let flip = yes(&c.flip_normals);
    let ng_unit = normalize(l, ng_obj);
    let ng = select3(l, flip, neg3(l, ng_unit), ng_unit);
    let [n0, n1, n2] = c.normals.each_ref().map(|k| load3(l, k, base));
    let ns = add3(l, add3(l, scale(l, n0, b0), scale(l, n1, b1)), scale(l, n2, b2));
    let ns_unit = normalize(l, ns);
    let ns_unit = select3(l, flip, neg3(l, ns_unit), ns_unit);
    let use_ns = l.and(yes(&c.has_normals), l.gt(dot(l, ns, ns), zero));
    let n_shading = select3(l, use_ns, ns_unit, ng);
    let n_shading = select3(l, finite3(l, n_shading), n_shading, ng);
    // `Frame::from_normal_tangent(n_shading, dpdu)`.
    let s_raw = sub3(l, dpdu, scale(l, n_shading, dot(l, n_shading, dpdu)));
    let len2 = dot(l, s_raw, s_raw);
    let tangent_ok =
        l.and(l.gt(len2, l.mul(l.splat(1e-20), dot(l, dpdu, dpdu))), l.lt(l.abs(len2), l.splat(f32::INFINITY)));
    let s_unit = scale(l, s_raw, l.div(l.splat(1.0), l.sqrt(len2)));
    let (basis_s, basis_t) = frame_from_normal(l, n_shading);
    let s = select3(l, tangent_ok, s_unit, basis_s);
    let t = select3(l, tangent_ok, cross(l, n_shading, s_unit), basis_t);
    // `shading`: a two-sided material's frame faces the viewer (`-ray.dir`).
    let dir = load3(l, &c.shared.v.dir, base);
    let facing_away = l.lt(dot(l, n_shading, neg3(l, dir)), zero);
    let turn = l.and(yes(&c.two_sided), facing_away);
    let n = select3(l, turn, neg3(l, n_shading), n_shading);
    let v = &mut c.shared.v;
    let keep = |new: V3<L::F>, col: &Column3| select3(l, from_mesh, new, load3(l, col, base));
    let (ng, n, s, t) = (keep(ng, &v.ng), keep(n, &v.n), keep(s, &v.s), keep(t, &v.t));
    store3(l, ng, &mut v.ng, base);
    store3(l, n, &mut v.n, base);
    store3(l, s, &mut v.s, base);
    store3(l, t, &mut v.t, base);
}
