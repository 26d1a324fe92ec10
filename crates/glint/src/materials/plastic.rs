//! `plastic` and `roughplastic`: a textured diffuse base under a smooth or rough dielectric
//! coating of index `eta` tinted by `specular`, with the internal-scattering correction of
//! the diffuse term (linear, or Mitsuba's `nonlinear`); the roughness is one number (BSDF:
//! [`PlasticParams`]).
//!
//! # The BSDF
//! Plastic: a diffuse base under a dielectric coating (Mitsuba's `plastic` and
//! `roughplastic`). Light that enters the coating scatters off the base and may be reflected
//! back by the coating many times; the sum of that series divides the diffuse albedo by
//! (1 - F_dr), with F_dr the coating's diffuse internal reflectance, computed here by
//! the fitted polynomial Mitsuba uses. The rough variant replaces the smooth Fresnel terms by
//! the rough interface's own transmittance, tabulated over the cosine at construction, and
//! its internal reflectance (Mitsuba's `roughplastic` model), both integrated here with the
//! rough dielectric BSDF.
//!
//! # Differentiable
//! `diffuse` (a constant or a bitmap texture per texel), `specular`, `eta` and `alpha`,
//! through the value of the non-delta lobes (a smooth plastic's specular lobe is a delta).
//! The rough coating's tables are a fixed quadrature, smooth in `alpha` only at about the
//! gradient's step (`docs/differentiable.md`). See `docs/differentiable.md`.

use super::{constant_microfacet, Bsdf, Describe, MaterialKind, Shade, Texture, TextureCache, TexturePoint};
use crate::bsdf::{fresnel_dielectric, reflect_local, BsdfSample, Microfacet, Scatter};
use crate::describe::slots::{roughness_slots, texture_slot, Slot};
use crate::describe::{checks, Roughness, TextureDesc};
use crate::error::Error;
use crate::math::{Rgb, Vec3, INV_PI};
use crate::sampling::warp;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

#[derive(Clone, Copy, Debug)]
pub struct PlasticParams {
    pub diffuse: Rgb,
    pub specular: Rgb,
    /// n_inside / n_outside of the coating.
    pub eta: f32,
    /// None: smooth coating (a delta reflection lobe).
    pub dist: Option<Microfacet>,
    /// Diffuse internal reflectance of the coating seen from inside.
    pub fdr_internal: f32,
    /// Rough coatings: energy transmitted through the interface against the cosine of the
    /// direction (TRANSMITTANCE_RES points over [0, 1]); `None` for smooth ones (1 - F).
    /// Interned (see `rough_coating_tables`), so that the BSDF stays small: it is built by
    /// value at every hit.
    pub transmittance: Option<&'static [f32; TRANSMITTANCE_RES]>,
    /// Mitsuba's `nonlinear`: each bounce inside the coating meets the base again, so the
    /// series sums to ρ / (1 - ρ F_dr) rather than ρ / (1 - F_dr) (which assumes the light
    /// reflected back down is not absorbed by the base).
    pub nonlinear: bool,
}

pub const TRANSMITTANCE_RES: usize = 64;

/// Directional albedos of a rough dielectric interface seen from direction cosine `mu` on
/// the side where the relative index is `eta`: (reflected, transmitted energy). Estimated by
/// importance sampling the BSDF on a fixed stratified set of 4096 samples.
fn rough_interface_albedo(dist: &Microfacet, eta: f32, mu: f32) -> (f32, f32) {
    use crate::bsdf::sample_rough_dielectric;
    let wo = crate::math::Vec3 { x: (1.0 - mu * mu).max(0.0).sqrt(), y: 0.0, z: mu };
    let n = 64;
    let (mut r, mut t) = (0.0f64, 0.0f64);
    for i in 0..n {
        for j in 0..n {
            let k = (i * n + j) as u32;
            let u_lobe = (k.reverse_bits() as f64 / 4_294_967_296.0) as f32;
            let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
            if let Some(s) = sample_rough_dielectric(dist, eta, Rgb::WHITE, Rgb::WHITE, wo, u_lobe, u) {
                if s.wi.z > 0.0 {
                    r += s.weight.r as f64;
                } else {
                    // Undo the radiance scaling 1/eta^2: this is transmitted energy.
                    t += (s.weight.r * eta * eta) as f64;
                }
            }
        }
    }
    let m = (n * n) as f64;
    ((r / m) as f32, (t / m) as f32)
}

/// Diffuse Fresnel reflectance: the cosine-weighted hemispherical average of Fresnel
/// reflectance, 2 ∫ F(cos θ) cos θ dcos θ, for light arriving from the side where the
/// relative index is `eta`. The published fits Mitsuba uses (d'Eon and Irving 2011 below 1,
/// Egan and Hilgeman 1973 above), so that plastics agree with Mitsuba; they are within
/// 0.5% of the integral (tested below).
pub fn diffuse_fresnel_reflectance(eta: f32) -> f32 {
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta
    } else {
        let i = 1.0 / eta;
        let (i2, i3) = (i * i, i * i * i);
        0.919317 - 3.4793 * i + 6.75335 * i2 - 7.80989 * i3 + 4.98554 * i2 * i2 - 1.36881 * i3 * i2
    }
}

