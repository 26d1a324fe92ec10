//! Acceleration structures: the binary SAH BVH (the reference), and triangle intersection.

mod bvh;
mod triangle;

pub use bvh::{Bvh, BvhNode, BvhSplit, BvhStats, SAH_INTERSECT_COST, SAH_TRAVERSAL_COST};
pub use triangle::{intersect_triangle, ShearedRay, TriangleHit};
