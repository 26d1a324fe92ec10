//! Mitsuba 3's `principled` BSDF (Burley's Disney BSDF, 2012 and 2015): a diffuse lobe with
//! retro-reflection and an optional fake-subsurface flattening, a sheen lobe, a main GGX
//! lobe that reflects and (with `spec_trans`) refracts, and a GTR1 clearcoat. The lobes,
//! their weights and their sampling probabilities are Mitsuba 3.9.1's, term by term, so that
//! a scene renders the same in both (including its clearcoat, which has no 1/(4 cos cos)
//! factor, and its Schlick Fresnel for the metallic and tinted parts).
//!
//! The main lobe is anisotropic GGX with visible-normal sampling; `microfacet.rs` is
//! isotropic, so the anisotropic distribution lives here ([`AnisoGgx`]).

use crate::bsdf::{fresnel_dielectric, BsdfSample, Scatter};
use crate::math::{Rgb, Vec3, INV_PI, PI};
use crate::sampling::warp;

/// Anisotropic GGX (Trowbridge-Reitz) with Smith's separable shadowing, as Mitsuba's
/// `MicrofacetDistribution` with `sample_visible`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnisoGgx {
    pub alpha_x: f32,
    pub alpha_y: f32,
}

impl AnisoGgx {
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let s = (m.x / ax).powi(2) + (m.y / ay).powi(2) + m.z * m.z;
        let r = 1.0 / (PI * ax * ay * s * s);
        // Mitsuba drops values this small to avoid trouble elsewhere; so does glint.
        if r * m.z > 1e-20 && r.is_finite() {
            r
        } else {
            0.0
        }
    }

    /// Smith's masking of direction `v` for microfacet normal `m`.
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let xy = (self.alpha_x * v.x).powi(2) + (self.alpha_y * v.y).powi(2);
        if xy == 0.0 {
            return 1.0;
        }
        let tan2 = xy / (v.z * v.z);
        2.0 / (1.0 + (1.0 + tan2).sqrt())
    }

    pub fn g(&self, a: Vec3, b: Vec3, m: Vec3) -> f32 {
        self.g1(a, m) * self.g1(b, m)
    }

    /// Density of visible normals seen from `v` (upper hemisphere).
    pub fn pdf_visible(&self, v: Vec3, m: Vec3) -> f32 {
        if v.z <= 0.0 {
            return 0.0;
        }
        let p = self.d(m) * self.g1(v, m) * v.dot(m).abs() / v.z;
        if p > 1e-20 {
            p
        } else {
            0.0
        }
    }

    /// A visible normal for `v` (upper hemisphere), by Heitz's 2018 method: stretch the
    /// view to the unit-roughness configuration, sample the projected hemisphere, unstretch.
    pub fn sample_visible(&self, v: Vec3, u: [f32; 2]) -> Vec3 {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let vh = Vec3 { x: ax * v.x, y: ay * v.y, z: v.z }.normalize();
        let lensq = vh.x * vh.x + vh.y * vh.y;
        let t1 = if lensq > 0.0 { Vec3 { x: -vh.y, y: vh.x, z: 0.0 } / lensq.sqrt() } else { Vec3::X };
        let t2 = vh.cross(t1);
        let r = u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        Vec3 { x: ax * nh.x, y: ay * nh.y, z: nh.z.max(1e-6) }.normalize()
    }
}

/// Burley's GTR1 distribution of the clearcoat (normals sampled from D cos θ).
#[derive(Clone, Copy, Debug)]
struct Gtr1 {
    alpha: f32,
}

impl Gtr1 {
    fn d(&self, m: Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let r = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * m.z * m.z));
        if r * m.z > 1e-20 {
            r
        } else {
            0.0
        }
    }

    fn pdf(&self, m: Vec3) -> f32 {
        if m.z < 0.0 {
            0.0
        } else {
            m.z * self.d(m)
        }
    }

    fn sample(&self, u: [f32; 2]) -> Vec3 {
        let (sin_phi, cos_phi) = (2.0 * PI * u[0]).sin_cos();
        let a2 = self.alpha * self.alpha;
        let cos2 = (1.0 - a2.powf(1.0 - u[1])) / (1.0 - a2);
        let sin_t = (1.0 - cos2).max(0.0).sqrt();
        Vec3 { x: cos_phi * sin_t, y: sin_phi * sin_t, z: cos2.max(0.0).sqrt() }
    }
}