/// The internal diffuse reflectance and the transmittance table of a rough coating, computed
/// once per distinct (interface, eta) and kept for the life of the process: a scene has a
/// handful of distinct coatings, and a `'static` table keeps `PlasticParams` `Copy`.
fn rough_coating_tables(d: &Microfacet, eta: f32) -> (f32, &'static [f32; TRANSMITTANCE_RES]) {
    type Cache = HashMap<(String, u32), (f32, &'static [f32; TRANSMITTANCE_RES])>;
    static CACHE: OnceLock<Mutex<Cache>> = OnceLock::new();
    let key = (format!("{d:?}"), eta.to_bits());
    let cache = CACHE.get_or_init(Default::default);
    if let Some(&hit) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return hit;
    }
    let mut table = [0.0f32; TRANSMITTANCE_RES];
    let mut internal = 0.0f32;
    for (i, t) in table.iter_mut().enumerate() {
        let mu = (i as f32 / (TRANSMITTANCE_RES - 1) as f32).max(1e-6);
        *t = rough_interface_albedo(d, eta, mu).1;
        internal += rough_interface_albedo(d, 1.0 / eta, mu).0 * mu;
    }
    let entry = (2.0 * internal / TRANSMITTANCE_RES as f32, &*Box::leak(Box::new(table)));
    *cache.lock().unwrap_or_else(|e| e.into_inner()).entry(key).or_insert(entry)
}

/// Energy transmitted through a coating of index `eta` for direction cosine `cos`: `1 - F`
/// without a table (a smooth coating), else the table interpolated linearly. A free function
/// so that the vertex lanes call this very code per lane (the table is a gather).
#[inline]
pub(crate) fn coating_transmittance(table: Option<&[f32; TRANSMITTANCE_RES]>, eta: f32, cos: f32) -> f32 {
    match table {
        None => 1.0 - fresnel_dielectric(cos, eta).reflectance,
        Some(t) => {
            let x = cos.clamp(0.0, 1.0) * (TRANSMITTANCE_RES - 1) as f32;
            let i = (x as usize).min(TRANSMITTANCE_RES - 2);
            let f = x - i as f32;
            t[i] * (1.0 - f) + t[i + 1] * f
        }
    }
}

impl PlasticParams {
    pub fn new(diffuse: Rgb, specular: Rgb, eta: f32, dist: Option<Microfacet>) -> PlasticParams {
        let (fdr_internal, transmittance) = match &dist {
            None => (diffuse_fresnel_reflectance(1.0 / eta), None),
            Some(d) => {
                let (internal, table) = rough_coating_tables(d, eta);
                (internal, Some(table))
            }
        };
        PlasticParams { diffuse, specular, eta, dist, fdr_internal, transmittance, nonlinear: false }
    }

    /// Energy transmitted through the coating for direction cosine `cos`.
    fn coating_transmittance(&self, cos: f32) -> f32 {
        coating_transmittance(self.transmittance, self.eta, cos)
    }

    fn specular_weight(&self) -> f32 {
        let d = self.diffuse.average();
        let s = self.specular.average();
        if d + s <= 0.0 {
            0.5
        } else {
            s / (d + s)
        }
    }

    /// Probability of choosing the specular lobe given the viewing cosine.
    fn prob_specular(&self, cos_o: f32) -> f32 {
        let f = fresnel_dielectric(cos_o, self.eta).reflectance;
        let sw = self.specular_weight();
        let ps = f * sw;
        let pd = (1.0 - f) * (1.0 - sw);
        if ps + pd <= 0.0 {
            0.0
        } else {
            ps / (ps + pd)
        }
    }

    fn diffuse_eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let to = self.coating_transmittance(wo.z);
        let ti = self.coating_transmittance(wi.z);
        let albedo = if self.nonlinear {
            self.diffuse.map(|d| d / (1.0 - d * self.fdr_internal))
        } else {
            self.diffuse / (1.0 - self.fdr_internal)
        };
        albedo * (INV_PI * wi.z * to * ti / (self.eta * self.eta))
    }

    fn finish(&self, wo: Vec3, wi: Vec3) -> Option<BsdfSample> {
        BsdfSample::non_delta(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }
}

