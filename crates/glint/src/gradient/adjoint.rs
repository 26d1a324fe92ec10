//! The adjoint pass's view of a replayed path: at each event, the adjoint radiance times
//! the event's derivative with respect to each parameter it depends on, added to the sums.

use super::params::{bitmap_taps, channel_derivative, scale_derivative, LightParam, LightProbe};
use super::{fixed, ParamSet};
use crate::integrators::{shadow_ray, transmittance, Counters, NextEvent, PathObserver, Scattering};
use crate::lights::Light;
use crate::materials::{ShadedBsdf, TexturePoint};
use crate::math::{rgb, Ray, Rgb, Vec3};
use crate::world::{SurfaceInteraction, World};

pub(super) struct Adjoint<'a> {
    world: &'a World,
    params: &'a ParamSet,
    /// The loss's derivative with respect to this sample's radiance.
    adjoint: Rgb,
    /// The sample's radiance, from the primal pass.
    total: Rgb,
    /// What the replay has gathered so far.
    gathered: Rgb,
    sums: &'a mut [i128],
    counters: Counters,
}

/// How a vertex's contribution depends on its BSDF value `f` (cosine included) towards
/// `wo` from `wi`: channel by channel, it is `weight(df)` for a change `df` of `f`.
struct BsdfUse<'e> {
    si: &'e SurfaceInteraction,
    bsdf: &'e ShadedBsdf,
    wo: Vec3,
    wi: Vec3,
}

impl<'a> Adjoint<'a> {
    pub fn new(world: &'a World, params: &'a ParamSet, adjoint: Rgb, total: Rgb, sums: &'a mut [i128]) -> Adjoint<'a> {
        Adjoint { world, params, adjoint, total, gathered: Rgb::BLACK, sums, counters: Counters::default() }
    }

    /// Adds `v` to entry `index`.
    #[inline]
    fn add_scalar(&mut self, index: usize, v: f64) {
        if v != 0.0 && v.is_finite() {
            self.sums[index] = self.sums[index].saturating_add(fixed(v));
        }
    }

    /// The adjoint times `d`, the derivative of this sample's radiance per channel.
    #[inline]
    fn dot(&self, d: Rgb) -> f64 {
        let a = self.adjoint;
        a.r as f64 * d.r as f64 + a.g as f64 * d.g as f64 + a.b as f64 * d.b as f64
    }

    /// Differentiates a contribution through the BSDF value of `u`'s material: `weight`
    /// turns a change of the BSDF value into a change of the sample's radiance.
    fn through_bsdf(&mut self, u: &BsdfUse<'_>, weight: impl Fn(Rgb) -> Rgb) {
        let params = self.params;
        let material = u.si.material;
        let (probes, textures) = (params.material_probes(material), params.texture_probes(material));
        if probes.is_empty() && textures.is_empty() {
            return;
        }
        let p: TexturePoint = self.world.texture_point(u.si);
        for probe in probes {
            let v = self.dot(weight(probe.difference.derivative(&p, u.bsdf, u.wo, u.wi)));
            self.add_scalar(probe.index, v);
        }
        for texture in textures {
            let taps = texture.taps(p.uv);
            for (c, probe) in texture.channels.iter().enumerate() {
                let v = self.dot(weight(probe.derivative(&p, u.bsdf, u.wo, u.wi)));
                for (index, w) in taps {
                    self.add_scalar(index + c, v * w as f64);
                }
            }
        }
    }

    /// Differentiates a contribution `weight * le` through light `light`'s emission `le`
    /// along `dir`; `at` finds the point of an area light that emits it.
    fn through_emission(
        &mut self,
        light: u32,
        dir: Vec3,
        at: impl FnOnce() -> Option<SurfaceInteraction>,
        le: Rgb,
        weight: Rgb,
    ) {
        let mut at = Some(at);
        for probe in self.params.light_probes(light) {
            match probe.param {
                LightParam::Texels { scale } => self.through_map_texels(probe, light, dir, weight * scale),
                LightParam::AreaTexels { width, height, uv } => {
                    // A light has at most one textured radiance: found once.
                    let Some(si) = at.take().and_then(|f| f()) else { continue };
                    let Some(l) = self.world.lights.get(light as usize) else { continue };
                    if l.emitting_texture(si.ng, dir).is_none() {
                        continue;
                    }
                    let p = self.world.texture_point(&si);
                    let taps = bitmap_taps(probe.index, width, height, uv, p.uv);
                    self.add_taps(&taps, weight);
                }
                LightParam::Channel { c, value } => {
                    let v = self.dot(weight * channel_derivative(le, c, value));
                    self.add_scalar(probe.index, v);
                }
                LightParam::Scale { value } => {
                    let v = self.dot(weight * scale_derivative(le, value));
                    self.add_scalar(probe.index, v);
                }
            }
        }
    }

    /// Adds the adjoint times `weight`, channel by channel, to the texels `taps` blends.
    fn add_taps(&mut self, taps: &[(usize, f32); 4], weight: Rgb) {
        let a = self.adjoint;
        let per_channel = [a.r * weight.r, a.g * weight.g, a.b * weight.b];
        for &(index, w) in taps {
            for (c, v) in per_channel.iter().enumerate() {
                self.add_scalar(index + c, *v as f64 * w as f64);
            }
        }
    }

    /// An environment map's texels: its emission along `dir` is `scale` times the blend of
    /// the texels its lookup reads, channel by channel (`weight` includes the scale).
    fn through_map_texels(&mut self, probe: &LightProbe, light: u32, dir: Vec3, weight: Rgb) {
        let Some(Light::EnvMap(env)) = self.world.lights.get(light as usize) else { return };
        let taps = env.taps(dir).map(|(texel, w)| (probe.index + 3 * texel, w));
        self.add_taps(&taps, weight);
    }
}

impl PathObserver for Adjoint<'_> {
    // A black BSDF value can still have a derivative.
    const SEES_BLACK_BSDF: bool = true;

