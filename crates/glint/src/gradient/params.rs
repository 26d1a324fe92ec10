//! The parameters a gradient render differentiates, as the adjoint pass meets them: per
//! material and per light of the built world, which entries of the gradient they feed and
//! how each derivative is taken.

use crate::materials::{Material, ShadedBsdf, TexturePoint};
use crate::math::{rgb, Rgb, Vec3};

/// A material built with one scalar of a parameter moved down and up. At a vertex, the
/// derivative of the BSDF value is `(f(plus) - f(minus)) * inv_step`, at the same texture
/// point and directions.
pub struct BsdfDifference {
    pub minus: Material,
    pub plus: Material,
    /// One over the distance between the two values.
    pub inv_step: f32,
}

/// One scalar of a material parameter (a number, or one channel of a colour) and the
/// gradient entry it feeds.
pub struct MaterialProbe {
    pub index: usize,
    pub difference: BsdfDifference,
}

impl BsdfDifference {
    /// The derivative of the BSDF value (cosine included) towards `wo` from `wi`, tilted as
    /// the vertex's own BSDF is by a normal or bump map.
    #[inline]
    pub fn derivative(&self, p: &TexturePoint, shaded: &ShadedBsdf, wo: Vec3, wi: Vec3) -> Rgb {
        let eval = |m: &Material| ShadedBsdf { bsdf: m.bsdf_at(p), tilt: shaded.tilt }.eval(wo, wi);
        (eval(&self.plus) - eval(&self.minus)) * self.inv_step
    }
}

/// A material's bitmap texture, per texel: `channels[c]` moves channel c of every texel,
/// so its derivative at a vertex is that of the BSDF with respect to the texture's value
/// there, which the bilinear lookup's weights share out among the texels it read.
pub struct TextureProbe {
    /// The gradient entry of texel 0's red channel; texel i's channel c is `base + 3i + c`.
    pub base: usize,
    pub width: usize,
    pub height: usize,
    /// The texture's (scale, offset) of surface uv.
    pub uv: [[f32; 2]; 2],
    pub channels: [BsdfDifference; 3],
}

impl TextureProbe {
    /// The texels the lookup at surface `uv` reads, as gradient entries of their red
    /// channels, and their weights.
    #[inline]
    pub fn taps(&self, uv: [f32; 2]) -> [(usize, f32); 4] {
        bitmap_taps(self.base, self.width, self.height, self.uv, uv)
    }
}

/// The texels a bitmap of `width` x `height` texels, mapping surface uv by `map` (scale,
/// offset), blends at `uv`, as gradient entries of their red channels (texel i's is
/// `base + 3i`), and their weights: the lookup's bilinear filter, wrapping at the edges as
/// `materials::Bitmap` does.
#[inline]
pub fn bitmap_taps(base: usize, width: usize, height: usize, map: [[f32; 2]; 2], uv: [f32; 2]) -> [(usize, f32); 4] {
    let [scale, offset] = map;
    let uv = [uv[0] * scale[0] + offset[0], uv[1] * scale[1] + offset[1]];
    let x = uv[0] * width as f32 - 0.5;
    let y = uv[1] * height as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let at = |x: i64, y: i64| {
        let texel = y.rem_euclid(height as i64) as usize * width + x.rem_euclid(width as i64) as usize;
        base + 3 * texel
    };
    [
        (at(x0, y0), (1.0 - fx) * (1.0 - fy)),
        (at(x0 + 1, y0), fx * (1.0 - fy)),
        (at(x0, y0 + 1), (1.0 - fx) * fy),
        (at(x0 + 1, y0 + 1), fx * fy),
    ]
}

/// Which part of a light's emission a parameter is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightParam {
    /// Channel `c` of a colour the emission is proportional to, channel by channel
    /// (radiance, intensity, irradiance), whose value is `value`.
    Channel { c: usize, value: Rgb },
    /// A scale the whole emission is proportional to, of value `value`.
    Scale { value: f32 },
    /// An environment map's texels (the probe's index is texel 0's red channel; texel i's
    /// channel c is `index + 3i + c`), the map's scale `scale`.
    Texels { scale: f32 },
    /// An area light's bitmap radiance, per texel (indices as `Texels`'): `width` x `height`
    /// texels, read at surface uv mapped by `uv` (scale, offset).
    AreaTexels { width: usize, height: usize, uv: [[f32; 2]; 2] },
}

/// A light parameter and the gradient entry it feeds.
#[derive(Clone, Copy, Debug)]
pub struct LightProbe {
    pub index: usize,
    pub param: LightParam,
}

/// The derivative of emitted radiance `le` with respect to a scale of value `value` it is
/// proportional to (emission is linear in each light parameter: `le` per unit).
#[inline]
pub fn scale_derivative(le: Rgb, value: f32) -> Rgb {
    if value != 0.0 {
        le / value
    } else {
        Rgb::BLACK
    }
}

/// The derivative of emitted radiance `le` with respect to channel `c` of a colour `value`
/// it is proportional to, channel by channel: `le` per unit in that channel. Where that
/// channel's value is zero, the unit response is read from another channel (the light's
/// geometry, falloff and distance act alike on all three).
#[inline]
pub fn channel_derivative(le: Rgb, c: usize, value: Rgb) -> Rgb {
    let (le, value) = (le.to_array(), value.to_array());
    let unit = if value[c] != 0.0 {
        le[c] / value[c]
    } else {
        (0..3).find(|&k| value[k] != 0.0).map_or(0.0, |k| le[k] / value[k])
    };
    let mut d = [0.0; 3];
    d[c] = unit;
    rgb(d[0], d[1], d[2])
}

/// Every parameter of a gradient render, by the material or light it belongs to.
#[derive(Default)]
pub struct ParamSet {
    len: usize,
    /// Indexed by the world's material index.
    materials: Vec<Vec<MaterialProbe>>,
    textures: Vec<Vec<TextureProbe>>,
    /// Indexed by the world's light index.
    lights: Vec<Vec<LightProbe>>,
}

impl ParamSet {
    /// The number of scalar gradient entries.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// A new gradient entry's index.
    pub fn new_entry(&mut self) -> usize {
        self.new_entries(1)
    }

    /// `n` new consecutive gradient entries, the first's index.
    pub fn new_entries(&mut self, n: usize) -> usize {
        self.len += n;
        self.len - n
    }

    pub fn add_texture_probe(&mut self, material: usize, probe: TextureProbe) {
        push_at(&mut self.textures, material, probe);
    }

    #[inline]
    pub fn texture_probes(&self, material: u32) -> &[TextureProbe] {
        self.textures.get(material as usize).map_or(&[], |v| v.as_slice())
    }

    pub fn add_material_probe(&mut self, material: usize, probe: MaterialProbe) {
        push_at(&mut self.materials, material, probe);
    }

    pub fn add_light_probe(&mut self, light: usize, probe: LightProbe) {
        push_at(&mut self.lights, light, probe);
    }

    #[inline]
    pub fn material_probes(&self, material: u32) -> &[MaterialProbe] {
        self.materials.get(material as usize).map_or(&[], |v| v.as_slice())
    }

    #[inline]
    pub fn light_probes(&self, light: u32) -> &[LightProbe] {
        self.lights.get(light as usize).map_or(&[], |v| v.as_slice())
    }
}

/// Adds `item` to list `index` of `lists`, adding empty lists up to it.
fn push_at<T>(lists: &mut Vec<Vec<T>>, index: usize, item: T) {
    if lists.len() <= index {
        lists.resize_with(index + 1, Vec::new);
    }
    lists[index].push(item);
}
