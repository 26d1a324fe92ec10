//! Acceleration structures: the binary SAH BVH (the reference), the wide SIMD BVH collapsed
//! from it, and triangle intersection.

mod batch;
mod binning;
mod build;
mod bvh;
mod huge_pages;
pub mod simd;
mod top_level;
pub mod tri4;
mod triangle;
pub mod wide;
mod wide_mesh;

pub use batch::LANES as BATCH_LANES;
pub use bvh::{
    BuildOptions, Bvh, BvhNode, BvhSplit, BvhStats, TraversalVisits, MAX_DEPTH, SAH_DEPTH_LIMIT, SAH_INTERSECT_COST,
    SAH_TRAVERSAL_COST,
};
pub use simd::SimdPath;
pub use top_level::{FlatMesh, TopLevelBvh};
pub use triangle::{intersect_triangle, ShearedRay, TriangleHit};
pub use wide::{WideBvh, WideStats};
pub use wide_mesh::TriangleWideBvh;
