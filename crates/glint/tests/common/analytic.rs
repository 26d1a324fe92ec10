//! Closed-form irradiance, for checking rendered direct lighting.

use glint::math::Vec3;

fn v64(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

/// Irradiance at `x` (unit normal `n`) from a planar polygon of uniform radiance `le`
/// lying wholly above x's horizon: Lambert's contour formula,
/// E = le/2 · |Σ_k angle(u_k, u_k+1) · n · unit(u_k × u_k+1)| with u_k the unit vectors to the
/// vertices.
pub fn polygon_irradiance(x: Vec3, n: Vec3, vertices: &[Vec3], le: f64) -> f64 {
    let (x, n) = (v64(x), v64(n));
    let u: Vec<[f64; 3]> = vertices.iter().map(|&v| normalize(sub(v64(v), x))).collect();
    let mut sum = 0.0;
    for k in 0..u.len() {
        let (a, b) = (u[k], u[(k + 1) % u.len()]);
        let angle = dot(a, b).clamp(-1.0, 1.0).acos();
        sum += angle * dot(n, normalize(cross(a, b)));
    }
    0.5 * le * sum.abs()
}

/// Irradiance under the centre of a disk of radius `r` at height `h`, facing it.
pub fn disk_irradiance(le: f64, r: f64, h: f64) -> f64 {
    std::f64::consts::PI * le * r * r / (h * h + r * r)
}

/// Irradiance at distance `d` from the centre of a sphere of radius `r`, facing it.
pub fn sphere_irradiance(le: f64, r: f64, d: f64) -> f64 {
    std::f64::consts::PI * le * (r / d).powi(2)
}
