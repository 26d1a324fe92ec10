//! Named parameters of a session's scene, read and changed in place: what the Python API's
//! `traverse` shows. A parameter edit changes the description and then as little of the
//! built world as it can: material, emission, light and camera edits are patched into the
//! world (no BVH is built), and a shape's transform edit rebuilds the world from the cached
//! meshes, the shape now traced through its transform (only the top-level BVH is built; the
//! image can differ in the last bits from a fresh load of the edited scene, which bakes the
//! transform into the vertices).
//!
//! Names: `materials.NAME.FIELD` (`reflectance`, `kd`, `diffuse` when the texture is a
//! constant; `ks`, `exponent`, `eta`, `k`, `specular`, `reflect`, `transmit`, `alpha`),
//! `lights.I.FIELD` or `lights.NAME.FIELD` for a light its file names (glTF's) (`intensity`,
//! `irradiance`, `radiance`, `scale`), `shapes.I.emission`,
//! `shapes.I.to_world`, `camera.fov`, `camera.to_world`.

use super::Session;
use crate::assemble::{patch_appearance, BuildCounters};
use crate::describe::slots::Slot;
use crate::describe::{Emission, LightKind, Matrix4, TextureDesc};
use crate::error::Error;
use crate::materials::SceneDesc;
use crate::math::Rgb;
use std::sync::Arc;

/// A parameter's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    Float(f32),
    Color(Rgb),
    Matrix(Matrix4),
}

impl ParamValue {
    fn kind(&self) -> &'static str {
        match self {
            ParamValue::Float(_) => "a number",
            ParamValue::Color(_) => "a colour (3 numbers)",
            ParamValue::Matrix(_) => "a 4x4 matrix",
        }
    }
}

/// A named parameter and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub name: String,
    pub value: ParamValue,
}

impl Slot<'_> {
    fn get(&self) -> Option<ParamValue> {
        Some(match self {
            Slot::Float(v) => ParamValue::Float(**v),
            Slot::Color(v) => ParamValue::Color(**v),
            Slot::Matrix(v) => ParamValue::Matrix(**v),
            Slot::OptionalMatrix(v) => ParamValue::Matrix((**v)?),
        })
    }

    /// Stores `value`, returning what was there (`None`: an unset camera transform).
    fn set(self, name: &str, value: ParamValue) -> Result<Option<ParamValue>, Error> {
        let old = self.get();
        match (self, value) {
            (Slot::Float(v), ParamValue::Float(x)) => *v = x,
            (Slot::Color(v), ParamValue::Color(x)) => *v = x,
            (Slot::Matrix(v), ParamValue::Matrix(x)) => *v = x,
            (Slot::OptionalMatrix(v), ParamValue::Matrix(x)) => *v = Some(x),
            (slot, value) => {
                let expected = slot.get().map_or("a 4x4 matrix", |v| v.kind());
                return Err(Error::new(format!("{name} is {expected}, not {}", value.kind())));
            }
        }
        Ok(old)
    }
}

/// What an edit changes in the built world.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Effect {
    Appearance,
    Transform(usize),
}

/// The object of the description a parameter belongs to (an index into its list).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Owner {
    Material(usize),
    Shape(usize),
    Light(usize),
    Camera,
}

fn light_slots(l: &mut LightKind) -> Vec<(&'static str, Slot<'_>)> {
    match l {
        LightKind::Point { intensity, .. } | LightKind::Spot { intensity, .. } => {
            vec![("intensity", Slot::Color(intensity))]
        }
        LightKind::Directional { irradiance, .. } => vec![("irradiance", Slot::Color(irradiance))],
        LightKind::Constant { radiance } => vec![("radiance", Slot::Color(radiance))],
        LightKind::EnvMap { scale, .. } => vec![("scale", Slot::Float(scale))],
        LightKind::TexturedSpot { intensity, .. } => vec![("intensity", Slot::Color(intensity))],
        LightKind::Projector { scale, .. } => vec![("scale", Slot::Float(scale))],
    }
}

/// Every parameter of the description with its slot and effect, in a fixed order.
fn slots(desc: &mut SceneDesc) -> Vec<(String, Slot<'_>, Effect)> {
    owned_slots(desc).into_iter().map(|(name, slot, effect, _)| (name, slot, effect)).collect()
}