/// Smith GGX masking with an isotropic `alpha` (the clearcoat's, fixed at 0.25).
fn smith_ggx1(v: Vec3, m: Vec3, alpha: f32) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    if v.z == 1.0 {
        return 1.0;
    }
    let c2 = v.z * v.z;
    let tan2 = (1.0 - c2) / c2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

pub(crate) fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    m * m * m * m * m
}

pub(crate) fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a * (1.0 - t) + b * t
}

/// Schlick's Fresnel with normal reflectance `r0` (per channel); inside a denser medium the
/// transmitted cosine is used, as Mitsuba does.
pub(crate) fn schlick(r0: Rgb, cos_i: f32, eta: f32) -> Rgb {
    let outside = cos_i >= 0.0;
    let (eta_it, eta_ti) = if outside { (eta, 1.0 / eta) } else { (1.0 / eta, eta) };
    let w = if eta_it > 1.0 {
        schlick_weight(cos_i.abs())
    } else {
        let cos_t2 = 1.0 - (1.0 - cos_i * cos_i) * eta_ti * eta_ti;
        schlick_weight(cos_t2.max(0.0).sqrt())
    };
    r0.map(|r| lerp(w, 1.0, r))
}

pub(crate) fn schlick_r0(eta: f32) -> f32 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// `base_color` over its luminance (white where it has none): the tint of `spec_tint` and
/// `sheen_tint`.
pub(crate) fn tint_of(base: Rgb) -> Rgb {
    let lum = base.luminance();
    if lum > 0.0 {
        base / lum
    } else {
        Rgb::WHITE
    }
}

/// Burley's diffuse lobe without its albedo and 1/π: the diffuse and retro-reflection
/// response, blended by `flatness` (when positive) with the Hanrahan-Krueger-like fake
/// subsurface term flattened by roughness. `ci` and `co` are the absolute cosines of the
/// light and view directions, `cos_d` the cosine between the light and the half vector.
/// Shared by `principled` and `principledthin`, whose lobes are the same term for term.
pub(crate) fn disney_diffuse(roughness: f32, flatness: f32, ci: f32, co: f32, cos_d: f32) -> f32 {
    let (f_light, f_view) = (schlick_weight(ci), schlick_weight(co));
    let f_diff = (1.0 - 0.5 * f_view) * (1.0 - 0.5 * f_light);
    let rr = 2.0 * roughness * cos_d * cos_d;
    let f_retro = rr * (f_light + f_view + f_light * f_view * (rr - 1.0));
    let mut lobe = f_diff + f_retro;
    if flatness > 0.0 {
        // Hanrahan-Krueger-like fake subsurface, flattened by roughness.
        let fss90 = rr / 2.0;
        let fss = lerp(1.0, fss90, f_light) * lerp(1.0, fss90, f_view);
        let f_ss = 1.25 * (fss * (1.0 / (ci + co) - 0.5) + 0.5);
        lobe = lerp(lobe, f_ss, flatness);
    }
    lobe
}

/// Mitsuba's `*_sampling_rate` parameters: relative weights of the lobes when sampling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledRates {
    pub diffuse: f32,
    pub specular: f32,
    pub clearcoat: f32,
}

impl Default for PrincipledRates {
    fn default() -> Self {
        PrincipledRates { diffuse: 1.0, specular: 1.0, clearcoat: 1.0 }
    }
}

/// The principled BSDF at one point (textures looked up).
#[derive(Clone, Copy, Debug)]
pub struct Principled {
    pub base_color: Rgb,
    pub roughness: f32,
    pub dist: AnisoGgx,
    pub metallic: f32,
    pub spec_trans: f32,
    /// Interior over exterior index (from `eta`, or from `specular`).
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    pub clearcoat: f32,
    /// GTR1 roughness of the clearcoat, lerp(0.1, 0.001, clearcoat_gloss).
    pub clearcoat_alpha: f32,
    pub rates: PrincipledRates,
}

