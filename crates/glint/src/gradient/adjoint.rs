//! The adjoint pass's view of a replayed path: at each event, the adjoint radiance times
//! the event's derivative with respect to each parameter it depends on, added to the sums.

use super::{fixed, ParamSet};
use crate::integrators::{shadow_ray, transmittance, Counters, NextEvent, PathObserver, Scattering};
use crate::math::Rgb;
use crate::world::World;

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

impl<'a> Adjoint<'a> {
    pub fn new(world: &'a World, params: &'a ParamSet, adjoint: Rgb, total: Rgb, sums: &'a mut [i128]) -> Adjoint<'a> {
        Adjoint { world, params, adjoint, total, gathered: Rgb::BLACK, sums, counters: Counters::default() }
    }

    /// Adds the adjoint times `d` (the derivative of this sample's radiance with respect
    /// to one parameter, per channel) to entry `index`.
    #[inline]
    fn add(&mut self, index: usize, d: Rgb) {
        let a = self.adjoint;
        let v = a.r as f64 * d.r as f64 + a.g as f64 * d.g as f64 + a.b as f64 * d.b as f64;
        if v != 0.0 && v.is_finite() {
            self.sums[index] = self.sums[index].saturating_add(fixed(v));
        }
    }
}

impl PathObserver for Adjoint<'_> {
    fn emission(&mut self, light: u32, throughput: Rgb, le: Rgb, mis_weight: f32) {
        self.gathered += throughput * le * mis_weight;
        for probe in self.params.light_probes(light) {
            self.add(probe.index, throughput * probe.derivative(le) * mis_weight);
        }
    }

    fn next_event(&mut self, e: &NextEvent<'_>) {
        let world = self.world;
        let visible = transmittance(world, &shadow_ray(e.si, e.ls.wi, e.ls.dist), &mut self.counters);
        if !(visible > 0.0) {
            return;
        }
        let scale = e.mis_weight * visible / e.light_pdf;
        self.gathered += e.throughput * e.f * e.ls.radiance * scale;
        let material_probes = self.params.material_probes(e.si.material);
        if !material_probes.is_empty() {
            let p = world.texture_point(e.si);
            for probe in material_probes {
                let df = probe.derivative(&p, e.bsdf, e.wo, e.wi);
                self.add(probe.index, e.throughput * df * e.ls.radiance * scale);
            }
        }
        for probe in self.params.light_probes(e.light) {
            self.add(probe.index, e.throughput * e.f * probe.derivative(e.ls.radiance) * scale);
        }
    }

    fn scattering(&mut self, e: &Scattering<'_>) {
        // A delta lobe has no BSDF value to differentiate (as in Mitsuba's prb).
        let probes = self.params.material_probes(e.si.material);
        if e.delta || probes.is_empty() {
            return;
        }
        let f = e.bsdf.eval(e.wo, e.wi);
        // Everything after this vertex is proportional, channel by channel, to its f.
        let rest = self.total - self.gathered;
        let ratio = |d: f32, f: f32| if f > 0.0 { d / f } else { 0.0 };
        let p = self.world.texture_point(e.si);
        for probe in probes {
            let df = probe.derivative(&p, e.bsdf, e.wo, e.wi);
            let d = crate::math::rgb(rest.r * ratio(df.r, f.r), rest.g * ratio(df.g, f.g), rest.b * ratio(df.b, f.b));
            self.add(probe.index, d);
        }
    }
}
