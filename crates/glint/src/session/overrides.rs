//! Render overrides: what a front end may change of a scene for a render (the command line's
//! flags, Python's keywords, the distributed driver's options), checked and applied here
//! once for all of them.

use crate::camera::CropWindow;
use crate::describe::{
    limits, DirectSettings, IntegratorDesc, PathSettings, SamplerDesc, Strategy, VolpathSettings, WhittedSettings,
};
use crate::error::Error;
use crate::lights::LightSelection;
use crate::materials::SceneDesc;
use crate::sampling::SamplerKind;
use std::sync::OnceLock;

/// Overrides of a scene's settings for one render; a field left `None` keeps the scene's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overrides {
    /// One of [`integrator_names`], with its default settings (the scene's own settings
    /// when it already uses that integrator).
    pub integrator: Option<String>,
    /// Longest path: for the path tracers, segments (negative: unbounded); for Whitted,
    /// the recursion depth. Not for the direct integrator.
    pub max_depth: Option<i64>,
    /// The path tracer's estimator.
    pub strategy: Option<Strategy>,
    /// Light selection for next-event estimation.
    pub light_selection: Option<LightSelection>,
    pub sampler: Option<SamplerKind>,
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    /// Image size; a new size drops the scene's crop window (given in its own pixels).
    pub width: Option<u32>,
    pub height: Option<u32>,
}

/// The integrator of each name a front end may ask for, with its default settings.
fn integrator_defaults() -> [IntegratorDesc; 4] {
    [
        IntegratorDesc::Whitted(WhittedSettings::default()),
        IntegratorDesc::Path(PathSettings::default()),
        IntegratorDesc::Direct(DirectSettings::default()),
        IntegratorDesc::Volpath(VolpathSettings::default()),
    ]
}

/// The list above's place of each integrator: a new integrator does not compile until it
/// is added to both.
fn integrator_index(d: &IntegratorDesc) -> usize {
    match d {
        IntegratorDesc::Whitted(_) => 0,
        IntegratorDesc::Path(_) => 1,
        IntegratorDesc::Direct(_) => 2,
        IntegratorDesc::Volpath(_) => 3,
    }
}

/// An integrator's name, as scene files spell it (serde's name of its variant).
pub fn integrator_name(d: &IntegratorDesc) -> String {
    match serde_json::to_value(d) {
        Ok(serde_json::Value::Object(map)) => map.keys().next().cloned().unwrap_or_default(),
        _ => String::new(),
    }
}

/// The names [`Overrides::integrator`] takes.
pub fn integrator_names() -> &'static [String] {
    static NAMES: OnceLock<Vec<String>> = OnceLock::new();
    NAMES.get_or_init(|| integrator_defaults().iter().map(integrator_name).collect())
}

/// The settings that overrides change: a scene's own are kept aside while overrides apply,
/// so that the next render's overrides start from them.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct OverridableSettings {
    width: u32,
    height: u32,
    crop: Option<CropWindow>,
    sampler: SamplerDesc,
    light_selection: LightSelection,
    integrator: IntegratorDesc,
}

impl OverridableSettings {
    pub(super) fn of(d: &SceneDesc) -> OverridableSettings {
        OverridableSettings {
            width: d.film.width,
            height: d.film.height,
            crop: d.film.crop,
            sampler: d.sampler.clone(),
            light_selection: d.light_selection,
            integrator: d.integrator.clone(),
        }
    }

    pub(super) fn store(&self, d: &mut SceneDesc) {
        d.film.width = self.width;
        d.film.height = self.height;
        d.film.crop = self.crop;
        d.sampler = self.sampler.clone();
        d.light_selection = self.light_selection;
        d.integrator = self.integrator.clone();
    }

    /// True when the built world depends on what differs (the camera's image size, the
    /// light selection); sampling and the integrator are read at render time.
    pub(super) fn world_differs(&self, other: &OverridableSettings) -> bool {
        (self.width, self.height, self.crop, self.light_selection)
            != (other.width, other.height, other.crop, other.light_selection)
    }
}

impl Overrides {
    /// The scene's settings `own` with these overrides applied, or why they cannot be.
    pub(super) fn applied_to(&self, own: &OverridableSettings) -> Result<OverridableSettings, Error> {
        let mut s = own.clone();
        if self.width.is_some() || self.height.is_some() {
            let (w, h) = (self.width.unwrap_or(s.width), self.height.unwrap_or(s.height));
            limits::check_resolution(w, h).map_err(|e| Error::new(format!("width/height: {e}")))?;
            (s.width, s.height, s.crop) = (w, h, None);
        }
        if let Some(spp) = self.spp {
            if spp == 0 || spp > limits::MAX_SPP {
                return Err(Error::new(format!("spp {spp} is out of range (1 to {})", limits::MAX_SPP)));
            }
            s.sampler.spp = spp;
        }
        if let Some(seed) = self.seed {
            s.sampler.seed = seed;
        }
        if let Some(kind) = self.sampler {
            s.sampler.kind = kind;
        }
        if let Some(sel) = self.light_selection {
            s.light_selection = sel;
        }
        if let Some(name) = &self.integrator {
            let Some(i) = integrator_names().iter().position(|n| n == name) else {
                let names = integrator_names().join(", ");
                return Err(Error::new(format!("unknown integrator '{name}' (expected one of {names})")));
            };
            if integrator_index(&s.integrator) != i {
                s.integrator = integrator_defaults()[i].clone();
            }
        }
        self.set_depth_and_strategy(&mut s.integrator)?;
        Ok(s)
    }

