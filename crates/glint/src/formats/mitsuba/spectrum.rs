//! Spectra as Mitsuba 3's RGB variants turn them into RGB: a wavelength:value list is
//! integrated against the CIE 1931 colour matching functions (times the D65 illuminant for
//! reflectances), normalised, and taken from XYZ to linear sRGB (Rec. 709), with Mitsuba's
//! quadrature and clamping (`spectrum_list_to_srgb` in Mitsuba's `src/core/spectrum.cpp`,
//! `Properties::get_texture_impl` in `src/core/properties.cpp`). A blackbody, which Mitsuba
//! renders only in its spectral variants, becomes the RGB that a spectral render shows of it
//! (its radiance integrated against the matching functions, with the same normalisation).
//!
//! The tables are the CIE 1931 2-degree colour matching functions and the CIE D65 illuminant
//! at 5 nm from 360 to 830 nm (CIE 015:2004), as Mitsuba tabulates and interpolates them.

use crate::math::Rgb;

/// How a parameter's spectrum is converted: Mitsuba's `get_texture`, `get_unbounded_texture`
/// and `get_emissive_texture`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumUse {
    /// A reflectance-like quantity: weighted by D65, clamped to [0, 1].
    Reflectance,
    /// A bounded-below quantity such as a conductor's eta and k: weighted by D65, clamped at 0.
    Unbounded,
    /// An emitter's radiance, intensity or irradiance: not weighted by D65, clamped at 0; a
    /// constant spectrum is not grey but `value * xyz_to_srgb(1, 1, 1)`.
    Emission,
}

const CIE_MIN: f64 = 360.0;
const CIE_MAX: f64 = 830.0;
const CIE_SAMPLES: usize = 95;
/// Scales the matching functions so that a unit spectrum has luminance 1.
const CIE_Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06;
/// Scales D65 so that it has luminance 1.
const CIE_D65_NORMALIZATION: f64 = 1.0 / 98.99741751876255;

