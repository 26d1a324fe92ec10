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
//!
//! A disk's Jacobian grows linearly with u (the radius) and vanishes at the centre, so a
//! per-cell mean would leave the density per unit area unbounded there (and the cells of
//! the last column, which wrap from the rim to the centre, would put half their samples on
//! a sliver at the centre). For [`UvJacobian::LinearU`] the Jacobian enters the density
//! exactly instead: each cell is weighed by the integral of the bilinear luminance times u
//! over it, and the point within it is drawn from that product (a quadratic in x on each
//! piece where u is linear, sampled as a mixture of its Bernstein terms), so the density
//! per unit area is the filtered luminance itself, normalised.

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
    /// Proportional to u (disks: u is the radius, v the azimuth over 2π); entered into the
    /// density exactly (see the module doc).
    LinearU,
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
    /// times a cell's row weight (for `LinearU`: times u) times the bilinear luminance.
    norm: f32,
    jacobian: UvJacobian,
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
                let w = match jacobian {
                    // ∫∫ bilinear × u over the cell, in cell units (rw is 1).
                    UvJacobian::LinearU => {
                        u_pieces(i, width)
                            .iter()
                            .map(|p| p.integral(lerp(p.x0, a + c, b + d), lerp(p.x1, a + c, b + d)))
                            .sum::<f32>()
                            * 0.5
                    }
                    UvJacobian::Uniform | UvJacobian::SinPiV => 0.25 * (a + b + c + d) * rw,
                };
                total += w as f64;
                weights.push(w);
            }
        }
        let cells = Distribution2d::new(&weights, width, height)?;
        let norm = ((width * height) as f64 / total) as f32;
        Some(TexelImportance { width, height, lum, row_weight, cells, norm, jacobian })
    }

    /// A uv in [0, 1)² and its density in uv (per unit of u times v). `None` on the measure
    /// zero set where the density vanishes.
    pub fn sample(&self, u: [f32; 2]) -> Option<([f32; 2], f32)> {
        let s = self.cells.sample(u);
        let [a, b, c, d] = corners(&self.lum, self.width, self.height, s.x, s.y);
        let x = match self.jacobian {
            UvJacobian::LinearU => sample_times_u(s.remapped[0], a + c, b + d, s.x, self.width),
            UvJacobian::Uniform | UvJacobian::SinPiV => sample_linear(s.remapped[0], a + c, b + d),
        };
        let y = sample_linear(s.remapped[1], lerp(x, a, b), lerp(x, c, d));
        let wrap = |k: usize, f: f32, n: usize| {
            let t = (k as f32 + 0.5 + f) / n as f32;
            let t = if t >= 1.0 { t - 1.0 } else { t };
            t.clamp(0.0, 0.999_999_94)
        };
        let uv = [wrap(s.x, x, self.width), wrap(s.y, y, self.height)];
        let pdf = self.weighed(uv, s.y) * bilinear([a, b, c, d], x, y);
        (pdf > 0.0).then_some((uv, pdf))
    }

    /// The normalisation times the Jacobian's weight at `uv` (in cell row `j`).
    #[inline]
    fn weighed(&self, uv: [f32; 2], j: usize) -> f32 {
        match self.jacobian {
            UvJacobian::LinearU => self.norm * uv[0],
            UvJacobian::Uniform | UvJacobian::SinPiV => self.norm * self.row_weight[j],
        }
    }

    /// The density in uv of [`TexelImportance::sample`] at `uv`.
    pub fn pdf(&self, uv: [f32; 2]) -> f32 {
        let cell = |t: f32, n: usize| {
            let x = t * n as f32 - 0.5;
            let f = x.floor();
            ((f as i64).rem_euclid(n as i64) as usize, (x - f).clamp(0.0, 1.0))
        };
        let ((i, x), (j, y)) = (cell(uv[0], self.width), cell(uv[1], self.height));
        self.weighed(uv, j) * bilinear(corners(&self.lum, self.width, self.height, i, j), x, y)
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

/// A stretch [x0, x1] of a cell (in cell units) over which u runs linearly from u0 to u1.
#[derive(Clone, Copy, Debug)]
struct UPiece {
    x0: f32,
    x1: f32,
    u0: f32,
    u1: f32,
}

impl UPiece {
    /// ∫ over the piece of l(x) u(x) dx, where l runs linearly from `l0` at x0 to `l1` at x1.
    fn integral(&self, l0: f32, l1: f32) -> f32 {
        let (u0, u1) = (self.u0, self.u1);
        (self.x1 - self.x0) * (2.0 * l0 * u0 + l0 * u1 + l1 * u0 + 2.0 * l1 * u1) / 6.0
    }
}

/// The pieces of cell column `i` of `w` over which u is linear: the column spans u from
/// (i + 0.5)/w to (i + 1.5)/w, and the last one wraps from the rim (u = 1) to the centre.
/// (The second piece of a column that does not wrap is empty.)
fn u_pieces(i: usize, w: usize) -> [UPiece; 2] {
    let (lo, wf) = ((i as f32 + 0.5) / w as f32, w as f32);
    if i + 1 < w {
        let empty = UPiece { x0: 1.0, x1: 1.0, u0: 0.0, u1: 0.0 };
        [UPiece { x0: 0.0, x1: 1.0, u0: lo, u1: (i as f32 + 1.5) / wf }, empty]
    } else {
        [UPiece { x0: 0.0, x1: 0.5, u0: lo, u1: 1.0 }, UPiece { x0: 0.5, x1: 1.0, u0: 0.0, u1: 0.5 / wf }]
    }
}

/// A point x of cell column `i` (of `w`) with density proportional to
/// ((1 - x) a + x b) u(x): a piece by its share of the integral, then the quadratic product
/// of two linear functions on it, written in the Bernstein basis (all three coefficients are
/// non-negative) and drawn as a mixture of its terms, each inverted in closed form.
fn sample_times_u(u: f32, a: f32, b: f32, i: usize, w: usize) -> f32 {
    let pieces = u_pieces(i, w);
    let l = |x: f32| lerp(x, a, b);
    let masses = pieces.map(|p| p.integral(l(p.x0), l(p.x1)));
    let total = masses[0] + masses[1];
    if !(total > 0.0) {
        return u;
    }
    // The piece, and u rescaled within its share.
    let target = u * total;
    let (p, r) = if target < masses[0] || !(masses[1] > 0.0) {
        (pieces[0], target / masses[0])
    } else {
        (pieces[1], (target - masses[0]) / masses[1])
    };
    let r = r.clamp(0.0, 0.999_999_94);
    let (l0, l1) = (l(p.x0), l(p.x1));
    // l u = c0 (1-t)² + c1 2t(1-t) + c2 t²; each basis term integrates to 1/3.
    let c = [l0 * p.u0, 0.5 * (l0 * p.u1 + l1 * p.u0), l1 * p.u1];
    let sum = c[0] + c[1] + c[2];
    let t = if !(sum > 0.0) {
        r
    } else {
        let mut s = r * sum;
        if s < c[0] {
            // Density 3(1-t)².
            1.0 - (1.0 - s / c[0]).cbrt()
        } else {
            s -= c[0];
            if s < c[1] {
                // Density 6t(1-t): its CDF 3t² - 2t³ is inverted by t = 1/2 + sin(asin(2r - 1)/3).
                0.5 + ((2.0 * s / c[1] - 1.0).clamp(-1.0, 1.0).asin() / 3.0).sin()
            } else {
                // Density 3t².
                ((s - c[1]) / c[2]).clamp(0.0, 1.0).cbrt()
            }
        }
    };
    (p.x0 + t.clamp(0.0, 1.0) * (p.x1 - p.x0)).clamp(0.0, 0.999_999_94)
}

/// The mean Jacobian over cell row `j`, which spans v from (j + 0.5)/h to (j + 1.5)/h (the
/// last row wraps past v = 1 to the first texel centre); 1 for `LinearU`, which does not vary
/// along v (its variation along u enters the density exactly).
fn row_weight(jacobian: UvJacobian, j: usize, h: usize) -> f32 {
    match jacobian {
        UvJacobian::Uniform | UvJacobian::LinearU => 1.0,
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

/// A disk light made as a fan of N triangles around its centre with polar uvs, as
/// `geometry::disk_mesh` makes it (triangle k: the centre at uv (0, (k + ½)/N), rim vertices
/// k and k + 1 at (1, k/N) and (1, (k + 1)/N)), under any affine map: the map from uv to
/// the surface and back. A uv is placed on the polygon itself, not on the circle: v picks
/// segment k and the point t = vN - k along its rim edge, u scales that point from the
/// centre. Over segment k the area per unit uv is then u times N |e0 × e1| (e0, e1 the
/// segment's rim vertices from the centre), linear in u as [`UvJacobian::LinearU`] has it,
/// and the map takes the unit square onto the mesh's triangles exactly, so a sampled point
/// is always on the light and every point of it has a uv.
#[derive(Clone, Debug)]
pub struct UvDisk {
    centre: Vec3,
    /// Segment k's rim vertices, in order of azimuth (each its own triangle's, as they are).
    edges: Vec<[Vec3; 2]>,
    /// Segment k's area per unit uv over u: N |e0 × e1|.
    jacobian: Vec<f32>,
    /// Segment k's rim edge in the unit disk's plane, for the way back from a point.
    chords: Vec<Chord>,
    /// The dual basis of the rim's axes (rim(φ) ≈ centre + ax cos φ + ay sin φ): a point's
    /// coordinates in the unit disk's plane.
    dual_x: Vec3,
    dual_y: Vec3,
}

/// A segment's rim edge from l0 to l1 in the unit disk's plane: a point u((1 - t) l0 + t l1)
/// has u = m·x / h, with m the edge's normal and h its distance from the centre (m·l0), and
/// t from its place along the edge. (Barycentrics in the segment's triangle, which is 1/40
/// of a radian wide, lose about three digits to the near-parallel sides; this does not.)
#[derive(Clone, Copy, Debug)]
struct Chord {
    l0: [f32; 2],
    normal: [f32; 2],
    height: f32,
    along: [f32; 2],
}

impl UvDisk {
    /// The map of a fan with centre `centre` and rim edges `edges` (segment k from azimuth
    /// 2πk/N to 2π(k+1)/N); `None` unless the rim vertices lie on one ellipse around the
    /// centre at those azimuths (within 1e-4 of its axes' length), N a multiple of 4.
    pub fn new(centre: Vec3, edges: Vec<[Vec3; 2]>) -> Option<UvDisk> {
        let n = edges.len();
        if n < 4 || !n.is_multiple_of(4) {
            return None;
        }
        let (ax, ay) = (edges[0][0] - centre, edges[n / 4][0] - centre);
        let gram = [ax.dot(ax), ax.dot(ay), ay.dot(ay)];
        let det = gram[0] * gram[2] - gram[1] * gram[1];
        if !(det > 1e-12 * gram[0] * gram[2]) {
            return None;
        }
        let tol = 1e-4 * (ax.length() + ay.length());
        let on_ellipse = |k: usize, q: Vec3| {
            let phi = 2.0 * std::f64::consts::PI * (k % n) as f64 / n as f64;
            let expected = centre + ax * phi.cos() as f32 + ay * phi.sin() as f32;
            (q - expected).length() <= tol
        };
        if !edges.iter().enumerate().all(|(k, e)| on_ellipse(k, e[0]) && on_ellipse(k + 1, e[1])) {
            return None;
        }
        let jacobian: Vec<f32> =
            edges.iter().map(|e| n as f32 * (e[0] - centre).cross(e[1] - centre).length()).collect();
        if !jacobian.iter().all(|j| *j > 0.0) {
            return None;
        }
        let dual_x = (ax * gram[2] - ay * gram[1]) / det;
        let dual_y = (ay * gram[0] - ax * gram[1]) / det;
        let local = |q: Vec3| [(q - centre).dot(dual_x), (q - centre).dot(dual_y)];
        let chords = edges
            .iter()
            .map(|e| {
                let (l0, l1) = (local(e[0]), local(e[1]));
                let along = [l1[0] - l0[0], l1[1] - l0[1]];
                let normal = [along[1], -along[0]];
                Chord { l0, normal, height: normal[0] * l0[0] + normal[1] * l0[1], along }
            })
            .collect::<Vec<_>>();
        if !chords.iter().all(|c| c.height > 0.0) {
            return None;
        }
        Some(UvDisk { centre, edges, jacobian, chords, dual_x, dual_y })
    }

    /// The point at `uv`, its segment, and the fraction t along the segment's rim edge.
    pub fn point(&self, uv: [f32; 2]) -> (Vec3, usize, f32) {
        let n = self.edges.len();
        let s = uv[1] * n as f32;
        let k = (s.max(0.0) as usize).min(n - 1);
        let t = (s - k as f32).clamp(0.0, 1.0);
        let [r0, r1] = self.edges[k];
        let rim = (r0 - self.centre) * (1.0 - t) + (r1 - self.centre) * t;
        (self.centre + rim * uv[0], k, t)
    }

    /// The uv of a point of the disk, its segment, and the fraction along that segment's edge.
    pub fn uv(&self, q: Vec3) -> ([f32; 2], usize, f32) {
        let n = self.edges.len();
        let d = q - self.centre;
        let (x, y) = (d.dot(self.dual_x), d.dot(self.dual_y));
        let turn = y.atan2(x) / (2.0 * PI);
        let turn = if turn < 0.0 { turn + 1.0 } else { turn };
        let k = ((turn * n as f32) as usize).min(n - 1);
        let c = &self.chords[k];
        let u = (c.normal[0] * x + c.normal[1] * y) / c.height;
        // Along the edge: (x, y)/u - l0, over the edge's length, squared.
        let t = if u > 0.0 {
            let (px, py) = (x / u - c.l0[0], y / u - c.l0[1]);
            (px * c.along[0] + py * c.along[1]) / (c.along[0] * c.along[0] + c.along[1] * c.along[1])
        } else {
            0.5
        };
        let t = t.clamp(0.0, 1.0);
        ([u.clamp(0.0, 1.0), ((k as f32 + t) / n as f32).min(0.999_999_94)], k, t)
    }

    /// The density per unit area at `uv` on segment `k` of a density `pdf_uv` per unit uv.
    pub fn area_density(&self, pdf_uv: f32, uv: [f32; 2], k: usize) -> f32 {
        let jacobian = uv[0] * self.jacobian[k];
        if jacobian > 0.0 {
            pdf_uv / jacobian
        } else {
            0.0
        }
    }
}

/// A textured disk's importance: the texels (with [`UvJacobian::LinearU`]) and where they lie.
#[derive(Clone, Debug)]
pub struct DiskImportance {
    pub texels: TexelImportance,
    pub map: UvDisk,
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
        for jac in [UvJacobian::Uniform, UvJacobian::SinPiV, UvJacobian::LinearU] {
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
    fn a_disks_density_is_the_filtered_luminance_times_u_normalised() {
        // LinearU: the density in uv is the texture's luminance times u over the mean of
        // that product, everywhere (the cells of the last column wrap from the rim to the
        // centre), so per unit of the disk's area it is the luminance itself.
        let t = texture(5, 4, |x, y| if (x, y) == (4, 1) { 30.0 } else { 0.2 + 0.3 * ((x + 2 * y) % 3) as f32 });
        let imp = TexelImportance::new(&t, UvJacobian::LinearU).unwrap();
        let n = 400;
        let product = |uv: [f32; 2]| t.eval(uv).luminance() as f64 * uv[0] as f64;
        let grid = || (0..n * n).map(|k| [((k % n) as f32 + 0.5) / n as f32, ((k / n) as f32 + 0.5) / n as f32]);
        let mean = grid().map(product).sum::<f64>() / (n * n) as f64;
        let mut integral = 0.0f64;
        for uv in grid() {
            let pdf = imp.pdf(uv) as f64;
            let expected = product(uv) / mean;
            assert!((pdf / expected - 1.0).abs() < 1e-3, "{uv:?}: {pdf} vs {expected}");
            integral += pdf / (n * n) as f64;
        }
        assert!((integral - 1.0).abs() < 1e-3, "{integral}");
    }

    #[test]
    fn disk_uvs_map_onto_the_fan_and_back() {
        // The unit disk's fan under a shear and an uneven scale: uv -> point -> uv is the
        // identity, points lie in their segment's triangle, and the Jacobian integrates to
        // the fan's area.
        let n = 16;
        let (centre, ax, ay) =
            (crate::math::vec3(0.3, -1.0, 2.0), crate::math::vec3(0.8, 0.1, 0.0), crate::math::vec3(0.2, 0.0, 0.5));
        let rim = |k: usize| {
            let phi = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            centre + ax * phi.cos() as f32 + ay * phi.sin() as f32
        };
        let edges: Vec<[Vec3; 2]> = (0..n).map(|k| [rim(k), rim((k + 1) % n)]).collect();
        let disk = UvDisk::new(centre, edges.clone()).unwrap();
        let mut rng = crate::sampling::Rng::new(3, 9);
        for _ in 0..2000 {
            let uv = [rng.next_f32(), rng.next_f32()];
            let (q, k, t) = disk.point(uv);
            let (back, k2, t2) = disk.uv(q);
            assert_eq!(k, k2, "{uv:?}");
            assert!((back[0] - uv[0]).abs() < 1e-5 && (back[1] - uv[1]).abs() < 1e-5, "{uv:?} -> {back:?}");
            assert!((t - t2).abs() < 1e-3 || uv[0] < 1e-3, "{t} vs {t2}");
        }
        let fan_area: f32 = edges.iter().map(|[a, b]| 0.5 * (*a - centre).cross(*b - centre).length()).sum();
        // ∫∫ u J_k du dv = Σ_k J_k / (2N).
        let mapped: f32 = disk.jacobian.iter().map(|j| j / (2 * n) as f32).sum();
        assert!((mapped / fan_area - 1.0).abs() < 1e-5, "{mapped} vs {fan_area}");
        // A rim off the ellipse is not a disk.
        let mut bent = edges;
        bent[3][1] += ax * 0.01;
        assert!(UvDisk::new(centre, bent).is_none());
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
