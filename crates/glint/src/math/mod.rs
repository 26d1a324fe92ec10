//! Vectors, colours, rays, boxes, transforms and frames.

mod aabb;
mod color;
mod frame;
pub mod lanes;
mod ray;
mod transform;
mod vec3;

pub use aabb::Aabb;
pub use color::{rgb, srgb_decode, srgb_encode, Rgb};
pub use frame::Frame;
pub use ray::{offset_origin, Ray};
pub use transform::{Mat4, Transform};
pub use vec3::{vec3, Vec3};

pub const PI: f32 = std::f32::consts::PI;
pub const INV_PI: f32 = std::f32::consts::FRAC_1_PI;
