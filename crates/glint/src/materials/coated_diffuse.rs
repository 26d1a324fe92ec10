//! pbrt-v4's `coateddiffuse`: a Lambertian base under a slab of homogeneous medium under a
//! smooth or rough dielectric coating. Nothing is tabulated or fitted: `eval`, `pdf` and
//! `sample` follow random walks between the two layers (pbrt-v4's `LayeredBxDF`, after Guo
//! et al. 2018, "Position-free Monte Carlo simulation for arbitrary layered BSDFs").
//!
//! # Parameters
//! (JSON `"type": "coateddiffuse"`; `ior` is accepted for `eta`.)
//!
//! | Parameter | Type | Default | Description |
//! |---|---|---|---|
//! | `reflectance` | spectrum or texture | 0.5 | Albedo of the Lambertian base. |
//! | `roughness` | float | 0 | GGX (Trowbridge-Reitz) α of the coating, used as given (pbrt's `remaproughness` is not applied); below 1e-3 the coating is smooth and reflects in a delta lobe. |
//! | `thickness` | float | 0.01 | Optical thickness of the slab (σt = 1 per unit). |
//! | `eta` | float | 1.5 | Index of refraction of the coating over the outside's (1: no interface). |
//! | `albedo` | spectrum | 0 | Single-scattering albedo of the slab. At 0 the slab only absorbs, exp(-thickness / cos θ) per crossing; otherwise it scatters with `g`. |
//! | `g` | float | 0 | Henyey-Greenstein mean cosine of the slab's scattering, in (-1, 1). |
//! | `maxdepth` | integer | 10 | Most scattering events (base, medium, or internal reflections at the coating) inside the coating on one path; longer paths are dropped, so the BSDF loses a little energy. |
//! | `nsamples` | integer | 1 | Random walks averaged by one `eval` or `pdf`. |
//!
//! # Estimators and determinism
//! `eval(wo, wi)` is an unbiased estimate of the layered BSDF (truncated at `maxdepth`) from
//! `nsamples` walks entering through the coating towards `wo` and leaving by next-event
//! estimation towards `wi`, as pbrt-v4 does. `pdf(wo, wi)` runs the same walk with each
//! kernel replaced by the density with which `sample` moves (the base sampled by cosine, the
//! medium by its phase function and free flights, the coating by Fresnel-weighted lobes), so
//! that it is an unbiased estimate of the density of `sample` itself: glint's tests can
//! compare sampled directions with its average. pbrt-v4 instead mixes a rougher estimate with
//! a uniform density; that suffices for MIS weights but is no density. `sample` follows one
//! walk and returns its throughput as the weight, which is eval/pdf only in expectation: the
//! weight is an unbiased estimate of the BSDF over the density the walk actually has. Its
//! `pdf` is `pdf(wo, wi)`, so the MIS weights of a BSDF-sampled and a light-sampled path
//! through the same direction come from one function and sum to one. `sample` uses neither
//! `nsamples` nor Russian roulette (`eval` and `pdf` use pbrt-v4's, which keeps them
//! unbiased), so that its density is exactly the one `pdf` estimates; a smooth coating's
//! reflection is a delta sample whose `pdf` is its probability, F.
//!
//! The coating is glint's rough dielectric (`microfacet.rs`, separable Smith shadowing) or
//! smooth Fresnel; the slab's phase function is `media::Phase`'s Henyey-Greenstein.
//!
//! `Scatter` passes no random numbers to `eval` and `pdf`, so each seeds its walks by hashing
//! the bit patterns of `wo`, `wi` and [`CoatedDiffuse::seed`], with a different salt for each
//! (an `eval` correlated with the `pdf` of the same direction would bias the MIS sum, and
//! pbrt-v4 separates them the same way); `sample` hashes `wo` and its own random numbers.
//! Every render stays bit-reproducible and independent of the thread count, and averaging
//! over `seed` averages independent estimates (the tests do).
//!
//! # Differentiable
//! Every parameter `traverse` lists for it. Its BSDF value is a random-walk estimate whose
//! random numbers the directions fix, so the gradient's symmetric difference uses common
//! random numbers. See `docs/differentiable.md`.

use super::{Bsdf, Describe, MaterialKind, Shade, Texture, TextureCache, TexturePoint};
use crate::bsdf::{eval_rough_dielectric, pdf_rough_dielectric, sample_rough_dielectric};
use crate::bsdf::{fresnel_dielectric, reflect_local, refract_local, BsdfSample, Microfacet, MicrofacetKind, Scatter};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::math::{Rgb, Vec3, INV_PI};
use crate::media::Phase;
use crate::sampling::{mix64, power_heuristic, warp, Rng};
use serde::{Deserialize, Serialize};

