//! The glTF 2.0 metallic-roughness BRDF (the specification's Appendix B) and the KHR
//! material extensions that change the scattering (`KHR_materials_ior`, `_specular`,
//! `_transmission`, `_volume`'s thin-walled or refractive boundary, `_clearcoat`, `_sheen`),
//! evaluated at one point: textures, factors and vertex colours already multiplied in by the
//! material. docs/gltf-brdf.md describes the model, its sampling and how it is tested.
//!
//! In the frame where `wo` is above the surface (a `wo` below is mirrored there: the back of
//! a double-sided or thin surface scatters as its front, and the inside of a volume boundary
//! sees the index ratio inverted):
//!
//! ```text
//! core     = metallic F_m(h) spec(h) + (1 - metallic) [F_d(h) spec(h) + (1 - max F_d(h)) base]
//! base     = (1 - T) baseColor / π  (reflection)  |  T baseColor btdf(wo, wi)  (transmission)
//! sheened  = sheenColor charlie(wo, wi) + core min(1 - max(sheenColor) E(cos o), ... E(cos i))
//! coated   = clearcoat F_c(cos o) coat(wo, wi) + (1 - clearcoat F_c(cos o)) sheened
//! ```
//!
//! spec and coat are GGX with the height-correlated Smith visibility (alpha = roughness²,
//! clamped at glint's microfacet bound 1e-4 rather than made a delta lobe: roughness comes
//! from textures, and one continuous lobe keeps MIS and light sampling valid across texels);
//! F_m and F_d are Schlick's (F_d with `KHR_materials_specular`'s f0 and f90, and, at a
//! volume boundary, the cosine on the thinner side with total internal reflection as
//! `KHR_materials_volume` gives them); btdf is the thin wall's mirrored GGX lobe or Walter's
//! refraction through the microfacet (radiance scaled by 1/eta² as everywhere in glint).

use super::lobes::{
    charlie_d, charlie_vis, schlick_weight, sheen_albedo, sheen_alpha, vis_height_correlated, vis_separable,
};
use crate::bsdf::{fresnel_dielectric, BsdfSample, Microfacet, MicrofacetKind, Scatter};
use crate::math::{Rgb, Vec3, INV_PI};
use crate::sampling::warp;

/// The glTF material at one point. Defaults (without an extension) are the specification's.
#[derive(Clone, Copy, Debug)]
pub struct GltfPbr {
    /// Linear base colour: `baseColorFactor` x `baseColorTexture` (sRGB decoded) x `COLOR_0`.
    pub base_color: Rgb,
    /// 0 dielectric to 1 metal (`metallicFactor` x the texture's blue channel).
    pub metallic: f32,
    /// Perceptual roughness (`roughnessFactor` x the texture's green channel); the GGX
    /// alpha is its square.
    pub roughness: f32,
    /// `KHR_materials_ior` (1.5 without it).
    pub ior: f32,
    /// `KHR_materials_specular`: strength of the dielectric specular layer (1 without it).
    pub specular: f32,
    /// `KHR_materials_specular`: colour of the dielectric F0 (white without it).
    pub specular_color: Rgb,
    /// `KHR_materials_transmission` (0 without it).
    pub transmission: f32,
    /// True without `KHR_materials_volume` (or with thickness 0): light crosses the surface
    /// as through a thin wall, without refraction; false: the surface bounds a volume.
    pub thin_walled: bool,
    /// `KHR_materials_clearcoat` strength (0 without it).
    pub clearcoat: f32,
    /// `KHR_materials_clearcoat` perceptual roughness.
    pub clearcoat_roughness: f32,
    /// `KHR_materials_sheen` colour (black without it).
    pub sheen_color: Rgb,
    /// `KHR_materials_sheen` perceptual roughness.
    pub sheen_roughness: f32,
}

/// Mirror through the surface plane (the frame flip and the thin wall's straight-through
/// direction).
fn mirror(v: Vec3) -> Vec3 {
    Vec3 { x: v.x, y: v.y, z: -v.z }
}

fn reflect(wo: Vec3, h: Vec3) -> Vec3 {
    h * (2.0 * wo.dot(h)) - wo
}

/// The refraction half vector of `wo` (above) and `wi` (below), `eta` = n(wi side) /
/// n(wo side), towards +z; `None` unless both see the microfacet from their own side.
fn refraction_half(wo: Vec3, wi: Vec3, eta: f32) -> Option<Vec3> {
    let h = wo + wi * eta;
    if !(h.length_squared() > 0.0) {
        return None;
    }
    let h = h.normalize();
    let h = if h.z < 0.0 { -h } else { h };
    (wo.dot(h) > 0.0 && wi.dot(h) < 0.0).then_some(h)
}

