//! The tangent of the shading frame: its local x axis follows the surface's dp/du, as
//! Mitsuba's shading frame does, so that anisotropic roughness (`alpha_u` along local x)
//! runs the same way in both renderers. Where Mitsuba has no parametrization (meshes
//! without uv, or a degenerate uv triangle) it takes the tangent of its branchless frame
//! around the geometric normal, which is glint's `Frame::from_normal` too.

use super::{Hit, Instance, ShapeRef, World};
use crate::math::{Frame, Vec3};

impl World {
    /// dp/du at a hit (world space, not normalised), or `None` where the surface has no
    /// uv parametrization there.
    pub(super) fn surface_dpdu(&self, inst: &Instance, hit: &Hit, p: Vec3) -> Option<Vec3> {
        match inst.shape {
            ShapeRef::Mesh(m) => {
                let mesh = &self.meshes[m as usize];
                let uvs = mesh.uvs.as_ref()?;
                let tri = hit.prim as usize;
                let [i0, i1, i2] = mesh.indices[tri];
                let [a, b, c] = mesh.vertices(tri);
                let (t0, t1, t2) = (uvs[i0 as usize], uvs[i1 as usize], uvs[i2 as usize]);
                let dpdu =
                    triangle_dpdu([b - a, c - a], [t1[0] - t0[0], t1[1] - t0[1]], [t2[0] - t0[0], t2[1] - t0[1]])?;
                Some(match &inst.to_world {
                    None => dpdu,
                    Some(t) => t.vector(dpdu),
                })
            }
            ShapeRef::Sphere(s) => {
                // u is the azimuth about +z: dp/du is along (-y, x, 0) from the centre.
                let d = p - self.spheres[s as usize].center;
                Some(Vec3 { x: -d.y, y: d.x, z: 0.0 })
            }
        }
    }
}

/// dp/du of a triangle with edges `dp` (p1 - p0, p2 - p0) and uv edges `duv1`, `duv2`:
/// the solution of dp_k = dp/du du_k + dp/dv dv_k. `None` when the uv triangle is flat.
pub(super) fn triangle_dpdu(dp: [Vec3; 2], duv1: [f32; 2], duv2: [f32; 2]) -> Option<Vec3> {
    let det = duv1[0] * duv2[1] - duv1[1] * duv2[0];
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let dpdu = (dp[0] * duv2[1] - dp[1] * duv1[1]) / det;
    dpdu.is_finite().then_some(dpdu)
}

/// The shading frame around unit normal `n` with its x axis along `dpdu` projected onto
/// the tangent plane; without a usable `dpdu`, the tangent of the frame around `ng`.
pub(super) fn shading_frame(n: Vec3, ng: Vec3, dpdu: Option<Vec3>) -> Frame {
    let along = dpdu.unwrap_or_else(|| Frame::from_normal(ng).s);
    let s = along - n * n.dot(along);
    let len2 = s.length_squared();
    if !(len2 > 1e-12 * along.length_squared().max(f32::MIN_POSITIVE)) || !len2.is_finite() {
        return Frame::from_normal(n);
    }
    let s = s / len2.sqrt();
    Frame { s, t: n.cross(s), n }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    #[test]
    fn dpdu_of_a_triangle_follows_u() {
        // u along +x with scale 2, v along +y: dp/du = (0.5, 0, 0).
        let dp = [vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)];
        let d = triangle_dpdu(dp, [2.0, 0.0], [0.0, 1.0]).unwrap();
        assert!((d - vec3(0.5, 0.0, 0.0)).length() < 1e-6, "{d:?}");
        // Flipping v (as OBJ readers do) leaves dp/du alone.
        let d = triangle_dpdu(dp, [2.0, 0.0], [0.0, -1.0]).unwrap();
        assert!((d - vec3(0.5, 0.0, 0.0)).length() < 1e-6, "{d:?}");
        assert!(triangle_dpdu(dp, [1.0, 1.0], [2.0, 2.0]).is_none());
    }

    #[test]
    fn frame_is_orthonormal_right_handed_and_along_dpdu() {
        let n = vec3(0.0, 0.6, 0.8);
        let f = shading_frame(n, n, Some(vec3(1.0, 1.0, 0.0)));
        assert!((f.s.length() - 1.0).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5);
        assert!((f.s.cross(f.t) - n).length() < 1e-5);
        assert!(f.s.dot(vec3(1.0, 1.0, 0.0)) > 0.5);
        // dp/du along the normal is no tangent: any frame around n will do.
        let f = shading_frame(vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), Some(vec3(0.0, 0.0, 3.0)));
        assert!(f.s.z.abs() < 1e-6 && (f.s.length() - 1.0).abs() < 1e-5);
    }
}
