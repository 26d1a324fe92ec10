//! `KHR_lights_punctual`: point, spot and directional lights at their nodes, with the
//! photometric units converted to radiometric ones at 683 lm/W (1 cd -> 1/683 W/sr,
//! 1 lx -> 1/683 W/m^2), as Blender's importer does.

use super::scene::Walk;
use crate::describe::{LightDesc, LightKind, Matrix4, SpotFalloff};
use crate::error::SourceLoc;
use crate::io::gltf::{GltfFile, Node};
use crate::materials::SceneDesc;
use crate::math::{rgb, vec3, Vec3};
use serde_json::Value;

/// Lumens per watt at 555 nm: the luminous efficacy the conversion uses.
pub const LUMENS_PER_WATT: f64 = 683.0;

fn point(m: &Matrix4, p: [f64; 3]) -> Vec3 {
    let w = |r: usize| (m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]) as f32;
    vec3(w(0), w(1), w(2))
}

fn direction(m: &Matrix4, v: [f64; 3]) -> Vec3 {
    let w = |r: usize| (m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2]) as f32;
    vec3(w(0), w(1), w(2)).normalize()
}

/// Adds the lights the walk met.
pub fn punctual(file: &GltfFile, walk: &Walk, d: &mut SceneDesc) -> Result<(), String> {
    let list = file
        .json
        .get("extensions")
        .and_then(|e| e.get("KHR_lights_punctual"))
        .and_then(|l| l.get("lights"))
        .and_then(Value::as_array)
        .map(Vec::as_slice)
        .unwrap_or(&[]);
    let loc = d.source.as_deref().map(SourceLoc::file).unwrap_or_default();
    for (node, li, world) in &walk.lights {
        let lp = format!("extensions.KHR_lights_punctual.lights[{li}]");
        let l = list.get(*li).ok_or_else(|| {
            format!("nodes[{node}].extensions.KHR_lights_punctual.light: {lp} does not exist ({} lights)", list.len())
        })?;
        let n = Node::new(l, &lp);
        let c = n.numbers("color", 3)?.unwrap_or(vec![1.0; 3]);
        let intensity = n.number_or("intensity", 1.0)?;
        if c.iter().any(|x| !(*x >= 0.0)) || !(intensity >= 0.0) {
            return Err(format!("{lp}: colour and intensity must not be negative"));
        }
        let k = intensity / LUMENS_PER_WATT;
        let power = rgb((c[0] * k) as f32, (c[1] * k) as f32, (c[2] * k) as f32);
        let position = point(world, [0.0; 3]);
        let dir = direction(world, [0.0, 0.0, -1.0]);
        if !dir.is_finite() {
            return Err(format!("nodes[{node}]: the light's transform collapses its direction"));
        }
        let light = match n.string("type")? {
            Some("point") => LightKind::Point { position, intensity: power },
            Some("directional") => LightKind::Directional { direction: dir, irradiance: power },
            Some("spot") => {
                let sp = format!("{lp}.spot");
                let s = Node::new(n.get("spot").unwrap_or(&Value::Null), &sp);
                let inner = s.number_or("innerConeAngle", 0.0)?;
                let outer = s.number_or("outerConeAngle", std::f64::consts::FRAC_PI_4)?;
                if !(0.0 <= inner && inner < outer && outer <= std::f64::consts::FRAC_PI_2) {
                    return Err(format!("{sp}: cone angles must satisfy 0 <= inner < outer <= pi/2"));
                }
                LightKind::Spot {
                    position,
                    direction: dir,
                    intensity: power,
                    cutoff_degrees: outer.to_degrees() as f32,
                    beam_degrees: inner.to_degrees() as f32,
                    falloff: SpotFalloff::Gltf,
                }
            }
            other => return Err(format!("{lp}.type: {other:?} is not point, spot or directional")),
        };
        // The light's own name, else its node's: what `traverse` calls it.
        let named = |v: &Value| v.get("name").and_then(Value::as_str).filter(|s| !s.is_empty()).map(str::to_string);
        let name = named(l).or_else(|| file.array("nodes").get(*node).and_then(named));
        d.lights.push(LightDesc { light, name, loc: loc.clone() });
    }
    Ok(())
}