/// Below this α the coating is smooth (pbrt-v4's `EffectivelySmooth`).
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// pbrt-v4's layered diffuse BSDF; see the module documentation for the parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoatedDiffuse {
    pub reflectance: Rgb,
    pub roughness: f32,
    pub thickness: f32,
    pub eta: f32,
    pub albedo: Rgb,
    pub g: f32,
    pub max_depth: u32,
    pub n_samples: u32,
    /// Salt of the hash that seeds the walks of `eval`, `pdf` and `sample` (0 in renders).
    pub seed: u32,
}

impl Default for CoatedDiffuse {
    /// pbrt-v4's defaults.
    fn default() -> CoatedDiffuse {
        CoatedDiffuse {
            reflectance: Rgb::splat(0.5),
            roughness: 0.0,
            thickness: 0.01,
            eta: 1.5,
            albedo: Rgb::BLACK,
            g: 0.0,
            max_depth: 10,
            n_samples: 1,
            seed: 0,
        }
    }
}

/// Bounds on `maxdepth` and `nsamples`: each bounds the work of one `eval` or `pdf`.
pub const MAX_DEPTH_LIMIT: u32 = 1000;
pub const N_SAMPLES_LIMIT: u32 = 256;

/// `coateddiffuse`'s parameters (the module documentation lists them): the base's
/// reflectance may be a texture, the rest is constant.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CoatedDiffuseDesc {
    pub reflectance: TextureDesc,
    pub roughness: f32,
    pub thickness: f32,
    pub eta: f32,
    pub albedo: Rgb,
    pub g: f32,
    pub max_depth: u32,
    pub n_samples: u32,
}

impl Default for CoatedDiffuseDesc {
    /// pbrt-v4's defaults.
    fn default() -> CoatedDiffuseDesc {
        let d = CoatedDiffuse::default();
        CoatedDiffuseDesc {
            reflectance: TextureDesc::constant(d.reflectance),
            roughness: d.roughness,
            thickness: d.thickness,
            eta: d.eta,
            albedo: d.albedo,
            g: d.g,
            max_depth: d.max_depth,
            n_samples: d.n_samples,
        }
    }
}

impl Describe for CoatedDiffuseDesc {
    type Built = CoatedDiffuseMaterial;

    fn build(&self, textures: &mut TextureCache) -> Result<CoatedDiffuseMaterial, Error> {
        Ok(CoatedDiffuseMaterial { reflectance: textures.texture(&self.reflectance)?, params: self.bsdf() })
    }

    fn validate(&self) -> Result<(), String> {
        self.bsdf().check()
    }

    fn textures(&self) -> Vec<&TextureDesc> {
        vec![&self.reflectance]
    }

    fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
        vec![&mut self.reflectance]
    }

    fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
        let mut out = Vec::new();
        texture_slot("reflectance", &mut self.reflectance, &mut out);
        out.push(("roughness", Slot::Float(&mut self.roughness)));
        out.push(("thickness", Slot::Float(&mut self.thickness)));
        out.push(("eta", Slot::Float(&mut self.eta)));
        out.push(("albedo", Slot::Color(&mut self.albedo)));
        out.push(("g", Slot::Float(&mut self.g)));
        out
    }
}

impl CoatedDiffuseDesc {
    /// The BSDF it gives, with a black base (the material looks its texture up).
    pub fn bsdf(&self) -> CoatedDiffuse {
        CoatedDiffuse {
            reflectance: Rgb::BLACK,
            roughness: self.roughness,
            thickness: self.thickness,
            eta: self.eta,
            albedo: self.albedo,
            g: self.g,
            max_depth: self.max_depth,
            n_samples: self.n_samples,
            seed: 0,
        }
    }
}

/// The textured base and the constant rest of the BSDF.
#[derive(Clone, Debug)]
pub struct CoatedDiffuseMaterial {
    pub reflectance: Texture,
    /// Everything but the base's reflectance (black here).
    pub params: CoatedDiffuse,
}

impl Shade for CoatedDiffuseMaterial {
    #[inline]
    fn bsdf_at(&self, p: &TexturePoint) -> Bsdf {
        Bsdf::CoatedDiffuse(CoatedDiffuse { reflectance: self.reflectance.eval_at(p), ..self.params })
    }

