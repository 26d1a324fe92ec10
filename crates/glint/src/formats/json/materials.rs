//! The JSON format's materials: one reader function per material `type`, listed in
//! [`READERS`], each reading its keys from the material's object straight into the
//! material's description (`materials::*Desc`) and its sidedness. A key a type does not read
//! is refused, pointing at it; so is a value of the wrong shape.

use super::{roughness, texture_of, Ctx, JsonColor, JsonTexture};
use crate::describe::{Roughness, TextureDesc};
use crate::error::Error;
use crate::materials::{
    conductor_preset, principled_eta_of_specular, BlendDesc, BlendPartDesc, BumpMapDesc, CoatedDiffuseDesc,
    ConductorDesc, DielectricDesc, DiffuseDesc, MaskDesc, MaterialDesc, MaterialModel, NormalMapDesc, NullDesc,
    PPlasticDesc, PhongDesc, PlasticDesc, PrincipledDesc, PrincipledThinDesc,
};
use crate::math::Rgb;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

/// A material's description and whether it scatters on both faces.
type Read = (MaterialModel, bool);

/// Reads one material type from its keys.
type Reader = fn(&mut Keys) -> Result<Read, Error>;

/// Every material type the JSON format names, with its reader.
const READERS: &[(&str, Reader)] = &[
    ("diffuse", diffuse),
    ("phong", phong),
    ("mirror", mirror),
    ("conductor", conductor),
    ("dielectric", dielectric),
    ("plastic", plastic),
    ("pplastic", pplastic),
    ("polarizer", polarizer),
    ("coateddiffuse", coated_diffuse),
    ("principled", principled),
    ("principledthin", principled_thin),
    ("blend", blend),
    ("normalmap", normal_map),
    ("bumpmap", bump_map),
    ("mask", mask),
    ("null", null),
];

/// The material called `name`, from its JSON object.
pub(super) fn material_of(ctx: &Ctx, name: &str, value: &Value) -> Result<MaterialDesc, Error> {
    let at = format!("materials/{name}");
    let (model, two_sided) = read_material(ctx, name, &at, value)?;
    Ok(MaterialDesc { name: name.to_string(), model, two_sided, loc: ctx.loc(&at) })
}

/// A material object at document path `at` (of the material called `name`).
fn read_material(ctx: &Ctx, name: &str, at: &str, value: &Value) -> Result<Read, Error> {
    let Some(object) = value.as_object() else {
        return Err(ctx.err(at, format!("material '{name}' must be an object with a \"type\"")));
    };
    let types = || READERS.iter().map(|(t, _)| *t).collect::<Vec<_>>().join(", ");
    let ty = match object.get("type") {
        Some(Value::String(t)) => t.as_str(),
        _ => return Err(ctx.err(at, format!("material '{name}' needs a \"type\" (one of {})", types()))),
    };
    let Some((_, reader)) = READERS.iter().find(|(t, _)| *t == ty) else {
        return Err(
            ctx.err(&format!("{at}/type"), format!("material '{name}': unknown type '{ty}' (one of {})", types()))
        );
    };
    let mut keys = Keys { ctx, name, at: at.to_string(), ty, object, asked: vec!["type"] };
    let read = reader(&mut keys)?;
    keys.finish()?;
    Ok(read)
}

/// A material object's keys, read by name; remembers which were asked for, so that the rest
/// can be refused.
struct Keys<'a> {
    ctx: &'a Ctx<'a>,
    name: &'a str,
    at: String,
    ty: &'a str,
    object: &'a Map<String, Value>,
    asked: Vec<&'static str>,
}