/// The parameters as the user gives them, before the derived roughnesses.
#[derive(Clone, Copy, Debug)]
pub struct PrincipledInputs {
    pub base_color: Rgb,
    pub roughness: f32,
    pub anisotropic: f32,
    pub metallic: f32,
    pub spec_trans: f32,
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    pub clearcoat: f32,
    pub clearcoat_gloss: f32,
    pub rates: PrincipledRates,
}

/// The main lobe's (alpha_x, alpha_y) from roughness and anisotropy (Burley's mapping).
pub fn principled_alphas(roughness: f32, anisotropic: f32) -> (f32, f32) {
    let r2 = roughness * roughness;
    // anisotropic is validated to [0, 1], so the aspect is at least sqrt(0.1).
    let aspect = (1.0 - 0.9 * anisotropic.clamp(0.0, 1.0)).sqrt();
    ((r2 / aspect).max(0.001), (r2 * aspect).max(0.001))
}

/// Whether the configuration of `m` with the two directions is a reflection (or, when
/// `reflection` is false, a refraction) through that microfacet seen from `wo`'s side.
pub(crate) fn compatible(m: Vec3, wo: Vec3, wi: Vec3, cos_o: f32, reflection: bool) -> bool {
    let ms = if cos_o < 0.0 { -m } else { m };
    if reflection {
        wo.dot(ms) > 0.0 && wi.dot(ms) > 0.0
    } else {
        wo.dot(ms) > 0.0 && wi.dot(ms) < 0.0
    }
}

/// What `pdf` and `sample` share: the lobe probabilities for one microfacet Fresnel value.
struct LobeProbabilities {
    diffuse: f32,
    clearcoat: f32,
    spec_trans: f32,
    spec_reflect: f32,
}

impl Principled {
    pub fn new(p: &PrincipledInputs) -> Principled {
        let (alpha_x, alpha_y) = principled_alphas(p.roughness, p.anisotropic);
        // Mitsuba nudges eta = 1 off one when there is transmission (it would not refract).
        let eta = if p.spec_trans > 0.0 && p.eta == 1.0 { 1.001 } else { p.eta };
        Principled {
            base_color: p.base_color,
            roughness: p.roughness,
            dist: AnisoGgx { alpha_x, alpha_y },
            metallic: p.metallic,
            spec_trans: p.spec_trans,
            eta,
            spec_tint: p.spec_tint,
            sheen: p.sheen,
            sheen_tint: p.sheen_tint,
            flatness: p.flatness,
            clearcoat: p.clearcoat,
            clearcoat_alpha: lerp(0.1, 0.001, p.clearcoat_gloss),
            rates: p.rates,
        }
    }

    /// Weights of the diffuse (BRDF) and transmissive (BSDF) major lobes.
    fn weights(&self) -> (f32, f32) {
        let dielectric = 1.0 - self.metallic;
        (dielectric * (1.0 - self.spec_trans), dielectric * self.spec_trans)
    }

    fn probabilities(&self, front: bool, f: f32) -> Option<LobeProbabilities> {
        let (brdf, bsdf) = self.weights();
        let r = &self.rates;
        let mut p = if front {
            LobeProbabilities {
                diffuse: brdf * r.diffuse,
                clearcoat: 0.25 * self.clearcoat * r.clearcoat,
                spec_trans: if self.spec_trans > 0.0 { r.specular * bsdf * (1.0 - f) } else { 0.0 },
                spec_reflect: r.specular * (1.0 - bsdf * (1.0 - f)),
            }
        } else {
            LobeProbabilities {
                diffuse: 0.0,
                clearcoat: 0.0,
                spec_trans: if self.spec_trans > 0.0 { 1.0 - f } else { 0.0 },
                spec_reflect: f,
            }
        };
        let total = p.diffuse + p.clearcoat + p.spec_trans + p.spec_reflect;
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        p.diffuse /= total;
        p.clearcoat /= total;
        p.spec_trans /= total;
        p.spec_reflect /= total;
        Some(p)
    }

