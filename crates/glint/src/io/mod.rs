//! File input and output: images and meshes.

pub mod image_io;
pub mod layers;
pub mod obj;
pub mod ply;
mod texture_file;

pub use image_io::{read_image, write_image, Image};
pub use texture_file::read_texture_image;