    fn emission(&mut self, light: u32, dir: Vec3, at: Option<&SurfaceInteraction>, throughput: Rgb, le: Rgb, w: f32) {
        self.gathered += throughput * le * w;
        self.through_emission(light, dir, || at.copied(), le, throughput * w);
    }

    fn next_event(&mut self, e: &NextEvent<'_>) {
        let visible = transmittance(self.world, &shadow_ray(e.si, e.ls.wi, e.ls.dist), &mut self.counters);
        if !(visible > 0.0) {
            return;
        }
        let scale = e.mis_weight * visible / e.light_pdf;
        self.gathered += e.throughput * e.f * e.ls.radiance * scale;
        let u = BsdfUse { si: e.si, bsdf: e.bsdf, wo: e.wo, wi: e.wi };
        let (throughput, radiance) = (e.throughput, e.ls.radiance);
        self.through_bsdf(&u, |df| throughput * df * radiance * scale);
        // The light's point, for a textured area light: the hit just past the shadow ray's end.
        let world = self.world;
        let at = || {
            let shadow = shadow_ray(e.si, e.ls.wi, e.ls.dist);
            let ray = Ray::segment(shadow.origin, shadow.dir, shadow.t_max * 1.01);
            let hit = world.intersect(&ray)?;
            let si = world.interaction(&ray, &hit);
            (si.light == Some(e.light)).then_some(si)
        };
        self.through_emission(e.light, e.ls.wi, at, e.ls.radiance, e.throughput * e.f * scale);
    }

    fn scattering(&mut self, e: &Scattering<'_>) {
        // A delta lobe has no BSDF value to differentiate (as in Mitsuba's prb).
        let material = e.si.material;
        let params = self.params;
        if e.delta || (params.material_probes(material).is_empty() && params.texture_probes(material).is_empty()) {
            return;
        }
        let f = e.bsdf.eval(e.wo, e.wi);
        // Everything after this vertex is proportional, channel by channel, to its f.
        let rest = self.total - self.gathered;
        let ratio = |d: f32, f: f32| if f > 0.0 { d / f } else { 0.0 };
        let u = BsdfUse { si: e.si, bsdf: e.bsdf, wo: e.wo, wi: e.wi };
        self.through_bsdf(&u, |df| {
            rgb(rest.r * ratio(df.r, f.r), rest.g * ratio(df.g, f.g), rest.b * ratio(df.b, f.b))
        });
    }
}
