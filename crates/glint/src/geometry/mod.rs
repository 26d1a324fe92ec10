//! Shapes: triangle meshes (with their own BVH) and analytic spheres.

mod attributes;
mod mesh;
mod sphere;

pub use attributes::{AttributeScope, MeshAttribute};
pub use mesh::{
    cube_mesh, disk_mesh, quad_mesh, rectangle_mesh, AccelStats, MeshAccel, TriangleMesh, WideTris, DISK_SEGMENTS,
};
pub use sphere::Sphere;