    fn albedo(&self, uv: [f32; 2]) -> Rgb {
        self.reflectance.eval(uv)
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}

impl CoatedDiffuse {
    /// The description's ranges (the base's texture is checked as a colour by the caller).
    pub fn check(&self) -> Result<(), String> {
        let finite = |name: &str, v: f32, ok: bool, range: &str| {
            if ok && v.is_finite() {
                Ok(())
            } else {
                Err(format!("coateddiffuse {name} {v} must be {range}"))
            }
        };
        finite("eta", self.eta, self.eta > 0.0, "positive and finite")?;
        finite("thickness", self.thickness, self.thickness > 0.0, "positive and finite")?;
        finite("roughness", self.roughness, self.roughness >= 0.0, "finite and at least 0")?;
        finite("g", self.g, self.g.abs() < 1.0, "in (-1, 1)")?;
        let a = self.albedo;
        if ![a.r, a.g, a.b].iter().all(|c| (0.0..=1.0).contains(c)) {
            return Err(format!("coateddiffuse albedo {a:?} must be in [0, 1]"));
        }
        for (name, n, max) in
            [("maxdepth", self.max_depth, MAX_DEPTH_LIMIT), ("nsamples", self.n_samples, N_SAMPLES_LIMIT)]
        {
            if !(1..=max).contains(&n) {
                return Err(format!("coateddiffuse {name} {n} is out of range (1 to {max})"));
            }
        }
        Ok(())
    }
}

/// Salts that keep the walks of `eval`, `pdf` and `sample` independent.
const SALT_EVAL: u64 = 0x6576_616c;
const SALT_PDF: u64 = 0x7064_6600;
const SALT_SAMPLE: u64 = 0x7361_6d70;

/// The coating: a dielectric interface, smooth (`dist` None) or GGX-rough.
#[derive(Clone, Copy, Debug)]
struct Coat {
    eta: f32,
    dist: Option<Microfacet>,
}

/// Which lobes of the coating a proposal may draw.
#[derive(Clone, Copy, PartialEq)]
enum Lobes {
    Reflect,
    Transmit,
    Both,
}

/// A direction drawn at the coating: `q` is the proposal's density for it (its probability
/// for a delta lobe), `value` the coating's eval / q (radiance, |cos| included) and `density`
/// the density of the full Fresnel-weighted sampler (which `sample` uses) over q.
#[derive(Clone, Copy, Debug)]
struct CoatSample {
    w: Vec3,
    q: f32,
    value: f32,
    density: f32,
}

impl Coat {
    fn lobe_tints(lobes: Lobes) -> (Rgb, Rgb) {
        match lobes {
            Lobes::Reflect => (Rgb::WHITE, Rgb::BLACK),
            Lobes::Transmit => (Rgb::BLACK, Rgb::WHITE),
            Lobes::Both => (Rgb::WHITE, Rgb::WHITE),
        }
    }

    /// Draws a direction from `v` (pointing away from the interface, either side).
    fn sample(&self, v: Vec3, lobes: Lobes, uc: f32, u: [f32; 2]) -> Option<CoatSample> {
        let Some(d) = &self.dist else {
            return self.sample_smooth(v, lobes, uc);
        };
        let (r, t) = Coat::lobe_tints(lobes);
        let s = sample_rough_dielectric(d, self.eta, r, t, v, uc, u)?;
        let full = if lobes == Lobes::Both { s.pdf } else { self.pdf(v, s.wi, Lobes::Both) };
        Some(CoatSample { w: s.wi, q: s.pdf, value: s.weight.r, density: full / s.pdf })
    }

    fn sample_smooth(&self, v: Vec3, lobes: Lobes, uc: f32) -> Option<CoatSample> {
        let fr = fresnel_dielectric(v.z, self.eta);
        let f = fr.reflectance;
        let reflect = match lobes {
            Lobes::Reflect => true,
            Lobes::Transmit => false,
            Lobes::Both => uc < f,
        };
        if reflect {
            if !(f > 0.0) {
                return None;
            }
            let q = if lobes == Lobes::Both { f } else { 1.0 };
            return Some(CoatSample { w: reflect_local(v), q, value: f / q, density: f / q });
        }
        if !(f < 1.0) {
            return None;
        }
        let q = if lobes == Lobes::Both { 1.0 - f } else { 1.0 };
        let value = (1.0 - f) / (fr.eta_ti * fr.eta_ti) / q;
        Some(CoatSample { w: refract_local(v, &fr), q, value, density: (1.0 - f) / q })
    }