const CIE_X: [f32; CIE_SAMPLES] = [
    0.0001299,
    0.0002321,
    0.0004149,
    0.0007416,
    0.001368,
    0.002236,
    0.004243,
    0.00765,
    0.01431,
    0.02319,
    0.04351,
    0.07763,
    0.13438,
    0.21477,
    0.2839,
    0.3285,
    0.34828,
    0.34806,
    0.3362,
    0.3187,
    0.2908,
    0.2511,
    0.19536,
    0.1421,
    0.09564,
    0.05795001,
    0.03201,
    0.0147,
    0.0049,
    0.0024,
    0.0093,
    0.0291,
    0.06327,
    0.1096,
    0.1655,
    0.2257499,
    0.2904,
    0.3597,
    0.4334499,
    0.5120501,
    0.5945,
    0.6784,
    0.7621,
    0.8425,
    0.9163,
    0.9786,
    1.0263,
    1.0567,
    1.0622,
    1.0456,
    1.0026,
    0.9384,
    0.8544499,
    0.7514,
    0.6424,
    0.5419,
    0.4479,
    0.3608,
    0.2835,
    0.2187,
    0.1649,
    0.1212,
    0.0874,
    0.0636,
    0.04677,
    0.0329,
    0.0227,
    0.01584,
    0.01135916,
    0.008110916,
    0.005790346,
    0.004109457,
    0.002899327,
    0.00204919,
    0.001439971,
    0.0009999493,
    0.0006900786,
    0.0004760213,
    0.0003323011,
    0.0002348261,
    0.0001661505,
    0.000117413,
    8.307527e-05,
    5.870652e-05,
    4.150994e-05,
    2.935326e-05,
    2.067383e-05,
    1.455977e-05,
    1.025398e-05,
    7.221456e-06,
    5.085868e-06,
    3.581652e-06,
    2.522525e-06,
    1.776509e-06,
    1.251141e-06,
];
const CIE_Y: [f32; CIE_SAMPLES] = [
    3.917e-06, 6.965e-06, 1.239e-05, 2.202e-05, 3.9e-05, 6.4e-05, 0.00012, 0.000217, 0.000396, 0.00064, 0.00121,
    0.00218, 0.004, 0.0073, 0.0116, 0.01684, 0.023, 0.0298, 0.038, 0.048, 0.06, 0.0739, 0.09098, 0.1126, 0.13902,
    0.1693, 0.20802, 0.2586, 0.323, 0.4073, 0.503, 0.6082, 0.71, 0.7932, 0.862, 0.9148501, 0.954, 0.9803, 0.9949501,
    1.0, 0.995, 0.9786, 0.952, 0.9154, 0.87, 0.8163, 0.757, 0.6949, 0.631, 0.5668, 0.503, 0.4412, 0.381, 0.321, 0.265,
    0.217, 0.175, 0.1382, 0.107, 0.0816, 0.061, 0.04458, 0.032, 0.0232, 0.017, 0.01192, 0.00821, 0.005723, 0.004102,
    0.002929, 0.002091, 0.001484, 0.001047, 0.00074, 0.00052, 0.0003611, 0.0002492, 0.0001719, 0.00012, 8.48e-05,
    6e-05, 4.24e-05, 3e-05, 2.12e-05, 1.499e-05, 1.06e-05, 7.4657e-06, 5.2578e-06, 3.7029e-06, 2.6078e-06, 1.8366e-06,
    1.2934e-06, 9.1093e-07, 6.4153e-07, 4.5181e-07,
];
const CIE_Z: [f32; CIE_SAMPLES] = [
    0.0006061,
    0.001086,
    0.001946,
    0.003486,
    0.006450001,
    0.01054999,
    0.02005001,
    0.03621,
    0.06785001,
    0.1102,
    0.2074,
    0.3713,
    0.6456,
    1.0390501,
    1.3856,
    1.62296,
    1.74706,
    1.7826,
    1.77211,
    1.7441,
    1.6692,
    1.5281,
    1.28764,
    1.0419,
    0.8129501,
    0.6162,
    0.46518,
    0.3533,
    0.272,
    0.2123,
    0.1582,
    0.1117,
    0.07824999,
    0.05725001,
    0.04216,
    0.02984,
    0.0203,
    0.0134,
    0.008749999,
    0.005749999,
    0.0039,
    0.002749999,
    0.0021,
    0.0018,
    0.001650001,
    0.0014,
    0.0011,
    0.001,
    0.0008,
    0.0006,
    0.00034,
    0.00024,
    0.00019,
    1e-04,
    4.999999e-05,
    3e-05,
    2e-05,
    1e-05,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
];

/// CIE D65, relative spectral power, 100 at 560 nm.
const CIE_D65: [f32; CIE_SAMPLES] = [
    46.6383, 49.3637, 52.0891, 51.0323, 49.9755, 52.3118, 54.6482, 68.7015, 82.7549, 87.1204, 91.486, 92.4589, 93.4318,
    90.057, 86.6823, 95.7736, 104.865, 110.936, 117.008, 117.41, 117.812, 116.336, 114.861, 115.392, 115.923, 112.367,
    108.811, 109.082, 109.354, 108.578, 107.802, 106.296, 104.79, 106.239, 107.689, 106.047, 104.405, 104.225, 104.046,
    102.023, 100.0, 98.1671, 96.3342, 96.0611, 95.788, 92.2368, 88.6856, 89.3459, 90.0062, 89.8026, 89.5991, 88.6489,
    87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.863, 80.0268, 80.1207, 80.2146, 81.2462, 82.2778, 80.281, 78.2842,
    74.0027, 69.7213, 70.6652, 71.6091, 72.979, 74.349, 67.9765, 61.604, 65.7448, 69.8856, 72.4863, 75.087, 69.3398,
    63.5927, 55.0054, 46.4182, 56.6118, 66.8054, 65.0941, 63.3828, 63.8434, 64.304, 61.8779, 59.4519, 55.7054, 51.959,
    54.6998, 57.4406, 58.8765, 60.3125,
];

