//! Importance sampling of a bitmap radiance over an area light's uv parameterisation.
//!
//! The texture is read bilinearly between texel centres (as `Bitmap::eval` reads it, wrapping
//! at the edges), so its luminance is bilinear over each *cell* between four texel centres.
//! A cell is chosen by a [`Distribution2d`] over the cells' mean luminance times a per-row
//! weight (the mean area Jacobian over the row where it varies: sin θ on a sphere), and the
//! point within it by the bilinear patch itself. The density in uv is then exactly the
//! filtered luminance times the row weight, normalised: a light of a few bright texels is
//! sampled where it is bright, bleed of the filter included. The shape maps uv to its
//! surface and divides by its area Jacobian; `pdf` gives the same density for any uv, so a
//! BSDF-sampled ray that hits the light is weighed by what light sampling would have done.

use crate::materials::Texture;
use crate::math::{Vec3, PI};
use crate::sampling::Distribution2d;

/// How the area per unit of uv varies over the parameterisation, for the rows' weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UvJacobian {
    /// Constant (rectangles, cylinders).
    Uniform,
    /// Proportional to sin(π v) (spheres: v is θ / π).
    SinPiV,
}

/// The texel distribution of one bitmap radiance (see the module doc).
#[derive(Clone, Debug)]
pub struct TexelImportance {
    width: usize,
    height: usize,
    /// Texel luminance, clamped at zero, row by row.
    lum: Vec<f32>,
    /// Each cell row's weight (its mean Jacobian, up to a constant).
    row_weight: Vec<f32>,
    cells: Distribution2d,
    /// Cells per unit of uv over the sum of the cells' weights: the density in uv is this
    /// times a cell's row weight times the bilinear luminance.
    norm: f32,
}

impl TexelImportance {
    /// The distribution of `radiance` where it is a bitmap read with the uvs as they are
    /// (scale 1, offset 0: the texture covers the parameterisation once); `None` otherwise,
    /// or when it is black.
    pub fn new(radiance: &Texture, jacobian: UvJacobian) -> Option<TexelImportance> {
        let Texture::Bitmap { image, uv_scale, uv_offset } = radiance else { return None };
        if *uv_scale != [1.0, 1.0] || *uv_offset != [0.0, 0.0] {
            return None;
        }
        let (width, height) = (image.width, image.height);
        if width == 0 || height == 0 {
            return None;
        }
        let lum: Vec<f32> = image.pixels.iter().map(|p| p.luminance().max(0.0)).collect();
        let row_weight: Vec<f32> = (0..height).map(|j| row_weight(jacobian, j, height)).collect();
        let mut weights = Vec::with_capacity(width * height);
        let mut total = 0.0f64;
        for (j, rw) in row_weight.iter().enumerate() {
            for i in 0..width {
                let [a, b, c, d] = corners(&lum, width, height, i, j);
                let w = 0.25 * (a + b + c + d) * rw;
                total += w as f64;
                weights.push(w);
            }
        }
        let cells = Distribution2d::new(&weights, width, height)?;
        let norm = ((width * height) as f64 / total) as f32;
        Some(TexelImportance { width, height, lum, row_weight, cells, norm })
    }

    /// A uv in [0, 1)² and its density in uv (per unit of u times v). `None` on the measure
    /// zero set where the density vanishes.
    pub fn sample(&self, u: [f32; 2]) -> Option<([f32; 2], f32)> {
        let s = self.cells.sample(u);
        let [a, b, c, d] = corners(&self.lum, self.width, self.height, s.x, s.y);
        let x = sample_linear(s.remapped[0], a + c, b + d);
        let y = sample_linear(s.remapped[1], lerp(x, a, b), lerp(x, c, d));
        let wrap = |k: usize, f: f32, n: usize| {
            let t = (k as f32 + 0.5 + f) / n as f32;
            let t = if t >= 1.0 { t - 1.0 } else { t };
            t.clamp(0.0, 0.999_999_94)
        };
        let uv = [wrap(s.x, x, self.width), wrap(s.y, y, self.height)];
        let pdf = self.norm * self.row_weight[s.y] * bilinear([a, b, c, d], x, y);
        (pdf > 0.0).then_some((uv, pdf))
    }

    /// The density in uv of [`TexelImportance::sample`] at `uv`.
    pub fn pdf(&self, uv: [f32; 2]) -> f32 {
        let cell = |t: f32, n: usize| {
            let x = t * n as f32 - 0.5;
            let f = x.floor();
            ((f as i64).rem_euclid(n as i64) as usize, (x - f).clamp(0.0, 1.0))
        };
        let ((i, x), (j, y)) = (cell(uv[0], self.width), cell(uv[1], self.height));
        self.norm * self.row_weight[j] * bilinear(corners(&self.lum, self.width, self.height, i, j), x, y)
    }
}

/// The luminance at the four texel centres around cell (i, j): (i, j), (i+1, j), (i, j+1),
/// (i+1, j+1), wrapping.
#[inline]
fn corners(lum: &[f32], w: usize, h: usize, i: usize, j: usize) -> [f32; 4] {
    let (i1, j1) = ((i + 1) % w, (j + 1) % h);
    [lum[j * w + i], lum[j * w + i1], lum[j1 * w + i], lum[j1 * w + i1]]
}

#[inline]
fn lerp(t: f32, a: f32, b: f32) -> f32 {
    (1.0 - t) * a + t * b
}

#[inline]
fn bilinear([a, b, c, d]: [f32; 4], x: f32, y: f32) -> f32 {
    lerp(y, lerp(x, a, b), lerp(x, c, d))
}

