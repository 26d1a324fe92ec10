//! Named parameters of a session's scene, read and changed in place: what the Python API's
//! `traverse` shows. A parameter edit changes the description and then as little of the
//! built world as it can: material, emission, light and camera edits are patched into the
//! world (no BVH is built), and a shape's transform edit rebuilds the world from the cached
//! meshes, the shape now traced through its transform (only the top-level BVH is built; the
//! image can differ in the last bits from a fresh load of the edited scene, which bakes the
//! transform into the vertices).
//!
//! Names: `materials.NAME.FIELD` (`reflectance`, `kd`, `diffuse` when the texture is a
//! constant; `ks`, `exponent`, `eta`, `k`, `specular`, `reflect`, `transmit`, `alpha`, ...:
//! each material's `slots`), `shapes.ID.emission` and `shapes.ID.to_world`,
//! `lights.ID.FIELD` (`intensity`, `irradiance`, `radiance`, `scale`), `camera.fov`,
//! `camera.to_world`. A shape or light is named by its file's id (Mitsuba's `id`, JSON's
//! `id`, glTF's node or light name) where no other shares it and it is not a plain number,
//! else by its index `I`.
//!
//! Aliases, the keys of Mitsuba 3's `mi.traverse`, are accepted by `set_params` (and
//! [`resolve_param_name`]) too: `ID.to_world`, `ID.emitter.radiance[.value]` (a shape's
//! area emitter), `MAT.FIELD[.value]` with Mitsuba's spellings (`diffuse_reflectance`,
//! `specular_reflectance`, `specular_transmittance`, `alpha_u`; through `brdf_0.` and
//! `nested_bsdf.` of wrappers), `ID.bsdf.FIELD[.value]` (a shape's material),
//! `LIGHT.FIELD[.value]`, and `SENSOR.to_world` / `SENSOR.x_fov` with the sensor's id or
//! class (`PerspectiveCamera`; `x_fov` only where the field of view is horizontal). Ids
//! are matched as the file gives them, so an alias of an id two objects share names both
//! and is refused.

use super::Session;
use crate::assemble::{patch_appearance, BuildCounters};
use crate::describe::slots::{texture_slot, Slot};
use crate::describe::{Emission, FovAxis, LightKind, MaterialRef, Matrix4, Projection, Texels};
use crate::error::Error;
use crate::materials::SceneDesc;
use crate::math::Rgb;
use std::sync::Arc;

/// A parameter's value.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Float(f32),
    Color(Rgb),
    Matrix(Matrix4),
    /// An image's texels (a bitmap texture's, an environment map's).
    Image(Texels),
}

