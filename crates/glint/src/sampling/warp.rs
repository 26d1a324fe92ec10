//! Maps from the unit square to directions and points, each with its density.
//! Densities are in solid angle for directions and in area for points.

use crate::math::{vec3, Vec3, INV_PI, PI};

/// Cosine-weighted hemisphere around +z (Malley's method on a concentric disk).
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
    vec3(d[0], d[1], z)
}

pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * INV_PI
}

/// Shirley-Chiu concentric map from the square to the unit disk.
pub fn concentric_disk(u: [f32; 2]) -> [f32; 2] {
    let a = 2.0 * u[0] - 1.0;
    let b = 2.0 * u[1] - 1.0;
    if a == 0.0 && b == 0.0 {
        return [0.0, 0.0];
    }
    let (r, phi) = if a.abs() > b.abs() { (a, PI / 4.0 * (b / a)) } else { (b, PI / 2.0 - PI / 4.0 * (a / b)) };
    [r * phi.cos(), r * phi.sin()]
}

pub fn uniform_sphere(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    vec3(r * phi.cos(), r * phi.sin(), z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

pub fn uniform_hemisphere(u: [f32; 2]) -> Vec3 {
    let z = u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    vec3(r * phi.cos(), r * phi.sin(), z)
}

/// Directions in the cone of half-angle `acos(cos_max)` around +z, uniform in solid angle.
pub fn uniform_cone(u: [f32; 2], cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u[0] * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    vec3(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// Barycentrics `(b1, b2)` uniform over a triangle (Heitz 2019's low-distortion map).
pub fn uniform_triangle(u: [f32; 2]) -> [f32; 2] {
    let (b0, b1);
    if u[0] < u[1] {
        b0 = u[0] / 2.0;
        b1 = u[1] - b0;
    } else {
        b1 = u[1] / 2.0;
        b0 = u[0] - b1;
    }
    [b0, b1]
}
