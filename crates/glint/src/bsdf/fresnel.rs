//! Fresnel reflectance for dielectrics and conductors (unpolarised light).

use crate::math::{Rgb, Vec3};

/// Reflectance at a smooth dielectric interface and the cosine of the refracted direction.
/// `cos_i` is measured on the side of the incident direction (positive: outside, where the
/// relative index is `eta` = n_inside / n_outside). Returns (F, cos_t, eta_it, eta_ti) with
/// `cos_t` signed opposite to `cos_i` (the transmitted side), and 0 under total internal reflection.
#[derive(Clone, Copy, Debug)]
pub struct DielectricFresnel {
    pub reflectance: f32,
    pub cos_t: f32,
    /// n_transmitted / n_incident.
    pub eta_ti: f32,
}

pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> DielectricFresnel {
    if eta == 1.0 {
        return DielectricFresnel { reflectance: 0.0, cos_t: -cos_i, eta_ti: 1.0 };
    }
    let eta_ti = if cos_i >= 0.0 { eta } else { 1.0 / eta };
    let cos_i_abs = cos_i.abs();
    let sin2_t = (1.0 - cos_i_abs * cos_i_abs) / (eta_ti * eta_ti);
    if sin2_t >= 1.0 {
        return DielectricFresnel { reflectance: 1.0, cos_t: 0.0, eta_ti };
    }
    let cos_t_abs = (1.0 - sin2_t).max(0.0).sqrt();
    let rs = (cos_i_abs - eta_ti * cos_t_abs) / (cos_i_abs + eta_ti * cos_t_abs);
    let rp = (eta_ti * cos_i_abs - cos_t_abs) / (eta_ti * cos_i_abs + cos_t_abs);
    let f = 0.5 * (rs * rs + rp * rp);
    DielectricFresnel { reflectance: f, cos_t: if cos_i >= 0.0 { -cos_t_abs } else { cos_t_abs }, eta_ti }
}

/// Exact conductor Fresnel reflectance for complex index `eta + i k` (per channel), as in
/// pbrt-v3 `FrConductor` / Mitsuba's `fresnel_conductor`.
pub fn fresnel_conductor(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    let c = cos_i.clamp(0.0, 1.0);
    let f = |eta: f32, k: f32| -> f32 {
        let c2 = c * c;
        let s2 = 1.0 - c2;
        let eta2 = eta * eta;
        let k2 = k * k;
        let t0 = eta2 - k2 - s2;
        let a2b2 = (t0 * t0 + 4.0 * eta2 * k2).max(0.0).sqrt();
        let t1 = a2b2 + c2;
        let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
        let t2 = 2.0 * c * a;
        let rs = (t1 - t2) / (t1 + t2);
        let t3 = c2 * a2b2 + s2 * s2;
        let t4 = t2 * s2;
        let rp = rs * (t3 - t4) / (t3 + t4);
        let r = 0.5 * (rp + rs);
        if r.is_finite() {
            r
        } else {
            1.0
        }
    };
    Rgb { r: f(eta.r, k.r), g: f(eta.g, k.g), b: f(eta.b, k.b) }
}

/// Mirror `v` about the local +z axis.
#[inline]
pub fn reflect_local(v: Vec3) -> Vec3 {
    Vec3 { x: -v.x, y: -v.y, z: v.z }
}

/// Refract local direction `wo` given the Fresnel result for it (cos_t signed).
#[inline]
pub fn refract_local(wo: Vec3, fr: &DielectricFresnel) -> Vec3 {
    let scale = -1.0 / fr.eta_ti;
    Vec3 { x: wo.x * scale, y: wo.y * scale, z: fr.cos_t }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rgb;

    #[test]
    fn normal_incidence_glass_reflects_four_percent() {
        let f = fresnel_dielectric(1.0, 1.5).reflectance;
        assert!((f - 0.04).abs() < 1e-6);
        // Symmetric from inside at normal incidence.
        assert!((fresnel_dielectric(-1.0, 1.5).reflectance - 0.04).abs() < 1e-6);
    }

    #[test]
    fn total_internal_reflection_beyond_critical_angle() {
        let crit = (1.0f32 / 1.5).asin();
        let cos_beyond = (crit + 0.01).cos();
        assert_eq!(fresnel_dielectric(-cos_beyond, 1.5).reflectance, 1.0);
        assert!(fresnel_dielectric(-(crit - 0.01).cos(), 1.5).reflectance < 1.0);
    }

    #[test]
    fn conductor_with_zero_k_matches_dielectric() {
        for c in [0.1f32, 0.5, 0.9, 1.0] {
            let fc = fresnel_conductor(c, Rgb::splat(1.5), Rgb::BLACK).r;
            let fd = fresnel_dielectric(c, 1.5).reflectance;
            assert!((fc - fd).abs() < 1e-4, "{c}: {fc} vs {fd}");
        }
        let gold = fresnel_conductor(1.0, rgb(0.143, 0.374, 1.442), rgb(3.983, 2.385, 1.603));
        assert!(gold.r > gold.b);
    }

    #[test]
    fn refraction_obeys_snell() {
        let wo = Vec3 { x: 0.6, y: 0.0, z: 0.8 };
        let fr = fresnel_dielectric(wo.z, 1.5);
        let wt = refract_local(wo, &fr);
        assert!((wt.length() - 1.0).abs() < 1e-5);
        let sin_i = 0.6f32;
        let sin_t = (wt.x * wt.x + wt.y * wt.y).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!(wt.z < 0.0 && wt.x < 0.0);
    }
}
