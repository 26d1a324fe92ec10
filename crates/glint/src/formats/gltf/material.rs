//! glTF materials as [`GltfMaterialDesc`]s: the metallic-roughness factors and textures,
//! the KHR material extensions Blender writes, and the emission each material gives the
//! shapes that use it.

use crate::describe::{Emission, GltfTextureDesc, GltfWrap, MediumDesc, PhaseDesc, TextureDesc, VolumeDesc};

use crate::error::SourceLoc;
use crate::io::gltf::{GltfFile, Node};
use crate::materials::{GltfAlphaMode, GltfMaterialDesc, MaterialDesc, MaterialModel, SceneDesc};
use crate::math::{rgb, Rgb};
use serde_json::Value;
use std::cell::Cell;
use std::path::Path;

/// The description's material for each glTF material, the emission of each, and the
/// medium inside each that bounds an absorbing volume.
pub struct Materials {
    pub index: Vec<usize>,
    pub emission: Vec<Option<Emission>>,
    /// Index into the description's media: `KHR_materials_volume`'s attenuation inside.
    pub interior: Vec<Option<usize>>,
    default: Cell<Option<usize>>,
}

impl Materials {
    /// The specification's default material, added on first use.
    pub fn default_material(&self, d: &mut SceneDesc) -> usize {
        if let Some(i) = self.default.get() {
            return i;
        }
        d.materials.push(MaterialDesc {
            name: "glTF default material".into(),
            model: MaterialModel::Gltf(GltfMaterialDesc::default_material()),
            two_sided: false,
            loc: d.camera.loc.clone(),
        });
        self.default.set(Some(d.materials.len() - 1));
        d.materials.len() - 1
    }
}

/// A factor in [0, 1] (or `default` when absent).
fn unit(n: &Node, key: &str, default: f64) -> Result<f32, String> {
    let v = n.number_or(key, default)?;
    if !(0.0..=1.0).contains(&v) {
        return Err(format!("{}.{key}: {v} is outside [0, 1]", n.path));
    }
    Ok(v as f32)
}

/// A colour factor of `len` (3 or 4) components in [0, 1].
fn color(n: &Node, key: &str, default: [f64; 4], len: usize) -> Result<[f32; 4], String> {
    let v = n.numbers(key, len)?.unwrap_or(default[..len].to_vec());
    if v.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(format!("{}.{key}: components must lie in [0, 1]", n.path));
    }
    let mut out = [1.0f32; 4];
    for (o, c) in out.iter_mut().zip(v) {
        *o = c as f32;
    }
    Ok(out)
}

fn wrap(n: &Node, key: &str) -> Result<GltfWrap, String> {
    Ok(match n.index(key)?.unwrap_or(10497) {
        10497 => GltfWrap::Repeat,
        33071 => GltfWrap::Clamp,
        33648 => GltfWrap::Mirror,
        w => return Err(format!("{}.{key}: unknown wrap mode {w}", n.path)),
    })
}

/// A `textureInfo` object at `path` as a texture description.
fn texture(file: &GltfFile, path: &Path, info: &Value, ip: &str, srgb: bool) -> Result<TextureDesc, String> {
    let n = Node::new(info, ip);
    let ti = n.required_index("index")?;
    let tp = format!("textures[{ti}]");
    let t = Node::new(file.item("textures", ti, &format!("{ip}.index"))?, &tp);
    let image = t
        .index("source")?
        .ok_or_else(|| format!("{tp}: no source image (compressed texture extensions are not supported)"))?;
    file.item("images", image, &format!("{tp}.source"))?;
    let (mut wrap_s, mut wrap_t, mut nearest) = (GltfWrap::Repeat, GltfWrap::Repeat, false);
    if let Some(si) = t.index("sampler")? {
        let sp = format!("samplers[{si}]");
        let s = Node::new(file.item("samplers", si, &format!("{tp}.sampler"))?, &sp);
        wrap_s = wrap(&s, "wrapS")?;
        wrap_t = wrap(&s, "wrapT")?;
        // Full-resolution lookups (no mip-maps): the magnification filter decides.
        nearest = s.index("magFilter")? == Some(9728);
    }
    let mut texcoord = n.index("texCoord")?.unwrap_or(0) as u32;
    let mut transform = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    if let Some(x) = info.get("extensions").and_then(|e| e.get("KHR_texture_transform")) {
        let xp = format!("{ip}.extensions.KHR_texture_transform");
        let x = Node::new(x, &xp);
        let o = x.numbers("offset", 2)?.unwrap_or(vec![0.0, 0.0]);
        let r = x.number_or("rotation", 0.0)?;
        let s = x.numbers("scale", 2)?.unwrap_or(vec![1.0, 1.0]);
        let (sin, cos) = r.sin_cos();
        // The extension's T R S, with R = [cos sin; -sin cos].
        transform = [
            [(cos * s[0]) as f32, (sin * s[1]) as f32, o[0] as f32],
            [(-sin * s[0]) as f32, (cos * s[1]) as f32, o[1] as f32],
        ];
        if let Some(tc) = x.index("texCoord")? {
            texcoord = tc as u32;
        }
    }
    if texcoord > 1 {
        return Err(format!("{ip}.texCoord: set {texcoord} (glint reads TEXCOORD_0 and TEXCOORD_1)"));
    }
    Ok(TextureDesc::Gltf(GltfTextureDesc {
        file: path.to_path_buf(),
        image,
        srgb,
        texcoord,
        wrap_s,
        wrap_t,
        nearest,
        transform,
        scale: Rgb::WHITE,
        loc: SourceLoc::file(path),
    }))
}

