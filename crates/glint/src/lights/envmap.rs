//! Environment maps in latitude-longitude layout, importance-sampled by luminance × sin θ.

use super::LightSample;
use crate::materials::Bitmap;
use crate::math::{Rgb, Transform, Vec3, PI};
use crate::sampling::Distribution2d;

#[derive(Clone, Debug)]
pub struct EnvMap {
    pub image: Bitmap,
    pub scale: f32,
    /// Environment-to-world rotation.
    pub to_world: Transform,
    pub scene_radius: f32,
    texels: Distribution2d,
}

impl EnvMap {
    pub fn new(image: Bitmap, scale: f32, to_world: Transform, scene_radius: f32) -> Result<EnvMap, String> {
        let (w, h) = (image.width, image.height);
        let mut weights = Vec::with_capacity(w * h);
        for y in 0..h {
            let sin_t = (PI * (y as f32 + 0.5) / h as f32).sin();
            weights.extend((0..w).map(|x| image.pixels[y * w + x].luminance().max(0.0) * sin_t));
        }
        let texels = Distribution2d::new(&weights, w, h).ok_or("the environment map is black everywhere")?;
        Ok(EnvMap { image, scale, to_world, scene_radius, texels })
    }

    pub fn mean_luminance(&self) -> f32 {
        self.image.mean().luminance() * self.scale
    }

    /// Direction (world) to pixel-space (u, v) in [0,1)^2. Mitsuba's layout: +y is up, u
    /// grows with azimuth measured from +x towards... see `dir_from_uv`.
    fn uv_from_dir(&self, d_world: Vec3) -> [f32; 2] {
        let d = self.to_world.inv_vector(d_world).normalize();
        let theta = d.y.clamp(-1.0, 1.0).acos();
        let mut phi = d.x.atan2(-d.z);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        [phi / (2.0 * PI), theta / PI]
    }

    fn dir_from_uv(&self, uv: [f32; 2]) -> (Vec3, f32) {
        let phi = uv[0] * 2.0 * PI;
        let theta = uv[1] * PI;
        let (st, ct) = theta.sin_cos();
        let d = Vec3 { x: st * phi.sin(), y: ct, z: -st * phi.cos() };
        (self.to_world.vector(d).normalize(), st)
    }

    /// Bilinear interpolation laid out as Mitsuba's envmap: columns are texel-centred and
    /// wrap around in u, rows are vertices from the north pole (row 0, v = 0) to the south
    /// pole (last row, v = 1). Sampling stays piecewise constant over texels; `pdf` describes
    /// that, so the estimate is unbiased whatever the interpolation.
    pub fn eval(&self, dir: Vec3) -> Rgb {
        let (x0, y0, fx, fy) = self.lookup(dir);
        let texel = |xi: i64, yi: i64| self.image.pixels[self.texel_index(xi, yi)];
        let a = texel(x0, y0) * (1.0 - fx) + texel(x0 + 1, y0) * fx;
        let b = texel(x0, y0 + 1) * (1.0 - fx) + texel(x0 + 1, y0 + 1) * fx;
        (a * (1.0 - fy) + b * fy) * self.scale
    }

    /// The lookup along `dir`: the texel at the blend's top left and the fractions towards
    /// the next column and row (see [`EnvMap::eval`]).
    fn lookup(&self, dir: Vec3) -> (i64, i64, f32, f32) {
        let uv = self.uv_from_dir(dir);
        let x = uv[0] * self.image.width as f32 - 0.5;
        let y = uv[1] * (self.image.height as i64 - 1).max(1) as f32;
        let (x0, y0) = (x.floor(), y.floor());
        (x0 as i64, y0 as i64, x - x0, y - y0)
    }

    /// The index in the image's pixels of column `x` (wrapping around) and row `y` (clamped).
    fn texel_index(&self, x: i64, y: i64) -> usize {
        let (w, h) = (self.image.width as i64, self.image.height as i64);
        y.clamp(0, h - 1) as usize * self.image.width + x.rem_euclid(w) as usize
    }

    /// The texels [`EnvMap::eval`] blends along `dir` (indices into the image's pixels) and
    /// their weights, before the scale.
    pub fn taps(&self, dir: Vec3) -> [(usize, f32); 4] {
        let (x0, y0, fx, fy) = self.lookup(dir);
        let at = |xi: i64, yi: i64| self.texel_index(xi, yi);
        [
            (at(x0, y0), (1.0 - fx) * (1.0 - fy)),
            (at(x0 + 1, y0), fx * (1.0 - fy)),
            (at(x0, y0 + 1), (1.0 - fx) * fy),
            (at(x0 + 1, y0 + 1), fx * fy),
        ]
    }

    pub fn pdf(&self, dir: Vec3) -> f32 {
        let uv = self.uv_from_dir(dir);
        let (w, h) = (self.image.width, self.image.height);
        let x = ((uv[0] * w as f32) as usize).min(w - 1);
        let y = ((uv[1] * h as f32) as usize).min(h - 1);
        let sin_t = (uv[1] * PI).sin();
        if sin_t <= 0.0 {
            return 0.0;
        }
        let pmf = self.texels.pmf(x, y);
        // Pixel density in uv is pmf * w * h; Jacobian uv -> solid angle is 2π² sin θ.
        pmf * (w * h) as f32 / (2.0 * PI * PI * sin_t)
    }

    pub fn sample(&self, u: [f32; 2]) -> Option<LightSample> {
        let (w, h) = (self.image.width, self.image.height);
        let s = self.texels.sample(u);
        let uv = [(s.x as f32 + s.remapped[0]) / w as f32, (s.y as f32 + s.remapped[1]) / h as f32];
        let (wi, sin_t) = self.dir_from_uv(uv);
        if sin_t <= 0.0 {
            return None;
        }
        let pdf = s.pmf * (w * h) as f32 / (2.0 * PI * PI * sin_t);
        if pdf <= 0.0 {
            return None;
        }
        Some(LightSample { wi, radiance: self.eval(wi), pdf, dist: f32::INFINITY, delta: false })
    }
}
