//! Denoising, the same for every front end (`glint render --denoise`, `glint.denoise`, the
//! distributed driver): Intel Open Image Denoise 2, found once per process (see [`oidn`]).
//!
//! As Cycles' "accurate" mode, the albedo and normal layers are denoised first and the image
//! is then filtered with `cleanAux`, so that the layers' own noise is not copied into it.

mod oidn;

use crate::describe::Aov;
use crate::error::Error;
use crate::io::Image;
use oidn::Oidn;
use std::path::Path;
use std::sync::OnceLock;

/// The layers that guide the denoiser: a film to be denoised keeps them.
pub const GUIDE_AOVS: [Aov; 2] = [Aov::Albedo, Aov::Normal];

/// `aovs`, then the guide layers among them when `denoise` is set.
pub fn with_guides(aovs: &[Aov], denoise: bool) -> Vec<Aov> {
    let mut out = aovs.to_vec();
    for g in GUIDE_AOVS.iter().filter(|_| denoise) {
        if !out.contains(g) {
            out.push(*g);
        }
    }
    out
}

/// The loaded denoiser.
#[derive(Clone, Copy)]
pub struct Denoiser {
    oidn: &'static Oidn,
}

static LOADED: OnceLock<Oidn> = OnceLock::new();

impl Denoiser {
    /// Finds and loads Open Image Denoise (once per process; a failed search is tried again
    /// on the next call). `python`: an interpreter whose `pyoidn` package to look in first
    /// (a Python front end passes its own). The error says in one line how to install it.
    pub fn load(python: Option<&Path>) -> Result<Denoiser, Error> {
        if let Some(oidn) = LOADED.get() {
            return Ok(Denoiser { oidn });
        }
        let found = Oidn::load(python).map_err(Error::new)?;
        Ok(Denoiser { oidn: LOADED.get_or_init(|| found) })
    }

    /// Denoises a linear HDR image, guided by the `albedo` and `normal` layers of the same
    /// render where given (a normal needs an albedo).
    pub fn denoise(&self, image: &Image, albedo: Option<&Image>, normal: Option<&Image>) -> Result<Image, Error> {
        if normal.is_some() && albedo.is_none() {
            return Err(Error::new("denoise: a normal guide needs an albedo guide too"));
        }
        self.oidn.denoise(image, albedo, normal).map_err(Error::new)
    }
}