impl Scatter for PlasticParams {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        self.dist.is_none()
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let mut v = self.diffuse_eval(wo, wi);
        if let Some(d) = &self.dist {
            let h = (wo + wi).normalize();
            let f = fresnel_dielectric(wo.dot(h), self.eta).reflectance;
            v += self.specular * (f * d.d(h) * d.g(wo, wi, h) / (4.0 * wo.z));
        }
        v
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.prob_specular(wo.z);
        let mut p = (1.0 - ps) * warp::cosine_hemisphere_pdf(wi.z);
        if let Some(d) = &self.dist {
            let h = (wo + wi).normalize();
            p += ps * d.pdf_wm(wo, h) / (4.0 * wo.dot(h));
        }
        p
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let ps = self.prob_specular(wo.z);
        if u_lobe < ps {
            match &self.dist {
                None => {
                    let f = fresnel_dielectric(wo.z, self.eta).reflectance;
                    return Some(BsdfSample {
                        wi: reflect_local(wo),
                        weight: self.specular * (f / ps),
                        pdf: ps,
                        delta: true,
                        eta: 1.0,
                    });
                }
                Some(d) => {
                    let h = d.sample_wm(wo, u);
                    let wi = h * (2.0 * wo.dot(h)) - wo;
                    return self.finish(wo, wi);
                }
            }
        }
        let wi = warp::cosine_hemisphere(u);
        if self.dist.is_none() {
            // Only the diffuse lobe has a density here; the delta lobe was not chosen.
            if wi.z <= 0.0 {
                return None;
            }
            let pdf = (1.0 - ps) * warp::cosine_hemisphere_pdf(wi.z);
            return Some(BsdfSample { wi, weight: self.diffuse_eval(wo, wi) / pdf, pdf, delta: false, eta: 1.0 });
        }
        self.finish(wo, wi)
    }

    fn diffuse_reflectance(&self) -> Rgb {
        self.diffuse
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_diffuse_fresnel_matches_the_integral() {
        for eta in [1.0 / 1.8, 1.0 / 1.49, 1.0 / 1.33, 1.33, 1.49, 1.8] {
            let n = 100_000;
            let integral: f32 = (0..n)
                .map(|i| {
                    let c = (i as f32 + 0.5) / n as f32;
                    fresnel_dielectric(c, eta).reflectance * 2.0 * c / n as f32
                })
                .sum();
            let fit = diffuse_fresnel_reflectance(eta);
            assert!((fit - integral).abs() < 5e-3, "eta {eta}: fit {fit} integral {integral}");
        }
    }
}

/// `plastic`'s and `roughplastic`'s parameters.
///
/// | Parameter | Type | Default (JSON, Mitsuba) | |
/// |---|---|---|---|
/// | `diffuse` | texture | (JSON: required; Mitsuba 0.5) | the base's albedo |
/// | `specular` | colour | 1 | the coating's tint |
/// | `eta` | float | 1.49 (JSON `ior`) | the coating's index |
/// | `roughness` | roughness | none: smooth | one isotropic, untextured `alpha` |
/// | `nonlinear` | bool | false | Mitsuba's `nonlinear` internal scattering |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlasticDesc {
    pub diffuse: TextureDesc,
    pub specular: Rgb,
    pub eta: f32,
    pub roughness: Option<Roughness>,
    /// Mitsuba's `nonlinear`: the internal scattering series divides the albedo ρ by
    /// 1 - ρ F_dr instead of 1 - F_dr, which darkens and saturates colours.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub nonlinear: bool,
}

impl Describe for PlasticDesc {
    type Built = PlasticMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<PlasticMaterial, Error> {
        let dist = self.roughness.as_ref().map(constant_microfacet).transpose()?;
        let diffuse = textures.texture(&self.diffuse)?;
        Ok(if self.nonlinear {
            PlasticMaterial::nonlinear(diffuse, self.specular, self.eta, dist)
        } else {
            PlasticMaterial::new(diffuse, self.specular, self.eta, dist)
        })
    }

    fn validate(&self) -> Result<(), String> {
        checks::eta(self.eta)?;
        checks::color(self.specular, "specular reflectance")?;
        checks::roughness(self.roughness.as_ref())
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        let rough = self.roughness.as_ref().map_or(Vec::new(), Roughness::textures);
        [vec![&self.diffuse], rough].concat()
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        let mut textures = vec![&mut self.diffuse];
        textures.extend(self.roughness.as_mut().map_or(Vec::new(), Roughness::textures_mut));
        textures
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = Vec::new();
        texture_slot("diffuse", &mut self.diffuse, &mut out);
        out.push(("specular", Slot::Color(&mut self.specular)));
        out.push(("eta", Slot::Float(&mut self.eta)));
        roughness_slots(&mut self.roughness, &mut out);
        out
    }
}

/// Diffuse base under a coating; `params` holds everything but the textured albedo.
#[derive(Clone, Debug)]
pub struct PlasticMaterial {
    pub diffuse: Texture,
    pub params: PlasticParams,
}

impl PlasticMaterial {
    pub fn new(diffuse: Texture, specular: Rgb, eta: f32, dist: Option<Microfacet>) -> PlasticMaterial {
        PlasticMaterial { diffuse, params: PlasticParams::new(Rgb::BLACK, specular, eta, dist) }
    }

    /// [`PlasticMaterial::new`] with Mitsuba's `nonlinear` internal scattering.
    pub fn nonlinear(diffuse: Texture, specular: Rgb, eta: f32, dist: Option<Microfacet>) -> PlasticMaterial {
        let params = PlasticParams { nonlinear: true, ..PlasticParams::new(Rgb::BLACK, specular, eta, dist) };
        PlasticMaterial { diffuse, params }
    }
}

impl Shade for PlasticMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::Plastic(PlasticParams { diffuse: self.diffuse.eval_at(p), ..self.params })
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.diffuse.eval(uv)
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