impl Keys<'_> {
    fn path(&self, key: &str) -> String {
        format!("{}/{key}", self.at)
    }

    /// An error about the material as a whole.
    fn err(&self, msg: impl std::fmt::Display) -> Error {
        self.ctx.err(&self.at, format!("material '{}': {msg}", self.name))
    }

    /// The value of `key`, if given, as a `T`.
    fn get<T: DeserializeOwned>(&mut self, key: &'static str) -> Result<Option<T>, Error> {
        self.asked.push(key);
        let Some(v) = self.object.get(key) else { return Ok(None) };
        T::deserialize(v)
            .map(Some)
            .map_err(|e| self.ctx.err(&self.path(key), format!("material '{}': '{key}': {e}", self.name)))
    }

    fn texture(&mut self, key: &'static str) -> Result<Option<TextureDesc>, Error> {
        let t: Option<JsonTexture> = self.get(key)?;
        Ok(t.map(|t| texture_of(self.ctx, &self.path(key), &t)))
    }

    fn required_texture(&mut self, key: &'static str) -> Result<TextureDesc, Error> {
        self.texture(key)?.ok_or_else(|| self.err(format!("{} needs '{key}'", self.ty)))
    }

    fn color(&mut self, key: &'static str) -> Result<Option<Rgb>, Error> {
        Ok(self.get::<JsonColor>(key)?.map(JsonColor::rgb))
    }

    /// The roughness of `alpha` (a number or a texture), `alpha_v` and `distribution`.
    fn roughness(&mut self) -> Result<Option<Roughness>, Error> {
        let (alpha, alpha_v) = (self.get("alpha")?, self.get("alpha_v")?);
        let distribution = self.get("distribution")?;
        roughness(self.ctx, &self.at, &distribution, &alpha, &alpha_v)
    }

    /// The nested material of `key`, at its own document path.
    fn material(&mut self, key: &'static str) -> Result<Read, Error> {
        self.asked.push(key);
        let v = self.object.get(key).ok_or_else(|| self.err(format!("{} needs '{key}'", self.ty)))?;
        read_material(self.ctx, self.name, &self.path(key), v)
    }

    /// Refuses every key no reader asked for.
    fn finish(&self) -> Result<(), Error> {
        let Some(key) = self.object.keys().find(|k| !self.asked.contains(&k.as_str())) else { return Ok(()) };
        let known = self.asked[1..].join(", ");
        Err(self.ctx.err(
            &self.path(key),
            format!("material '{}': unknown key '{key}' for type '{}' (it reads {known})", self.name, self.ty),
        ))
    }
}

fn diffuse(k: &mut Keys) -> Result<Read, Error> {
    let reflectance = k.required_texture("reflectance")?;
    Ok((DiffuseDesc { reflectance }.into(), k.get("two_sided")?.unwrap_or(true)))
}

fn phong(k: &mut Keys) -> Result<Read, Error> {
    let kd = k.required_texture("kd")?;
    let ks = k.color("ks")?.unwrap_or(Rgb::BLACK);
    let exponent = k.get("exponent")?.unwrap_or(32.0);
    Ok((PhongDesc { kd, ks, exponent }.into(), k.get("two_sided")?.unwrap_or(true)))
}

/// A perfect mirror: a conductor of reflectance 1 (or `specular`).
fn mirror(k: &mut Keys) -> Result<Read, Error> {
    let specular = k.color("specular")?.unwrap_or(Rgb::WHITE);
    Ok((ConductorDesc { eta: Rgb::BLACK, k: Rgb::WHITE, specular, roughness: None }.into(), true))
}

fn conductor(k: &mut Keys) -> Result<Read, Error> {
    let (metal, eta, kk) = (k.get::<String>("metal")?, k.color("eta")?, k.color("k")?);
    let (eta, kk) = match (metal, eta, kk) {
        (Some(name), None, None) => conductor_preset(&name).ok_or_else(|| {
            k.ctx.err(
                &k.path("metal"),
                format!("unknown metal '{name}' (Mitsuba's conductor presets, e.g. Au, Ag, Cu, Al, Cr)"),
            )
        })?,
        (None, Some(e), Some(kk)) => (e, kk),
        (None, None, None) => (Rgb::BLACK, Rgb::WHITE),
        _ => return Err(k.err("give either 'metal' or both 'eta' and 'k'")),
    };
    let specular = k.color("specular")?.unwrap_or(Rgb::WHITE);
    let roughness = k.roughness()?;
    Ok((ConductorDesc { eta, k: kk, specular, roughness }.into(), true))
}

fn dielectric(k: &mut Keys) -> Result<Read, Error> {
    let eta = k.get("ior")?.unwrap_or(1.5);
    let thin = k.get("thin")?.unwrap_or(false);
    // A thin sheet is smooth: its roughness keys are read past, unchecked.
    let roughness = if thin {
        k.asked.extend(["alpha", "alpha_v", "distribution"]);
        None
    } else {
        k.roughness()?
    };
    Ok((DielectricDesc { eta, reflect: Rgb::WHITE, transmit: Rgb::WHITE, roughness, thin }.into(), false))
}