    /// The generalised half vector (towards +z) and the relative index along the path.
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, bool)> {
        let reflect = wo.z * wi.z > 0.0;
        let eta_path = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let h = wo + wi * if reflect { 1.0 } else { eta_path };
        if !(h.length_squared() > 0.0) {
            return None;
        }
        let h = h.normalize();
        Some((if h.z < 0.0 { -h } else { h }, eta_path, reflect))
    }

    /// Fresnel of the main reflection: dielectric, blended with Schlick terms for the
    /// metallic and tinted parts on the front side; plain dielectric (times the transmission
    /// weight) from inside.
    fn main_fresnel(&self, f_dielectric: f32, cos: f32, front: bool) -> Rgb {
        let (_, bsdf) = self.weights();
        if !front {
            return Rgb::splat(bsdf * f_dielectric);
        }
        let eta_it = if cos >= 0.0 { self.eta } else { 1.0 / self.eta };
        let mut f = Rgb::BLACK;
        if self.metallic > 0.0 {
            f += schlick(self.base_color, cos, self.eta) * self.metallic;
        }
        if self.spec_tint > 0.0 {
            let r0 = tint_of(self.base_color) * schlick_r0(eta_it);
            f += schlick(r0, cos, self.eta) * ((1.0 - self.metallic) * self.spec_tint);
        }
        f + Rgb::splat((1.0 - self.metallic) * (1.0 - self.spec_tint) * f_dielectric)
    }

    fn diffuse_and_sheen(&self, wo: Vec3, wi: Vec3, wh: Vec3, brdf: f32) -> Rgb {
        let (ci, co) = (wi.z.abs(), wo.z.abs());
        let cos_d = wh.dot(wi);
        let lobe = disney_diffuse(self.roughness, self.flatness, ci, co, cos_d);
        let mut value = self.base_color * (brdf * ci * INV_PI * lobe);
        if self.sheen > 0.0 && 1.0 - self.metallic > 0.0 {
            let fd = schlick_weight(cos_d.abs());
            let c_sheen = Rgb::WHITE * (1.0 - self.sheen_tint) + tint_of(self.base_color) * self.sheen_tint;
            value += c_sheen * (self.sheen * (1.0 - self.metallic) * fd * ci);
        }
        value
    }
}