    /// eval(a, b) of a rough coating (0 for a smooth one: its lobes are deltas).
    fn eval(&self, a: Vec3, b: Vec3) -> f32 {
        match &self.dist {
            None => 0.0,
            Some(d) => eval_rough_dielectric(d, self.eta, Rgb::WHITE, Rgb::WHITE, a, b).r,
        }
    }

    /// The density of `sample(a, lobes)` at `b` (0 for a smooth coating).
    fn pdf(&self, a: Vec3, b: Vec3, lobes: Lobes) -> f32 {
        let (r, t) = Coat::lobe_tints(lobes);
        match &self.dist {
            None => 0.0,
            Some(d) => pdf_rough_dielectric(d, self.eta, r, t, a, b),
        }
    }
}

/// The way out of one walk, drawn once from `wi` as pbrt-v4 does: `t` is the direction into
/// the slab, `q` its proposal density, and `value` and `density` what a path arriving at the
/// coating from below along -t carries out to `wi`, over q: eval_coat(t, wi) / q and the
/// full sampler's density of `wi` from t, over q.
struct Exit {
    wi: Vec3,
    t: Vec3,
    q: f32,
    value: f32,
    density: f32,
}

/// Running sums of a walk: the BSDF value and the density of `sample`.
#[derive(Clone, Copy, Default)]
struct Pair {
    value: Rgb,
    density: f32,
}

/// A walk's throughput and what it has gathered.
#[derive(Clone, Copy, Default)]
struct State {
    beta: Pair,
    sum: Pair,
}

impl State {
    /// Gathers a path that leaves with the further factors `value` and `density`.
    fn add(&mut self, value: Rgb, density: f32) {
        self.sum.value += self.beta.value * value;
        self.sum.density += self.beta.density * density;
    }
}

/// What one free flight in the slab ends at.
enum Flight {
    /// A scattering event in the medium at this height.
    Scatter(f32),
    /// The coating (top) or the base, with the transmittance the value walk multiplies by.
    Top(f32),
    Bottom(f32),
}

/// Which estimate Russian roulette looks at.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    Value,
    Density,
}

/// A hash of a direction's bit pattern.
fn bits(v: Vec3) -> u64 {
    let xy = ((v.x.to_bits() as u64) << 32) | v.y.to_bits() as u64;
    mix64(xy ^ mix64(v.z.to_bits() as u64 ^ 0x2545_f491_4f6c_dd1d))
}

impl CoatedDiffuse {
    fn coat(&self) -> Coat {
        let smooth = !(self.roughness >= SMOOTH_ALPHA) || self.eta == 1.0;
        Coat { eta: self.eta, dist: (!smooth).then(|| Microfacet::new(MicrofacetKind::Ggx, self.roughness)) }
    }

    fn rng(&self, salt: u64, a: Vec3, b: Vec3) -> Rng {
        Rng::for_key(salt ^ ((self.seed as u64) << 32), bits(a), bits(b))
    }

    /// Transmittance over height `dz` along `w`: (for the value, for the density). A black
    /// slab only absorbs and `sample` crosses it regardless; a scattering one scatters, so
    /// reaching the far side is the free flight's probability for `sample` too.
    fn tr(&self, dz: f32, w: Vec3) -> (f32, f32) {
        // No slab (thickness 0 outside scene files) transmits everything, also at w.z = 0.
        let tr = if dz == 0.0 { 1.0 } else { (-(dz / w.z).abs()).exp() };
        (tr, if self.albedo.is_black() { 1.0 } else { tr })
    }

    /// A free flight from height `z` along `w` (σt = 1).
    fn flight(&self, z: f32, w: Vec3, rng: &mut Rng) -> Flight {
        let up = w.z > 0.0;
        let boundary = |tr: f32| if up { Flight::Top(tr) } else { Flight::Bottom(tr) };
        if self.albedo.is_black() {
            return boundary(self.tr(self.thickness, w).0);
        }
        let to_boundary = if up { self.thickness - z } else { z };
        let dz = -(1.0 - rng.next_f32()).ln() * w.z.abs();
        if dz < to_boundary {
            Flight::Scatter(if up { z + dz } else { z - dz })
        } else {
            boundary(1.0)
        }
    }

    fn phase(&self) -> Phase {
        Phase::HenyeyGreenstein { g: self.g }
    }