fn ext<'a>(m: &Node<'a>, name: &str) -> Option<&'a Value> {
    m.get("extensions").and_then(|e| e.get(name))
}

/// One material.
fn material(file: &GltfFile, path: &Path, mi: usize) -> Result<(GltfMaterialDesc, Option<TextureDesc>, Rgb), String> {
    let mp = format!("materials[{mi}]");
    let m = Node::new(&file.array("materials")[mi], &mp);
    let mut g = GltfMaterialDesc::default_material();
    let tex = |v: &Value, p: &str, srgb: bool| texture(file, path, v, p, srgb);
    let pp = format!("{mp}.pbrMetallicRoughness");
    let empty = Value::Object(Default::default());
    let pbr = Node::new(m.get("pbrMetallicRoughness").unwrap_or(&empty), &pp);
    let base = color(&pbr, "baseColorFactor", [1.0; 4], 4)?;
    g.base_color = rgb(base[0], base[1], base[2]);
    g.base_alpha = base[3];
    g.metallic = unit(&pbr, "metallicFactor", 1.0)?;
    g.roughness = unit(&pbr, "roughnessFactor", 1.0)?;
    if let Some(t) = pbr.get("baseColorTexture") {
        g.base_color_texture = Some(tex(t, &format!("{pp}.baseColorTexture"), true)?);
    }
    if let Some(t) = pbr.get("metallicRoughnessTexture") {
        g.metallic_roughness_texture = Some(tex(t, &format!("{pp}.metallicRoughnessTexture"), false)?);
    }
    if let Some(sg) = ext(&m, "KHR_materials_pbrSpecularGlossiness") {
        // Approximated: the diffuse colour as a dielectric base, glossiness as 1 - roughness.
        let sp = format!("{mp}.extensions.KHR_materials_pbrSpecularGlossiness");
        let sg = Node::new(sg, &sp);
        let diffuse = color(&sg, "diffuseFactor", [1.0; 4], 4)?;
        g.base_color = rgb(diffuse[0], diffuse[1], diffuse[2]);
        g.base_alpha = diffuse[3];
        g.metallic = 0.0;
        g.roughness = 1.0 - unit(&sg, "glossinessFactor", 1.0)?;
        if let Some(t) = sg.get("diffuseTexture") {
            g.base_color_texture = Some(tex(t, &format!("{sp}.diffuseTexture"), true)?);
        }
    }
    if let Some(t) = m.get("normalTexture") {
        let np = format!("{mp}.normalTexture");
        g.normal_texture = Some(tex(t, &np, false)?);
        g.normal_scale = Node::new(t, &np).number_or("scale", 1.0)? as f32;
    }
    g.alpha = match m.string("alphaMode")?.unwrap_or("OPAQUE") {
        "OPAQUE" => GltfAlphaMode::Opaque,
        "MASK" => {
            let cutoff = m.number_or("alphaCutoff", 0.5)?;
            if cutoff < 0.0 {
                return Err(format!("{mp}.alphaCutoff: {cutoff} is negative"));
            }
            GltfAlphaMode::Mask { cutoff: cutoff as f32 }
        }
        "BLEND" => GltfAlphaMode::Blend,
        other => return Err(format!("{mp}.alphaMode: unknown mode '{other}'")),
    };
    g.double_sided = m.get("doubleSided").and_then(Value::as_bool).unwrap_or(false);
    let e = |name: &str| ext(&m, name).map(|v| (v, format!("{mp}.extensions.{name}")));
    if let Some((v, p)) = e("KHR_materials_ior") {
        let ior = Node::new(v, &p).number_or("ior", 1.5)?;
        // 0 is the extension's way of saying "no refraction"; glint's BSDF needs an index.
        g.ior = if ior == 0.0 { 1.0 } else { ior as f32 };
        if !(g.ior >= 1.0) {
            return Err(format!("{p}.ior: {ior} is less than 1"));
        }
    }
    // An extension's texture `key` of `n` (at `p`), if it has one.
    let ext_tex = |n: &Node, p: &str, key: &str, srgb: bool| -> Result<Option<TextureDesc>, String> {
        n.get(key).map(|t| tex(t, &format!("{p}.{key}"), srgb)).transpose()
    };
    if let Some((v, p)) = e("KHR_materials_transmission") {
        let n = Node::new(v, &p);
        g.transmission = unit(&n, "transmissionFactor", 0.0)?;
        g.transmission_texture = ext_tex(&n, &p, "transmissionTexture", false)?;
    }
    if let Some((v, p)) = e("KHR_materials_volume") {
        let n = Node::new(v, &p);
        let thickness = n.number_or("thicknessFactor", 0.0)?;
        g.thin_walled = !(thickness > 0.0);
        let c = color(&n, "attenuationColor", [1.0; 4], 3)?;
        g.attenuation_color = rgb(c[0], c[1], c[2]);
        let dist = n.number_or("attenuationDistance", f64::INFINITY)?;
        if !(dist > 0.0) {
            return Err(format!("{p}.attenuationDistance: {dist} must be positive"));
        }
        g.attenuation_distance = dist.min(f32::MAX as f64) as f32;
        g.thickness_texture = ext_tex(&n, &p, "thicknessTexture", false)?;
    }
    if let Some((v, p)) = e("KHR_materials_specular") {
        let n = Node::new(v, &p);
        g.specular = unit(&n, "specularFactor", 1.0)?;
        let c = n.numbers("specularColorFactor", 3)?.unwrap_or(vec![1.0; 3]);
        if c.iter().any(|x| !(*x >= 0.0)) {
            return Err(format!("{p}.specularColorFactor: components must not be negative"));
        }
        g.specular_color = rgb(c[0] as f32, c[1] as f32, c[2] as f32);
        g.specular_texture = ext_tex(&n, &p, "specularTexture", false)?;
        g.specular_color_texture = ext_tex(&n, &p, "specularColorTexture", true)?;
    }
    if let Some((v, p)) = e("KHR_materials_clearcoat") {
        let n = Node::new(v, &p);
        g.clearcoat = unit(&n, "clearcoatFactor", 0.0)?;
        g.clearcoat_roughness = unit(&n, "clearcoatRoughnessFactor", 0.0)?;
        g.clearcoat_texture = ext_tex(&n, &p, "clearcoatTexture", false)?;
        g.clearcoat_roughness_texture = ext_tex(&n, &p, "clearcoatRoughnessTexture", false)?;
    }
    if let Some((v, p)) = e("KHR_materials_sheen") {
        let n = Node::new(v, &p);
        let c = color(&n, "sheenColorFactor", [0.0; 4], 3)?;
        g.sheen_color = rgb(c[0], c[1], c[2]);
        g.sheen_roughness = unit(&n, "sheenRoughnessFactor", 0.0)?;
        g.sheen_color_texture = ext_tex(&n, &p, "sheenColorTexture", true)?;
        g.sheen_roughness_texture = ext_tex(&n, &p, "sheenRoughnessTexture", false)?;
    }
    g.unlit = e("KHR_materials_unlit").is_some();
    // Emission: factor x strength, textured or not.
    let ef = m.numbers("emissiveFactor", 3)?.unwrap_or(vec![0.0; 3]);
    if ef.iter().any(|c| !(*c >= 0.0)) {
        return Err(format!("{mp}.emissiveFactor: components must not be negative"));
    }
    let strength = match e("KHR_materials_emissive_strength") {
        Some((v, p)) => {
            let s = Node::new(v, &p).number_or("emissiveStrength", 1.0)?;
            if !(s >= 0.0) {
                return Err(format!("{p}.emissiveStrength: {s} is negative"));
            }
            s
        }
        None => 1.0,
    };
    let emissive = rgb((ef[0] * strength) as f32, (ef[1] * strength) as f32, (ef[2] * strength) as f32);
    let emissive_texture = match m.get("emissiveTexture") {
        Some(t) => Some(tex(t, &format!("{mp}.emissiveTexture"), true)?),
        None => None,
    };
    Ok((g, emissive_texture, emissive))
}

