//! Shapes: triangle meshes (with their own BVH), analytic spheres and cylinders, signed
//! distance grids, round curves (with their own BVH).

mod attributes;
mod curve;
pub mod curve_hit;
mod cylinder;
mod mesh;
mod sdfgrid;
mod sphere;

pub use attributes::{AttributeScope, MeshAttribute};
pub use curve::{CurveBasis, CurveHit, CurvePoint, Curves, MAX_CURVE_POINTS};
pub use cylinder::{Cylinder, CylinderPoint};
pub use mesh::{
    cube_mesh, disk_mesh, quad_mesh, rectangle_mesh, AccelStats, MeshAccel, TriangleMesh, WideTris, DISK_SEGMENTS,
};
pub use sdfgrid::{solve_first_root, SdfGrid, SdfGridData, SdfNormals, SdfPoint};
pub use sphere::Sphere;