/// A point of [0, 1) with density proportional to (1 - x) a + x b (a, b ≥ 0), by inverting
/// its quadratic CDF in the form that does not cancel when a ≈ b.
#[inline]
fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if !(a + b > 0.0) {
        return u;
    }
    let x = u * (a + b) / (a + lerp(u, a * a, b * b).sqrt());
    x.clamp(0.0, 0.999_999_94)
}

/// The mean Jacobian over cell row `j`, which spans v from (j + 0.5)/h to (j + 1.5)/h (the
/// last row wraps past v = 1 to the first texel centre).
fn row_weight(jacobian: UvJacobian, j: usize, h: usize) -> f32 {
    match jacobian {
        UvJacobian::Uniform => 1.0,
        UvJacobian::SinPiV => {
            // ∫ sin(π v) dv from 0 to v, for v in [0, 1].
            let integral = |v: f64| (1.0 - (std::f64::consts::PI * v).cos()) / std::f64::consts::PI;
            let (a, b) = ((j as f64 + 0.5) / h as f64, (j as f64 + 1.5) / h as f64);
            let area =
                if b <= 1.0 { integral(b) - integral(a) } else { integral(1.0) - integral(a) + integral(b - 1.0) };
            (area * h as f64) as f32
        }
    }
}

/// A rectangle light whose uvs are affine over it and cover the unit square once (as the
/// `rectangle` shape's and a quad's do): the map from uv to the surface and back.
#[derive(Clone, Copy, Debug)]
pub struct UvRectangle {
    pub origin: Vec3,
    pub du: Vec3,
    pub dv: Vec3,
    pub area: f32,
}

impl UvRectangle {
    pub fn point(&self, uv: [f32; 2]) -> Vec3 {
        self.origin + self.du * uv[0] + self.dv * uv[1]
    }

    /// The uv of a point on the rectangle (the edges are perpendicular).
    pub fn uv(&self, q: Vec3) -> [f32; 2] {
        let d = q - self.origin;
        [d.dot(self.du) / self.du.length_squared(), d.dot(self.dv) / self.dv.length_squared()]
    }
}

/// A textured rectangle's importance: the texels and where they lie.
#[derive(Clone, Debug)]
pub struct RectangleImportance {
    pub texels: TexelImportance,
    pub map: UvRectangle,
}

/// The area Jacobian of the sphere's uv over r² sin θ: dA = 2π² r² sin θ du dv.
pub const SPHERE_UV_JACOBIAN: f32 = 2.0 * PI * PI;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::Bitmap;
    use crate::math::Rgb;
    use std::sync::Arc;

    fn texture(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> Texture {
        let pixels = (0..w * h).map(|k| Rgb::splat(f(k % w, k / w))).collect();
        Texture::Bitmap {
            image: Arc::new(Bitmap { width: w, height: h, pixels }),
            uv_scale: [1.0; 2],
            uv_offset: [0.0; 2],
        }
    }

    #[test]
    fn density_is_the_filtered_luminance_normalised() {
        // Uniform Jacobian: the density in uv is the texture's luminance over its mean.
        let t = texture(5, 3, |x, y| if (x, y) == (1, 2) { 40.0 } else { 0.1 + 0.2 * x as f32 });
        let imp = TexelImportance::new(&t, UvJacobian::Uniform).unwrap();
        let n = 300;
        let mut integral = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let uv = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
                let pdf = imp.pdf(uv);
                let mean = imp.norm.recip();
                let expected = t.eval(uv).luminance() / mean;
                assert!((pdf / expected - 1.0).abs() < 1e-3, "{uv:?}: {pdf} vs {expected}");
                integral += pdf as f64 / (n * n) as f64;
            }
        }
        assert!((integral - 1.0).abs() < 1e-3, "{integral}");
    }

    #[test]
    fn samples_report_the_density_pdf_gives() {
        let t = texture(4, 6, |x, y| ((x * 7 + y * 3) % 5) as f32 + if y == 0 { 0.0 } else { 0.05 });
        for jac in [UvJacobian::Uniform, UvJacobian::SinPiV] {
            let imp = TexelImportance::new(&t, jac).unwrap();
            let mut rng = crate::sampling::Rng::new(7, 1);
            for _ in 0..20_000 {
                let Some((uv, pdf)) = imp.sample([rng.next_f32(), rng.next_f32()]) else { continue };
                assert!((0.0..1.0).contains(&uv[0]) && (0.0..1.0).contains(&uv[1]), "{uv:?}");
                assert!((imp.pdf(uv) / pdf - 1.0).abs() < 1e-3, "{jac:?} {uv:?}: {} vs {pdf}", imp.pdf(uv));
            }
        }
    }

    #[test]
    fn sphere_rows_weigh_the_area_they_cover() {
        // The weights of all rows average to the mean of sin(π v) over [0, 1], 2/π.
        let h = 7;
        let mean = (0..h).map(|j| row_weight(UvJacobian::SinPiV, j, h)).sum::<f32>() / h as f32;
        assert!((mean - 2.0 / PI).abs() < 1e-5, "{mean}");
        // The last row wraps across both poles, and still covers some area.
        assert!(row_weight(UvJacobian::SinPiV, h - 1, h) > 0.0);
    }

    #[test]
    fn only_plain_bitmaps_are_importance_sampled() {
        assert!(TexelImportance::new(&Texture::Constant(Rgb::WHITE), UvJacobian::Uniform).is_none());
        let black = texture(2, 2, |_, _| 0.0);
        assert!(TexelImportance::new(&black, UvJacobian::Uniform).is_none());
        let Texture::Bitmap { image, .. } = texture(2, 2, |_, _| 1.0) else { unreachable!() };
        let tiled = Texture::Bitmap { image, uv_scale: [2.0, 1.0], uv_offset: [0.0; 2] };
        assert!(TexelImportance::new(&tiled, UvJacobian::Uniform).is_none());
    }
}
