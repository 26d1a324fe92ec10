//! The two materials without parameters: `black` absorbs everything (emitters without a
//! material), `null` lets light through unchanged (Mitsuba's `null`: a medium's boundary).
//! Their BSDFs ([`Black`], [`Null`]) are their built form.
//!
//! # The BSDF
//! The two BSDFs without parameters: [`Black`] absorbs everything (emitters without a
//! material), [`Null`] passes light straight through unchanged (Mitsuba's `null`: the
//! boundary of a medium).
//!
//! # Differentiable
//! Nothing: `black` and `null` have no parameters. See `docs/differentiable.md`.

use super::{Bsdf, Describe, MaterialKind, Shade, TextureCache, TexturePoint};
use crate::bsdf::{BsdfSample, Scatter};
use crate::describe::slots::Slot;
use crate::describe::TextureDesc;
use crate::error::Error;
use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

/// Absorbs everything.
#[derive(Clone, Copy, Debug)]
pub struct Black;

/// Passes light straight through, unchanged.
#[derive(Clone, Copy, Debug)]
pub struct Null;

impl Scatter for Black {
    fn is_delta(&self) -> bool {
        false
    }

    fn has_delta_lobe(&self) -> bool {
        false
    }

    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, _wo: Vec3, _u_lobe: f32, _u: [f32; 2]) -> Option<BsdfSample> {
        None
    }

    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }
}

impl Scatter for Null {
    fn is_delta(&self) -> bool {
        true
    }

    fn has_delta_lobe(&self) -> bool {
        true
    }

    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::BLACK
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, _u: [f32; 2]) -> Option<BsdfSample> {
        Some(BsdfSample { wi: -wo, weight: Rgb::WHITE, pdf: 1.0, delta: true, eta: 1.0 })
    }

    fn diffuse_reflectance(&self) -> Rgb {
        Rgb::BLACK
    }

    fn passage_transmission(&self, _wo: Vec3) -> Option<Rgb> {
        Some(Rgb::WHITE)
    }
}

/// `black` has no parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlackDesc {}

/// `null` has no parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NullDesc {}

/// The description of a material without parameters: its built form is its BSDF.
macro_rules! unit_describe {
    ($($desc:ty => $built:expr),+) => {$(
        impl Describe for $desc {
            type Built = MaterialKind;

            fn build(&self, _textures: &mut TextureCache) -> Result<MaterialKind, Error> {
                Ok($built.into())
            }

            fn validate(&self) -> Result<(), String> {
                Ok(())
            }

            fn textures(&self) -> Vec<&TextureDesc> {
                Vec::new()
            }

            fn textures_mut(&mut self) -> Vec<&mut TextureDesc> {
                Vec::new()
            }

            fn slots(&mut self) -> Vec<(&'static str, Slot<'_>)> {
                Vec::new()
            }
        }
    )+};
}

unit_describe!(BlackDesc => Black, NullDesc => Null);

impl Shade for Black {
    #[inline]
    fn bsdf_at(&self, _p: &TexturePoint) -> Bsdf {
        Bsdf::Black(Black)
    }

    fn albedo(&self, _uv: [f32; 2]) -> Rgb {
        Rgb::BLACK
    }

    fn is_transmissive(&self) -> bool {
        false
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}

impl Shade for Null {
    #[inline]
    fn bsdf_at(&self, _p: &TexturePoint) -> Bsdf {
        Bsdf::Null(Null)
    }

    fn albedo(&self, _uv: [f32; 2]) -> Rgb {
        Rgb::WHITE
    }

    fn is_transmissive(&self) -> bool {
        true
    }

    fn nested(&self) -> Option<&MaterialKind> {
        None
    }
}