impl Scatter for Principled {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 {
            return Rgb::BLACK;
        }
        let Some((wh, eta_path, reflect)) = self.half_vector(wo, wi) else { return Rgb::BLACK };
        let refract = cos_o * cos_i < 0.0;
        let front = cos_o > 0.0;
        let (brdf, bsdf) = self.weights();
        let f_d = fresnel_dielectric(wo.dot(wh), self.eta).reflectance;
        let reflect_ok = compatible(wh, wo, wi, cos_o, true);
        let refract_ok = compatible(wh, wo, wi, cos_o, false);
        let d = self.dist.d(wh);
        let g = self.dist.g(wo, wi, wh);
        let mut value = Rgb::BLACK;
        if reflect && reflect_ok && f_d > 0.0 {
            value += self.main_fresnel(f_d, wo.dot(wh), front) * (d * g / (4.0 * cos_o.abs()));
        }
        if bsdf > 0.0 && refract && refract_ok && f_d < 1.0 {
            // Radiance is compressed by 1/eta_path² when it refracts.
            let scale = 1.0 / (eta_path * eta_path);
            let (oh, ih) = (wo.dot(wh), wi.dot(wh));
            let t =
                scale * (1.0 - f_d) * d * g * eta_path * eta_path * oh * ih / (cos_o * (oh + eta_path * ih).powi(2));
            value += self.base_color.map(f32::sqrt) * (bsdf * t.abs());
        }
        if self.clearcoat > 0.0 && reflect && reflect_ok && front {
            let fcc = schlick(Rgb::splat(0.04), wo.dot(wh), self.eta).r;
            let dcc = Gtr1 { alpha: self.clearcoat_alpha }.d(wh);
            let gcc = smith_ggx1(wo, wh, 0.25) * smith_ggx1(wi, wh, 0.25);
            value += Rgb::splat(self.clearcoat * 0.25 * fcc * dcc * gcc * cos_i.abs());
        }
        if brdf > 0.0 && reflect && front {
            value += self.diffuse_and_sheen(wo, wi, wh, brdf);
        }
        value
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 {
            return 0.0;
        }
        let Some((wh, eta_path, reflect)) = self.half_vector(wo, wi) else { return 0.0 };
        let refract = cos_o * cos_i < 0.0;
        let front = cos_o > 0.0;
        let f_d = fresnel_dielectric(wo.dot(wh), self.eta).reflectance;
        let Some(p) = self.probabilities(front, f_d) else { return 0.0 };
        let (oh, ih) = (wo.dot(wh), wi.dot(wh));
        let dwh_dwi = if reflect {
            (1.0 / (4.0 * ih)).abs()
        } else {
            (eta_path * eta_path * ih / (oh + eta_path * ih).powi(2)).abs()
        };
        let v = if cos_o < 0.0 { -wo } else { wo };
        let mut pdf = 0.0;
        let reflect_ok = reflect && compatible(wh, wo, wi, cos_o, true);
        if reflect_ok {
            pdf += p.spec_reflect * self.dist.pdf_visible(v, wh) * dwh_dwi;
            if p.clearcoat > 0.0 {
                pdf += p.clearcoat * Gtr1 { alpha: self.clearcoat_alpha }.pdf(wh) * dwh_dwi;
            }
        }
        if reflect && p.diffuse > 0.0 {
            pdf += p.diffuse * warp::cosine_hemisphere_pdf(cos_i.abs());
        }
        if refract && p.spec_trans > 0.0 && compatible(wh, wo, wi, cos_o, false) {
            pdf += p.spec_trans * self.dist.pdf_visible(v, wh) * dwh_dwi;
        }
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 {
            return None;
        }
        let front = cos_o > 0.0;
        let (_, bsdf) = self.weights();
        if !front && !(bsdf > 0.0) {
            return None;
        }
        let v = if front { wo } else { -wo };
        let m = self.dist.sample_visible(v, u);
        let fr = fresnel_dielectric(wo.dot(m), self.eta);
        let p = self.probabilities(front, fr.reflectance)?;
        let (mut eta, mut refracted) = (1.0, false);
        let wi = if u_lobe < p.diffuse {
            warp::cosine_hemisphere(u)
        } else if u_lobe < p.diffuse + p.clearcoat {
            let mc = Gtr1 { alpha: self.clearcoat_alpha }.sample(u);
            let wi = mc * (2.0 * wo.dot(mc)) - wo;
            if !compatible(mc, wo, wi, cos_o, true) {
                return None;
            }
            wi
        } else if u_lobe < p.diffuse + p.clearcoat + p.spec_trans {
            if fr.reflectance >= 1.0 {
                return None;
            }
            let cos_om = wo.dot(m);
            let wi = (-wo / fr.eta_ti + m * (cos_om / fr.eta_ti + fr.cos_t)).normalize();
            if !(cos_o * wi.z < 0.0) || !compatible(m, wo, wi, cos_o, false) {
                return None;
            }
            (eta, refracted) = (fr.eta_ti, true);
            wi
        } else {
            let wi = m * (2.0 * wo.dot(m)) - wo;
            if !compatible(m, wo, wi, cos_o, true) {
                return None;
            }
            wi
        };
        if !refracted && cos_o * wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        let value = self.eval(wo, wi);
        Some(BsdfSample { wi, weight: value / pdf, pdf, delta: false, eta })
    }

    /// The diffuse colour (for the Whitted integrator and denoiser guides).
    fn diffuse_reflectance(&self) -> Rgb {
        self.base_color
    }
}
