//! Shapes: triangle meshes (with their own BVH), analytic spheres and cylinders.

mod attributes;
mod cylinder;
mod mesh;
mod sphere;

pub use attributes::{AttributeScope, MeshAttribute};
pub use cylinder::{Cylinder, CylinderPoint};
pub use mesh::{
    cube_mesh, disk_mesh, quad_mesh, rectangle_mesh, AccelStats, MeshAccel, TriangleMesh, WideTris, DISK_SEGMENTS,
};
pub use sphere::Sphere;
