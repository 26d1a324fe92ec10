//! Analytic open cylinders (Mitsuba's `cylinder`): the unit tube x² + y² = 1, 0 ≤ z ≤ 1, in
//! object space, placed by an affine object-to-world transform that the radius, the end
//! points and the shape's `to_world` are folded into. Rays are intersected in object space
//! (in f64: a secondary ray starts a hair off the surface, and its near root must not
//! vanish in rounding), so any invertible transform is exact; Mitsuba warns about shear and
//! non-uniform scale but traces them the same way.

use crate::math::{vec3, Aabb, Frame, Ray, Transform, Vec3, PI};

#[derive(Clone, Copy, Debug)]
pub struct Cylinder {
    /// Unit cylinder to world.
    pub to_world: Transform,
}

/// What shading needs about a point of the cylinder.
#[derive(Clone, Copy, Debug)]
pub struct CylinderPoint {
    pub p: Vec3,
    /// Unit, outward (before `flip_normals`): ∂p/∂u × ∂p/∂v, as Mitsuba orients it.
    pub n: Vec3,
    /// Mitsuba's: u the azimuth over 2π from the local +x towards +y, v the height 0 to 1.
    pub uv: [f32; 2],
    /// Position derivatives along u and v (world space), as Mitsuba's.
    pub dpdu: Vec3,
    pub dpdv: Vec3,
}

