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
    // phi = t in the wedges around the x axis (r = a), pi/2 - t around the y axis (r = b),
    // with |t| <= pi/4, where short series give cos t and sin t to f32 precision. Written
    // with selects, not branches: which wedge a sample falls in is a coin toss.
    let around_y = a.abs() <= b.abs();
    let (r, q) = if around_y { (b, a) } else { (a, b) };
    if r == 0.0 {
        return [0.0, 0.0]; // the centre (rare: a branch the CPU predicts)
    }
    let (sin_t, cos_t) = sin_cos_quarter(PI / 4.0 * (q / r));
    let (x, y) = if around_y { (sin_t, cos_t) } else { (cos_t, sin_t) };
    [r * x, r * y]
}

/// sin t and cos t for |t| <= pi/4, by their Taylor series to t^9 and t^10: the first terms
/// left out are below 2e-9 there, under half an f32 ulp of the results.
#[inline]
fn sin_cos_quarter(t: f32) -> (f32, f32) {
    let t2 = t * t;
    let sin = t * (1.0 + t2 * (-1.0 / 6.0 + t2 * (1.0 / 120.0 + t2 * (-1.0 / 5040.0 + t2 * (1.0 / 362_880.0)))));
    let cos =
        1.0 + t2 * (-0.5 + t2 * (1.0 / 24.0 + t2 * (-1.0 / 720.0 + t2 * (1.0 / 40_320.0 + t2 * (-1.0 / 3_628_800.0)))));
    (sin, cos)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_sin_cos_match_f64_to_f32_precision() {
        let quarter = std::f64::consts::FRAC_PI_4;
        for i in 0..=200_000 {
            let t = (-quarter + 2.0 * quarter * i as f64 / 200_000.0) as f32;
            let (s, c) = sin_cos_quarter(t);
            let (s64, c64) = (t as f64).sin_cos();
            assert!((s as f64 - s64).abs() <= 1.2e-7, "sin {t}: {s} against {s64}");
            assert!((c as f64 - c64).abs() <= 1.2e-7, "cos {t}: {c} against {c64}");
        }
    }

    #[test]
    fn concentric_disk_matches_the_polar_map_and_stays_in_the_disk() {
        for i in 0..=300 {
            for j in 0..=300 {
                let u = [i as f32 / 300.0, j as f32 / 300.0];
                let d = concentric_disk(u);
                let (a, b) = (2.0 * u[0] as f64 - 1.0, 2.0 * u[1] as f64 - 1.0);
                let (r, phi) = if a == 0.0 && b == 0.0 {
                    (0.0, 0.0)
                } else if a.abs() > b.abs() {
                    (a, std::f64::consts::FRAC_PI_4 * (b / a))
                } else {
                    (b, std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (a / b))
                };
                let want = [r * phi.cos(), r * phi.sin()];
                assert!((d[0] as f64 - want[0]).abs() < 1e-6 && (d[1] as f64 - want[1]).abs() < 1e-6, "{u:?}");
                assert!(d[0] * d[0] + d[1] * d[1] <= 1.0 + 1e-6, "{u:?} leaves the disk");
            }
        }
    }
}
