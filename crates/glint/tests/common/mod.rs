//! Support code shared by the validation tests (each test binary uses a part of it).
#![allow(dead_code)]

pub mod analytic;
pub mod bsdf_check;
pub mod load;
pub mod scenes;
pub mod scratch;
pub mod stats;
