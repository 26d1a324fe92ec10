//! Point lights that project a texture: Mitsuba's `spot` with a `texture`, and its
//! `projector`. Both are delta lights at the origin of their `to_world`, looking along its
//! local +z, with the texture laid over the directions as Mitsuba lays it:
//! - spot: u = ½ + ½ x / (z tan cutoff), v = ½ + ½ y / (z tan cutoff) (the texture
//!   spans the square around the cone), times the spot's intensity and angular falloff;
//! - projector: the uv a perspective camera with the projector's field of view and the
//!   texture's aspect ratio would see (u grows towards local -x, v towards -y), scaled so
//!   that the irradiance on the plane z = 1 in front of it is π · scale · texture(uv).

use super::{spot_falloff, LightSample};
use crate::materials::Texture;
use crate::math::{Rgb, Transform, Vec3, PI};

#[derive(Clone, Debug)]
pub enum ProjectedKind {
    Spot {
        intensity: Rgb,
        cutoff: f32,
        beam: f32,
    },
    /// `tan_half_x`: tangent of half the horizontal field of view; `aspect`: the texture's
    /// width over height.
    Projector {
        scale: f32,
        tan_half_x: f32,
        aspect: f32,
    },
}

#[derive(Clone, Debug)]
pub struct ProjectedLight {
    pub to_world: Transform,
    pub texture: Texture,
    pub kind: ProjectedKind,
}

impl ProjectedLight {
    pub fn position(&self) -> Vec3 {
        self.to_world.point(Vec3::ZERO)
    }

    /// The texture coordinates of local direction (or point) `l`, if the texture covers it.
    fn uv(&self, l: Vec3) -> Option<[f32; 2]> {
        if !(l.z > 0.0) {
            return None;
        }
        let uv = match self.kind {
            ProjectedKind::Spot { cutoff, .. } => {
                let f = cutoff.tan();
                [0.5 + 0.5 * l.x / (l.z * f), 0.5 + 0.5 * l.y / (l.z * f)]
            }
            ProjectedKind::Projector { tan_half_x, aspect, .. } => {
                let (x, y) = (l.x / (l.z * tan_half_x), l.y / (l.z * tan_half_x));
                [0.5 * (1.0 - x), 0.5 * (1.0 - aspect * y)]
            }
        };
        let inside = uv.iter().all(|v| (0.0..=1.0).contains(v));
        // A spot's cone may reach past the texture's square only for cutoffs near 90°,
        // where Mitsuba's lookup repeats the texture; glint clamps it to the edge.
        match self.kind {
            ProjectedKind::Spot { .. } => Some(uv.map(|v| v.clamp(0.0, 1.0))),
            ProjectedKind::Projector { .. } => inside.then_some(uv),
        }
    }

    /// The light arriving at `p`: towards the light, as a delta sample.
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        let d = self.position() - p;
        let dist2 = d.length_squared();
        let dist = dist2.sqrt();
        if !(dist > 0.0) {
            return None;
        }
        let wi = d / dist;
        let local = self.to_world.inv_point(p);
        let uv = self.uv(local)?;
        let radiance = match self.kind {
            ProjectedKind::Spot { intensity, cutoff, beam } => {
                let dir = local.normalize();
                let falloff = spot_falloff(dir.z, cutoff, beam);
                if falloff <= 0.0 {
                    return None;
                }
                intensity * self.texture.eval(uv) * (falloff / dist2)
            }
            ProjectedKind::Projector { scale, .. } => {
                let axis = self.to_world.vector(Vec3::Z);
                let cos_t = -axis.dot(wi);
                if !(cos_t > 0.0) {
                    return None;
                }
                self.texture.eval(uv) * (PI * scale / (local.z * local.z * cos_t))
            }
        };
        Some(LightSample { wi, radiance, pdf: 1.0, dist, delta: true })
    }

    /// Emitted flux (luminance), for choosing among lights.
    pub fn power(&self) -> f32 {
        let mean = self.texture.mean().luminance();
        match self.kind {
            ProjectedKind::Spot { intensity, cutoff, beam } => {
                let mid = 0.5 * (cutoff + beam);
                2.0 * PI * (1.0 - mid.cos()) * intensity.luminance() * mean
            }
            // The flux through the plane z = 1: π scale E over the image's rectangle there.
            ProjectedKind::Projector { scale, tan_half_x, aspect } => {
                PI * scale * mean * 4.0 * tan_half_x * tan_half_x / aspect
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::vec3;

    fn projector(scale: f32) -> ProjectedLight {
        let to_world = Transform::look_at(vec3(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y).unwrap();
        ProjectedLight {
            to_world,
            texture: Texture::Constant(Rgb::splat(2.0)),
            kind: ProjectedKind::Projector { scale, tan_half_x: 0.5, aspect: 2.0 },
        }
    }

    #[test]
    fn projector_irradiance_on_the_unit_plane_is_pi_scale_texture() {
        // Points 1 unit in front of the projector: irradiance on a plane facing it.
        let l = projector(3.0);
        for (x, y) in [(0.0, 0.0), (0.3, 0.1), (-0.45, -0.2)] {
            let p = vec3(x, y, 4.0);
            let s = l.sample_li(p).unwrap();
            let e = s.radiance.g * s.wi.dot(Vec3::Z);
            assert!((e - PI * 3.0 * 2.0).abs() < 1e-3 * e, "{e}");
        }
        // Outside the field of view (half width 0.5, half height 0.25 at z = 1): nothing.
        assert!(l.sample_li(vec3(0.6, 0.0, 4.0)).is_none());
        assert!(l.sample_li(vec3(0.0, 0.3, 4.0)).is_none());
        // Behind it: nothing.
        assert!(l.sample_li(vec3(0.0, 0.0, 6.0)).is_none());
    }

    #[test]
    fn spot_texture_spans_the_cone() {
        let to_world = Transform::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y).unwrap();
        let l = ProjectedLight {
            to_world,
            texture: Texture::Constant(Rgb::WHITE),
            kind: ProjectedKind::Spot { intensity: Rgb::splat(4.0), cutoff: 0.5, beam: 0.4 },
        };
        assert_eq!(l.uv(vec3(0.0, 0.0, 1.0)), Some([0.5, 0.5]));
        let edge = l.uv(vec3(0.5f32.tan(), 0.0, 1.0)).unwrap();
        assert!((edge[0] - 1.0).abs() < 1e-5);
        let s = l.sample_li(vec3(0.0, 0.0, 2.0)).unwrap();
        assert!((s.radiance.r - 1.0).abs() < 1e-5);
        assert!(l.sample_li(vec3(2.0, 0.0, 2.0)).is_none());
    }
}