impl ParamValue {
    fn kind(&self) -> &'static str {
        match self {
            ParamValue::Float(_) => "a number",
            ParamValue::Color(_) => "a colour (3 numbers)",
            ParamValue::Matrix(_) => "a 4x4 matrix",
            ParamValue::Image(_) => "an image (height, width, 3)",
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
    /// The value; an image's texels are read from its file until an edit sets them (`None`
    /// where the file cannot be read: the build reports that).
    pub(crate) fn get(&self) -> Option<ParamValue> {
        Some(match self {
            Slot::Float(v) => ParamValue::Float(**v),
            Slot::Color(v) => ParamValue::Color(**v),
            Slot::Matrix(v) => ParamValue::Matrix(**v),
            Slot::OptionalMatrix(v) => ParamValue::Matrix((**v)?),
            Slot::Texels { texels: Some(t), .. } => ParamValue::Image(t.clone()),
            Slot::Texels { file, raw, texels: None, .. } => {
                let image = crate::io::read_texture_image(file, *raw).ok()?;
                ParamValue::Image(Texels { width: image.width, height: image.height, pixels: image.pixels })
            }
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
            (Slot::Texels { texels, .. }, ParamValue::Image(t)) => {
                crate::describe::checks::texels(&t).map_err(|m| Error::new(format!("{name}: {m}")))?;
                *texels = Some(t);
            }
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
        LightKind::EnvMap { scale, file, texels, .. } => {
            let uv = [[1.0, 1.0], [0.0, 0.0]];
            vec![("scale", Slot::Float(scale)), ("data", Slot::Texels { file, raw: true, texels, uv })]
        }
        LightKind::TexturedSpot { intensity, .. } => vec![("intensity", Slot::Color(intensity))],
        LightKind::Projector { scale, .. } => vec![("scale", Slot::Float(scale))],
    }
}

/// How Mitsuba spells a parameter's field under its object's id (`mi.traverse`'s keys).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Field {
    /// A material's field, glint's name.
    Material(&'static str),
    /// A shape's area emitter's radiance.
    Emission,
    ToWorld,
    /// A light's field, named as in Mitsuba.
    Light(&'static str),
    /// The camera's horizontal field of view (only where glint's is horizontal too).
    XFov,
}

/// Mitsuba's names for a glint material field where they differ from glint's (its
/// `specular_reflectance` is a plastic's or conductor's `specular`, a dielectric's
/// `reflect`; an anisotropic roughness's `alpha_u` is glint's `alpha`).
fn mitsuba_material_names(field: &str) -> &'static [&'static str] {
    match field {
        "diffuse" | "kd" => &["diffuse_reflectance"],
        "specular" | "ks" | "reflect" => &["specular_reflectance"],
        "transmit" => &["specular_transmittance"],
        "alpha" => &["alpha_u"],
        _ => &[],
    }
}

impl Field {
    /// Whether `rest`, what follows the object's id and a dot, spells this field.
    fn spelled_by(self, rest: &str) -> bool {
        // A texture's or spectrum's value is `FIELD.value`, a bitmap's texels `FIELD.data`;
        // a number is `FIELD`.
        let rest = rest.strip_suffix(".value").or_else(|| rest.strip_suffix(".data")).unwrap_or(rest);
        match self {
            Field::Material(field) => {
                // Wrappers glint folds into the material (twosided, mask, bump and normal
                // maps) add a level to Mitsuba's names.
                let mut rest = rest;
                while let Some(r) = rest.strip_prefix("brdf_0.").or_else(|| rest.strip_prefix("nested_bsdf.")) {
                    rest = r;
                }
                rest == field || mitsuba_material_names(field).contains(&rest)
            }
            Field::Emission => rest == "emitter.radiance",
            Field::ToWorld => rest == "to_world",
            Field::Light(field) => rest == field,
            Field::XFov => rest == "x_fov",
        }
    }
}

/// A parameter: its canonical name, slot and effect, and the ids of its object by which
/// Mitsuba's names (aliases) refer to it.
pub(crate) struct Entry<'a> {
    pub name: String,
    pub slot: Slot<'a>,
    effect: Effect,
    ids: Vec<String>,
    field: Field,
    /// The object it belongs to.
    pub owner: Owner,
}

impl Entry<'_> {
    fn answers_to(&self, alias: &str) -> bool {
        self.ids.iter().any(|id| {
            alias.strip_prefix(id.as_str()).and_then(|r| r.strip_prefix('.')).is_some_and(|r| self.field.spelled_by(r))
        })
    }
}

/// How `traverse` names each of several objects: by its file's id where no other object
/// of the list shares it and it is not a plain number (that would read as an index), else
/// by its index.
fn labels(ids: &[Option<&str>]) -> Vec<String> {
    ids.iter()
        .enumerate()
        .map(|(i, id)| match id {
            Some(n) if ids.iter().filter(|m| *m == id).count() == 1 && n.parse::<usize>().is_err() => n.to_string(),
            _ => i.to_string(),
        })
        .collect()
}

/// Every parameter of the description, in a fixed order.
pub(crate) fn slots(desc: &mut SceneDesc) -> Vec<Entry<'_>> {
    // Names are worked out before the slots borrow the description.
    let shape_ids: Vec<Option<String>> = desc.shapes.iter().map(|s| s.id.clone()).collect();
    let shape_labels = labels(&shape_ids.iter().map(Option::as_deref).collect::<Vec<_>>());
    let light_labels = labels(&desc.lights.iter().map(|l| l.name.as_deref()).collect::<Vec<_>>());
    // Mitsuba names a shape's nested BSDF `SHAPE.bsdf`.
    let material_ids: Vec<Vec<String>> = (0..desc.materials.len())
        .map(|m| {
            let users = desc.shapes.iter().filter(|s| s.material == MaterialRef::Index(m));
            std::iter::once(desc.materials[m].name.clone())
                .chain(users.filter_map(|s| s.id.as_ref().map(|id| format!("{id}.bsdf"))))
                .collect()
        })
        .collect();
    // Mitsuba names a sensor without an id by its class.
    let camera = &desc.camera;
    let class = match camera.projection {
        Projection::Perspective if camera.lens_radius > 0.0 => "ThinLensCamera",
        Projection::Perspective => "PerspectiveCamera",
        Projection::Orthographic => "OrthographicCamera",
    };
    let camera_ids: Vec<String> = camera.id.iter().cloned().chain([class.to_string()]).collect();
    let x_fov = camera.fov_axis == FovAxis::X && camera.projection == Projection::Perspective;