fn plastic(k: &mut Keys) -> Result<Read, Error> {
    let diffuse = k.required_texture("diffuse")?;
    let eta = k.get("ior")?.unwrap_or(1.49);
    // Plastics are isotropic with a constant roughness, as in Mitsuba.
    let alpha = k.get::<f32>("alpha")?.map(|a| JsonTexture::Color(JsonColor::Grey(a)));
    let distribution = k.get("distribution")?;
    let roughness = roughness(k.ctx, &k.at, &distribution, &alpha, &None)?;
    let nonlinear = k.get("nonlinear")?.unwrap_or(false);
    Ok((PlasticDesc { diffuse, specular: Rgb::WHITE, eta, roughness, nonlinear }.into(), true))
}

/// Mitsuba's `pplastic` as its RGB variants render it (Mitsuba's defaults: Beckmann, alpha
/// 0.1).
fn pplastic(k: &mut Keys) -> Result<Read, Error> {
    let diffuse = k.required_texture("diffuse")?;
    let specular = k.color("specular")?.unwrap_or(Rgb::WHITE);
    let eta = k.get("ior")?.unwrap_or(1.49);
    let alpha = k.get("alpha")?.or(Some(JsonTexture::Color(JsonColor::Grey(0.1))));
    let alpha_v = k.get("alpha_v")?;
    let distribution = k.get::<String>("distribution")?.or(Some("beckmann".into()));
    let roughness = roughness(k.ctx, &k.at, &distribution, &alpha, &alpha_v)?
        .ok_or_else(|| k.ctx.err(&k.path("alpha"), "pplastic needs a positive alpha"))?;
    Ok((PPlasticDesc { diffuse, specular, eta, roughness }.into(), true))
}

/// Mitsuba's `polarizer` on unpolarized light: passes half of `transmittance`.
fn polarizer(k: &mut Keys) -> Result<Read, Error> {
    let transmit = k.color("transmittance")?.unwrap_or(Rgb::WHITE) * 0.5;
    Ok((DielectricDesc { eta: 1.0, reflect: Rgb::BLACK, transmit, roughness: None, thin: true }.into(), false))
}

/// pbrt-v4's `coateddiffuse`, with pbrt-v4's defaults; `ior` is accepted for `eta`.
fn coated_diffuse(k: &mut Keys) -> Result<Read, Error> {
    let d = CoatedDiffuseDesc::default();
    let (eta, ior) = (k.get("eta")?, k.get("ior")?);
    if let (Some(_), Some(_)) = (eta, ior) {
        return Err(k.err("give either 'eta' or 'ior', not both"));
    }
    let desc = CoatedDiffuseDesc {
        reflectance: k.texture("reflectance")?.unwrap_or(d.reflectance),
        roughness: k.get("roughness")?.unwrap_or(d.roughness),
        thickness: k.get("thickness")?.unwrap_or(d.thickness),
        eta: eta.or(ior).unwrap_or(d.eta),
        albedo: k.color("albedo")?.unwrap_or(d.albedo),
        g: k.get("g")?.unwrap_or(d.g),
        max_depth: k.get("maxdepth")?.unwrap_or(d.max_depth),
        n_samples: k.get("nsamples")?.unwrap_or(d.n_samples),
    };
    Ok((desc.into(), k.get("two_sided")?.unwrap_or(true)))
}

/// Mitsuba's principled BSDF; every key optional, with Mitsuba's defaults.
fn principled(k: &mut Keys) -> Result<Read, Error> {
    let d = PrincipledDesc::default();
    let (ior, specular) = (k.get("ior")?, k.get("specular")?);
    let eta = match (ior, specular) {
        (Some(_), Some(_)) => return Err(k.ctx.err(&k.at, "principled: give either 'ior' or 'specular', not both")),
        (Some(ior), None) => ior,
        (None, Some(s)) => principled_eta_of_specular(s),
        (None, None) => d.eta,
    };
    let mut tex = |key: &'static str, default: &TextureDesc| -> Result<TextureDesc, Error> {
        Ok(k.texture(key)?.unwrap_or_else(|| default.clone()))
    };
    let desc = PrincipledDesc {
        base_color: tex("base_color", &d.base_color)?,
        roughness: tex("roughness", &d.roughness)?,
        anisotropic: tex("anisotropic", &d.anisotropic)?,
        metallic: tex("metallic", &d.metallic)?,
        spec_trans: tex("spec_trans", &d.spec_trans)?,
        eta,
        spec_tint: tex("spec_tint", &d.spec_tint)?,
        sheen: tex("sheen", &d.sheen)?,
        sheen_tint: tex("sheen_tint", &d.sheen_tint)?,
        flatness: tex("flatness", &d.flatness)?,
        clearcoat: tex("clearcoat", &d.clearcoat)?,
        clearcoat_gloss: tex("clearcoat_gloss", &d.clearcoat_gloss)?,
        ..d
    };
    Ok((desc.into(), k.get("two_sided")?.unwrap_or(true)))
}

