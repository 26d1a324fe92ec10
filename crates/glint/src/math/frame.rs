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
    #[inline(always)]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        vec3(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
    #[inline(always)]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}
