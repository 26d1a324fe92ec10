//! Gradient renders (see `gradient`): the parameter names resolved against the scene, each
//! turned into what the adjoint pass reads.

use super::edit::{resolve_param_name, slots, Owner};
use super::ParamValue;
use super::Session;
use crate::assemble::{build_material, WorldLayout};
use crate::describe::slots::Slot;
use crate::describe::PixelFilter;
use crate::describe::Texels;
use crate::error::Error;
use crate::gradient::{
    render_gradient, BsdfDifference, GradientJob, LightParam, LightProbe, MaterialProbe, ParamGradient, ParamSet,
    TextureProbe,
};
use crate::integrators::Integrator;
use crate::lights::Light;
use crate::materials::{Material, MaterialDesc, SceneDesc, TextureCache, TexturePoint};
use crate::math::Rgb;
use crate::world::World;
use std::sync::atomic::AtomicBool;

/// A material parameter's step, relative to its size: small enough that a symmetric
/// difference's error (the step squared, times the third derivative) is far below Monte
/// Carlo noise, large enough that f32 rounding of the BSDF values is too.
const RELATIVE_STEP: f32 = 1e-2;
/// The step's floor, for parameters at or near zero.
const MIN_STEP: f32 = 1e-3;

/// Why a parameter has no gradient.
const NOT_GEOMETRY: &str = "gradients through geometry and the camera (which move visibility) are not supported";

impl Session {
    /// The gradient of `sum(grad_image * image)` with respect to each parameter `names`
    /// names, for the image a path-traced render of `spp` samples per pixel with `seed` and
    /// a box filter makes (see `gradient`). `grad_image` is `width * height` colours, rows
    /// from the top. Runs on the current rayon pool; `cancel` stops it within 64 samples.
    pub fn render_gradient(
        &mut self,
        names: &[String],
        grad_image: &[Rgb],
        spp: u32,
        seed: u64,
        cancel: &AtomicBool,
    ) -> Result<Vec<ParamGradient>, Error> {
        let Integrator::Path(path) = self.integrator() else {
            return Err(Error::new(format!(
                "gradients need the path integrator (Mitsuba's prb or path); the scene uses '{}'",
                self.integrator().name()
            )));
        };
        if self.desc.film.filter != PixelFilter::Box {
            return Err(Error::new(
                "gradients need the box pixel filter (each pixel the mean of its samples); set <rfilter type=\"box\"/> or \"filter\": \"box\"",
            ));
        }
        if spp == 0 {
            return Err(Error::new("spp: must be at least 1"));
        }
        let (w, h) = (self.desc.film.width as usize, self.desc.film.height as usize);
        if grad_image.len() != w * h {
            return Err(Error::new(format!("grad_image: {} pixels, but the film is {w}x{h}", grad_image.len())));
        }
        let world = self.world()?;
        let layout = self.layout.as_ref().expect("a built world has a layout");
        let mut set = ParamSet::default();
        let mut out = Vec::new();
        let desc = &mut self.desc;
        let mut canonical = Vec::new();
        for name in names {
            let c = resolve_param_name(desc, name)?;
            if canonical.contains(&c) {
                return Err(Error::new(format!("'{name}' is asked for twice")));
            }
            canonical.push(c.clone());
            let shape = add_param(&mut set, desc, &world, layout, &c)?;
            let size = shape.iter().product();
            out.push(ParamGradient { name: name.clone(), shape, values: vec![0.0; size] });
        }
        let render = crate::render::RenderSettings { seed, ..self.render_settings() };
        let job = GradientJob { world: &world, path: &path, render: &render, params: &set, grad_image, spp };
        let sums = render_gradient(&job, cancel)?;
        let mut next = sums.into_iter();
        for g in &mut out {
            for v in &mut g.values {
                *v = next.next().expect("one sum per scalar");
            }
        }
        Ok(out)
    }
}