/// Linear interpolation in a 5 nm table, zero outside [360, 830] nm (as Mitsuba's lookups).
fn lookup(table: &[f32; CIE_SAMPLES], w: f64) -> f64 {
    if !(CIE_MIN..=CIE_MAX).contains(&w) {
        return 0.0;
    }
    let t = (w - CIE_MIN) * ((CIE_SAMPLES - 1) as f64 / (CIE_MAX - CIE_MIN));
    let i0 = (t as usize).min(CIE_SAMPLES - 2);
    let w1 = t - i0 as f64;
    (1.0 - w1) * table[i0] as f64 + w1 * table[i0 + 1] as f64
}

fn cie_xyz(w: f64) -> [f64; 3] {
    [lookup(&CIE_X, w), lookup(&CIE_Y, w), lookup(&CIE_Z, w)]
}

fn cie_d65(w: f64) -> f64 {
    lookup(&CIE_D65, w) * CIE_D65_NORMALIZATION
}

/// XYZ to linear sRGB (Rec. 709), Mitsuba's matrix.
pub fn xyz_to_srgb(xyz: [f64; 3]) -> [f64; 3] {
    const M: [[f64; 3]; 3] =
        [[3.240479, -1.537150, -0.498535], [-0.969256, 1.875991, 0.041556], [0.055648, -0.204043, 1.057311]];
    let row = |r: [f64; 3]| r[0] * xyz[0] + r[1] * xyz[1] + r[2] * xyz[2];
    [row(M[0]), row(M[1]), row(M[2])]
}

fn clamp(rgb: [f64; 3], bounded: bool) -> Rgb {
    let c = |v: f64| if bounded { v.clamp(0.0, 1.0) } else { v.max(0.0) } as f32;
    Rgb { r: c(rgb[0]), g: c(rgb[1]), b: c(rgb[2]) }
}

/// A constant spectrum of `value`.
pub fn constant_to_rgb(value: f64, usage: SpectrumUse) -> Rgb {
    match usage {
        SpectrumUse::Emission => {
            let w = xyz_to_srgb([1.0, 1.0, 1.0]);
            Rgb { r: (value * w[0]) as f32, g: (value * w[1]) as f32, b: (value * w[2]) as f32 }
        }
        _ => Rgb::splat(value as f32),
    }
}