    /// Draws the way out towards `wi` (see [`Exit`]).
    fn exit(&self, coat: &Coat, wi: Vec3, rng: &mut Rng) -> Option<Exit> {
        let s = coat.sample(wi, Lobes::Transmit, rng.next_f32(), rng.next_2d())?;
        let t = s.w;
        if !(t.z < 0.0) {
            return None;
        }
        let (value, density) = match coat.dist {
            // A delta: by reciprocity eval(t, wi) = η² |cos wi| / |cos t| eval(wi, t), and the
            // density of wi is that of t times the Jacobian |cos wi| / (η² |cos t|).
            None => {
                let k = s.density * wi.z / t.z.abs();
                (k, k / (self.eta * self.eta))
            }
            Some(_) => (coat.eval(t, wi) / s.q, coat.pdf(t, wi, Lobes::Both) / s.q),
        };
        Some(Exit { wi, t, q: s.q, value, density })
    }

    /// Leaving along `u` (upward, from height `z`) after the walk drew `u` with density
    /// `p`: the rough coating's own term, MIS-weighted against the exit proposal.
    fn leave_along(&self, coat: &Coat, exit: &Exit, z: f32, u: Vec3, p: f32, st: &mut State) {
        if coat.dist.is_none() || !(u.z > 0.0) {
            return;
        }
        let (trv, trd) = self.tr(self.thickness - z, u);
        let mis = power_heuristic(p, coat.pdf(exit.wi, -u, Lobes::Transmit));
        let value = coat.eval(-u, exit.wi) * trv * mis;
        st.add(Rgb::splat(value), coat.pdf(-u, exit.wi, Lobes::Both) * trd * mis);
    }

    /// A scattering event in the medium at height `z` reached along `w`: next-event
    /// estimation through the exit, then a new direction from the phase function.
    fn medium_vertex(&self, coat: &Coat, exit: &Exit, z: f32, w: Vec3, st: &mut State, rng: &mut Rng) -> Vec3 {
        let phase = self.phase();
        let up = -exit.t;
        let (trv, trd) = self.tr(self.thickness - z, up);
        let p = phase.eval(-w, up);
        let mis = if coat.dist.is_some() { power_heuristic(exit.q, p) } else { 1.0 };
        st.add(self.albedo * (p * trv * exit.value * mis), p * trd * exit.density * mis);
        let ps = phase.sample(-w, rng.next_2d());
        st.beta.value *= self.albedo;
        self.leave_along(coat, exit, z, ps.wi, ps.pdf, st);
        ps.wi
    }

    /// A reflection off the base: next-event estimation through the exit, then a cosine-
    /// distributed new direction.
    fn bottom_vertex(&self, coat: &Coat, exit: &Exit, st: &mut State, rng: &mut Rng) -> Option<Vec3> {
        let up = -exit.t;
        let (trv, trd) = self.tr(self.thickness, up);
        let p = warp::cosine_hemisphere_pdf(up.z);
        let mis = if coat.dist.is_some() { power_heuristic(exit.q, p) } else { 1.0 };
        st.add(self.reflectance * (INV_PI * up.z * trv * exit.value * mis), p * trd * exit.density * mis);
        let u = warp::cosine_hemisphere(rng.next_2d());
        if !(u.z > 0.0) {
            return None;
        }
        st.beta.value *= self.reflectance;
        self.leave_along(coat, exit, 0.0, u, warp::cosine_hemisphere_pdf(u.z), st);
        Some(u)
    }

    /// Russian roulette on the estimate `mode` asks for (pbrt-v4's rule), applied to both
    /// throughputs so that both estimates stay unbiased; false when the walk ends.
    fn survives(st: &mut State, mode: Mode, rng: &mut Rng) -> bool {
        let b = if mode == Mode::Value { st.beta.value.max_component() } else { st.beta.density };
        if b >= 0.25 {
            return true;
        }
        let q = (1.0 - b).max(0.0);
        if rng.next_f32() < q {
            return false;
        }
        st.beta.value = st.beta.value / (1.0 - q);
        st.beta.density /= 1.0 - q;
        true
    }

