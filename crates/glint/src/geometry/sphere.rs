//! Analytic spheres, stored in world space (a sphere's transform is folded into its centre,
//! radius and axes when the scene is built; a non-uniform scale is rejected there).

use crate::math::{Aabb, Ray, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    /// World directions of the sphere's own x, y and z axes (unit length): its uv
    /// parameterisation (Mitsuba's, about the local z axis) turns with its transform.
    pub axes: [Vec3; 3],
}

impl Sphere {
    /// A sphere with the world's axes.
    pub fn new(center: Vec3, radius: f32) -> Sphere {
        Sphere { center, radius, axes: [Vec3::X, Vec3::Y, Vec3::Z] }
    }

    /// The world direction `n` in the sphere's own axes.
    #[inline]
    pub fn to_local(&self, n: Vec3) -> Vec3 {
        Vec3 { x: n.dot(self.axes[0]), y: n.dot(self.axes[1]), z: n.dot(self.axes[2]) }
    }

    /// A direction in the sphere's own axes, in the world.
    #[inline]
    pub fn to_world(&self, l: Vec3) -> Vec3 {
        self.axes[0] * l.x + self.axes[1] * l.y + self.axes[2] * l.z
    }

    /// Mitsuba's uv of the point with unit outward normal `n` (world): u the azimuth over 2π
    /// about the sphere's own z axis from its +x, v the polar angle over π from its +z.
    pub fn uv(&self, n: Vec3) -> [f32; 2] {
        let local = self.to_local(n);
        let theta = local.z.clamp(-1.0, 1.0).acos();
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * std::f32::consts::PI;
        }
        [phi / (2.0 * std::f32::consts::PI), theta / std::f32::consts::PI]
    }

    pub fn bounds(&self) -> Aabb {
        Aabb { min: self.center - Vec3::splat(self.radius), max: self.center + Vec3::splat(self.radius) }
    }

    /// Nearest root in `(t_min, t_max)`. Uses the numerically stable form of the quadratic
    /// (the `b` term computed from the vector rejection, as in Ray Tracing Gems ch. 7).
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let d = ray.dir;
        let f = ray.origin - self.center;
        let a = d.dot(d);
        let b = -f.dot(d);
        // discriminant / 4a computed as r^2 - |f - (f.d/a) d|^2 to avoid cancellation.
        let l = f + d * (b / a);
        let disc = a * (self.radius * self.radius - l.dot(l));
        if disc < 0.0 {
            return None;
        }
        let q = b + b.signum() * disc.sqrt();
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, (f.dot(f) - self.radius * self.radius) / q) };
        let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        if near > ray.t_min && near < ray.t_max {
            Some(near)
        } else if far > ray.t_min && far < ray.t_max {
            Some(far)
        } else {
            None
        }
    }

    pub fn area(&self) -> f32 {
        4.0 * std::f32::consts::PI * self.radius * self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    #[test]
    fn hits_front_then_back_from_inside() {
        let s = Sphere::new(vec3(0.0, 0.0, 10.0), 2.0);
        let r = Ray::new(Vec3::ZERO, vec3(0.0, 0.0, 1.0));
        assert!((s.intersect(&r).unwrap() - 8.0).abs() < 1e-5);
        let inside = Ray::new(vec3(0.0, 0.0, 10.0), vec3(0.0, 0.0, 2.0));
        assert!((inside.at(s.intersect(&inside).unwrap()).z - 12.0).abs() < 1e-5);
    }

    #[test]
    fn far_sphere_is_still_accurate() {
        let s = Sphere::new(vec3(0.0, 0.0, 1.0e4), 1.0);
        let r = Ray::new(Vec3::ZERO, vec3(0.0, 0.0, 1.0));
        assert!((s.intersect(&r).unwrap() - 9999.0).abs() < 1e-2);
    }
}
