//! File input and output: images and meshes.

pub mod image_io;
pub mod obj;
pub mod ply;

pub use image_io::{read_image, write_image, Image};