    /// One walk from `wo` into the slab, gathering both estimates of paths that leave
    /// towards `exit.wi` after at most `max_depth` scattering events.
    fn walk(&self, coat: &Coat, wo: Vec3, exit: &Exit, mode: Mode, rng: &mut Rng) -> Pair {
        let Some(enter) = coat.sample(wo, Lobes::Transmit, rng.next_f32(), rng.next_2d()) else {
            return Pair::default();
        };
        let mut st =
            State { beta: Pair { value: Rgb::splat(enter.value), density: enter.density }, ..State::default() };
        let (mut z, mut w) = (self.thickness, enter.w);
        for depth in 1..=self.max_depth {
            if depth > 4 && !CoatedDiffuse::survives(&mut st, mode, rng) {
                break;
            }
            match self.flight(z, w, rng) {
                Flight::Scatter(zp) => {
                    z = zp;
                    w = self.medium_vertex(coat, exit, z, w, &mut st, rng);
                }
                Flight::Bottom(tr) => {
                    st.beta.value *= tr;
                    z = 0.0;
                    let Some(u) = self.bottom_vertex(coat, exit, &mut st, rng) else { break };
                    w = u;
                }
                Flight::Top(tr) => {
                    // Leaving here was counted at the vertex before: only reflect.
                    let Some(s) = coat.sample(-w, Lobes::Reflect, rng.next_f32(), rng.next_2d()) else { break };
                    st.beta.value *= tr * s.value;
                    st.beta.density *= s.density;
                    (z, w) = (self.thickness, s.w);
                }
            }
        }
        st.sum
    }

    /// The mean of `n_samples` walks' estimates (paths through the slab only).
    fn estimate(&self, coat: &Coat, wo: Vec3, wi: Vec3, mode: Mode, rng: &mut Rng) -> Pair {
        let mut sum = Pair::default();
        for _ in 0..self.n_samples {
            if let Some(exit) = self.exit(coat, wi, rng) {
                let p = self.walk(coat, wo, &exit, mode, rng);
                sum.value += p.value;
                sum.density += p.density;
            }
        }
        let n = self.n_samples.max(1) as f32;
        Pair { value: sum.value / n, density: sum.density / n }
    }

    /// Follows a path that entered the slab as `first` until it leaves through the coating:
    /// its direction and throughput, or `None` past `max_depth` scattering events.
    fn sample_walk(&self, coat: &Coat, first: &CoatSample, rng: &mut Rng) -> Option<(Vec3, Rgb)> {
        let mut beta = Rgb::splat(first.value);
        let (mut z, mut w) = (self.thickness, first.w);
        let mut events = 0;
        loop {
            match self.flight(z, w, rng) {
                Flight::Scatter(zp) => {
                    beta *= self.albedo;
                    (z, w) = (zp, self.phase().sample(-w, rng.next_2d()).wi);
                }
                Flight::Bottom(tr) => {
                    beta *= self.reflectance * tr;
                    (z, w) = (0.0, warp::cosine_hemisphere(rng.next_2d()));
                    if !(w.z > 0.0) {
                        return None;
                    }
                }
                Flight::Top(tr) => {
                    let s = coat.sample(-w, Lobes::Both, rng.next_f32(), rng.next_2d())?;
                    beta *= tr * s.value;
                    if s.w.z > 0.0 {
                        return Some((s.w, beta));
                    }
                    (z, w) = (self.thickness, s.w);
                }
            }
            events += 1;
            if events > self.max_depth {
                return None;
            }
        }
    }
}

impl Scatter for CoatedDiffuse {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        self.coat().dist.is_none()
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return Rgb::BLACK;
        }
        let coat = self.coat();
        let mut rng = self.rng(SALT_EVAL, wo, wi);
        Rgb::splat(coat.eval(wo, wi)) + self.estimate(&coat, wo, wi, Mode::Value, &mut rng).value
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let coat = self.coat();
        let mut rng = self.rng(SALT_PDF, wo, wi);
        coat.pdf(wo, wi, Lobes::Both) + self.estimate(&coat, wo, wi, Mode::Density, &mut rng).density
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let coat = self.coat();
        let first = coat.sample(wo, Lobes::Both, u_lobe, u)?;
        if first.w.z > 0.0 {
            // Reflected by the coating: a delta lobe when it is smooth.
            let (pdf, delta) = match coat.dist {
                None => (first.q, true),
                Some(_) => (self.pdf(wo, first.w), false),
            };
            return Some(BsdfSample { wi: first.w, weight: Rgb::splat(first.value), pdf, delta, eta: 1.0 });
        }
        let key = Vec3 { x: u_lobe, y: u[0], z: u[1] };
        let mut rng = self.rng(SALT_SAMPLE, wo, key);
        let (wi, weight) = self.sample_walk(&coat, &first, &mut rng)?;
        Some(BsdfSample { wi, weight, pdf: self.pdf(wo, wi), delta: false, eta: 1.0 })
    }

    fn diffuse_reflectance(&self) -> Rgb {
        self.reflectance
    }
}