/// The material in the frame where `wo` is above the surface.
struct Oriented<'a> {
    m: &'a GltfPbr,
    /// n(far side) / n(wo's side) at a volume boundary; `None` for a thin wall.
    eta: Option<f32>,
    dist: Microfacet,
    coat: Microfacet,
    metallic: f32,
    transmission: f32,
    clearcoat: f32,
    /// α_g of the sheen, `None` when the sheen colour is black.
    sheen: Option<f32>,
}

/// Probabilities of the three sampling groups: the coat's GGX lobe, the cosine-distributed
/// lobes (diffuse and sheen) and the base's GGX lobe (reflection or transmission).
struct Groups {
    coat: f32,
    cosine: f32,
    micro: f32,
}

impl Oriented<'_> {
    /// F_c of `KHR_materials_clearcoat`, weighted: clearcoat (0.04 + 0.96 (1 - cos o)^5).
    fn coat_weight(&self, co: f32) -> f32 {
        self.clearcoat * (0.04 + 0.96 * schlick_weight(co))
    }

    /// The sheen's albedo scaling of everything under it, min over both directions (at
    /// least 0: near grazing the fitted sheen's albedo exceeds 1).
    fn sheen_scaling(&self, co: f32, ci: f32) -> f32 {
        match self.sheen {
            None => 1.0,
            Some(_) => {
                let c = self.m.sheen_color.max_component();
                let r = self.m.sheen_roughness;
                (1.0 - c * sheen_albedo(co, r)).min(1.0 - c * sheen_albedo(ci.abs(), r)).max(0.0)
            }
        }
    }

    /// F_d for a microfacet seen at `cos_oh` from wo's side: Schlick with
    /// `KHR_materials_specular`'s f0 and f90, on the thinner side's cosine; white under total
    /// internal reflection (`KHR_materials_volume`: f90 is not scaled there).
    fn dielectric_fresnel(&self, cos_oh: f32) -> Rgb {
        let c = match self.eta {
            Some(eta) if eta < 1.0 => {
                let sin2 = (1.0 - cos_oh * cos_oh) / (eta * eta);
                if sin2 >= 1.0 {
                    return Rgb::WHITE;
                }
                (1.0 - sin2).sqrt()
            }
            _ => cos_oh,
        };
        let f0 = self.m.dielectric_f0();
        f0 + (Rgb::splat(self.m.specular) - f0) * schlick_weight(c)
    }

    /// conductor_fresnel: Schlick with f0 = baseColor.
    fn metal_fresnel(&self, cos_oh: f32) -> Rgb {
        let b = self.m.base_color;
        b + (Rgb::WHITE - b) * schlick_weight(cos_oh)
    }

    /// The base's reflected and transmitted weights at microfacet `cos_oh` (channel
    /// averages of the factors in front of the GGX lobes), which split the GGX group.
    fn micro_split(&self, cos_oh: f32) -> (f32, f32) {
        let fd = self.dielectric_fresnel(cos_oh);
        let r = self.metallic * self.metal_fresnel(cos_oh).average() + (1.0 - self.metallic) * fd.average();
        let t = (1.0 - self.metallic) * (1.0 - fd.max_component()) * self.transmission * self.m.base_color.average();
        (r, t)
    }

    /// Probability of choosing reflection within the GGX group.
    fn p_reflect(&self, cos_oh: f32) -> f32 {
        let (r, t) = self.micro_split(cos_oh);
        if r + t > 0.0 {
            r / (r + t)
        } else {
            1.0
        }
    }

    /// Group probabilities from estimates of each group's albedo at `co` (Schlick at the
    /// normal). A group that can scatter at all keeps at least a small share, so that the
    /// mixture's density is never zero where `eval` is not.
    fn groups(&self, co: f32) -> Option<Groups> {
        let w = schlick_weight(co);
        let coat = self.coat_weight(co);
        let sheen_e = match self.sheen {
            Some(_) => self.m.sheen_color.max_component() * sheen_albedo(co, self.m.sheen_roughness),
            None => 0.0,
        };
        let under = (1.0 - coat) * (1.0 - sheen_e).max(0.0);
        let f0 = self.m.dielectric_f0();
        let fd = f0 + (Rgb::splat(self.m.specular) - f0) * w;
        let fm = self.m.base_color + (Rgb::WHITE - self.m.base_color) * w;
        let base = self.m.base_color.average();
        let dielectric = 1.0 - self.metallic;
        let floor = |possible: bool, est: f32| if possible { est.max(0.01) } else { 0.0 };
        let diffuse_possible = dielectric > 0.0 && self.transmission < 1.0 && base > 0.0;
        let diffuse = under * dielectric * (1.0 - fd.max_component()) * (1.0 - self.transmission) * base;
        let cosine = floor(diffuse_possible || self.sheen.is_some(), diffuse + (1.0 - coat) * sheen_e);
        let micro_possible = self.metallic > 0.0
            || (dielectric > 0.0 && (self.m.specular > 0.0 || (self.transmission > 0.0 && base > 0.0)));
        let micro_est = self.metallic * fm.average()
            + dielectric * (fd.average() + (1.0 - fd.max_component()) * self.transmission * base);
        let micro = floor(micro_possible, under * micro_est);
        let total = coat + cosine + micro;
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        Some(Groups { coat: coat / total, cosine: cosine / total, micro: micro / total })
    }

    /// The transmission lobe without baseColor and weights: btdf(wo, wi) (no cosine), for
    /// `wi` below the surface.
    fn btdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let alpha = self.dist.alpha_u;
        match self.eta {
            None => {
                let wr = mirror(wi);
                let h = (wo + wr).normalize();
                let fd = self.dielectric_fresnel(wo.dot(h));
                (1.0 - fd.max_component()) * self.dist.d(h) * vis_separable(alpha, wo.z, wr.z)
            }
            Some(eta) => {
                let Some(h) = refraction_half(wo, wi, eta) else { return 0.0 };
                let (oh, ih) = (wo.dot(h), wi.dot(h));
                let fd = self.dielectric_fresnel(oh);
                let g = vis_separable(alpha, wo.z, wi.z) * 4.0 * wo.z * wi.z.abs();
                let denom = (oh + eta * ih).powi(2) * wo.z * wi.z.abs();
                (1.0 - fd.max_component()) * self.dist.d(h) * g * (oh * ih).abs() / denom
            }
        }
    }

    /// eval (with |cos θi|) for `wo` above the surface.
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let (co, ci) = (wo.z, wi.z);
        let mut core = Rgb::BLACK;
        let mut sheen = Rgb::BLACK;
        let mut coat = 0.0;
        if ci > 0.0 {
            let h = (wo + wi).normalize();
            let oh = wo.dot(h);
            let spec = self.dist.d(h) * vis_height_correlated(self.dist.alpha_u, co, ci);
            let fd = self.dielectric_fresnel(oh);
            let diffuse = self.m.base_color * ((1.0 - fd.max_component()) * (1.0 - self.transmission) * INV_PI);
            core = self.metal_fresnel(oh) * (self.metallic * spec) + (fd * spec + diffuse) * (1.0 - self.metallic);
            if let Some(a) = self.sheen {
                sheen = self.m.sheen_color * (charlie_d(a, h.z) * charlie_vis(a, co, ci));
            }
            if self.clearcoat > 0.0 {
                coat = self.coat.d(h) * vis_height_correlated(self.coat.alpha_u, co, ci);
            }
        } else if ci < 0.0 && self.transmission > 0.0 && self.metallic < 1.0 {
            core = self.m.base_color * ((1.0 - self.metallic) * self.transmission * self.btdf(wo, wi));
        }
        let cw = self.coat_weight(co);
        let sheened = core * self.sheen_scaling(co, ci) + sheen;
        (sheened * (1.0 - cw) + Rgb::splat(cw * coat)) * ci.abs()
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(g) = self.groups(wo.z) else { return 0.0 };
        let mut pdf = 0.0;
        if wi.z > 0.0 {
            let h = (wo + wi).normalize();
            let jacobian = 1.0 / (4.0 * wo.dot(h));
            if g.coat > 0.0 {
                pdf += g.coat * self.coat.pdf_wm(wo, h) * jacobian;
            }
            pdf += g.cosine * warp::cosine_hemisphere_pdf(wi.z);
            if g.micro > 0.0 {
                pdf += g.micro * self.dist.pdf_wm(wo, h) * jacobian * self.p_reflect(wo.dot(h));
            }
        } else if wi.z < 0.0 && g.micro > 0.0 {
            pdf += g.micro
                * match self.eta {
                    None => {
                        let h = (wo + mirror(wi)).normalize();
                        let oh = wo.dot(h);
                        self.dist.pdf_wm(wo, h) / (4.0 * oh) * (1.0 - self.p_reflect(oh))
                    }
                    Some(eta) => match refraction_half(wo, wi, eta) {
                        None => 0.0,
                        Some(h) => {
                            let (oh, ih) = (wo.dot(h), wi.dot(h));
                            let jacobian = eta * eta * ih.abs() / (oh + eta * ih).powi(2);
                            self.dist.pdf_wm(wo, h) * jacobian * (1.0 - self.p_reflect(oh))
                        }
                    },
                };
        }
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    /// A sampled direction and the relative index crossed (1 unless refracted).
    fn sample_direction(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<(Vec3, f32)> {
        let g = self.groups(wo.z)?;
        if u_lobe < g.coat {
            let wi = reflect(wo, self.coat.sample_wm(wo, u));
            return (wi.z > 0.0).then_some((wi, 1.0));
        }
        if u_lobe < g.coat + g.cosine {
            return Some((warp::cosine_hemisphere(u), 1.0));
        }
        // Reuse what is left of u_lobe to choose reflection or transmission.
        let u_split = ((u_lobe - g.coat - g.cosine) / g.micro).clamp(0.0, 1.0);
        let h = self.dist.sample_wm(wo, u);
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return None;
        }
        if u_split < self.p_reflect(oh) {
            let wi = reflect(wo, h);
            return (wi.z > 0.0).then_some((wi, 1.0));
        }
        match self.eta {
            None => {
                let wi = mirror(reflect(wo, h));
                (wi.z < 0.0).then_some((wi, 1.0))
            }
            Some(eta) => {
                let fr = fresnel_dielectric(oh, eta);
                if fr.reflectance >= 1.0 {
                    return None;
                }
                let wi = (-wo / fr.eta_ti + h * (oh / fr.eta_ti + fr.cos_t)).normalize();
                (wi.z < 0.0).then_some((wi, fr.eta_ti))
            }
        }
    }
}

