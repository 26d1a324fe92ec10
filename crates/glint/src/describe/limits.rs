//! The bounds on what a description may ask for: readers check their numbers against these
//! before narrowing them, and the builder checks every description against them.

/// The longest side and the most pixels an image may have.
pub const MAX_SIDE: u32 = 65536;
pub const MAX_PIXELS: u64 = 1 << 28;
/// The most samples per pixel a description may ask for.
pub const MAX_SPP: u32 = 1 << 24;
/// The deepest Whitted recursion (it is iterative: this bounds the work, not the stack).
pub const MAX_WHITTED_DEPTH: u32 = 1 << 16;
/// The most light or BSDF samples the direct integrator may take per camera sample.
pub const MAX_DIRECT_SAMPLES: u32 = 1 << 12;
/// The largest extinction (per unit length, after `scale`) a medium may have: denser ones
/// would make paths of billions of tiny steps.
pub const MAX_EXTINCTION: f32 = 1e9;

/// Rejects zero and absurd resolutions.
pub fn check_resolution(w: u32, h: u32) -> Result<(), String> {
    if w == 0 || h == 0 {
        return Err(format!("resolution {w}x{h}: width and height must each be at least 1"));
    }
    if w > MAX_SIDE || h > MAX_SIDE || (w as u64) * (h as u64) > MAX_PIXELS {
        return Err(format!("resolution {w}x{h} is too large (at most {MAX_SIDE} per side and 2^28 pixels)"));
    }
    Ok(())
}
