//! glint: a physically based renderer for the CPU.
//!
//! The crate is organised one concept per module: [`math`], [`sampling`], [`accel`] (BVH),
//! [`geometry`] (shapes), [`bsdf`] and [`materials`], [`lights`], [`camera`],
//! [`integrators`], [`render`] (tiles, threads), [`scene`] (descriptions and the
//! render-ready scene) and [`io`] (images and meshes). Front ends (the `glint` command line)
//! live in their own crates and only call into this one.

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod geometry;
pub mod integrators;
pub mod io;
pub mod lights;
pub mod materials;
pub mod math;
pub mod render;
pub mod sampling;
pub mod scene;
