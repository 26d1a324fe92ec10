//! glTF cameras: perspective (`yfov`, `aspectRatio`; `znear`/`zfar` ignored, as a path
//! tracer has no clip planes) and orthographic (`xmag`, `ymag`). The first camera node of
//! a depth-first walk of the default scene is used unless the user picks one.

use super::mul;
use super::scene::Walk;
use crate::describe::{FovAxis, Matrix4, Projection};
use crate::io::gltf::{GltfFile, Node};
use crate::materials::SceneDesc;
use serde_json::Value;

/// Film height when a camera gives the aspect ratio; both sides default to 640 x 480.
const FILM_HEIGHT: u32 = 480;

/// Chooses the camera (by `pick`: a camera's index, or its name or its node's name).
pub fn choose(
    file: &GltfFile,
    walk: &Walk,
    pick: Option<&str>,
    d: &mut SceneDesc,
    warnings: &mut Vec<String>,
) -> Result<(), String> {
    let name_of = |list: &str, i: usize| file.array(list).get(i).and_then(|v| v.get("name")).and_then(Value::as_str);
    let chosen = match pick {
        None => walk.cameras.first(),
        Some(p) => {
            let by_index = p.parse::<usize>().ok();
            let found = walk.cameras.iter().find(|(node, cam, _)| {
                by_index == Some(*cam) || name_of("cameras", *cam) == Some(p) || name_of("nodes", *node) == Some(p)
            });
            if found.is_none() {
                let names: Vec<String> = walk
                    .cameras
                    .iter()
                    .map(|(n, c, _)| {
                        format!("{c} ({})", name_of("cameras", *c).or(name_of("nodes", *n)).unwrap_or("unnamed"))
                    })
                    .collect();
                return Err(format!(
                    "--camera {p}: no camera of the default scene has that index or name (cameras: {})",
                    if names.is_empty() { "none".to_string() } else { names.join(", ") }
                ));
            }
            found
        }
    };
    let Some((_, ci, world)) = chosen else {
        warnings.push("the glTF scene has no camera: framing the scene from the front".into());
        return Ok(());
    };
    let cp = format!("cameras[{ci}]");
    let c = Node::new(&file.array("cameras")[*ci], &cp);
    // glTF cameras look down -z with +x right; glint's look down +z with +x left.
    let flip: Matrix4 = [[-1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
    match c.string("type")? {
        Some("perspective") => {
            let pp = format!("{cp}.perspective");
            let p = Node::new(c.get("perspective").ok_or_else(|| format!("{pp}: missing"))?, &pp);
            let yfov = p.number("yfov")?.ok_or_else(|| format!("{pp}.yfov: missing"))?;
            if !(yfov > 0.0 && yfov < std::f64::consts::PI) {
                return Err(format!("{pp}.yfov: {yfov} is not an angle in (0, pi)"));
            }
            if let Some(aspect) = p.number("aspectRatio")? {
                film_aspect(d, aspect, &pp)?;
            }
            d.camera.to_world = Some(mul(world, &flip));
            d.camera.fov_degrees = yfov.to_degrees() as f32;
            d.camera.fov_axis = FovAxis::Y;
            d.camera.projection = Projection::Perspective;
        }
        Some("orthographic") => {
            let op = format!("{cp}.orthographic");
            let o = Node::new(c.get("orthographic").ok_or_else(|| format!("{op}: missing"))?, &op);
            let xmag = o.number("xmag")?.ok_or_else(|| format!("{op}.xmag: missing"))?;
            let ymag = o.number("ymag")?.ok_or_else(|| format!("{op}.ymag: missing"))?;
            if !(xmag > 0.0 && ymag > 0.0) {
                return Err(format!("{op}: xmag and ymag must be positive"));
            }
            film_aspect(d, xmag / ymag, &op)?;
            // Camera space's window is x in [-1, 1], y in [-1/aspect, 1/aspect]: scaled by
            // xmag it spans [-xmag, xmag] x [-ymag, ymag].
            let scale: Matrix4 =
                [[-xmag, 0.0, 0.0, 0.0], [0.0, xmag, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
            d.camera.to_world = Some(mul(world, &scale));
            d.camera.projection = Projection::Orthographic;
        }
        other => return Err(format!("{cp}.type: {other:?} is neither \"perspective\" nor \"orthographic\"")),
    }
    Ok(())
}

fn film_aspect(d: &mut SceneDesc, aspect: f64, path: &str) -> Result<(), String> {
    if !(aspect > 1e-3 && aspect < 1e3) {
        return Err(format!("{path}: aspect ratio {aspect} is out of range"));
    }
    d.film.height = FILM_HEIGHT;
    d.film.width = ((FILM_HEIGHT as f64 * aspect).round() as u32).max(1);
    Ok(())
}