/// A piecewise-linear spectrum (at least two wavelengths, increasing) as Mitsuba's RGB
/// variants convert it: 1,000 samples over [360, 830] nm, zero outside the given range.
pub fn list_to_rgb(wavelengths: &[f64], values: &[f64], usage: SpectrumUse) -> Rgb {
    debug_assert!(wavelengths.len() >= 2 && wavelengths.len() == values.len());
    let d65 = usage != SpectrumUse::Emission;
    let steps = 1000;
    let mut xyz = [0.0f64; 3];
    let (first, last) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    for i in 0..steps {
        let w = CIE_MIN + (i as f64 / (steps - 1) as f64) * (CIE_MAX - CIE_MIN);
        if w < first || w > last {
            continue;
        }
        // The interval [w0, w1] holding w (the last one for w at the end).
        let index = wavelengths.partition_point(|&x| x <= w).clamp(1, wavelengths.len() - 1) - 1;
        let (w0, w1, v0, v1) = (wavelengths[index], wavelengths[index + 1], values[index], values[index + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        let weight = v * if d65 { cie_d65(w) } else { 1.0 };
        let c = cie_xyz(w);
        for k in 0..3 {
            xyz[k] += c[k] * weight;
        }
    }
    let scale = (CIE_MAX - CIE_MIN) * CIE_Y_NORMALIZATION / steps as f64;
    clamp(xyz_to_srgb(xyz.map(|v| v * scale)), usage == SpectrumUse::Reflectance)
}

/// Planck's law, W m^-2 sr^-1 nm^-1 at `nm` nanometres (Mitsuba's constants).
fn planck(nm: f64, kelvin: f64) -> f64 {
    const C: f64 = 2.99792458e8;
    const H: f64 = 6.62607004e-34;
    const K: f64 = 1.38064852e-23;
    let l = nm * 1e-9;
    1e-9 * 2.0 * H * C * C / (l.powi(5) * ((H * C / K / (l * kelvin)).exp_m1()))
}

/// A blackbody's emitted radiance, as Mitsuba's spectral variants show it in an RGB image:
/// Planck's law on [wavelength_min, wavelength_max] integrated against the matching
/// functions (0.05 nm steps), normalised as for any spectrum, taken to linear sRGB and
/// clamped at 0.
pub fn blackbody_to_rgb(kelvin: f64, wavelength_min: f64, wavelength_max: f64) -> Rgb {
    let lo = wavelength_min.max(CIE_MIN);
    let hi = wavelength_max.min(CIE_MAX);
    let mut xyz = [0.0f64; 3];
    if hi > lo {
        let n = ((hi - lo) / 0.05).ceil() as usize;
        let dw = (hi - lo) / n as f64;
        for i in 0..n {
            let w = lo + (i as f64 + 0.5) * dw;
            let p = planck(w, kelvin) * dw;
            let c = cie_xyz(w);
            for k in 0..3 {
                xyz[k] += c[k] * p;
            }
        }
    }
    clamp(xyz_to_srgb(xyz.map(|v| v * CIE_Y_NORMALIZATION)), false)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Rgb, b: [f32; 3], tol: f32) {
        for (x, y) in [a.r, a.g, a.b].into_iter().zip(b) {
            assert!((x - y).abs() <= tol * y.abs().max(1e-3), "{a:?} vs {b:?}");
        }
    }

    /// Values printed by Mitsuba 3.9.1 (`mi.spectrum_list_to_srgb`, scalar_rgb) for the
    /// spectra of its Cornell box scenes.
    #[test]
    fn lists_convert_as_mitsuba_converts_them() {
        close(
            list_to_rgb(&[400.0, 500.0, 600.0, 700.0], &[0.78; 4], SpectrumUse::Reflectance),
            [0.776368, 0.779809, 0.776029],
            1e-5,
        );
        close(
            list_to_rgb(&[400.0, 500.0, 600.0, 700.0], &[0.0, 8.0, 15.6, 18.4], SpectrumUse::Emission),
            [20.7108, 10.8546, 2.77115],
            1e-5,
        );
        close(constant_to_rgb(1.0, SpectrumUse::Emission), [1.20479, 0.948291, 0.908916], 1e-5);
        close(constant_to_rgb(0.3, SpectrumUse::Reflectance), [0.3, 0.3, 0.3], 0.0);
    }

    /// Mitsuba 3.9.1's scalar_spectral render of a `constant` emitter with a blackbody
    /// radiance, seen directly (4,096 spp over 16 pixels; standard errors under 0.2%).
    #[test]
    fn blackbody_matches_a_spectral_render() {
        close(blackbody_to_rgb(2700.0, 360.0, 830.0), [314.3371, 130.67393, 31.319273], 5e-3);
        close(blackbody_to_rgb(6500.0, 360.0, 830.0), [43965.7, 41447.008, 43738.773], 5e-3);
    }

    /// Luminance normalisation: a unit spectrum over the whole range has Y = 1, and a unit
    /// reflectance under D65 is (nearly) white.
    #[test]
    fn normalisation() {
        let w = [360.0, 830.0];
        let white = list_to_rgb(&w, &[1.0, 1.0], SpectrumUse::Unbounded);
        close(white, [1.0, 1.0, 1.0], 0.01);
        // The hotter the bluer; the luminance of a blackbody grows with temperature.
        let (a, b) = (blackbody_to_rgb(2700.0, 360.0, 830.0), blackbody_to_rgb(6500.0, 360.0, 830.0));
        assert!(a.r > a.b && b.b / b.r > a.b / a.r, "{a:?} {b:?}");
        assert!(b.g > a.g);
    }
}
