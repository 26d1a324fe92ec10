//! Affine transforms as 4x4 matrices with their inverse kept alongside.

use super::{vec3, Aabb, Vec3};

/// Row-major 4x4 matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat4(pub [[f64; 4]; 4]);

impl Mat4 {
    pub const IDENTITY: Mat4 =
        Mat4([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]);

    pub fn mul(&self, o: &Mat4) -> Mat4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..4).map(|k| self.0[i][k] * o.0[k][j]).sum();
            }
        }
        Mat4(r)
    }

    pub fn transpose(&self) -> Mat4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.0[j][i];
            }
        }
        Mat4(r)
    }

    /// Whether every entry is finite (no NaN, no infinity).
    pub fn is_finite(&self) -> bool {
        self.0.iter().flatten().all(|v| v.is_finite())
    }

    /// Inverse by Gauss-Jordan elimination with partial pivoting; `None` when singular or
    /// when the input or the result is not finite (a NaN pivot would otherwise pass the
    /// singularity test, since every comparison with NaN is false).
    pub fn inverse(&self) -> Option<Mat4> {
        if !self.is_finite() {
            return None;
        }
        let mut a = self.0;
        let mut inv = Mat4::IDENTITY.0;
        for c in 0..4 {
            let pivot = (c..4).max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))?;
            // A NaN pivot (inf - inf during elimination) counts as singular too.
            let pivot_size = a[pivot][c].abs();
            if pivot_size.is_nan() || pivot_size < 1e-300 {
                return None;
            }
            a.swap(c, pivot);
            inv.swap(c, pivot);
            let p = a[c][c];
            for j in 0..4 {
                a[c][j] /= p;
                inv[c][j] /= p;
            }
            for r in 0..4 {
                if r != c {
                    let f = a[r][c];
                    for j in 0..4 {
                        a[r][j] -= f * a[c][j];
                        inv[r][j] -= f * inv[c][j];
                    }
                }
            }
        }
        let inv = Mat4(inv);
        inv.is_finite().then_some(inv)
    }
}