/// Mitsuba's thin principled BSDF, two-sided by itself; every key optional, with Mitsuba's
/// names and defaults.
fn principled_thin(k: &mut Keys) -> Result<Read, Error> {
    let d = PrincipledThinDesc::default();
    let mut tex = |key: &'static str, default: &TextureDesc| -> Result<TextureDesc, Error> {
        Ok(k.texture(key)?.unwrap_or_else(|| default.clone()))
    };
    let mut desc = PrincipledThinDesc {
        base_color: tex("base_color", &d.base_color)?,
        roughness: tex("roughness", &d.roughness)?,
        anisotropic: tex("anisotropic", &d.anisotropic)?,
        spec_trans: tex("spec_trans", &d.spec_trans)?,
        eta: tex("eta", &d.eta)?,
        spec_tint: tex("spec_tint", &d.spec_tint)?,
        sheen: tex("sheen", &d.sheen)?,
        sheen_tint: tex("sheen_tint", &d.sheen_tint)?,
        flatness: tex("flatness", &d.flatness)?,
        diff_trans: tex("diff_trans", &d.diff_trans)?,
        ..d
    };
    for (key, rate) in [
        ("diffuse_reflectance_sampling_rate", &mut desc.diffuse_reflectance_sampling_rate),
        ("diffuse_transmittance_sampling_rate", &mut desc.diffuse_transmittance_sampling_rate),
        ("specular_reflectance_sampling_rate", &mut desc.specular_reflectance_sampling_rate),
        ("specular_transmittance_sampling_rate", &mut desc.specular_transmittance_sampling_rate),
    ] {
        if let Some(v) = k.get(key)? {
            *rate = v;
        }
    }
    Ok((desc.into(), true))
}

/// (1 - weight) · first + weight · second, the two in `materials`.
fn blend(k: &mut Keys) -> Result<Read, Error> {
    let weight = k.required_texture("weight")?;
    let parts: [Value; 2] = k.get("materials")?.ok_or_else(|| k.err("blend needs 'materials' (two of them)"))?;
    let part = |i: usize| -> Result<Box<BlendPartDesc>, Error> {
        let name = format!("{}/materials/{i}", k.name);
        let (model, two_sided) = read_material(k.ctx, &name, &format!("materials/{name}"), &parts[i])?;
        Ok(Box::new(BlendPartDesc { model, two_sided }))
    };
    let (first, second) = (part(0)?, part(1)?);
    Ok((BlendDesc { weight, first, second }.into(), k.get("two_sided")?.unwrap_or(true)))
}

/// A wrapper's nested material, refused when it is itself a normal or bump map (a mask may
/// hold one).
fn nested(k: &mut Keys, may_perturb: bool) -> Result<(Box<MaterialModel>, bool), Error> {
    let (model, two_sided) = k.material("material")?;
    if !may_perturb && model.perturbs_normals() {
        return Err(k.err("a normal or bump map inside another one is not supported"));
    }
    Ok((Box::new(model), two_sided))
}

/// `material` shaded with a tangent-space normal map.
fn normal_map(k: &mut Keys) -> Result<Read, Error> {
    let normals = k.required_texture("normals")?;
    let (nested, two_sided) = nested(k, false)?;
    Ok((NormalMapDesc { normals, nested }.into(), two_sided))
}

/// `material` shaded with the normals of `scale` times a height texture.
fn bump_map(k: &mut Keys) -> Result<Read, Error> {
    let height = k.required_texture("height")?;
    let scale = k.get("scale")?.unwrap_or(1.0);
    let (nested, two_sided) = nested(k, false)?;
    Ok((BumpMapDesc { height, scale, nested }.into(), two_sided))
}

/// `material` where opaque; light passes through with probability 1 - opacity.
fn mask(k: &mut Keys) -> Result<Read, Error> {
    let opacity = k.required_texture("opacity")?;
    let (nested, two_sided) = nested(k, true)?;
    Ok((MaskDesc { opacity, nested }.into(), two_sided))
}

/// Lets light through unchanged: a medium's boundary.
fn null(_k: &mut Keys) -> Result<Read, Error> {
    Ok((NullDesc {}.into(), false))
}

