//! What a path does, shown to whoever watches it: the adjoint pass of differentiable
//! rendering (`gradient`) replays a path and, at each event, propagates the adjoint radiance
//! to the parameters the event depends on. Rendering passes [`Unobserved`], whose empty
//! methods compile away, so the primal path is the same code and the same bits.

use crate::lights::LightSample;
use crate::materials::ShadedBsdf;
use crate::math::{Rgb, Vec3};
use crate::world::SurfaceInteraction;

/// Next-event estimation at a vertex, before its shadow ray is traced: the light `light`
/// sampled in direction `wi` (local to the shading frame), whose radiance the vertex's BSDF value `f`
/// (cosine included) turns towards `wo`. Its contribution, if the light is visible, is
/// `throughput * f * ls.radiance * (mis_weight / light_pdf)`.
pub(crate) struct NextEvent<'a> {
    pub si: &'a SurfaceInteraction,
    pub bsdf: &'a ShadedBsdf,
    pub wo: Vec3,
    pub wi: Vec3,
    pub ls: &'a LightSample,
    pub light: u32,
    pub throughput: Rgb,
    pub f: Rgb,
    pub mis_weight: f32,
    pub light_pdf: f32,
}

/// A BSDF sample that continues the path from a vertex: the direction `wi` (local), drawn
/// by a delta lobe or not. Reported after the vertex's emission and next-event estimation,
/// and before Russian roulette.
pub(crate) struct Scattering<'a> {
    pub si: &'a SurfaceInteraction,
    pub bsdf: &'a ShadedBsdf,
    pub wo: Vec3,
    pub wi: Vec3,
    pub delta: bool,
}

pub(crate) trait PathObserver {
    /// Whether [`PathObserver::next_event`] also sees lights whose BSDF value is black
    /// (which rendering skips: they add nothing).
    const SEES_BLACK_BSDF: bool;

    /// Light `light` added `throughput * le * mis_weight` to the path's radiance along
    /// direction `dir`: an area light hit at `at`, or an environment light seen by an escaped
    /// ray (`at` None).
    fn emission(
        &mut self,
        light: u32,
        dir: Vec3,
        at: Option<&SurfaceInteraction>,
        throughput: Rgb,
        le: Rgb,
        mis_weight: f32,
    );
    /// Next-event estimation chose a light; its shadow ray is the observer's to trace.
    fn next_event(&mut self, e: &NextEvent<'_>);
    fn scattering(&mut self, e: &Scattering<'_>);
}

/// Watches nothing: what rendering passes.
pub(crate) struct Unobserved;

impl PathObserver for Unobserved {
    const SEES_BLACK_BSDF: bool = false;

    #[inline(always)]
    fn emission(&mut self, _: u32, _: Vec3, _: Option<&SurfaceInteraction>, _: Rgb, _: Rgb, _: f32) {}
    #[inline(always)]
    fn next_event(&mut self, _e: &NextEvent<'_>) {}
    #[inline(always)]
    fn scattering(&mut self, _e: &Scattering<'_>) {}
}