/// Adds the parameter `name` to the set, returning its shape.
fn add_param(
    set: &mut ParamSet,
    desc: &mut SceneDesc,
    world: &World,
    layout: &WorldLayout,
    name: &str,
) -> Result<Vec<usize>, Error> {
    let mut entries = slots(desc);
    let Some(position) = entries.iter().position(|e| e.name == name) else {
        return Err(Error::new(format!("no parameter called '{name}'")));
    };
    // The slot's place among its owner's, to find it again in a copy of the owner.
    let owner = entries[position].owner;
    let rank = entries[..position].iter().filter(|e| e.owner == owner).count();
    let slot = entries.swap_remove(position).slot;
    let not = |why: &str| Error::new(format!("'{name}' is not differentiable: {why}"));
    match owner {
        Owner::Material(m) => {
            drop(entries);
            material_param(set, &desc.materials[m], m, rank, name)
        }
        Owner::Shape(s) => {
            let lights: Vec<usize> = layout.shape_instances[s]
                .clone()
                .filter_map(|i| world.instances[i as usize].light.map(|l| l as usize))
                .collect();
            match slot {
                Slot::Color(value) => {
                    colour_light_param(set, &lights, *value);
                    Ok(vec![3])
                }
                slot @ Slot::Texels { .. } => {
                    let Slot::Texels { uv, .. } = &slot else { unreachable!("matched above") };
                    let uv = *uv;
                    let Some(ParamValue::Image(t)) = slot.get() else {
                        return Err(Error::new(format!("'{name}': the emission's image cannot be read")));
                    };
                    let (width, height) = (t.width, t.height);
                    let index = set.new_entries(width * height * 3);
                    for &light in &lights {
                        let param = LightParam::AreaTexels { width, height, uv };
                        set.add_light_probe(light, LightProbe { index, param });
                    }
                    Ok(vec![height, width, 3])
                }
                Slot::Float(_) | Slot::Matrix(_) | Slot::OptionalMatrix(_) => Err(not(NOT_GEOMETRY)),
            }
        }
        Owner::Light(l) => {
            let light = layout.shape_lights as usize + l;
            match slot {
                Slot::Color(value) => {
                    colour_light_param(set, &[light], *value);
                    Ok(vec![3])
                }
                Slot::Float(value) => {
                    let index = set.new_entry();
                    set.add_light_probe(light, LightProbe { index, param: LightParam::Scale { value: *value } });
                    Ok(vec![])
                }
                Slot::Texels { .. } => {
                    let Some(Light::EnvMap(env)) = world.lights.get(light) else {
                        return Err(not("only an environment map's texels are"));
                    };
                    let (w, h) = (env.image.width, env.image.height);
                    let index = set.new_entries(w * h * 3);
                    set.add_light_probe(light, LightProbe { index, param: LightParam::Texels { scale: env.scale } });
                    Ok(vec![h, w, 3])
                }
                Slot::Matrix(_) | Slot::OptionalMatrix(_) => Err(not(NOT_GEOMETRY)),
            }
        }
        Owner::Camera => Err(not(NOT_GEOMETRY)),
    }
}

/// A colour that a light's emission is proportional to, channel by channel, on each light.
fn colour_light_param(set: &mut ParamSet, lights: &[usize], value: Rgb) {
    for c in 0..3 {
        let index = set.new_entry();
        for &light in lights {
            set.add_light_probe(light, LightProbe { index, param: LightParam::Channel { c, value } });
        }
    }
}

/// A material parameter's value: its scalars, or an image's texels.
enum Value {
    Scalars(Vec<f32>),
    Texels(Texels, [[f32; 2]; 2]),
}

/// The `rank`-th parameter of material `d`.
fn value_of(d: &mut MaterialDesc, rank: usize) -> Option<Value> {
    match d.model.slots().into_iter().nth(rank).map(|(_, s)| s)? {
        Slot::Float(v) => Some(Value::Scalars(vec![*v])),
        Slot::Color(v) => Some(Value::Scalars(v.to_array().to_vec())),
        slot @ Slot::Texels { .. } => {
            let Slot::Texels { uv, .. } = &slot else { return None };
            let uv = *uv;
            match slot.get()? {
                ParamValue::Image(t) => Some(Value::Texels(t, uv)),
                ParamValue::Float(_) | ParamValue::Color(_) | ParamValue::Matrix(_) => None,
            }
        }
        Slot::Matrix(_) | Slot::OptionalMatrix(_) => None,
    }
}

