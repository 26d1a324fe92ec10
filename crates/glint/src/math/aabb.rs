use super::{Ray, Vec3};

/// Axis-aligned bounding box. The empty box has `min = +inf`, `max = -inf` so that union
/// with it is the identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    pub fn from_points(points: &[Vec3]) -> Aabb {
        points.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p))
    }
    #[inline(always)]
    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }
    #[inline(always)]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    #[inline(always)]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }
    #[inline(always)]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    /// Surface area; 0 for the empty box.
    #[inline(always)]
    pub fn area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
    /// Slab test. Returns the entry distance when the ray overlaps the box within its interval.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, inv_dir: Vec3) -> Option<f32> {
        let t0 = (self.min - ray.origin) * inv_dir;
        let t1 = (self.max - ray.origin) * inv_dir;
        // 0 * inf = NaN when the ray runs exactly in the plane of a face (a zero direction
        // component): the ray is then inside that slab's closed interval, so the axis must not
        // constrain the interval (f32::min/max would turn NaN into a spurious bound).
        let lo = |a: f32, b: f32| if a.is_nan() || b.is_nan() { f32::NEG_INFINITY } else { a.min(b) };
        let hi = |a: f32, b: f32| if a.is_nan() || b.is_nan() { f32::INFINITY } else { a.max(b) };
        let tmin = lo(t0.x, t1.x).max(lo(t0.y, t1.y)).max(lo(t0.z, t1.z)).max(ray.t_min);
        let tmax = hi(t0.x, t1.x).min(hi(t0.y, t1.y)).min(hi(t0.z, t1.z)).min(ray.t_max);
        // Scale tmax up by 2 ulp-ish so that boxes that are flat in one axis and rays that
        // touch them exactly are not lost to rounding (Ize 2013, "Robust BVH ray traversal").
        #[allow(clippy::excessive_precision)] // as written in the paper; 1 + 2 ulp
        let widen = 1.000_000_24f32;
        if tmin <= tmax * widen {
            Some(tmin)
        } else {
            None
        }
    }
}
