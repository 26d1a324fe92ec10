//! glint: a physically based renderer for the CPU.
//!
//! The library is a pipeline whose modules read in order:
//! - [`formats`] read files (native JSON, Mitsuba XML, bare OBJ/PLY) into a
//!   [`describe::SceneDesc`], plain data that remembers where each entity came from;
//! - [`assemble`] turns a description into the render-ready [`world::World`] (meshes loaded
//!   once, BVHs built in parallel, area lights made, every default applied);
//! - [`integrators`] estimate radiance along rays of a world; [`render`] schedules passes of
//!   samples over tiles and threads into a film;
//! - [`session`] ties these together behind one API, which every front end (the `glint`
//!   command line, Python, the distributed driver) uses: overrides, outputs and their
//!   layers, denoising ([`denoise`]) are decided there once for all of them; [`preview`] holds
//!   the live views it feeds as passes land (a page in the browser, tev).
//!
//! Below them: [`math`], [`sampling`], [`accel`] (BVHs over boxes and triangles),
//! [`geometry`] (shapes), [`bsdf`] and [`materials`], [`media`] (participating media), [`lights`], [`camera`], [`io`] (images
//! and meshes) and [`error`] (one error type with a source location).

pub mod accel;
pub mod assemble;
pub mod bsdf;
pub mod camera;
pub mod denoise;
pub mod describe;
pub mod error;
pub mod formats;
pub mod geometry;
pub mod gradient;
pub mod integrators;
pub mod io;
pub mod lights;
pub mod materials;
pub mod math;
pub mod media;
pub mod preview;
pub mod render;
pub mod sampling;
pub mod session;
pub mod world;

/// Scratch folders for the unit tests that write files: the integration tests' helper, so
/// that there is one.
#[cfg(test)]
#[path = "../tests/common/scratch.rs"]
mod scratch;

pub use error::{Error, SourceLoc};