impl Cylinder {
    /// The cylinder of Mitsuba's `p0`, `p1` and `radius`, placed by `to_world` (applied
    /// after them). `None` when the end points coincide or the radius is not positive.
    pub fn new(p0: Vec3, p1: Vec3, radius: f32, to_world: &Transform) -> Option<Cylinder> {
        let d = p1 - p0;
        let length = d.length();
        if !(length > 0.0 && length.is_finite() && radius > 0.0 && radius.is_finite()) {
            return None;
        }
        // Mitsuba's frame around the axis (the Duff et al. basis): u = 0 lies along its s.
        let f = Frame::from_normal(d / length);
        let m = crate::math::Mat4([
            [(f.s.x * radius) as f64, (f.t.x * radius) as f64, (f.n.x * length) as f64, p0.x as f64],
            [(f.s.y * radius) as f64, (f.t.y * radius) as f64, (f.n.y * length) as f64, p0.y as f64],
            [(f.s.z * radius) as f64, (f.t.z * radius) as f64, (f.n.z * length) as f64, p0.z as f64],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let local = Transform::from_matrix(m)?;
        let to_world = to_world.then_after(&local);
        to_world.is_finite().then_some(Cylinder { to_world })
    }

    /// The box around the two end circles (enough to bound the tube), as Mitsuba's.
    pub fn bounds(&self) -> Aabb {
        let (e1, e2) = (self.to_world.vector(Vec3::X), self.to_world.vector(Vec3::Y));
        let half = vec3(e1.x.hypot(e2.x), e1.y.hypot(e2.y), e1.z.hypot(e2.z));
        let (p0, p1) = (self.to_world.point(Vec3::ZERO), self.to_world.point(Vec3::Z));
        Aabb { min: (p0 - half).min(p1 - half), max: (p0 + half).max(p1 + half) }
    }

    /// Nearest hit in `(t_min, t_max)` (the ray's `t`, whatever the length of its direction).
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let inv = &self.to_world.inv.0;
        let (o, d) = (ray.origin, ray.dir);
        let row = |r: &[f64; 4], v: Vec3, w: f64| r[0] * v.x as f64 + r[1] * v.y as f64 + r[2] * v.z as f64 + r[3] * w;
        let (ox, oy, oz) = (row(&inv[0], o, 1.0), row(&inv[1], o, 1.0), row(&inv[2], o, 1.0));
        let (dx, dy, dz) = (row(&inv[0], d, 0.0), row(&inv[1], d, 0.0), row(&inv[2], d, 0.0));
        let a = dx * dx + dy * dy;
        let b = 2.0 * (dx * ox + dy * oy);
        let c = ox * ox + oy * oy - 1.0;
        // a == 0: a ray along the axis never meets the tube; NaN fails every test below.
        if !(a > 0.0) {
            return None;
        }
        let disc = b * b - 4.0 * a * c;
        if !(disc >= 0.0) {
            return None;
        }
        // The stable form of the roots (no cancellation between b and the square root).
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
        let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        [near, far]
            .into_iter()
            .find(|&t| {
                let z = oz + dz * t;
                (0.0..=1.0).contains(&z) && (t as f32) > ray.t_min && (t as f32) < ray.t_max
            })
            .map(|t| t as f32)
    }

    /// The surface point of a hit at `t` along `ray`, re-projected onto the tube.
    pub fn point(&self, ray: &Ray, t: f32) -> CylinderPoint {
        let mut local = self.to_world.inv_point(ray.at(t));
        let r = local.x.hypot(local.y);
        if r > 0.0 {
            local.x /= r;
            local.y /= r;
        }
        self.point_at(local)
    }

    /// The uv of a point on the tube (as `point` would give it).
    pub fn uv_at(&self, q: Vec3) -> [f32; 2] {
        let local = self.to_world.inv_point(q);
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        [phi / (2.0 * PI), local.z.clamp(0.0, 1.0)]
    }

    /// The point at local coordinates `(cos φ, sin φ, z)`.
    fn point_at(&self, local: Vec3) -> CylinderPoint {
        let dp_du = self.to_world.vector(vec3(-local.y, local.x, 0.0));
        let dp_dv = self.to_world.vector(Vec3::Z);
        let mut n = dp_du.cross(dp_dv).normalize();
        if !n.is_finite() {
            n = self.to_world.normal(vec3(local.x, local.y, 0.0)).normalize();
        }
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        CylinderPoint {
            p: self.to_world.point(local),
            n,
            uv: [phi / (2.0 * PI), local.z.clamp(0.0, 1.0)],
            dpdu: dp_du * (2.0 * PI),
            dpdv: dp_dv,
        }
    }

    /// The point of parameters `u` (azimuth over 2π) and `v` (height), both in [0, 1]:
    /// uniform in `u, v` is uniform in area for a tube of circular cross-section.
    pub fn sample(&self, u: [f32; 2]) -> CylinderPoint {
        let (s, c) = (2.0 * PI * u[0]).sin_cos();
        self.point_at(vec3(c, s, u[1]))
    }

    /// Surface area: 2π r h, with r and h measured as Mitsuba does (the images of the local
    /// x and z axes).
    pub fn area(&self) -> f32 {
        2.0 * PI * self.to_world.vector(Vec3::X).length() * self.to_world.vector(Vec3::Z).length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn tilted() -> Cylinder {
        let xf = Transform::rotate(vec3(1.0, 2.0, 0.5), 37.0).then_after(&Transform::translate(vec3(0.3, -0.2, 0.1)));
        Cylinder::new(vec3(0.1, 0.2, -0.5), vec3(-0.3, 0.4, 1.2), 0.7, &xf).unwrap()
    }

    #[test]
    fn default_cylinder_is_mitsubas() {
        let c = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, &Transform::IDENTITY).unwrap();
        assert!(c.to_world.is_identity());
        let r = Ray::new(vec3(5.0, 0.0, 0.5), vec3(-1.0, 0.0, 0.0));
        let t = c.intersect(&r).unwrap();
        assert!((t - 4.0).abs() < 1e-6);
        let p = c.point(&r, t);
        assert!((p.n - Vec3::X).length() < 1e-6);
        assert!((p.uv[0] - 0.0).abs() < 1e-6 && (p.uv[1] - 0.5).abs() < 1e-6);
        // +y is a quarter turn.
        let r = Ray::new(vec3(0.0, 5.0, 0.25), vec3(0.0, -1.0, 0.0));
        let p = c.point(&r, c.intersect(&r).unwrap());
        assert!((p.uv[0] - 0.25).abs() < 1e-6 && (p.uv[1] - 0.25).abs() < 1e-6);
        assert!((c.area() - 2.0 * PI).abs() < 1e-5);
    }

    #[test]
    fn open_ends_and_inside_hits() {
        let c = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, &Transform::IDENTITY).unwrap();
        // Down the axis: no hit (open tube). Above the top, aimed sideways: no hit.
        assert!(c.intersect(&Ray::new(vec3(0.0, 0.0, 5.0), vec3(0.0, 0.0, -1.0))).is_none());
        assert!(c.intersect(&Ray::new(vec3(5.0, 0.0, 1.5), vec3(-1.0, 0.0, 0.0))).is_none());
        // From inside: the far wall, whose outward normal faces away from the ray.
        let r = Ray::new(vec3(0.0, 0.0, 0.5), vec3(1.0, 0.0, 0.0));
        let t = c.intersect(&r).unwrap();
        assert!((t - 1.0).abs() < 1e-6);
        assert!(c.point(&r, t).n.dot(r.dir) > 0.0);
        // Entering through the open top, the ray meets the inside of the wall.
        let r = Ray::new(vec3(0.0, 0.0, 2.0), vec3(1.0, 0.0, -1.0));
        let t = c.intersect(&r).unwrap();
        assert!((r.at(t).z - 1.0).abs() < 1e-5 && (r.at(t).x - 1.0).abs() < 1e-5);
        // A ray that grazes the outside of the near wall through the top misses it and
        // hits the far wall's inside.
        let r = Ray::new(vec3(-2.0, 0.0, 1.6), vec3(1.0, 0.0, -0.5));
        let t = c.intersect(&r).unwrap();
        assert!((r.at(t).x - 1.0).abs() < 1e-4, "{:?}", r.at(t));
    }

