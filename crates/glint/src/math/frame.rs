use super::{vec3, Vec3};

/// Orthonormal basis; local coordinates have the normal along +z.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Builds a frame around a unit normal (Duff et al. 2017, branchless ONB).
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = vec3(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }
    /// A frame around the unit normal `n` whose `s` is `tangent` made orthogonal to `n`
    /// (Gram-Schmidt), as Mitsuba builds its shading frame from dp/du; where the tangent is
    /// zero, not finite or parallel to `n`, the frame of [`Frame::from_normal`].
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Frame {
        let s = tangent - n * n.dot(tangent);
        let len2 = s.length_squared();
        if !(len2 > 1e-20 * tangent.length_squared()) || !len2.is_finite() {
            return Frame::from_normal(n);
        }
        let s = s / len2.sqrt();
        Frame { s, t: n.cross(s), n }
    }
    #[inline(always)]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        vec3(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
    #[inline(always)]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}