impl GltfPbr {
    /// The specification's default material: white, metallic 1, roughness 1.
    pub fn default_material() -> GltfPbr {
        GltfPbr {
            base_color: Rgb::splat(1.0),
            metallic: 1.0,
            roughness: 1.0,
            ior: 1.5,
            specular: 1.0,
            specular_color: Rgb::splat(1.0),
            transmission: 0.0,
            thin_walled: true,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            sheen_color: Rgb::BLACK,
            sheen_roughness: 0.0,
        }
    }

    /// `KHR_materials_specular`'s dielectric f0: min(f0(ior) specularColor, 1) specular.
    fn dielectric_f0(&self) -> Rgb {
        let r = ((self.ior - 1.0) / (self.ior + 1.0)).powi(2);
        let r = if r.is_finite() { r } else { 1.0 };
        (self.specular_color * r).map(|c| c.min(1.0)) * self.specular
    }

    /// The index ratio refraction uses at a volume boundary: `ior` (nudged off 1, where
    /// the refraction half vector is undefined, as Mitsuba's principled does; `ior` 0, the
    /// specular-glossiness conversion, has no refraction and gets the same).
    fn refraction_eta(&self) -> f32 {
        if self.ior.is_finite() {
            self.ior.max(1.001)
        } else {
            1.001
        }
    }

