//! A BSDF evaluated in a tilted shading frame: what normal and bump maps do to the BSDF
//! they wrap (Mitsuba's `normalmap` and `bumpmap`).
//!
//! Directions come in and go out in the surface's own shading frame (as for any BSDF); the
//! wrapped BSDF sees them in the tilted frame. As in Mitsuba, a light direction on the other
//! side of the tilted surface than of the real one scatters nothing, and the value is
//! attenuated by the microfacet shadowing term of Estevez et al. 2019 ("A microfacet-based
//! shadowing function to solve the bump terminator problem"), which hides the hard
//! terminator a tilted normal otherwise draws.

use super::Bsdf;
use crate::bsdf::BsdfSample;
use crate::math::{Frame, Rgb, Vec3};

/// The BSDF a surface scatters with, and the tilted frame (expressed in the surface's shading
/// frame) it is evaluated in, if any.
#[derive(Clone, Debug)]
pub struct ShadedBsdf {
    pub bsdf: Bsdf,
    pub tilt: Option<Frame>,
}

impl From<Bsdf> for ShadedBsdf {
    fn from(bsdf: Bsdf) -> ShadedBsdf {
        ShadedBsdf { bsdf, tilt: None }
    }
}

/// Estevez et al.'s shadowing of a surface tilted to `n` (unit, in the surface's frame), seen
/// from `w`: 1 where the tilt is zero or `w` is the normal.
pub fn bump_shadowing(n: Vec3, w: Vec3) -> f32 {
    let tan2 = |v: Vec3| {
        let c2 = v.z * v.z;
        ((1.0 - c2).max(0.0) / c2).max(0.0)
    };
    let alpha2 = (0.125 * tan2(n)).min(1.0);
    let g = 2.0 / (1.0 + (1.0 + alpha2 * tan2(w)).sqrt());
    // A grazing w (tan² infinite) or a degenerate normal: fully shadowed, never NaN.
    if g.is_finite() {
        g
    } else {
        0.0
    }
}

impl ShadedBsdf {
    pub fn is_delta(&self) -> bool {
        self.bsdf.is_delta()
    }

    pub fn has_delta_lobe(&self) -> bool {
        self.bsdf.has_delta_lobe()
    }

    pub fn diffuse_reflectance(&self) -> Rgb {
        self.bsdf.diffuse_reflectance()
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let Some(f) = &self.tilt else { return self.bsdf.eval(wo, wi) };
        let twi = f.to_local(wi);
        if !(wi.z * twi.z > 0.0) {
            return Rgb::BLACK;
        }
        self.bsdf.eval(f.to_local(wo), twi) * bump_shadowing(f.n, wi)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(f) = &self.tilt else { return self.bsdf.pdf(wo, wi) };
        let twi = f.to_local(wi);
        if !(wi.z * twi.z > 0.0) {
            return 0.0;
        }
        self.bsdf.pdf(f.to_local(wo), twi)
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let Some(f) = &self.tilt else { return self.bsdf.sample(wo, u_lobe, u) };
        let mut bs = self.bsdf.sample(f.to_local(wo), u_lobe, u)?;
        let wi = f.to_world(bs.wi);
        if !(wi.z * bs.wi.z > 0.0) {
            return None;
        }
        if !bs.delta {
            // Evaluated again at the direction returned: the round trip through the tilted
            // frame moves it by a rounding error, which near the tilted horizon changes the
            // cosine noticeably; this keeps weight = eval / pdf exact.
            let pdf = self.pdf(wo, wi);
            if !(pdf > 0.0) {
                return None;
            }
            return Some(BsdfSample { wi, weight: self.eval(wo, wi) / pdf, pdf, ..bs });
        }
        bs.weight *= bump_shadowing(f.n, wi);
        bs.wi = wi;
        Some(bs)
    }
}