/// An invertible affine transform (object to world) with its cached inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub m: Mat4,
    pub inv: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform { m: Mat4::IDENTITY, inv: Mat4::IDENTITY };

    /// `None` when the matrix is singular (a zero scale, say).
    pub fn from_matrix(m: Mat4) -> Option<Transform> {
        Some(Transform { m, inv: m.inverse()? })
    }
    pub fn translate(t: Vec3) -> Transform {
        let mut m = Mat4::IDENTITY;
        m.0[0][3] = t.x as f64;
        m.0[1][3] = t.y as f64;
        m.0[2][3] = t.z as f64;
        let mut inv = Mat4::IDENTITY;
        inv.0[0][3] = -t.x as f64;
        inv.0[1][3] = -t.y as f64;
        inv.0[2][3] = -t.z as f64;
        Transform { m, inv }
    }
    pub fn scale(s: Vec3) -> Option<Transform> {
        let mut m = Mat4::IDENTITY;
        m.0[0][0] = s.x as f64;
        m.0[1][1] = s.y as f64;
        m.0[2][2] = s.z as f64;
        Transform::from_matrix(m)
    }
    /// Rotation by `degrees` about `axis` (right-handed, as pbrt and Mitsuba).
    pub fn rotate(axis: Vec3, degrees: f32) -> Transform {
        let a = axis.normalize();
        let (x, y, z) = (a.x as f64, a.y as f64, a.z as f64);
        let (s, c) = (degrees as f64).to_radians().sin_cos();
        let m = Mat4([
            [x * x + (1.0 - x * x) * c, x * y * (1.0 - c) - z * s, x * z * (1.0 - c) + y * s, 0.0],
            [x * y * (1.0 - c) + z * s, y * y + (1.0 - y * y) * c, y * z * (1.0 - c) - x * s, 0.0],
            [x * z * (1.0 - c) - y * s, y * z * (1.0 - c) + x * s, z * z + (1.0 - z * z) * c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform { m, inv: m.transpose() }
    }
    /// Camera-to-world transform that places the origin at `eye` looking at `target`, with
    /// +z forward, +y up and +x to the left (Mitsuba's convention, so that XML scenes match).
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Option<Transform> {
        let dir = (target - eye).normalize();
        let left = up.normalize().cross(dir);
        if left.length() < 1e-8 || !dir.is_finite() {
            return None;
        }
        let left = left.normalize();
        let new_up = dir.cross(left);
        let m = Mat4([
            [left.x as f64, new_up.x as f64, dir.x as f64, eye.x as f64],
            [left.y as f64, new_up.y as f64, dir.y as f64, eye.y as f64],
            [left.z as f64, new_up.z as f64, dir.z as f64, eye.z as f64],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform::from_matrix(m)
    }
    /// `self * other`: applies `other` first.
    pub fn then_after(&self, other: &Transform) -> Transform {
        Transform { m: self.m.mul(&other.m), inv: other.inv.mul(&self.inv) }
    }
    pub fn inverse(&self) -> Transform {
        Transform { m: self.inv, inv: self.m }
    }
    /// Whether the matrix and its inverse are finite: what a scene builder should require
    /// before letting a transform near the acceleration structures.
    pub fn is_finite(&self) -> bool {
        self.m.is_finite() && self.inv.is_finite()
    }
    pub fn is_identity(&self) -> bool {
        self.m == Mat4::IDENTITY
    }
    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        xform_point(&self.m, p)
    }
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        xform_vector(&self.m, v)
    }
    /// Normals transform by the inverse transpose.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        let m = &self.inv.0;
        vec3(
            (m[0][0] * n.x as f64 + m[1][0] * n.y as f64 + m[2][0] * n.z as f64) as f32,
            (m[0][1] * n.x as f64 + m[1][1] * n.y as f64 + m[2][1] * n.z as f64) as f32,
            (m[0][2] * n.x as f64 + m[1][2] * n.y as f64 + m[2][2] * n.z as f64) as f32,
        )
    }
    pub fn inv_point(&self, p: Vec3) -> Vec3 {
        xform_point(&self.inv, p)
    }
    pub fn inv_vector(&self, v: Vec3) -> Vec3 {
        xform_vector(&self.inv, v)
    }
    pub fn aabb(&self, b: &Aabb) -> Aabb {
        let mut out = Aabb::EMPTY;
        for i in 0..8 {
            let c = vec3(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            out = out.grow(self.point(c));
        }
        out
    }
    /// True when the transform flips orientation (negative determinant).
    pub fn swaps_handedness(&self) -> bool {
        let m = &self.m.0;
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        det < 0.0
    }
}

#[inline]
fn xform_point(m: &Mat4, p: Vec3) -> Vec3 {
    let m = &m.0;
    let (x, y, z) = (p.x as f64, p.y as f64, p.z as f64);
    let w = m[3][0] * x + m[3][1] * y + m[3][2] * z + m[3][3];
    vec3(
        ((m[0][0] * x + m[0][1] * y + m[0][2] * z + m[0][3]) / w) as f32,
        ((m[1][0] * x + m[1][1] * y + m[1][2] * z + m[1][3]) / w) as f32,
        ((m[2][0] * x + m[2][1] * y + m[2][2] * z + m[2][3]) / w) as f32,
    )
}

#[inline]
fn xform_vector(m: &Mat4, v: Vec3) -> Vec3 {
    let m = &m.0;
    let (x, y, z) = (v.x as f64, v.y as f64, v.z as f64);
    vec3(
        (m[0][0] * x + m[0][1] * y + m[0][2] * z) as f32,
        (m[1][0] * x + m[1][1] * y + m[1][2] * z) as f32,
        (m[2][0] * x + m[2][1] * y + m[2][2] * z) as f32,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_round_trips() {
        let t = Transform::translate(vec3(1.0, 2.0, 3.0))
            .then_after(&Transform::rotate(vec3(1.0, 1.0, 0.0), 33.0))
            .then_after(&Transform::scale(vec3(2.0, 0.5, 3.0)).unwrap());
        let p = vec3(0.3, -0.7, 2.0);
        let q = t.inv_point(t.point(p));
        assert!((p - q).length() < 1e-5);
        let inv = t.m.inverse().unwrap();
        let id = t.m.mul(&inv);
        for i in 0..4 {
            for j in 0..4 {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((id.0[i][j] - e).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn normals_stay_perpendicular_under_nonuniform_scale() {
        let t = Transform::scale(vec3(3.0, 1.0, 0.2)).unwrap();
        let tangent = vec3(1.0, 1.0, 0.0);
        let n = vec3(1.0, -1.0, 0.0);
        assert!(t.vector(tangent).dot(t.normal(n)).abs() < 1e-6);
    }

    #[test]
    fn non_finite_matrices_are_not_invertible() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for (i, j) in [(0, 0), (1, 2), (2, 3), (3, 3)] {
                let mut m = Mat4::IDENTITY;
                m.0[i][j] = bad;
                assert!(m.inverse().is_none(), "entry ({i}, {j}) = {bad} was inverted");
                assert!(Transform::from_matrix(m).is_none());
            }
        }
    }

    #[test]
    fn an_inverse_that_overflows_is_rejected() {
        // Finite, with a pivot above the singularity threshold, but the inverse's
        // translation is -1e10 / 1e-300, which overflows f64.
        let m = Mat4([[1e-300, 0.0, 0.0, 1e10], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]);
        assert!(m.inverse().is_none());
        let ok = Mat4([[1e-300, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]);
        assert!(ok.inverse().is_some_and(|i| i.is_finite()));
    }

    #[test]
    fn transform_finiteness_checks_both_matrices() {
        assert!(Transform::IDENTITY.is_finite());
        assert!(Transform::translate(vec3(1.0, 2.0, 3.0)).is_finite());
        assert!(!Transform::translate(vec3(f32::INFINITY, 0.0, 0.0)).is_finite());
        assert!(!Transform::translate(vec3(0.0, f32::NAN, 0.0)).is_finite());
        assert!(Transform::look_at(Vec3::ZERO, vec3(0.0, 0.0, 1.0), vec3(f32::INFINITY, 1.0, 0.0)).is_none());
    }

    #[test]
    fn singular_scale_is_rejected() {
        assert!(Transform::scale(vec3(1.0, 0.0, 1.0)).is_none());
    }
}