    /// The material seen from `wo`'s side: `back` when `wo` was below the surface.
    fn oriented(&self, back: bool) -> Oriented<'_> {
        let eta = (!self.thin_walled).then(|| if back { 1.0 / self.refraction_eta() } else { self.refraction_eta() });
        let alpha = |r: f32| {
            let r = r.clamp(0.0, 1.0);
            r * r
        };
        Oriented {
            m: self,
            eta,
            dist: Microfacet::new(MicrofacetKind::Ggx, alpha(self.roughness)),
            coat: Microfacet::new(MicrofacetKind::Ggx, alpha(self.clearcoat_roughness)),
            metallic: self.metallic.clamp(0.0, 1.0),
            transmission: self.transmission.clamp(0.0, 1.0),
            clearcoat: self.clearcoat.clamp(0.0, 1.0),
            sheen: (self.sheen_color.max_component() > 0.0).then(|| sheen_alpha(self.sheen_roughness)),
        }
    }

    fn diffuse_albedo(&self) -> Rgb {
        self.base_color * ((1.0 - self.metallic.clamp(0.0, 1.0)) * (1.0 - self.transmission.clamp(0.0, 1.0)))
    }
}

/// `wo` and `wi` in the frame where `wo` is above, and whether they were mirrored.
fn orient(wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3, bool)> {
    if wo.z > 0.0 {
        Some((wo, wi, false))
    } else if wo.z < 0.0 {
        Some((mirror(wo), mirror(wi), true))
    } else {
        None
    }
}

impl Scatter for GltfPbr {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match orient(wo, wi) {
            Some((wo, wi, back)) if wi.z != 0.0 => self.oriented(back).eval(wo, wi),
            _ => Rgb::BLACK,
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match orient(wo, wi) {
            Some((wo, wi, back)) if wi.z != 0.0 => self.oriented(back).pdf(wo, wi),
            _ => 0.0,
        }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let (wo_up, _, back) = orient(wo, wo)?;
        let m = self.oriented(back);
        let (wi_up, eta) = m.sample_direction(wo_up, u_lobe, u)?;
        let pdf = m.pdf(wo_up, wi_up);
        if !(pdf > 0.0) || wi_up.z == 0.0 {
            return None;
        }
        let value = m.eval(wo_up, wi_up);
        let wi = if back { mirror(wi_up) } else { wi_up };
        Some(BsdfSample { wi, weight: value / pdf, pdf, delta: false, eta })
    }

    fn diffuse_reflectance(&self) -> Rgb {
        self.diffuse_albedo()
    }
}