/// [`slots`], each with the object it belongs to.
pub(crate) fn owned_slots(desc: &mut SceneDesc) -> Vec<(String, Slot<'_>, Effect, Owner)> {
    let mut out = Vec::new();
    for (i, m) in desc.materials.iter_mut().enumerate() {
        let name = m.name.clone();
        for (field, slot) in m.model.slots() {
            out.push((format!("materials.{name}.{field}"), slot, Effect::Appearance, Owner::Material(i)));
        }
    }
    for (i, s) in desc.shapes.iter_mut().enumerate() {
        // A uniform emitted radiance is editable (a textured one, as a material's texture, not).
        if let Some(Emission { radiance: TextureDesc::Constant { color }, .. }) = &mut s.emission {
            out.push((format!("shapes.{i}.emission"), Slot::Color(color), Effect::Appearance, Owner::Shape(i)));
        }
        out.push((
            format!("shapes.{i}.to_world"),
            Slot::Matrix(&mut s.to_world),
            Effect::Transform(i),
            Owner::Shape(i),
        ));
    }
    // A light is named by its file's name where it has one no other light shares (a glTF
    // light's), else by its index.
    let names: Vec<Option<String>> = desc.lights.iter().map(|l| l.name.clone()).collect();
    for (i, l) in desc.lights.iter_mut().enumerate() {
        let label = match &l.name {
            Some(n) if names.iter().filter(|m| m.as_ref() == Some(n)).count() == 1 && n.parse::<usize>().is_err() => {
                n.clone()
            }
            _ => i.to_string(),
        };
        for (field, slot) in light_slots(&mut l.light) {
            out.push((format!("lights.{label}.{field}"), slot, Effect::Appearance, Owner::Light(i)));
        }
    }
    let camera = &mut desc.camera;
    out.push(("camera.fov".to_string(), Slot::Float(&mut camera.fov_degrees), Effect::Appearance, Owner::Camera));
    let to_world = Slot::OptionalMatrix(&mut camera.to_world);
    out.push(("camera.to_world".to_string(), to_world, Effect::Appearance, Owner::Camera));
    out
}

/// Sets one parameter, returning its old value and what the edit affects.
fn set_one(desc: &mut SceneDesc, p: &Param) -> Result<(Option<ParamValue>, Effect), Error> {
    let (_, slot, effect) = slots(desc)
        .into_iter()
        .find(|(name, _, _)| *name == p.name)
        .ok_or_else(|| Error::new(format!("no parameter called '{}'", p.name)))?;
    Ok((slot.set(&p.name, p.value)?, effect))
}

impl Session {
    /// Every editable parameter and its value (the camera's transform only once it is set).
    pub fn params(&mut self) -> Vec<Param> {
        slots(&mut self.desc)
            .into_iter()
            .filter_map(|(name, slot, _)| slot.get().map(|value| Param { name, value }))
            .collect()
    }

    /// Sets parameters; on an error (an unknown name, a wrong kind of value, a value the
    /// scene cannot take) nothing is changed. Rebuilds as little as the edits need (see the
    /// module doc).
    pub fn set_params(&mut self, params: &[Param]) -> Result<(), Error> {
        // Old values, to put back on an error; the camera's transform may have been unset.
        let mut undo = Vec::new();
        let camera_to_world = self.desc.camera.to_world;
        let mut transforms = Vec::new();
        for p in params {
            match set_one(&mut self.desc, p) {
                Ok((old, effect)) => {
                    if let Some(value) = old {
                        undo.push(Param { name: p.name.clone(), value });
                    }
                    if let Effect::Transform(i) = effect {
                        transforms.push(i);
                    }
                }
                Err(e) => {
                    self.undo(&undo, camera_to_world);
                    return Err(e);
                }
            }
        }
        if let Err(e) = self.apply(&transforms) {
            self.undo(&undo, camera_to_world);
            return Err(e);
        }
        Ok(())
    }

    fn undo(&mut self, undo: &[Param], camera_to_world: Option<Matrix4>) {
        for p in undo.iter().rev() {
            set_one(&mut self.desc, p).expect("an old value goes back where it was");
        }
        self.desc.camera.to_world = camera_to_world;
    }

    /// Brings the built world (if any) up to date with edited parameters.
    fn apply(&mut self, transforms: &[usize]) -> Result<(), Error> {
        if !transforms.is_empty() {
            crate::assemble::validate_description(&self.desc)?;
            self.instanced.extend(transforms.iter().copied());
            self.world = None;
            return Ok(());
        }
        let (Some(world), Some(layout)) = (&mut self.world, &self.layout) else {
            return crate::assemble::validate_description(&self.desc);
        };
        // The world is shared while a render holds it; it is then built again, from the
        // cached meshes.
        let patched = match Arc::get_mut(world) {
            Some(w) => patch_appearance(w, &self.desc, layout)?,
            None => false,
        };
        if !patched {
            crate::assemble::validate_description(&self.desc)?;
            self.world = None;
        }
        Ok(())
    }

    /// How many BVHs this session's builds have made so far.
    pub fn build_counters(&self) -> BuildCounters {
        self.cache.counters
    }
}
