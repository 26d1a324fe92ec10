//! Linear RGB radiance and reflectance. A separate type from `Vec3` so that a colour is
//! never passed where a direction is expected.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Rgb {
    pub r: f32,
    pub g: f32,
    pub b: f32,
}

#[inline(always)]
pub const fn rgb(r: f32, g: f32, b: f32) -> Rgb {
    Rgb { r, g, b }
}

impl Rgb {
    pub const BLACK: Rgb = rgb(0.0, 0.0, 0.0);
    pub const WHITE: Rgb = rgb(1.0, 1.0, 1.0);

    #[inline(always)]
    pub const fn splat(v: f32) -> Rgb {
        rgb(v, v, v)
    }
    #[inline(always)]
    pub fn is_black(self) -> bool {
        self.r == 0.0 && self.g == 0.0 && self.b == 0.0
    }
    #[inline(always)]
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }
    #[inline(always)]
    pub fn max_component(self) -> f32 {
        self.r.max(self.g).max(self.b)
    }
    #[inline(always)]
    pub fn average(self) -> f32 {
        (self.r + self.g + self.b) / 3.0
    }
    /// Rec. 709 luminance of linear RGB.
    #[inline(always)]
    pub fn luminance(self) -> f32 {
        0.2126 * self.r + 0.7152 * self.g + 0.0722 * self.b
    }
    #[inline(always)]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Rgb {
        rgb(f(self.r), f(self.g), f(self.b))
    }
    #[inline(always)]
    pub fn to_array(self) -> [f32; 3] {
        [self.r, self.g, self.b]
    }
    #[inline(always)]
    pub fn from_array(a: [f32; 3]) -> Rgb {
        rgb(a[0], a[1], a[2])
    }
    #[inline(always)]
    pub fn channel(self, i: usize) -> f32 {
        match i {
            0 => self.r,
            1 => self.g,
            _ => self.b,
        }
    }
}

impl Add for Rgb {
    type Output = Rgb;
    #[inline(always)]
    fn add(self, o: Rgb) -> Rgb {
        rgb(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}
impl Sub for Rgb {
    type Output = Rgb;
    #[inline(always)]
    fn sub(self, o: Rgb) -> Rgb {
        rgb(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}
impl Mul for Rgb {
    type Output = Rgb;
    #[inline(always)]
    fn mul(self, o: Rgb) -> Rgb {
        rgb(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}
impl Mul<f32> for Rgb {
    type Output = Rgb;
    #[inline(always)]
    fn mul(self, s: f32) -> Rgb {
        rgb(self.r * s, self.g * s, self.b * s)
    }
}
impl Div<f32> for Rgb {
    type Output = Rgb;
    #[inline(always)]
    fn div(self, s: f32) -> Rgb {
        self * (1.0 / s)
    }
}
impl Div for Rgb {
    type Output = Rgb;
    #[inline(always)]
    fn div(self, o: Rgb) -> Rgb {
        rgb(self.r / o.r, self.g / o.g, self.b / o.b)
    }
}
impl AddAssign for Rgb {
    #[inline(always)]
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}
impl MulAssign for Rgb {
    #[inline(always)]
    fn mul_assign(&mut self, o: Rgb) {
        *self = *self * o;
    }
}
impl MulAssign<f32> for Rgb {
    #[inline(always)]
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}

/// sRGB transfer function (linear -> encoded), per IEC 61966-2-1.
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.0031308 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB transfer function (encoded -> linear).
pub fn srgb_decode(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}