    fn set_depth_and_strategy(&self, integrator: &mut IntegratorDesc) -> Result<(), Error> {
        let name = integrator_name(integrator);
        if self.strategy.is_some() && !matches!(integrator, IntegratorDesc::Path(_)) {
            return Err(Error::new(format!("strategy applies to the path integrator only, not to {name}")));
        }
        match integrator {
            IntegratorDesc::Whitted(w) => {
                if let Some(depth) = self.max_depth {
                    let max = limits::MAX_WHITTED_DEPTH as i64;
                    if !(1..=max).contains(&depth) {
                        return Err(Error::new(format!(
                            "max depth {depth}: the Whitted integrator needs a depth from 1 to {max}"
                        )));
                    }
                    w.max_depth = depth as u32;
                }
            }
            IntegratorDesc::Direct(_) => {
                if self.max_depth.is_some() {
                    return Err(Error::new(
                        "max depth does not apply to the direct integrator (it stops at the first hit)",
                    ));
                }
            }
            IntegratorDesc::Path(p) => {
                if let Some(depth) = self.max_depth {
                    p.max_depth = unbounded_depth(depth)?;
                }
                if let Some(s) = self.strategy {
                    p.strategy = s;
                }
            }
            IntegratorDesc::Volpath(v) => {
                if let Some(depth) = self.max_depth {
                    v.max_depth = unbounded_depth(depth)?;
                }
            }
        }
        Ok(())
    }
}

/// A path tracer's depth: negative is unbounded.
fn unbounded_depth(depth: i64) -> Result<Option<u32>, Error> {
    if depth >= u32::MAX as i64 {
        return Err(Error::new(format!(
            "max depth {depth} is out of range (-1 for unbounded, or 0 to {})",
            u32::MAX - 1
        )));
    }
    Ok(u32::try_from(depth).ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn own() -> OverridableSettings {
        OverridableSettings {
            width: 8,
            height: 8,
            crop: None,
            sampler: SamplerDesc::default(),
            light_selection: LightSelection::Power,
            integrator: IntegratorDesc::Path(PathSettings::default()),
        }
    }

    #[test]
    fn every_integrator_has_its_name_in_the_list() {
        let names = integrator_names();
        assert_eq!(names, ["whitted", "path", "direct", "volpath"]);
        for (i, d) in integrator_defaults().iter().enumerate() {
            assert_eq!(integrator_index(d), i);
            let o = Overrides { integrator: Some(names[i].clone()), ..Overrides::default() };
            assert_eq!(&o.applied_to(&own()).unwrap().integrator, d);
        }
        let e = Overrides { integrator: Some("bdpt".into()), ..Overrides::default() }.applied_to(&own());
        assert!(e.unwrap_err().message.contains("whitted, path, direct, volpath"));
    }

    #[test]
    fn overrides_keep_the_scenes_settings_of_the_same_integrator() {
        let mut s = own();
        s.integrator = IntegratorDesc::Path(PathSettings { rr_depth: 2, ..PathSettings::default() });
        let o = Overrides {
            integrator: Some("path".into()),
            max_depth: Some(-1),
            strategy: Some(Strategy::Light),
            ..Overrides::default()
        };
        let IntegratorDesc::Path(p) = o.applied_to(&s).unwrap().integrator else { panic!("not a path tracer") };
        assert_eq!((p.rr_depth, p.max_depth, p.strategy), (2, None, Strategy::Light));
    }

    #[test]
    fn bad_overrides_say_which_and_why() {
        let cases = [
            (Overrides { spp: Some(0), ..Overrides::default() }, "spp 0"),
            (Overrides { width: Some(0), ..Overrides::default() }, "resolution 0x"),
            (Overrides { integrator: Some("whitted".into()), max_depth: Some(0), ..Overrides::default() }, "1 to"),
            (Overrides { integrator: Some("direct".into()), max_depth: Some(3), ..Overrides::default() }, "direct"),
            (
                Overrides {
                    integrator: Some("volpath".into()),
                    strategy: Some(Strategy::Bsdf),
                    ..Overrides::default()
                },
                "volpath",
            ),
            (Overrides { max_depth: Some(u32::MAX as i64), ..Overrides::default() }, "out of range"),
        ];
        for (o, says) in cases {
            let e = o.applied_to(&own()).unwrap_err().message;
            assert!(e.contains(says), "{o:?}: {e}");
        }
    }
}