/// Material `d` with its `rank`-th parameter moved: scalar `k` (a number's, or a colour's
/// channel k) to `to`, or an image's channel k by `to` in every texel. `None` where the
/// material refuses the value.
fn moved(d: &MaterialDesc, rank: usize, k: usize, to: f32, textures: &mut TextureCache) -> Option<Material> {
    let mut d = d.clone();
    match d.model.slots().into_iter().nth(rank).map(|(_, s)| s)? {
        Slot::Float(x) => *x = to,
        Slot::Color(x) => {
            let mut a = x.to_array();
            a[k] = to;
            *x = crate::math::rgb(a[0], a[1], a[2]);
        }
        Slot::Texels { texels, .. } => {
            let t = texels.as_mut()?;
            for p in &mut t.pixels {
                let mut a = p.to_array();
                a[k] += to;
                *p = crate::math::rgb(a[0], a[1], a[2]);
            }
        }
        Slot::Matrix(_) | Slot::OptionalMatrix(_) => return None,
    }
    d.model.validate().ok()?;
    build_material(&d, textures).ok()
}

/// Material `m`'s `rank`-th parameter: one probe per scalar, or per channel of an image.
fn material_param(
    set: &mut ParamSet,
    desc: &MaterialDesc,
    m: usize,
    rank: usize,
    name: &str,
) -> Result<Vec<usize>, Error> {
    let mut textures = TextureCache::default();
    let built = build_material(desc, &mut textures)?;
    if built.bsdf_at(&TexturePoint::uv([0.5, 0.5])).is_delta() {
        return Err(Error::new(format!(
            "'{name}' is not differentiable: material '{}' scatters only through delta lobes, which have no BSDF value to differentiate",
            desc.name
        )));
    }
    let mut desc = desc.clone();
    let Some(value) = value_of(&mut desc, rank) else {
        return Err(Error::new(format!("'{name}' is not differentiable: {NOT_GEOMETRY}")));
    };
    // A side the material refuses (a roughness at zero, say) is the value itself: the
    // difference is then one-sided.
    let mut probe = |k: usize, v: f32, from: f32, d: &MaterialDesc| -> Result<BsdfDifference, Error> {
        let step = (v.abs() * RELATIVE_STEP).max(MIN_STEP);
        let (lo, minus) = match moved(d, rank, k, from - step, &mut textures) {
            Some(x) => (from - step, x),
            None => (from, built.clone()),
        };
        let (hi, plus) = match moved(d, rank, k, from + step, &mut textures) {
            Some(x) => (from + step, x),
            None => (from, built.clone()),
        };
        if !(hi > lo) {
            return Err(Error::new(format!("'{name}': the material accepts no value near {v} but {v}")));
        }
        Ok(BsdfDifference { minus, plus, inv_step: 1.0 / (hi - lo) })
    };
    match value {
        Value::Scalars(values) => {
            for (k, &v) in values.iter().enumerate() {
                let index = set.new_entry();
                let difference = probe(k, v, v, &desc)?;
                set.add_material_probe(m, MaterialProbe { index, difference });
            }
            Ok(if values.len() == 1 { vec![] } else { vec![3] })
        }
        Value::Texels(t, uv) => {
            // The probes hold the texels (read from the file once), moved by a step.
            let mut with_texels = desc.clone();
            if let Some(Slot::Texels { texels, .. }) = with_texels.model.slots().into_iter().nth(rank).map(|(_, s)| s) {
                *texels = Some(t.clone());
            }
            let base = set.new_entries(t.width * t.height * 3);
            let mut channels = Vec::with_capacity(3);
            for k in 0..3 {
                let typical = t.pixels.iter().map(|p| p.to_array()[k].abs()).sum::<f32>() / t.pixels.len() as f32;
                channels.push(probe(k, typical, 0.0, &with_texels)?);
            }
            let channels: [BsdfDifference; 3] = channels.try_into().map_err(|_| Error::new("three channels"))?;
            set.add_texture_probe(m, TextureProbe { base, width: t.width, height: t.height, uv, channels });
            Ok(vec![t.height, t.width, 3])
        }
    }
}
