//! Which PLY properties become mesh attributes, and under which names: Mitsuba 3's rules
//! (its PLY loader), so that a `mesh_attribute` texture names the same data in both.
//!
//! - `r`, `g`, `b` (or `red`, `green`, `blue`) anywhere in the element: `{vertex|face}_color`.
//! - Other consecutive properties `{prefix}_{c}` whose suffixes run through one of `x y z w`,
//!   `r g b a`, `0 1 2 3` or `1 2 3 4`, with 1 or 3 of them: `{vertex|face}_{prefix}`, with
//!   `_color` appended for the `r g b a` scheme. Anything else is skipped, as Mitsuba skips it.
//! - Values are used as stored, integers too: Mitsuba 3.9.1 keeps a `uchar` 255 as 255.0
//!   (with a warning that colours should be in [0, 1]), and so does glint.

use crate::geometry::{AttributeScope, MeshAttribute};

/// One attribute to fill: its name and the property indices (within the element) it reads.
#[derive(Clone, Debug, PartialEq)]
pub struct AttributeLayout {
    pub name: String,
    pub props: Vec<usize>,
}

/// The attributes of an element whose (non-list) properties are `names`, minus `reserved`
/// ones; `prefix` is `vertex_` or `face_`.
pub fn attribute_layout(names: &[&str], reserved: &[&str], prefix: &str) -> Vec<AttributeLayout> {
    let pos = |n: &str| names.iter().position(|m| *m == n);
    let mut out = Vec::new();
    let mut colour: Vec<&str> = vec![];
    for set in [["r", "g", "b"], ["red", "green", "blue"]] {
        if set.iter().all(|n| pos(n).is_some()) && colour.is_empty() {
            out.push(AttributeLayout {
                name: format!("{prefix}color"),
                props: set.iter().filter_map(|n| pos(n)).collect(),
            });
            colour = set.to_vec();
        }
    }
    let skip = |n: &str| reserved.contains(&n) || colour.contains(&n) || ["r", "g", "b", "a", "alpha"].contains(&n);
    const SCHEMES: [&str; 4] = ["xyzw", "rgba", "0123", "1234"];
    let mut seen: Vec<String> = Vec::new();
    // The group being read: its prefix, scheme and properties.
    let mut group: Option<(String, usize, Vec<usize>)> = None;
    let flush =
        |g: &mut Option<(String, usize, Vec<usize>)>, out: &mut Vec<AttributeLayout>, seen: &mut Vec<String>| {
            if let Some((p, scheme, props)) = g.take() {
                let name = |suffix: &str| format!("{prefix}{p}{suffix}");
                if (props.len() == 1 || props.len() == 3)
                    && !out.iter().any(|a| a.name == name(if scheme == 1 { "_color" } else { "" }))
                {
                    let suffix = if scheme == 1 { "_color" } else { "" };
                    out.push(AttributeLayout { name: format!("{prefix}{p}{suffix}"), props });
                }
                seen.push(p);
            }
        };
    for (i, name) in names.iter().enumerate() {
        if skip(name) {
            continue;
        }
        let Some((p, post)) = name.rsplit_once('_') else {
            flush(&mut group, &mut out, &mut seen);
            continue;
        };
        let mut chars = post.chars();
        let (Some(c), None) = (chars.next(), chars.next()) else {
            flush(&mut group, &mut out, &mut seen);
            continue;
        };
        if let Some((gp, scheme, props)) = &mut group {
            if gp == p {
                if SCHEMES[*scheme].chars().nth(props.len()) == Some(c) {
                    props.push(i);
                } else {
                    // A broken sequence: Mitsuba drops the whole attribute.
                    seen.push(p.to_string());
                    group = None;
                }
                continue;
            }
            flush(&mut group, &mut out, &mut seen);
        }
        if seen.iter().any(|s| s == p) {
            continue;
        }
        if let Some(scheme) = SCHEMES.iter().position(|s| s.starts_with(c)) {
            group = Some((p.to_string(), scheme, vec![i]));
        }
    }
    flush(&mut group, &mut out, &mut seen);
    out
}

/// Collects attribute values while an element is read.
pub struct AttributeReader {
    layouts: Vec<AttributeLayout>,
    values: Vec<Vec<f32>>,
    scope: AttributeScope,
}

impl AttributeReader {
    pub fn new(layouts: Vec<AttributeLayout>, scope: AttributeScope) -> AttributeReader {
        let values = layouts.iter().map(|_| Vec::new()).collect();
        AttributeReader { layouts, values, scope }
    }

    /// Appends one entry's values (`vals` holds every property of the element), `repeat`
    /// times (a polygon's triangles).
    pub fn push(&mut self, vals: &[f32], repeat: usize) {
        for (l, out) in self.layouts.iter().zip(&mut self.values) {
            for _ in 0..repeat {
                out.extend(l.props.iter().map(|&k| vals[k]));
            }
        }
    }

    pub fn finish(self) -> Vec<MeshAttribute> {
        let scope = self.scope;
        self.layouts
            .into_iter()
            .zip(self.values)
            .map(|(l, values)| MeshAttribute { dim: l.props.len(), name: l.name, scope, values })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(l: &[AttributeLayout]) -> Vec<(String, Vec<usize>)> {
        l.iter().map(|a| (a.name.clone(), a.props.clone())).collect()
    }

    #[test]
    fn groups_as_mitsuba_does() {
        let n = ["x", "y", "z", "color_0", "color_1", "color_2", "weight_x"];
        let l = attribute_layout(&n, &["x", "y", "z"], "vertex_");
        assert_eq!(
            names(&l),
            vec![("vertex_color".to_string(), vec![3, 4, 5]), ("vertex_weight".to_string(), vec![6])]
        );
        let l = attribute_layout(&["x", "blue", "green", "red"], &["x"], "vertex_");
        assert_eq!(names(&l), vec![("vertex_color".to_string(), vec![3, 2, 1])]);
        let l = attribute_layout(&["albedo_r", "albedo_g", "albedo_b", "two_x", "two_y"], &[], "face_");
        assert_eq!(names(&l), vec![("face_albedo_color".to_string(), vec![0, 1, 2])]);
        // A broken sequence and a name without a suffix are skipped.
        let l = attribute_layout(&["q_x", "q_z", "plain"], &[], "face_");
        assert!(l.is_empty());
    }
}