    let mut out = Vec::new();
    for (i, (m, ids)) in desc.materials.iter_mut().zip(material_ids).enumerate() {
        let name = m.name.clone();
        for (field, slot) in m.model.slots() {
            out.push(Entry {
                name: format!("materials.{name}.{field}"),
                slot,
                effect: Effect::Appearance,
                ids: ids.clone(),
                field: Field::Material(field),
                owner: Owner::Material(i),
            });
        }
    }
    for (i, (s, label)) in desc.shapes.iter_mut().zip(shape_labels).enumerate() {
        let ids: Vec<String> = s.id.iter().cloned().collect();
        // An emitted radiance is editable as a material's texture is: a constant's colour, a
        // bitmap's texels.
        if let Some(Emission { radiance, .. }) = &mut s.emission {
            let mut emission = Vec::new();
            texture_slot("emission", radiance, &mut emission);
            for (_, slot) in emission {
                out.push(Entry {
                    name: format!("shapes.{label}.emission"),
                    slot,
                    effect: Effect::Appearance,
                    ids: ids.clone(),
                    field: Field::Emission,
                    owner: Owner::Shape(i),
                });
            }
        }
        out.push(Entry {
            name: format!("shapes.{label}.to_world"),
            slot: Slot::Matrix(&mut s.to_world),
            effect: Effect::Transform(i),
            ids,
            field: Field::ToWorld,
            owner: Owner::Shape(i),
        });
    }
    for (i, (l, label)) in desc.lights.iter_mut().zip(light_labels).enumerate() {
        let ids: Vec<String> = l.name.iter().cloned().collect();
        for (field, slot) in light_slots(&mut l.light) {
            out.push(Entry {
                name: format!("lights.{label}.{field}"),
                slot,
                effect: Effect::Appearance,
                ids: ids.clone(),
                field: Field::Light(field),
                owner: Owner::Light(i),
            });
        }
    }
    out.push(Entry {
        name: "camera.fov".to_string(),
        slot: Slot::Float(&mut desc.camera.fov_degrees),
        effect: Effect::Appearance,
        ids: if x_fov { camera_ids.clone() } else { Vec::new() },
        field: Field::XFov,
        owner: Owner::Camera,
    });
    out.push(Entry {
        name: "camera.to_world".to_string(),
        slot: Slot::OptionalMatrix(&mut desc.camera.to_world),
        effect: Effect::Appearance,
        ids: camera_ids,
        field: Field::ToWorld,
        owner: Owner::Camera,
    });
    out
}

/// The canonical name (as `params` gives it) of a parameter given by that name or by an
/// alias, Mitsuba's name for it (see the module doc). An unknown name and an alias that
/// names two parameters are errors.
pub(crate) fn resolve_param_name(desc: &mut SceneDesc, name: &str) -> Result<String, Error> {
    let entries = slots(desc);
    if entries.iter().any(|e| e.name == name) {
        return Ok(name.to_string());
    }
    let matches: Vec<&Entry> = entries.iter().filter(|e| e.answers_to(name)).collect();
    match matches.as_slice() {
        [one] => Ok(one.name.clone()),
        [] => {
            let nearest = nearest_name(name, entries.iter().map(|e| e.name.as_str()));
            Err(Error::new(match nearest {
                Some(n) => format!("no parameter called '{name}' (did you mean '{n}'?)"),
                None => format!("no parameter called '{name}'"),
            }))
        }
        [a, b, ..] => Err(Error::new(format!(
            "'{name}' is ambiguous: it could be '{}' or '{}' (use one of those names)",
            a.name, b.name
        ))),
    }
}

/// The known name closest to `name` in edit distance, if it is close (a typo, not another
/// parameter).
fn nearest_name<'a>(name: &str, known: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let (distance, nearest) = known.map(|k| (edit_distance(name, k), k)).min()?;
    (distance <= 2.max(name.chars().count() / 4)).then_some(nearest)
}

/// Levenshtein distance, in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != *cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

/// Sets one parameter (by its name or an alias), returning its canonical name, its old
/// value and what the edit affects.
fn set_one(desc: &mut SceneDesc, p: &Param) -> Result<(String, Option<ParamValue>, Effect), Error> {
    let name = resolve_param_name(desc, &p.name)?;
    let shown = if name == p.name { name.clone() } else { format!("{} ({name})", p.name) };
    let entry = slots(desc)
        .into_iter()
        .find(|e| e.name == name)
        .ok_or_else(|| Error::new(format!("no parameter called '{name}'")))?;
    Ok((name, entry.slot.set(&shown, p.value.clone())?, entry.effect))
}