/// The tilted frame of a tangent-space normal `n` (any length; in the surface's shading
/// frame) seen from `wo`, as Mitsuba's `normalmap` builds it: a normal that faces away from
/// the viewer is mirrored in the xy-plane, `s` follows the surface's own `s` (+x). `None` for
/// a zero or non-finite normal.
pub fn normal_map_frame(n: Vec3, wo: Vec3) -> Option<Frame> {
    let n = flip_invalid(n, wo);
    let len = n.length();
    if !(len > 0.0) || !len.is_finite() {
        return None;
    }
    Some(Frame::from_normal_tangent(n / len, Vec3 { x: 1.0, y: 0.0, z: 0.0 }))
}

/// As Mitsuba's `flip_invalid_normals`: a tilted normal on the other side of the viewer
/// than the surface's normal is mirrored to (−x, −y, z).
pub fn flip_invalid(n: Vec3, wo: Vec3) -> Vec3 {
    if wo.z * wo.dot(n) <= 0.0 {
        Vec3 { x: -n.x, y: -n.y, z: n.z }
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::Diffuse;
    use crate::math::vec3;
    use crate::sampling::Rng;

    fn random_dir(rng: &mut Rng) -> Vec3 {
        loop {
            let v = vec3(rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.0);
            if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }

    #[test]
    fn a_flat_normal_map_leaves_the_bsdf_unchanged() {
        let bsdf = Bsdf::Diffuse(Diffuse { reflectance: Rgb::splat(0.7) });
        let mut rng = Rng::new(7, 0);
        for _ in 0..1000 {
            let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
            let tilt = normal_map_frame(vec3(0.0, 0.0, 1.0), wo);
            let s = ShadedBsdf { bsdf: bsdf.clone(), tilt };
            let plain = ShadedBsdf::from(bsdf.clone());
            assert!((s.eval(wo, wi) - plain.eval(wo, wi)).max_component().abs() < 1e-6);
            assert!((s.pdf(wo, wi) - plain.pdf(wo, wi)).abs() < 1e-5);
            let u = [rng.next_f32(), rng.next_f32()];
            match (s.sample(wo, 0.5, u), plain.sample(wo, 0.5, u)) {
                (Some(a), Some(b)) => {
                    assert!((a.wi - b.wi).length() < 1e-5 && (a.weight - b.weight).max_component().abs() < 1e-5)
                }
                (None, None) => {}
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn tilted_frames_are_orthonormal_for_hostile_normals() {
        let mut rng = Rng::new(3, 0);
        let hostile = [
            vec3(0.0, 0.0, -1.0),
            vec3(1.0, 0.0, 0.0),
            vec3(-1.0, 0.0, 1e-30),
            vec3(1e30, 1e30, 1e-30),
            vec3(1e-30, 0.0, 0.0),
            vec3(0.0, 0.0, 0.0),
            vec3(f32::NAN, 0.0, 1.0),
            vec3(f32::INFINITY, 0.0, 1.0),
        ];
        for i in 0..2000 {
            let n = if i < hostile.len() { hostile[i] } else { random_dir(&mut rng) * (rng.next_f32() * 4.0) };
            let wo = random_dir(&mut rng);
            let Some(f) = normal_map_frame(n, wo) else {
                assert!(!(n.length() > 0.0) || !n.length().is_finite(), "{n:?}");
                continue;
            };
            for (a, b) in [(f.s, f.t), (f.t, f.n), (f.n, f.s)] {
                assert!(a.dot(b).abs() < 1e-4, "{n:?}: {f:?}");
            }
            for v in [f.s, f.t, f.n] {
                assert!((v.length() - 1.0).abs() < 1e-4, "{n:?}: {f:?}");
            }
            assert!(f.s.cross(f.t).dot(f.n) > 0.99, "{n:?}: not right-handed");
            let g = bump_shadowing(f.n, random_dir(&mut rng));
            assert!((0.0..=1.0).contains(&g), "{g}");
        }
    }
}