/// Every material of the file, added to the description in the file's order.
pub fn materials(file: &GltfFile, path: &Path, d: &mut SceneDesc) -> Result<Materials, String> {
    let mut out = Materials { index: Vec::new(), emission: Vec::new(), interior: Vec::new(), default: Cell::new(None) };
    let loc = SourceLoc::file(path);
    for mi in 0..file.array("materials").len() {
        let (g, emissive_texture, emissive) = material(file, path, mi)?;
        let name = file.array("materials")[mi].get("name").and_then(Value::as_str).unwrap_or("");
        let mut name = if name.is_empty() { format!("material {mi}") } else { name.to_string() };
        if d.material_index(&name).is_some() {
            name = format!("{name} ({mi})");
        }
        let emission = emission(&g, emissive_texture, emissive);
        out.index.push(d.materials.len());
        out.emission.push(emission);
        out.interior.push(volume_medium(&g, &name, &loc).map(|m| {
            d.media.push(m);
            d.media.len() - 1
        }));
        let two_sided = g.double_sided;
        d.materials.push(MaterialDesc { name, model: MaterialModel::Gltf(g), two_sided, loc: loc.clone() });
    }
    Ok(out)
}

/// The absorbing medium inside a `KHR_materials_volume` boundary (thickness > 0) that lets
/// light in (transmission > 0) and attenuates (a finite `attenuationDistance`, an
/// `attenuationColor` below 1 in some channel): Beer-Lambert absorption, sigma_a =
/// -ln(attenuationColor) / attenuationDistance per channel (a channel of colour 0 absorbs at
/// glint's largest extinction), nothing scattered.
fn volume_medium(g: &GltfMaterialDesc, name: &str, loc: &SourceLoc) -> Option<MediumDesc> {
    let absorbs = g.attenuation_color.to_array().iter().any(|&c| c < 1.0);
    if g.thin_walled || !(g.transmission > 0.0) || !(g.attenuation_distance < f32::MAX) || !absorbs {
        return None;
    }
    let d = g.attenuation_distance as f64;
    let sigma = |c: f32| ((-(c as f64).ln() / d).min(crate::describe::limits::MAX_EXTINCTION as f64) as f32).max(0.0);
    let c = g.attenuation_color;
    Some(MediumDesc {
        name: format!("{name} (KHR_materials_volume)"),
        sigma_t: crate::math::rgb(sigma(c.r), sigma(c.g), sigma(c.b)),
        albedo: VolumeDesc::Constant(Rgb::BLACK),
        scale: 1.0,
        phase: PhaseDesc::Isotropic,
        sample_emitters: false,
        density: None,
        absorbing_only: true,
        loc: loc.clone(),
    })
}

/// What a material's surfaces emit: the emissive colour (times its texture), or for an
/// unlit material its base colour (times its texture); none when black.
fn emission(g: &GltfMaterialDesc, texture: Option<TextureDesc>, emissive: Rgb) -> Option<Emission> {
    let (texture, scale) = if g.unlit { (g.base_color_texture.clone(), g.base_color) } else { (texture, emissive) };
    if scale.max_component() <= 0.0 {
        return None;
    }
    let radiance = match texture {
        Some(TextureDesc::Gltf(mut t)) => {
            t.scale = scale;
            TextureDesc::Gltf(t)
        }
        _ => TextureDesc::constant(scale),
    };
    Some(Emission { radiance, two_sided: g.double_sided })
}