impl Session {
    /// Every editable parameter and its value (the camera's transform only once it is set).
    pub fn params(&mut self) -> Vec<Param> {
        slots(&mut self.desc)
            .into_iter()
            .filter_map(|e| e.slot.get().map(|value| Param { name: e.name, value }))
            .collect()
    }

    /// [`Session::params`]' names, each with its value but an image's (`None`): images are
    /// read from their files, so a listing leaves them to [`Session::param`].
    pub fn param_listing(&mut self) -> Vec<(String, Option<ParamValue>)> {
        slots(&mut self.desc)
            .into_iter()
            .filter_map(|e| match e.slot {
                Slot::Texels { .. } => Some((e.name, None)),
                Slot::Float(_) | Slot::Color(_) | Slot::Matrix(_) | Slot::OptionalMatrix(_) => {
                    e.slot.get().map(|value| (e.name, Some(value)))
                }
            })
            .collect()
    }

    /// The value of the parameter named `name` or by an alias of it.
    pub fn param(&mut self, name: &str) -> Result<ParamValue, Error> {
        let name = resolve_param_name(&mut self.desc, name)?;
        slots(&mut self.desc).into_iter().find(|e| e.name == name).and_then(|e| e.slot.get()).ok_or_else(|| {
            Error::new(format!(
                "'{name}' has no value to read (an image whose file cannot be read, or an unset camera transform)"
            ))
        })
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
                Ok((name, old, effect)) => {
                    if let Some(value) = old {
                        undo.push(Param { name, value });
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

    /// The canonical name of a parameter given by its name or an alias (see the module
    /// doc): what `params` calls it.
    pub fn param_name(&mut self, name: &str) -> Result<String, Error> {
        resolve_param_name(&mut self.desc, name)
    }

    /// How many BVHs this session's builds have made so far.
    pub fn build_counters(&self) -> BuildCounters {
        self.cache.counters
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const SCENE: &str = r#"<scene version="3.0.0">
        <sensor type="perspective" id="cam">
            <float name="fov" value="40"/>
            <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
        </sensor>
        <bsdf type="diffuse" id="paint"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf>
        <bsdf type="twosided" id="shell">
            <bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf>
        </bsdf>
        <shape type="sphere" id="ball"><ref id="paint"/></shape>
        <shape type="sphere" id="lamp">
            <emitter type="area"><rgb name="radiance" value="4, 4, 4"/></emitter>
        </shape>
        <shape type="cube"><ref id="shell"/></shape>
        <shape type="sphere" id="7"/>
        <shape type="sphere" id="twin"><bsdf type="dielectric"/></shape>
        <shape type="sphere" id="twin2"/>
        <emitter type="point" id="sun"><rgb name="intensity" value="1, 2, 3"/></emitter>
        <emitter type="constant"/>
    </scene>"#;

    fn desc() -> SceneDesc {
        let mut d = crate::formats::mitsuba::read_str(SCENE, Path::new("edit.xml"), &[]).unwrap();
        // Two shapes of one id, as a JSON or glTF file may give them (Mitsuba refuses it).
        d.shapes[5].id = Some("twin".into());
        d
    }

    fn names(desc: &mut SceneDesc) -> Vec<String> {
        slots(desc).into_iter().map(|e| e.name).collect()
    }

    fn resolve(name: &str) -> Result<String, String> {
        resolve_param_name(&mut desc(), name).map_err(|e| e.to_string())
    }

    #[test]
    fn shapes_and_lights_are_named_by_unique_ids_else_by_index() {
        let names = names(&mut desc());
        for expected in [
            "shapes.ball.to_world",
            "shapes.lamp.emission",
            "shapes.lamp.to_world",
            // No id, a plain number, an id two shapes share: the index.
            "shapes.2.to_world",
            "shapes.3.to_world",
            "shapes.4.to_world",
            "shapes.5.to_world",
            "lights.sun.intensity",
            "lights.1.radiance",
            "materials.paint.reflectance",
            "materials.shell.alpha",
            "camera.fov",
            "camera.to_world",
        ] {
            assert!(names.iter().any(|n| n == expected), "{expected} missing from {names:?}");
        }
        assert!(!names.iter().any(|n| n.starts_with("shapes.0.") || n.starts_with("shapes.twin")), "{names:?}");
    }

    #[test]
    fn canonical_names_resolve_to_themselves() {
        for name in ["shapes.ball.to_world", "shapes.2.to_world", "lights.sun.intensity", "camera.fov"] {
            assert_eq!(resolve(name).as_deref(), Ok(name));
        }
    }

    #[test]
    fn mitsuba_keys_resolve_to_canonical_names() {
        for (alias, canonical) in [
            ("ball.to_world", "shapes.ball.to_world"),
            ("lamp.emitter.radiance.value", "shapes.lamp.emission"),
            ("lamp.emitter.radiance", "shapes.lamp.emission"),
            ("paint.reflectance.value", "materials.paint.reflectance"),
            ("paint.reflectance", "materials.paint.reflectance"),
            ("ball.bsdf.reflectance.value", "materials.paint.reflectance"),
            // Mitsuba's spellings of plastic's fields, under the twosided wrapper's level.
            ("shell.brdf_0.diffuse_reflectance.value", "materials.shell.diffuse"),
            ("shell.brdf_0.specular_reflectance.value", "materials.shell.specular"),
            ("shell.brdf_0.alpha", "materials.shell.alpha"),
            ("shell.eta", "materials.shell.eta"),
            ("sun.intensity.value", "lights.sun.intensity"),
            ("cam.to_world", "camera.to_world"),
            ("PerspectiveCamera.to_world", "camera.to_world"),
            ("cam.x_fov", "camera.fov"),
            // A plain-number id is matched as given.
            ("7.to_world", "shapes.3.to_world"),
        ] {
            assert_eq!(resolve(alias).as_deref(), Ok(canonical), "{alias}");
        }
    }

    #[test]
    fn dielectric_fields_take_mitsubas_spellings() {
        let mut d = desc();
        let reflect = resolve_param_name(&mut d, "twin.bsdf.specular_reflectance.value");
        // Of the two shapes called twin only the first has a material of its own.
        assert!(reflect.as_ref().is_ok_and(|n| n.ends_with(".reflect")), "{reflect:?}");
        let transmit = resolve_param_name(&mut d, "twin.bsdf.specular_transmittance.value");
        assert!(transmit.as_ref().is_ok_and(|n| n.ends_with(".transmit")), "{transmit:?}");
    }

    #[test]
    fn an_alias_of_a_shared_id_is_ambiguous() {
        let e = resolve("twin.to_world").unwrap_err();
        assert_eq!(
            e,
            "'twin.to_world' is ambiguous: it could be 'shapes.4.to_world' or 'shapes.5.to_world' (use one of those names)"
        );
    }

    #[test]
    fn unknown_names_are_one_line_and_suggest_a_close_name() {
        assert_eq!(
            resolve("shapes.bal.to_world").unwrap_err(),
            "no parameter called 'shapes.bal.to_world' (did you mean 'shapes.ball.to_world'?)"
        );
        assert_eq!(resolve("ball.radius").unwrap_err(), "no parameter called 'ball.radius'");
        // The field of view is vertical here, which Mitsuba's x_fov is not.
        let mut d = desc();
        d.camera.fov_axis = FovAxis::Y;
        assert!(resolve_param_name(&mut d, "cam.x_fov").is_err());
        // Only the sensor's own class names it.
        assert!(resolve("OrthographicCamera.to_world").is_err());
    }

    #[test]
    fn an_alias_edits_what_its_canonical_name_edits() {
        let mut session = Session::from_description(desc());
        let red = Rgb { r: 0.9, g: 0.1, b: 0.1 };
        session.set_params(&[Param { name: "paint.reflectance.value".into(), value: ParamValue::Color(red) }]).unwrap();
        let mut m = crate::describe::IDENTITY;
        m[0][3] = 2.0;
        session.set_params(&[Param { name: "ball.to_world".into(), value: ParamValue::Matrix(m) }]).unwrap();
        let params = session.params();
        let get = |n: &str| params.iter().find(|p| p.name == n).map(|p| p.value.clone());
        assert_eq!(get("materials.paint.reflectance"), Some(ParamValue::Color(red)));
        assert_eq!(get("shapes.ball.to_world"), Some(ParamValue::Matrix(m)));
        // A wrong value names the alias and the parameter, and changes nothing.
        let e = session
            .set_params(&[
                Param { name: "sun.intensity.value".into(), value: ParamValue::Color(Rgb::WHITE) },
                Param { name: "cam.x_fov".into(), value: ParamValue::Color(red) },
            ])
            .unwrap_err();
        assert_eq!(e.to_string(), "cam.x_fov (camera.fov) is a number, not a colour (3 numbers)");
        let sun = session.params().into_iter().find(|p| p.name == "lights.sun.intensity").map(|p| p.value);
        assert_eq!(sun, Some(ParamValue::Color(Rgb { r: 1.0, g: 2.0, b: 3.0 })));
    }
}
