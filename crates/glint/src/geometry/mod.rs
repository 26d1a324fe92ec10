//! Shapes: triangle meshes (with their own BVH) and analytic spheres.

mod mesh;
mod sphere;

pub use mesh::{cube_mesh, disk_mesh, quad_mesh, AccelStats, MeshAccel, TriangleMesh, WideTris};
pub use sphere::Sphere;
