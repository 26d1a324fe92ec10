//! Per-vertex and per-face attributes of a mesh (Mitsuba's `vertex_NAME` and `face_NAME`,
//! read from PLY properties), looked up by the `mesh_attribute` texture.

use crate::math::{rgb, Rgb};

/// Whether an attribute has one value per vertex (interpolated) or per face (constant).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AttributeScope {
    Vertex,
    Face,
}

/// One attribute: `dim` (1 or 3) floats per vertex or per face.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttribute {
    /// Mitsuba's name, with its prefix: `vertex_color`, `face_color`, `vertex_weight`, ...
    pub name: String,
    pub scope: AttributeScope,
    pub dim: usize,
    pub values: Vec<f32>,
}

impl MeshAttribute {
    /// The value at barycentrics (b1, b2) of triangle `prim` with vertices `tri`; a
    /// 1-dimensional attribute is grey. Out-of-range indices give black (the mesh checks
    /// the sizes when it is built, so this is only a guard).
    pub fn eval(&self, tri: [u32; 3], prim: u32, bary: [f32; 2]) -> Rgb {
        let at = |i: usize| -> Rgb {
            let v = |k: usize| self.values.get(i * self.dim + k).copied().unwrap_or(0.0);
            if self.dim == 3 {
                rgb(v(0), v(1), v(2))
            } else {
                Rgb::splat(v(0))
            }
        };
        match self.scope {
            AttributeScope::Face => at(prim as usize),
            AttributeScope::Vertex => {
                let b0 = 1.0 - bary[0] - bary[1];
                at(tri[0] as usize) * b0 + at(tri[1] as usize) * bary[0] + at(tri[2] as usize) * bary[1]
            }
        }
    }

    /// Number of values the attribute must have for a mesh of `vertices` and `faces`.
    pub fn expected_len(&self, vertices: usize, faces: usize) -> usize {
        self.dim
            * match self.scope {
                AttributeScope::Vertex => vertices,
                AttributeScope::Face => faces,
            }
    }
}