#[cfg(test)]
mod tests {
    use crate::materials::{MaterialModel, SceneDesc};
    use std::path::Path;

    /// A scene of one material object (given as JSON text) named `m`.
    fn read(material: &str) -> Result<SceneDesc, String> {
        let text = format!(
            "{{\n\"camera\": {{\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"fov\": 40}},\n\
             \"film\": {{\"width\": 4, \"height\": 4}},\n\
             \"materials\": {{\n\"m\": {material}\n}}\n}}"
        );
        super::super::read(Path::new("s.json"), &text).map_err(|e| e.to_string())
    }

    #[test]
    fn every_type_reads_its_smallest_object() {
        let smallest = [
            r#"{"type": "diffuse", "reflectance": 0.5}"#,
            r#"{"type": "phong", "kd": 0.5}"#,
            r#"{"type": "mirror"}"#,
            r#"{"type": "conductor", "metal": "Au", "alpha": 0.2}"#,
            r#"{"type": "dielectric"}"#,
            r#"{"type": "plastic", "diffuse": [0.1, 0.2, 0.3]}"#,
            r#"{"type": "pplastic", "diffuse": 0.5}"#,
            r#"{"type": "polarizer"}"#,
            r#"{"type": "coateddiffuse"}"#,
            r#"{"type": "principled"}"#,
            r#"{"type": "principledthin", "diff_trans": 1.5, "specular_reflectance_sampling_rate": 2}"#,
            r#"{"type": "blend", "weight": 0.5, "materials": [{"type": "null"}, {"type": "mirror"}]}"#,
            r#"{"type": "normalmap", "normals": 0.5, "material": {"type": "diffuse", "reflectance": 1}}"#,
            r#"{"type": "bumpmap", "height": 0.5, "material": {"type": "diffuse", "reflectance": 1}}"#,
            r#"{"type": "mask", "opacity": 0.5, "material": {"type": "diffuse", "reflectance": 1}}"#,
            r#"{"type": "null"}"#,
        ];
        assert_eq!(smallest.len(), super::READERS.len(), "a case per material type");
        for m in smallest {
            let d = read(m).unwrap_or_else(|e| panic!("{m}: {e}"));
            assert_eq!(d.materials.len(), 1, "{m}");
        }
    }

    #[test]
    fn keys_land_in_the_description() {
        let d = read(r#"{"type": "dielectric", "ior": 1.33, "alpha": 0.1}"#).unwrap();
        let MaterialModel::Dielectric(g) = &d.materials[0].model else { panic!("{:?}", d.materials[0].model) };
        assert_eq!(g.eta, 1.33);
        assert!(g.roughness.is_some() && !g.thin);
        let d = read(r#"{"type": "dielectric", "thin": true, "alpha": 0.1, "distribution": "none"}"#).unwrap();
        let MaterialModel::Dielectric(g) = &d.materials[0].model else { panic!() };
        assert!(g.thin && g.roughness.is_none(), "a thin sheet is smooth; its roughness keys are not read");
        assert!(!d.materials[0].two_sided);
    }

    #[test]
    fn an_unknown_key_is_refused_where_it_is() {
        let e = read("{\"type\": \"diffuse\",\n \"reflectance\": 0.5,\n \"reflectanse\": 0.5}").unwrap_err();
        // The key is on the object's third line, the file's seventh.
        assert!(e.contains("s.json:7:") && e.contains("'reflectanse'") && e.contains("reflectance"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }

    #[test]
    fn an_unknown_type_or_a_bad_value_is_one_line_naming_the_material() {
        let nested = r#"{"type": "normalmap", "normals": 0.5, "material": {"type": "mask", "opacity": 1,
            "material": {"type": "bumpmap", "height": 0.5, "material": {"type": "null"}}}}"#;
        for (m, needles) in [
            (r#"{"type": "difuse", "reflectance": 0.5}"#, ["'difuse'", "coateddiffuse"]),
            (r#"{"type": "phong", "kd": 0.5, "exponent": "high"}"#, ["material 'm'", "'exponent'"]),
            (r#"{"type": "diffuse"}"#, ["material 'm'", "needs 'reflectance'"]),
            (r#"{"reflectance": 0.5}"#, ["material 'm'", "needs a \"type\""]),
            (nested, ["material 'm'", "inside another one"]),
        ] {
            let e = read(m).unwrap_err();
            assert!(e.starts_with("s.json:") && needles.iter().all(|n| e.contains(n)), "{m}: {e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }
}
