//! Mitsuba's `shapegroup` and `instance`. A group (at scene level, with an `id`) holds
//! shapes that are not drawn themselves; each `instance` that refers to it draws every one
//! of them, placed by the shape's own `to_world` and then the instance's. Mesh files of a
//! group are loaded once (`SceneDesc::meshes`) and traced through each instance's transform,
//! so a group placed many times costs its memory once. As in Mitsuba, a group cannot hold
//! emitters, other groups or instances.

use super::props::Props;
use super::xml::Element;
use super::Reader;
use crate::describe::MeshFileDesc;
use crate::error::Error;
use std::path::PathBuf;

impl<'a> Reader<'a> {
    /// A group is drawn only through its instances; here its children are only checked.
    pub(super) fn shape_group(&mut self, el: &'a Element) -> Result<(), Error> {
        if el.attr("id").is_none() {
            return Err(el.err("a shapegroup needs an id (instances refer to it by <ref id>)"));
        }
        for c in &el.children {
            let result = match c.tag.as_str() {
                "shape" => match c.attr("type").unwrap_or("") {
                    "shapegroup" => Err(c.err("a shapegroup cannot hold another shapegroup (as in Mitsuba)")),
                    "instance" => Err(c.err("a shapegroup cannot hold an instance (as in Mitsuba)")),
                    _ => match c.children.iter().find(|e| self.is_emitter(e)) {
                        Some(e) => Err(e.err("shapes in a shapegroup cannot emit light (as in Mitsuba)")),
                        None => Ok(()),
                    },
                },
                "ref" => Err(c.err("a shapegroup holds its shapes nested, not by <ref>")),
                other => Err(c.err(format!("unexpected <{other}> in a shapegroup (it holds <shape>s)"))),
            };
            self.note(result);
        }
        Ok(())
    }

    fn is_emitter(&self, e: &'a Element) -> bool {
        e.tag == "emitter" || (e.tag == "ref" && self.resolve(e).is_ok_and(|t| t.tag == "emitter"))
    }

    /// Draws the group an instance refers to, through the instance's `to_world`.
    pub(super) fn instance(&mut self, el: &'a Element) -> Result<(), Error> {
        let p = Props::new(el);
        let to_world = p.transform("to_world")?;
        let refs: Vec<&Element> = el.children.iter().filter(|c| matches!(c.tag.as_str(), "ref" | "shape")).collect();
        let [r] = refs.as_slice() else {
            return Err(el.err("an instance needs exactly one <ref id> to a shapegroup"));
        };
        let group = self.resolve(r)?;
        if group.tag != "shape" || group.attr("type") != Some("shapegroup") {
            return Err(r.err("an instance can only refer to a shapegroup"));
        }
        for c in &el.children {
            if matches!(c.tag.as_str(), "bsdf" | "emitter" | "medium") {
                self.note::<()>(Err(
                    c.err(format!("an instance takes no <{}> (its group's shapes have their own)", c.tag))
                ));
            }
        }
        if to_world.swaps_handedness() {
            // Mitsuba keeps an instanced shape's normals outward through a mirror; glint's
            // instanced and baked meshes turn with the winding instead.
            return Err(el.err("an instance transform that mirrors (negative determinant) is not supported"));
        }
        self.warn_unused(&p);
        // The group's errors were reported where it stands; its good shapes are drawn.
        for c in group.children.iter().filter(|c| c.tag == "shape") {
            let ty = c.attr("type").unwrap_or("");
            if ty == "shapegroup" || ty == "instance" || c.children.iter().any(|e| self.is_emitter(e)) {
                continue;
            }
            let result = self.placed_shape(c, Some(&to_world));
            self.note(result);
        }
        Ok(())
    }

    /// The index in `SceneDesc::meshes` of a mesh file shared by instances.
    pub(super) fn shared_mesh(&mut self, el: &Element, file: PathBuf, face_normals: bool, shape_index: u32) -> usize {
        if let Some(i) = self
            .meshes
            .iter()
            .position(|m| m.file == file && m.face_normals == face_normals && m.shape_index == shape_index)
        {
            return i;
        }
        self.meshes.push(MeshFileDesc {
            name: format!("mesh@{}:{}", el.file.display(), el.line),
            file,
            face_normals,
            loc: el.loc(),
            shape_index,
            reverse_winding: false,
        });
        self.meshes.len() - 1
    }
}
