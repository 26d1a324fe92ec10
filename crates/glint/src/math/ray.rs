use super::Vec3;

/// A ray `origin + t * dir` for `t` in `[t_min, t_max]`. `dir` need not be unit length
/// (instances trace object-space rays whose `t` matches the world-space ray's).
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub t_min: f32,
    pub t_max: f32,
}

impl Ray {
    #[inline(always)]
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        Ray { origin, dir, t_min: 0.0, t_max: f32::INFINITY }
    }
    #[inline(always)]
    pub fn segment(origin: Vec3, dir: Vec3, t_max: f32) -> Ray {
        Ray { origin, dir, t_min: 0.0, t_max }
    }
    #[inline(always)]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Moves a ray origin off a surface along the geometric normal, by an amount that scales
/// with the magnitude of the coordinates (float error grows with them), towards the side
/// `dir` leaves through. This is how glint avoids self-intersection without a global epsilon.
#[inline]
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let scale = 1e-4 * (1.0 + p.abs().max_component());
    let n = if ng.dot(dir) < 0.0 { -ng } else { ng };
    p + n * scale
}