    #[test]
    fn random_hits_lie_on_the_surface_with_unit_outward_normals() {
        let c = tilted();
        let inv = c.to_world.inverse();
        let mut rng = Rng::new(7, 0);
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = vec3(rng.next_f32() * 6.0 - 3.0, rng.next_f32() * 6.0 - 3.0, rng.next_f32() * 6.0 - 3.0);
            let d = vec3(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5);
            let r = Ray::new(o, d);
            let Some(t) = c.intersect(&r) else { continue };
            hits += 1;
            let p = c.point(&r, t);
            let l = inv.point(p.p);
            assert!((l.x.hypot(l.y) - 1.0).abs() < 1e-4 && l.z > -1e-4 && l.z < 1.0 + 1e-4, "{l:?}");
            assert!((r.at(t) - p.p).length() < 1e-4);
            assert!((p.n.length() - 1.0).abs() < 1e-5);
            // Outward: the normal points away from the axis.
            let axis_p = c.to_world.point(vec3(0.0, 0.0, l.z));
            assert!(p.n.dot(p.p - axis_p) > 0.0);
            let b = c.bounds();
            assert!(p.p.x >= b.min.x - 1e-4 && p.p.y >= b.min.y - 1e-4 && p.p.z >= b.min.z - 1e-4);
            assert!(p.p.x <= b.max.x + 1e-4 && p.p.y <= b.max.y + 1e-4 && p.p.z <= b.max.z + 1e-4);
            // Nothing nearer: a shortened ray misses.
            assert!(c.intersect(&Ray { t_max: t * 0.999, ..r }).is_none() || t < 1e-3);
        }
        assert!(hits > 500, "{hits}");
    }

    #[test]
    fn bad_rays_never_panic_or_hit() {
        let c = tilted();
        for d in [vec3(f32::NAN, 0.0, 1.0), Vec3::ZERO, vec3(f32::INFINITY, 1.0, 0.0)] {
            assert!(c.intersect(&Ray::new(Vec3::ZERO, d)).is_none());
        }
        assert!(c.intersect(&Ray::new(vec3(f32::NAN, 0.0, 0.0), Vec3::X)).is_none());
        assert!(Cylinder::new(Vec3::ZERO, Vec3::ZERO, 1.0, &Transform::IDENTITY).is_none());
        assert!(Cylinder::new(Vec3::ZERO, Vec3::Z, 0.0, &Transform::IDENTITY).is_none());
        // Grazing: tangent to the wall.
        let u = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, &Transform::IDENTITY).unwrap();
        let _ = u.intersect(&Ray::new(vec3(1.0, -5.0, 0.5), Vec3::Y));
    }

    #[test]
    fn samples_lie_on_the_surface_and_area_matches_the_transform() {
        let c = tilted();
        let inv = c.to_world.inverse();
        for i in 0..100 {
            let p = c.sample([i as f32 / 100.0, (i * 37 % 100) as f32 / 100.0]);
            let l = inv.point(p.p);
            assert!((l.x.hypot(l.y) - 1.0).abs() < 1e-4);
        }
        let len = (vec3(-0.3, 0.4, 1.2) - vec3(0.1, 0.2, -0.5)).length();
        assert!((c.area() - 2.0 * PI * 0.7 * len).abs() < 1e-4);
    }
}
