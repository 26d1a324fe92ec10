//! Each lane of the diffuse kernel against the one-path code it replaces (`PathState::scatter`
//! for a Lambertian BSDF, through the real `Diffuse`, `power_heuristic`, `shadow_ray`,
//! `spawn_ray` and `Frame`), bit for bit, on every instruction set the CPU has: random
//! vertices, and special values (NaN, ±0, infinities, grazing and backfacing directions,
//! black reflectances, infinite light distances). NaNs compare equal whatever their sign and
//! payload: Rust leaves those unspecified (LLVM may swap the operands of a multiplication),
//! and the film discards a sample that is not finite.

use super::columns::SharedColumns;
use super::diffuse::DiffuseChunk;
use super::lane_math::{load3, store3};
use super::microfacet::MicrofacetColumns;
use super::plastic::PlasticChunk;
use super::principled::PrincipledChunk;
use super::rough::RoughChunk;
use super::rough_dielectric::RoughDielectricChunk;
use super::rough_plastic::RoughPlasticChunk;
use super::smooth::{Smooth, SmoothChunk};
use super::*;
use crate::bsdf::{Microfacet, MicrofacetKind};
use crate::integrators::{shadow_ray, spawn_ray};
use crate::materials::{
    Bsdf, Conductor, Dielectric, Diffuse, PlasticParams, Principled, PrincipledInputs, PrincipledRates, RoughConductor,
    RoughDielectric,
};
use crate::math::{Frame, Ray};
use crate::sampling::{power_heuristic, Rng};
use crate::world::SurfaceInteraction;
use crate::world::{unit_normals, TriangleSurface};

/// What the one-path code leaves: the shadow ray and its contribution and weight, and the
/// next ray and its density.
/// A shadow ray's origin, direction, end, contribution and MIS weight, as bits.
type ShadowBits = ([u32; 3], [u32; 3], u32, [u32; 3], u32);

#[derive(Debug, PartialEq)]
struct Outcome {
    shadow: Option<ShadowBits>,
    next: Option<([u32; 3], [u32; 3], u32)>,
}

/// The bits of `x`, one pattern for every NaN.
fn bits1(x: f32) -> u32 {
    if x.is_nan() {
        f32::NAN.to_bits()
    } else {
        x.to_bits()
    }
}

fn bits(v: Vec3) -> [u32; 3] {
    [bits1(v.x), bits1(v.y), bits1(v.z)]
}

/// Runs `check` on every lane width the CPU has, saying which ones it cannot test here.
fn on_every_isa(kernel: &str, check: fn(LaneIsa)) {
    check(LaneIsa::One);
    #[cfg(target_arch = "x86_64")]
    {
        if Avx2x8::new().is_some() {
            check(LaneIsa::Avx2);
        } else {
            eprintln!("no AVX2 on this CPU: the eight-lane {kernel} kernel is not tested here");
        }
        if Avx512x16::new().is_some() {
            check(LaneIsa::Avx512);
        } else {
            eprintln!("no AVX-512F on this CPU: the sixteen-lane {kernel} kernel is not tested here");
        }
    }
}

/// The shadow ray lane `i` left, as bits.
fn shadow_bits(c: &SharedColumns, i: usize) -> Option<ShadowBits> {
    let ne = &c.ne;
    (ne.shadow[i] != 0.0).then(|| {
        (
            bits(get3(&ne.shadow_origin, i)),
            bits(get3(&ne.shadow_dir, i)),
            bits1(ne.shadow_t_max[i]),
            bits(get3(&ne.contribution, i)),
            bits1(ne.mis_weight[i]),
        )
    })
}

/// The continuation lane `i` left (origin, direction, weight, density, eta), as bits.
fn sample_bits(c: &SharedColumns, i: usize) -> Option<SampleBits> {
    let next = &c.next;
    (next.sampled[i] != 0.0).then(|| {
        (
            bits(get3(&next.origin, i)),
            bits(get3(&next.dir, i)),
            bits(get3(&next.weight, i)),
            bits1(next.pdf[i]),
            bits1(next.eta[i]),
        )
    })
}

/// One lane's vertex.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    dir: Vec3,
    p: Vec3,
    ng: Vec3,
    frame: Frame,
    reflectance: Rgb,
    throughput: Rgb,
    light: Option<LightSample>,
    pick_pmf: f32,
    u: [f32; 2],
}

/// The interaction the one-path code would have at the vertex (what the kernels read of it).
fn surface(v: &Vertex) -> SurfaceInteraction {
    SurfaceInteraction {
        p: v.p,
        ng: v.ng,
        frame: v.frame,
        uv: [0.0; 2],
        instance: 0,
        material: 0,
        light: None,
        t: 1.0,
        dpdu: Vec3::ZERO,
        dpdv: Vec3::ZERO,
        prim: 0,
        bary: [0.0; 2],
    }
}

/// The shadow ray `PathState::scatter` leaves at the vertex for a BSDF that is not delta.
fn reference_shadow(v: &Vertex, bsdf: &Bsdf, light_only: bool) -> Option<ShadowBits> {
    let si = surface(v);
    let wo = v.frame.to_local(-v.dir);
    let ls = v.light?;
    let wi = v.frame.to_local(ls.wi);
    let f = bsdf.eval(wo, wi);
    if f.is_black() {
        return None;
    }
    let light_pdf = v.pick_pmf * ls.pdf;
    let mis = if ls.delta || light_only { 1.0 } else { power_heuristic(light_pdf, bsdf.pdf(wo, wi)) };
    let r = shadow_ray(&si, ls.wi, ls.dist);
    let c = v.throughput * f * ls.radiance;
    Some((bits(r.origin), bits(r.dir), bits1(r.t_max), bits(vec3(c.r, c.g, c.b)), bits1(mis)))
}

fn reference(v: &Vertex, light_only: bool) -> Outcome {
    let si = surface(v);
    let bsdf = Bsdf::Diffuse(Diffuse { reflectance: v.reflectance });
    let wo = v.frame.to_local(-v.dir);
    let shadow = reference_shadow(v, &bsdf, light_only);
    let next = bsdf.sample(wo, 0.5, v.u).filter(|bs| !bs.weight.is_black()).map(|bs| {
        let r = spawn_ray(&si, v.frame.to_world(bs.wi));
        (bits(r.origin), bits(r.dir), bits1(bs.pdf))
    });
    Outcome { shadow, next }
}

fn fill(c: &mut DiffuseChunk, i: usize, v: &Vertex) {
    c.shared.len = c.shared.len.max(i + 1);
    c.shared.v.put_ray(i, v.dir, v.p);
    c.shared.v.put_frame(i, v.ng, &v.frame);
    put3(&mut c.reflectance, i, v.reflectance.to_array());
    put3(&mut c.shared.throughput, i, v.throughput.to_array());
    c.shared.ne.put(i, v.light.map(|ls| (ls, v.pick_pmf)));
    c.shared.u[0][i] = v.u[0];
    c.shared.u[1][i] = v.u[1];
}

fn outcome(c: &DiffuseChunk, i: usize) -> Outcome {
    let shadow = shadow_bits(&c.shared, i);
    let next = (c.shared.next.sampled[i] != 0.0).then(|| {
        (bits(get3(&c.shared.next.origin, i)), bits(get3(&c.shared.next.dir, i)), bits1(c.shared.next.pdf[i]))
    });
    Outcome { shadow, next }
}

const SPECIAL: [f32; 10] = [0.0, -0.0, 1.0, -1.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-30, -1e30, 0.5];

/// A value that is special one time in `1 / rate`, else uniform in [-range, range].
fn value(rng: &mut Rng, range: f32, rate: u32) -> f32 {
    if rng.next_u32().is_multiple_of(rate) {
        SPECIAL[(rng.next_u32() % SPECIAL.len() as u32) as usize]
    } else {
        (2.0 * rng.next_f32() - 1.0) * range
    }
}

fn vector(rng: &mut Rng, range: f32, rate: u32) -> Vec3 {
    vec3(value(rng, range, rate), value(rng, range, rate), value(rng, range, rate))
}

fn unit(rng: &mut Rng, rate: u32) -> Vec3 {
    let v = vector(rng, 1.0, rate);
    let n = v.normalize();
    if n.is_finite() {
        n
    } else {
        v
    }
}

fn vertex(rng: &mut Rng) -> Vertex {
    // Mostly sane vertices (special values in one coordinate in 40), so that every branch
    // runs often: lights in front and behind, samples kept and rejected.
    let n = unit(rng, 40);
    let frame = Frame::from_normal(n);
    // Directions near the tangent plane now and then (grazing).
    let dir = if rng.next_u32().is_multiple_of(8) { frame.s * -1.0 + n * value(rng, 1e-6, 40) } else { unit(rng, 40) };
    let light = (!rng.next_u32().is_multiple_of(5)).then(|| LightSample {
        wi: if rng.next_u32().is_multiple_of(8) { frame.t + n * value(rng, 1e-6, 40) } else { unit(rng, 40) },
        radiance: Rgb::from_array([value(rng, 10.0, 40).abs(), value(rng, 10.0, 40).abs(), value(rng, 10.0, 40).abs()]),
        pdf: value(rng, 100.0, 40).abs(),
        dist: if rng.next_u32().is_multiple_of(6) { f32::INFINITY } else { value(rng, 50.0, 40).abs() },
        delta: rng.next_u32().is_multiple_of(7),
    });
    let black = rng.next_u32().is_multiple_of(10);
    let refl = |rng: &mut Rng| if black { 0.0 } else { rng.next_f32() };
    Vertex {
        dir,
        p: vector(rng, 100.0, 40),
        ng: if rng.next_u32().is_multiple_of(2) { n } else { unit(rng, 40) },
        frame,
        reflectance: Rgb::from_array([refl(rng), refl(rng), refl(rng)]),
        throughput: Rgb::from_array([value(rng, 4.0, 40).abs(), value(rng, 4.0, 40).abs(), rng.next_f32()]),
        light,
        pick_pmf: value(rng, 1.0, 40).abs(),
        // Sampler numbers are in [0, 1); the centre of the square and its edges now and then.
        u: match rng.next_u32() % 10 {
            0 => [0.5, 0.5],
            1 => [0.0, rng.next_f32()],
            2 => [0.5, rng.next_f32()],
            _ => [rng.next_f32(), rng.next_f32()],
        },
    }
}

fn check(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(23, lanes as u64);
    let (mut shadows, mut samples, mut total) = (0, 0, 0);
    for round in 0..4000 {
        let light_only = round % 5 == 0;
        let vertices: Vec<Vertex> = (0..lanes).map(|_| vertex(&mut rng)).collect();
        let mut chunk = DiffuseChunk::default();
        // A part-full chunk now and then: the lanes past `len` must not matter.
        let used = if round % 7 == 0 { 1 + round % lanes } else { lanes };
        for (i, v) in vertices.iter().take(used).enumerate() {
            fill(&mut chunk, i, v);
        }
        chunk.run(isa, if light_only { Strategy::Light } else { Strategy::Mis });
        for (i, v) in vertices.iter().take(used).enumerate() {
            let want = reference(v, light_only);
            total += 1;
            shadows += want.shadow.is_some() as u32;
            samples += want.next.is_some() as u32;
            assert_eq!(outcome(&chunk, i), want, "{isa:?} lane {i}, round {round}: {v:?}");
        }
    }
    // The inputs exercise both outcomes of both halves often (about a fifth of the vertices
    // leave a shadow ray, two fifths a next ray).
    assert!(
        shadows > total / 8 && shadows < total && samples > total / 4 && samples < total,
        "{isa:?}: {shadows} shadow rays, {samples} samples of {total} vertices"
    );
}

#[test]
fn every_lane_scatters_as_the_one_path_code_does() {
    on_every_isa("diffuse", check);
}

/// A triangle hit for the interaction kernel: random corners (degenerate ones and special
/// values now and then), normals (zero ones too) and uvs (repeated ones, a zero determinant).
fn mesh_hit(rng: &mut Rng) -> (MeshHit, Vec3, Vec3) {
    let a = vector(rng, 10.0, 60);
    let b = if rng.next_u32().is_multiple_of(12) { a } else { vector(rng, 10.0, 60) };
    let c = vector(rng, 10.0, 60);
    let b1 = rng.next_f32();
    let b2 = rng.next_f32() * (1.0 - b1);
    let normals = (!rng.next_u32().is_multiple_of(3)).then(|| {
        if rng.next_u32().is_multiple_of(10) {
            [Vec3::ZERO; 3]
        } else {
            [unit(rng, 60), unit(rng, 60), unit(rng, 60)]
        }
    });
    let uvs = (!rng.next_u32().is_multiple_of(3)).then(|| {
        let t0 = [value(rng, 1.0, 60), value(rng, 1.0, 60)];
        let t1 = if rng.next_u32().is_multiple_of(10) { t0 } else { [value(rng, 1.0, 60), value(rng, 1.0, 60)] };
        [t0, t1, [value(rng, 1.0, 60), value(rng, 1.0, 60)]]
    });
    let hit = MeshHit {
        corners: [a, b, c],
        bary: [1.0 - b1 - b2, b1, b2],
        normals,
        uvs,
        reflectance: Rgb::from_array([rng.next_f32(), rng.next_f32(), rng.next_f32()]),
        flip_normals: rng.next_u32().is_multiple_of(4),
        two_sided: rng.next_u32().is_multiple_of(2),
    };
    let p = TriangleSurface::at(hit.corners, hit.normals, hit.uvs, b1, b2).p;
    (hit, p, unit(rng, 40))
}

/// `World::interaction`'s normals and frame for the hit (its mesh branch, without a
/// transform), then `shading`'s turn of a two-sided frame.
fn reference_frame(hit: &MeshHit, dir: Vec3) -> (Vec3, Frame) {
    let surface = TriangleSurface::at(hit.corners, hit.normals, hit.uvs, hit.bary[1], hit.bary[2]);
    let (ng, ns) = unit_normals(surface.ng, surface.ns, hit.flip_normals);
    let mut frame = Frame::from_normal_tangent(ns, surface.dpdu);
    if hit.two_sided && frame.n.dot(-dir) < 0.0 {
        frame = Frame { s: frame.s, t: frame.t, n: -frame.n };
    }
    (ng, frame)
}

fn check_mesh_frames(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(29, lanes as u64);
    for round in 0..4000 {
        let mut chunk = DiffuseChunk::default();
        let mut want = Vec::new();
        for i in 0..lanes {
            // Every third lane arrives with its frame from the scalar code: it must keep it.
            if i % 3 == 2 {
                let v = vertex(&mut rng);
                fill(&mut chunk, i, &v);
                want.push((v.ng, v.frame));
            } else {
                let (hit, p, dir) = mesh_hit(&mut rng);
                chunk.shared.len = i;
                let mut sampler = Sampler::from_rng(Rng::new(1, i as u64));
                let path = PathState::new(&PathSettings::default(), &Ray::new(Vec3::ZERO, dir));
                chunk.push_mesh(i as u32, &path, &hit, p, None, &mut sampler);
                want.push(reference_frame(&hit, dir));
            }
        }
        chunk.shared.len = lanes;
        chunk.run(isa, Strategy::Mis);
        for (i, (ng, frame)) in want.iter().enumerate() {
            let got = [
                get3(&chunk.shared.v.ng, i),
                get3(&chunk.shared.v.n, i),
                get3(&chunk.shared.v.s, i),
                get3(&chunk.shared.v.t, i),
            ]
            .map(bits);
            let expected = [*ng, frame.n, frame.s, frame.t].map(bits);
            assert_eq!(got, expected, "{isa:?} lane {i}, round {round}");
        }
    }
}

#[test]
fn every_lane_finds_the_mesh_frame_the_one_path_code_finds() {
    on_every_isa("mesh interaction", check_mesh_frames);
}

/// The smooth BSDFs' lanes against `Conductor::sample` and `Dielectric::sample` (with the
/// lobe number the chunk drew), `Frame::to_world` and `spawn_ray`: the next ray, the weight
/// and eta, or no sample. Conductors and dielectrics share chunks.
fn check_smooth(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(31, lanes as u64);
    let (mut kept, mut refracted, mut total) = (0, 0, 0);
    for round in 0..4000 {
        let mut chunk = SmoothChunk::default();
        let mut want = Vec::new();
        for i in 0..lanes {
            let v = vertex(&mut rng);
            // Gold-like to dielectric-like constants, index-matched glass, special values.
            let bsdf = if rng.next_u32().is_multiple_of(2) {
                Smooth::Conductor(Conductor {
                    eta: Rgb::from_array([value(&mut rng, 3.0, 30).abs(), value(&mut rng, 3.0, 30), 1.5]),
                    k: Rgb::from_array([value(&mut rng, 5.0, 30).abs(), 0.0, value(&mut rng, 5.0, 30)]),
                    specular: if round % 9 == 0 { Rgb::BLACK } else { Rgb::from_array([1.0, rng.next_f32(), 0.5]) },
                })
            } else {
                let eta = match rng.next_u32() % 4 {
                    0 => 1.0,
                    1 => 1.0 / 1.5,
                    _ => 1.0 + value(&mut rng, 1.5, 30).abs(),
                };
                Smooth::Dielectric(Dielectric {
                    eta,
                    reflect: Rgb::from_array([1.0, rng.next_f32(), 0.0]),
                    transmit: if round % 11 == 0 { Rgb::BLACK } else { Rgb::from_array([rng.next_f32(), 1.0, 0.7]) },
                })
            };
            let si = surface(&v);
            let mut sampler = Sampler::from_rng(Rng::new(2, (round * lanes + i) as u64));
            let path = PathState::new(&PathSettings::default(), &Ray::new(Vec3::ZERO, v.dir));
            chunk.push(i as u32, &path, &si, &v.frame, bsdf, &mut sampler);
            let wo = v.frame.to_local(-v.dir);
            let scalar = match bsdf {
                Smooth::Conductor(m) => Bsdf::Conductor(m),
                Smooth::Dielectric(d) => Bsdf::Dielectric(d),
            };
            let sample = scalar.sample(wo, chunk.shared.u_lobe[i], [0.5, 0.5]).filter(|bs| !bs.weight.is_black());
            want.push(sample.map(|bs| {
                let r = spawn_ray(&si, v.frame.to_world(bs.wi));
                (bits(r.origin), bits(r.dir), bits(vec3(bs.weight.r, bs.weight.g, bs.weight.b)), bits1(bs.eta))
            }));
        }
        chunk.run(isa, Strategy::Mis);
        for (i, w) in want.iter().enumerate() {
            let got = (chunk.shared.next.sampled[i] != 0.0).then(|| {
                (
                    bits(get3(&chunk.shared.next.origin, i)),
                    bits(get3(&chunk.shared.next.dir, i)),
                    bits(get3(&chunk.shared.next.weight, i)),
                    bits1(chunk.shared.next.eta[i]),
                )
            });
            assert_eq!(&got, w, "{isa:?} lane {i}, round {round}");
            total += 1;
            kept += w.is_some() as u32;
            refracted += w.is_some_and(|w| w.3 != 1.0f32.to_bits()) as u32;
        }
    }
    assert!(
        kept > total / 4 && kept < total && refracted > total / 10,
        "{isa:?}: {kept} kept, {refracted} refracted of {total}"
    );
}

#[test]
fn every_lane_samples_smooth_bsdfs_as_the_one_path_code_does() {
    on_every_isa("smooth BSDF", check_smooth);
}

/// The lanes' dielectric Fresnel term against `bsdf::fresnel_dielectric` (whose reflectance
/// the sample tests above see only through the lobe choice).
fn check_fresnel_dielectric<L: Lanes>(l: L) {
    let mut rng = Rng::new(37, L::N as u64);
    let mut out = [[0.0f32; MAX_LANES]; 3];
    for _ in 0..20_000 {
        let cos_i: Vec<f32> = (0..L::N).map(|_| value(&mut rng, 1.0, 20)).collect();
        let eta: Vec<f32> = (0..L::N)
            .map(|_| if rng.next_u32().is_multiple_of(8) { 1.0 } else { value(&mut rng, 2.5, 20).abs() })
            .collect();
        let fr = super::smooth::fresnel_dielectric(l, l.load(&cos_i), l.load(&eta));
        l.store(fr.reflectance, &mut out[0]);
        l.store(fr.cos_t, &mut out[1]);
        l.store(fr.eta_ti, &mut out[2]);
        for i in 0..L::N {
            let want = crate::bsdf::fresnel_dielectric(cos_i[i], eta[i]);
            let got = [out[0][i], out[1][i], out[2][i]].map(bits1);
            assert_eq!(got, [want.reflectance, want.cos_t, want.eta_ti].map(bits1), "cos {} eta {}", cos_i[i], eta[i]);
        }
    }
}

#[test]
fn every_lane_finds_the_dielectric_fresnel_term_of_the_one_path_code() {
    check_fresnel_dielectric(One);
    #[cfg(target_arch = "x86_64")]
    {
        if let Some(l) = Avx2x8::new() {
            check_fresnel_dielectric(l);
        }
        if let Some(l) = Avx512x16::new() {
            check_fresnel_dielectric(l);
        }
    }
}

/// Roughness for the microfacet tests: sane values mostly, the clamp's bound, tiny and huge
/// ones, infinity, NaN and zero now and then (unclamped where the distribution is built
/// directly).
fn alpha(rng: &mut Rng) -> f32 {
    const SPECIAL: [f32; 12] = [1e-4, 1e-3, 0.01, 0.1, 0.2, 0.5, 1.0, 3.0, 1e3, f32::INFINITY, f32::NAN, 0.0];
    if rng.next_u32().is_multiple_of(3) {
        SPECIAL[(rng.next_u32() % SPECIAL.len() as u32) as usize]
    } else {
        0.01 + rng.next_f32()
    }
}

/// A GGX or Beckmann distribution, isotropic half the time; built by `Microfacet::anisotropic`
/// (as materials build it) but one time in 16, where the roughness goes in unclamped.
fn microfacet(rng: &mut Rng) -> Microfacet {
    let kind = if rng.next_u32().is_multiple_of(2) { MicrofacetKind::Ggx } else { MicrofacetKind::Beckmann };
    let alpha_u = alpha(rng);
    let alpha_v = if rng.next_u32().is_multiple_of(2) { alpha_u } else { alpha(rng) };
    if rng.next_u32().is_multiple_of(16) {
        Microfacet { kind, alpha_u, alpha_v }
    } else {
        Microfacet::anisotropic(kind, alpha_u, alpha_v)
    }
}

/// The lanes' distribution functions against `Microfacet::d`, `g1`, `g`, `pdf_wm` and
/// `sample_wm`, on random and special directions and normals (the kernel sees them only
/// through its results).
fn check_microfacet<L: Lanes>(l: L) {
    let mut rng = Rng::new(41, L::N as u64);
    let mut cols = MicrofacetColumns::default();
    let mut dirs = [[[0.0f32; MAX_LANES]; 3]; 3];
    // The squares in the first two columns.
    let mut u = [[0.0f32; MAX_LANES]; 3];
    let mut out = [[0.0f32; MAX_LANES]; 5];
    let mut wm = [[0.0f32; MAX_LANES]; 3];
    for round in 0..20_000 {
        let mut want = Vec::new();
        for i in 0..L::N {
            let m = microfacet(&mut rng);
            cols.put(i, &m);
            // Mostly upper-hemisphere normals (where D lives), directions on both sides,
            // grazing ones now and then.
            let mut h = unit(&mut rng, 30);
            if !rng.next_u32().is_multiple_of(4) {
                h.z = h.z.abs();
            }
            let wo = if rng.next_u32().is_multiple_of(8) {
                vec3(1.0, 0.0, value(&mut rng, 1e-6, 10))
            } else {
                unit(&mut rng, 30)
            };
            let wi = unit(&mut rng, 30);
            let ui = [rng.next_f32(), if rng.next_u32().is_multiple_of(10) { 0.0 } else { rng.next_f32() }];
            for (k, v) in [h, wo, wi].iter().enumerate() {
                put3(&mut dirs[k], i, [v.x, v.y, v.z]);
            }
            put3(&mut u, i, [ui[0], ui[1], 0.0]);
            let expected = [m.d(h), m.g1(wo, h), m.g(wo, wi, h), m.pdf_wm(wo, h)].map(bits1);
            want.push((expected, bits(m.sample_wm(wo, ui)), m));
        }
        let dist = cols.lanes(l, 0);
        let [h, wo, wi] = dirs.each_ref().map(|d| load3(l, d, 0));
        l.store(dist.d(l, h), &mut out[0]);
        l.store(dist.g1(l, wo, h), &mut out[1]);
        l.store(dist.g(l, wo, wi, h), &mut out[2]);
        l.store(dist.pdf_wm(l, wo, h), &mut out[3]);
        let all = (1u32 << L::N) - 1;
        store3(l, dist.sample_wm(l, wo, [l.load(&u[0]), l.load(&u[1])], all), &mut wm, 0);
        for (i, (expected, sampled, m)) in want.iter().enumerate() {
            let got = [out[0][i], out[1][i], out[2][i], out[3][i]].map(bits1);
            let ctx = (get3(&dirs[0], i), get3(&dirs[1], i), get3(&dirs[2], i), [u[0][i], u[1][i]]);
            assert_eq!(&got, expected, "round {round} lane {i}: {m:?} (h, wo, wi, u) {ctx:?}");
            assert_eq!(&bits(get3(&wm, i)), sampled, "round {round} lane {i}: {m:?} sample_wm {ctx:?}");
        }
    }
}

#[test]
fn every_lane_finds_the_microfacet_terms_of_the_one_path_code() {
    check_microfacet(One);
    #[cfg(target_arch = "x86_64")]
    {
        if let Some(l) = Avx2x8::new() {
            check_microfacet(l);
        } else {
            eprintln!("no AVX2 on this CPU: the eight-lane microfacet terms are not tested here");
        }
        if let Some(l) = Avx512x16::new() {
            check_microfacet(l);
        } else {
            eprintln!("no AVX-512F on this CPU: the sixteen-lane microfacet terms are not tested here");
        }
    }
}

/// A rough conductor: gold-like to dielectric-like constants with special values, black
/// specular now and then, and a distribution from `microfacet`.
fn rough_conductor(rng: &mut Rng, black: bool) -> RoughConductor {
    RoughConductor {
        dist: microfacet(rng),
        eta: Rgb::from_array([value(rng, 3.0, 30).abs(), value(rng, 3.0, 30), 1.5]),
        k: Rgb::from_array([value(rng, 5.0, 30).abs(), 0.0, value(rng, 5.0, 30)]),
        specular: if black { Rgb::BLACK } else { Rgb::from_array([1.0, rng.next_f32(), 0.5]) },
    }
}

/// The rough conductor's lanes against `PathState::scatter`'s one-path code for
/// `Bsdf::RoughConductor` (`eval`, `pdf`, `power_heuristic`, `shadow_ray`, then `sample`,
/// `Frame::to_world` and `spawn_ray`): the shadow ray, and the next ray with its weight and
/// density, or none.
fn check_rough(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(43, lanes as u64);
    let (mut shadows, mut samples, mut beckmann, mut total) = (0, 0, 0, 0);
    type NextBits = ([u32; 3], [u32; 3], u32, [u32; 3]);
    for round in 0..4000 {
        let light_only = round % 5 == 0;
        let mut chunk = RoughChunk::default();
        let used = if round % 7 == 0 { 1 + round % lanes } else { lanes };
        let mut want: Vec<(Option<ShadowBits>, Option<NextBits>, Vertex, RoughConductor)> = Vec::new();
        for i in 0..used {
            let v = vertex(&mut rng);
            let m = rough_conductor(&mut rng, round % 13 == 0);
            let si = surface(&v);
            let mut sampler = Sampler::from_rng(Rng::new(3, (round * lanes + i) as u64));
            let path = PathState::new(&PathSettings::default(), &Ray::new(Vec3::ZERO, v.dir));
            chunk.push(i as u32, &path, &si, &v.frame, &m, v.light.map(|ls| (ls, v.pick_pmf)), &mut sampler);
            // The vertex's own throughput and square, in place of a new path's and the sampler's.
            put3(&mut chunk.shared.throughput, i, v.throughput.to_array());
            chunk.shared.u[0][i] = v.u[0];
            chunk.shared.u[1][i] = v.u[1];
            let bsdf = Bsdf::RoughConductor(m);
            let wo = v.frame.to_local(-v.dir);
            let next = bsdf.sample(wo, 0.5, v.u).filter(|bs| !bs.weight.is_black()).map(|bs| {
                let r = spawn_ray(&si, v.frame.to_world(bs.wi));
                (bits(r.origin), bits(r.dir), bits1(bs.pdf), bits(vec3(bs.weight.r, bs.weight.g, bs.weight.b)))
            });
            want.push((reference_shadow(&v, &bsdf, light_only), next, v, m));
        }
        chunk.run(isa, if light_only { Strategy::Light } else { Strategy::Mis });
        for (i, (shadow, next, v, m)) in want.iter().enumerate() {
            let got_shadow = shadow_bits(&chunk.shared, i);
            let got_next = (chunk.shared.next.sampled[i] != 0.0).then(|| {
                (
                    bits(get3(&chunk.shared.next.origin, i)),
                    bits(get3(&chunk.shared.next.dir, i)),
                    bits1(chunk.shared.next.pdf[i]),
                    bits(get3(&chunk.shared.next.weight, i)),
                )
            });
            assert_eq!(&got_shadow, shadow, "{isa:?} lane {i}, round {round}, shadow: {m:?} {v:?}");
            assert_eq!(&got_next, next, "{isa:?} lane {i}, round {round}, next: {m:?} {v:?}");
            total += 1;
            shadows += shadow.is_some() as u32;
            samples += next.is_some() as u32;
            beckmann += (next.is_some() && m.dist.kind == MicrofacetKind::Beckmann) as u32;
        }
    }
    assert!(
        shadows > total / 10 && shadows < total && samples > total / 5 && samples < total && beckmann > total / 12,
        "{isa:?}: {shadows} shadow rays, {samples} samples ({beckmann} Beckmann) of {total} vertices"
    );
}

#[test]
fn every_lane_scatters_off_rough_conductors_as_the_one_path_code_does() {
    on_every_isa("rough conductor", check_rough);
}

/// The one-path code's whole step at `v` for a BSDF that is not delta: the shadow ray, then
/// the sample (origin, direction, weight, density, eta) that `scatter` keeps.
type SampleBits = ([u32; 3], [u32; 3], [u32; 3], u32, u32);

fn reference_scatter(
    v: &Vertex,
    bsdf: &Bsdf,
    u_lobe: f32,
    u: [f32; 2],
    light_only: bool,
) -> (Option<ShadowBits>, Option<SampleBits>) {
    let si = surface(v);
    let wo = v.frame.to_local(-v.dir);
    let shadow = reference_shadow(v, bsdf, light_only);
    let next = bsdf.sample(wo, u_lobe, u).filter(|bs| !bs.weight.is_black()).map(|bs| {
        let r = spawn_ray(&si, v.frame.to_world(bs.wi));
        (bits(r.origin), bits(r.dir), bits(vec3(bs.weight.r, bs.weight.g, bs.weight.b)), bits1(bs.pdf), bits1(bs.eta))
    });
    (shadow, next)
}

fn random_principled(rng: &mut Rng) -> Principled {
    // Each parameter at its bounds now and then (the lobes' `if`s), else inside them.
    let unit = |rng: &mut Rng| match rng.next_u32() % 6 {
        0 => 0.0,
        1 => 1.0,
        _ => rng.next_f32(),
    };
    let base_color =
        if rng.next_u32().is_multiple_of(12) { Rgb::BLACK } else { Rgb::from_array([unit(rng), unit(rng), unit(rng)]) };
    let eta = match rng.next_u32() % 5 {
        0 => 1.0,
        1 => 1.0 / 1.5,
        _ => 1.0 + 1.5 * rng.next_f32(),
    };
    Principled::new(&PrincipledInputs {
        base_color,
        roughness: unit(rng),
        anisotropic: unit(rng),
        metallic: unit(rng),
        spec_trans: unit(rng),
        eta,
        spec_tint: unit(rng),
        sheen: unit(rng),
        sheen_tint: unit(rng),
        flatness: unit(rng),
        clearcoat: unit(rng),
        clearcoat_gloss: unit(rng),
        rates: PrincipledRates { diffuse: unit(rng), specular: 1.0, clearcoat: unit(rng) },
    })
}

fn check_principled(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(41, lanes as u64);
    let (mut shadows, mut kept, mut refracted, mut total) = (0, 0, 0, 0);
    for round in 0..3000 {
        let light_only = round % 5 == 0;
        let mut chunk = PrincipledChunk::default();
        let mut want = Vec::new();
        let used = if round % 7 == 0 { 1 + round % lanes } else { lanes };
        for i in 0..used {
            // A new path's throughput (1): the product is the diffuse test's.
            let v = Vertex { throughput: Rgb::WHITE, ..vertex(&mut rng) };
            let b = random_principled(&mut rng);
            let si = surface(&v);
            let mut sampler = Sampler::from_rng(Rng::new(3, (round * lanes + i) as u64));
            let path = PathState::new(&PathSettings::default(), &Ray::new(Vec3::ZERO, v.dir));
            chunk.push(i as u32, &path, &si, &v.frame, &b, v.light.map(|ls| (ls, v.pick_pmf)), &mut sampler);
            let u = [chunk.shared.u[0][i], chunk.shared.u[1][i]];
            want.push((reference_scatter(&v, &Bsdf::Principled(b), chunk.shared.u_lobe[i], u, light_only), v, b));
        }
        chunk.run(isa, if light_only { Strategy::Light } else { Strategy::Mis });
        for (i, (w, v, b)) in want.iter().enumerate() {
            let c = &chunk;
            let shadow = shadow_bits(&c.shared, i);
            let next = sample_bits(&c.shared, i);
            assert_eq!(&(shadow, next), w, "{isa:?} lane {i}, round {round}: {v:?} {b:?}");
            total += 1;
            shadows += w.0.is_some() as u32;
            kept += w.1.is_some() as u32;
            refracted += w.1.is_some_and(|n| n.4 != 1.0f32.to_bits()) as u32;
        }
    }
    assert!(
        shadows > total / 10 && kept > total / 4 && kept < total && refracted > total / 50,
        "{isa:?}: {shadows} shadow rays, {kept} samples ({refracted} refracted) of {total}"
    );
}

#[test]
fn every_lane_scatters_off_the_principled_bsdf_as_the_one_path_code_does() {
    on_every_isa("principled", check_principled);
}

/// A smooth plastic for the plastic kernel: dielectric-like indices (index-matched, inside
/// a denser medium, special values now and then), black bases and coats, nonlinear or not.
fn plastic_params(rng: &mut Rng) -> PlasticParams {
    let eta = match rng.next_u32() % 5 {
        0 => 1.0,
        1 => 1.0 / 1.5,
        2 => 1.49,
        _ => value(rng, 2.0, 30).abs(),
    };
    let colour = |rng: &mut Rng, black: bool| {
        if black {
            Rgb::BLACK
        } else {
            Rgb::from_array([value(rng, 1.0, 30).abs(), rng.next_f32(), rng.next_f32()])
        }
    };
    let black = rng.next_u32().is_multiple_of(8);
    let diffuse = colour(rng, black);
    let black = rng.next_u32().is_multiple_of(8);
    let specular = colour(rng, black);
    let p = PlasticParams::new(diffuse, specular, eta, None);
    PlasticParams { nonlinear: rng.next_u32().is_multiple_of(2), ..p }
}

/// What the one-path code leaves at a smooth plastic: the shadow ray, and the next ray with
/// its density, weight and kind.
type PlasticNext = ([u32; 3], [u32; 3], u32, [u32; 3], bool);

fn plastic_reference(
    v: &Vertex,
    p: &PlasticParams,
    u_lobe: f32,
    light_only: bool,
) -> (Option<ShadowBits>, Option<PlasticNext>) {
    let si = surface(v);
    let bsdf = Bsdf::Plastic(*p);
    let wo = v.frame.to_local(-v.dir);
    let shadow = reference_shadow(v, &bsdf, light_only);
    let next = bsdf.sample(wo, u_lobe, v.u).filter(|bs| !bs.weight.is_black()).map(|bs| {
        assert_eq!(bs.eta, 1.0);
        let r = spawn_ray(&si, v.frame.to_world(bs.wi));
        (bits(r.origin), bits(r.dir), bits1(bs.pdf), bits(vec3(bs.weight.r, bs.weight.g, bs.weight.b)), bs.delta)
    });
    (shadow, next)
}

/// A lobe number in [0, 1): uniform, 0, or at the specular lobe's probability and either
/// side of it (read off the delta sample the scalar code gives for lobe number 0).
fn plastic_u_lobe(rng: &mut Rng, v: &Vertex, p: &PlasticParams) -> f32 {
    let wo = v.frame.to_local(-v.dir);
    let ps = Bsdf::Plastic(*p).sample(wo, 0.0, v.u).filter(|bs| bs.delta).map(|bs| bs.pdf);
    let u = match (rng.next_u32() % 6, ps) {
        (0, _) => 0.0,
        (1, Some(ps)) => ps,
        (2, Some(ps)) => f32::from_bits(ps.to_bits().saturating_sub(1)),
        (3, Some(ps)) => f32::from_bits(ps.to_bits() + 1),
        _ => rng.next_f32(),
    };
    if (0.0..1.0).contains(&u) {
        u
    } else {
        rng.next_f32()
    }
}

fn check_plastic(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(41, lanes as u64);
    let (mut shadows, mut deltas, mut diffuse, mut none, mut total) = (0, 0, 0, 0, 0);
    for round in 0..4000 {
        let light_only = round % 5 == 0;
        let mut chunk = PlasticChunk::default();
        let used = if round % 7 == 0 { 1 + round % lanes } else { lanes };
        let mut want = Vec::new();
        for i in 0..used {
            let v = vertex(&mut rng);
            let p = plastic_params(&mut rng);
            let u_lobe = plastic_u_lobe(&mut rng, &v, &p);
            let si = surface(&v);
            let mut path = PathState::new(&PathSettings::default(), &Ray::new(Vec3::ZERO, v.dir));
            // The path's throughput, as `go_on` leaves it.
            let mut sampler = Sampler::from_rng(Rng::new(3, (round * lanes + i) as u64));
            let prev = crate::integrators::estimators::PrevEvent { pdf: 1.0, delta: true, p: Vec3::ZERO };
            let no_roulette = PathSettings { rr_depth: u32::MAX, ..Default::default() };
            path.go_on(&no_roulette, v.throughput, 1.0, prev, Ray::new(Vec3::ZERO, v.dir), &mut sampler);
            chunk.push(i as u32, &path, &si, &v.frame, &p, v.light.map(|ls| (ls, v.pick_pmf)), &mut sampler);
            chunk.shared.u_lobe[i] = u_lobe;
            chunk.shared.u[0][i] = v.u[0];
            chunk.shared.u[1][i] = v.u[1];
            want.push((v, p, plastic_reference(&v, &p, u_lobe, light_only)));
        }
        chunk.run(isa, if light_only { Strategy::Light } else { Strategy::Mis });
        for (i, (v, p, want)) in want.iter().enumerate() {
            let shadow = shadow_bits(&chunk.shared, i);
            let next = (chunk.shared.next.sampled[i] != 0.0).then(|| {
                (
                    bits(get3(&chunk.shared.next.origin, i)),
                    bits(get3(&chunk.shared.next.dir, i)),
                    bits1(chunk.shared.next.pdf[i]),
                    bits(get3(&chunk.shared.next.weight, i)),
                    chunk.shared.next.delta[i] != 0.0,
                )
            });
            assert_eq!(
                &(shadow, next),
                want,
                "{isa:?} lane {i}, round {round}: {v:?} {p:?} u_lobe {}",
                chunk.shared.u_lobe[i]
            );
            total += 1;
            shadows += want.0.is_some() as u32;
            match want.1 {
                Some((.., true)) => deltas += 1,
                Some((.., false)) => diffuse += 1,
                None => none += 1,
            }
        }
    }
    assert!(
        shadows > total / 10 && deltas > total / 10 && diffuse > total / 10 && none > total / 10,
        "{isa:?}: {shadows} shadow rays, {deltas} delta samples, {diffuse} diffuse samples, {none} ends of {total}"
    );
}

#[test]
fn every_lane_scatters_off_smooth_plastic_as_the_one_path_code_does() {
    on_every_isa("smooth plastic", check_plastic);
}

/// A rough dielectric: glass-like indices from either side (index-matched, below 1, above 1,
/// special values now and then), white, coloured, black or special tints, and a distribution
/// from `microfacet` (GGX and Beckmann, tiny, huge, anisotropic and unclamped roughness).
fn rough_dielectric(rng: &mut Rng) -> RoughDielectric {
    let eta = match rng.next_u32() % 8 {
        0 => 1.0,
        1 => 1.0 / 1.5,
        2 => 1.5,
        3 => 1.0 + 1e-6,
        4 => value(rng, 3.0, 8).abs(),
        _ => 1.0 + 1.5 * rng.next_f32(),
    };
    let tint = |rng: &mut Rng| match rng.next_u32() % 10 {
        0 => Rgb::BLACK,
        1..=4 => Rgb::WHITE,
        5 => Rgb::from_array([value(rng, 2.0, 4), value(rng, 1.0, 4), 0.0]),
        _ => Rgb::from_array([rng.next_f32(), rng.next_f32(), rng.next_f32()]),
    };
    RoughDielectric { dist: microfacet(rng), eta, reflect: tint(rng), transmit: tint(rng) }
}

/// A lobe number in [0, 1): uniform, 0, or at the reflection's probability at the normal that
/// `u` samples and either side of it (computed as `lobe_probabilities` computes it).
fn rough_dielectric_u_lobe(rng: &mut Rng, v: &Vertex, b: &RoughDielectric) -> f32 {
    let wo = v.frame.to_local(-v.dir);
    let wm = b.dist.sample_wm(wo, v.u);
    let f = crate::bsdf::fresnel_dielectric(wo.dot(wm), b.eta).reflectance;
    let (pr, pt) = (f * crate::bsdf::lobe_weight(b.reflect), (1.0 - f) * crate::bsdf::lobe_weight(b.transmit));
    let pr = pr / (pr + pt);
    let u = match rng.next_u32() % 8 {
        0 => 0.0,
        1 => pr,
        2 => f32::from_bits(pr.to_bits().saturating_sub(1)),
        3 => f32::from_bits(pr.to_bits() + 1),
        _ => rng.next_f32(),
    };
    if (0.0..1.0).contains(&u) {
        u
    } else {
        rng.next_f32()
    }
}

/// The rough dielectric's lanes against `PathState::scatter`'s one-path code for
/// `Bsdf::RoughDielectric` (`reference_scatter`): the shadow ray, and the next ray with its
/// weight, density and eta, or none.
fn check_rough_dielectric(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(47, lanes as u64);
    let (mut shadows, mut reflected, mut refracted, mut inside, mut ends, mut beckmann, mut total) =
        (0, 0, 0, 0, 0, 0, 0);
    for round in 0..4000 {
        let light_only = round % 5 == 0;
        let mut chunk = RoughDielectricChunk::default();
        let used = if round % 7 == 0 { 1 + round % lanes } else { lanes };
        let mut want = Vec::new();
        for i in 0..used {
            let v = vertex(&mut rng);
            let b = rough_dielectric(&mut rng);
            let u_lobe = rough_dielectric_u_lobe(&mut rng, &v, &b);
            let si = surface(&v);
            let mut sampler = Sampler::from_rng(Rng::new(3, (round * lanes + i) as u64));
            let path = PathState::new(&PathSettings::default(), &Ray::new(Vec3::ZERO, v.dir));
            chunk.push(i as u32, &path, &si, &v.frame, &b, v.light.map(|ls| (ls, v.pick_pmf)), &mut sampler);
            // The vertex's own throughput and numbers, in place of a new path's and the sampler's.
            put3(&mut chunk.shared.throughput, i, v.throughput.to_array());
            chunk.shared.u_lobe[i] = u_lobe;
            chunk.shared.u[0][i] = v.u[0];
            chunk.shared.u[1][i] = v.u[1];
            let bsdf = Bsdf::RoughDielectric(b);
            let wo = v.frame.to_local(-v.dir);
            let kind = bsdf.sample(wo, u_lobe, v.u).filter(|bs| !bs.weight.is_black()).map(|bs| bs.wi.z * wo.z < 0.0);
            want.push((reference_scatter(&v, &bsdf, u_lobe, v.u, light_only), kind, wo.z < 0.0, v, b));
        }
        chunk.run(isa, if light_only { Strategy::Light } else { Strategy::Mis });
        for (i, (w, kind, below, v, b)) in want.iter().enumerate() {
            let c = &chunk;
            let shadow = shadow_bits(&c.shared, i);
            let next = sample_bits(&c.shared, i);
            assert_eq!(
                &(shadow, next),
                w,
                "{isa:?} lane {i}, round {round}: {v:?} {b:?} u_lobe {}",
                c.shared.u_lobe[i]
            );
            total += 1;
            shadows += w.0.is_some() as u32;
            match kind {
                Some(true) => refracted += 1,
                Some(false) => reflected += 1,
                None => ends += 1,
            }
            inside += (kind.is_some() && *below) as u32;
            beckmann += (kind.is_some() && b.dist.kind == MicrofacetKind::Beckmann) as u32;
        }
    }
    assert!(
        shadows > total / 10
            && reflected > total / 10
            && refracted > total / 10
            && ends > total / 10
            && inside > total / 10
            && beckmann > total / 10,
        "{isa:?}: {shadows} shadow rays, {reflected} reflected and {refracted} refracted samples ({inside} from \
         inside, {beckmann} Beckmann), {ends} ends of {total} vertices"
    );
}

#[test]
fn every_lane_scatters_off_rough_dielectrics_as_the_one_path_code_does() {
    on_every_isa("rough dielectric", check_rough_dielectric);
}

/// A rough plastic for the rough plastic kernel. The coating's tables are interned per
/// distribution and index and cost a quadrature each, so the coatings come from a few:
/// GGX and Beckmann, isotropic (at the clamp's bound, moderate, huge) and anisotropic, index
/// matched, below and above 1. Now and then the distribution is swapped for any of
/// `microfacet`'s (NaN, infinite, zero, unclamped roughness) under the same table, the index
/// for a special one, or the table dropped (`1 - F`, the free function's other branch): the
/// lanes must follow whatever the parameters hold. The bases and coats are
/// `plastic_params`'.
fn rough_plastic_params(rng: &mut Rng) -> PlasticParams {
    const ALPHAS: [(f32, f32); 4] = [(1e-4, 1e-4), (0.3, 0.3), (0.05, 0.6), (3.0, 3.0)];
    const ETAS: [f32; 4] = [1.0, 1.0 / 1.5, 1.49, 2.5];
    let kind = if rng.next_u32().is_multiple_of(2) { MicrofacetKind::Ggx } else { MicrofacetKind::Beckmann };
    let (au, av) = ALPHAS[(rng.next_u32() % 4) as usize];
    let eta = ETAS[(rng.next_u32() % 4) as usize];
    let colours = plastic_params(rng);
    let p = PlasticParams::new(colours.diffuse, colours.specular, eta, Some(Microfacet::anisotropic(kind, au, av)));
    let mut p = PlasticParams { nonlinear: colours.nonlinear, ..p };
    match rng.next_u32() % 24 {
        0..=2 => p.dist = Some(microfacet(rng)),
        3 => p.eta = value(rng, 2.0, 4).abs(),
        4 => p.transmittance = None,
        _ => {}
    }
    p
}

/// The specular lobe's probability `prob_specular(wo.z)` of a plastic (the delta sample's
/// density of its smooth twin at lobe number 0), or None where the scalar code samples no
/// lobe with it (`wo` below, or a probability of 0).
fn plastic_ps(v: &Vertex, p: &PlasticParams) -> Option<f32> {
    let wo = v.frame.to_local(-v.dir);
    let smooth = Bsdf::Plastic(PlasticParams { dist: None, ..*p });
    smooth.sample(wo, 0.0, v.u).filter(|bs| bs.delta).map(|bs| bs.pdf)
}

/// The rough plastic's lanes against `PathState::scatter`'s one-path code for
/// `Bsdf::Plastic` with a rough coating (`reference_scatter`: `eval`, `pdf`,
/// `power_heuristic`, `shadow_ray`, then `sample`, `Frame::to_world` and `spawn_ray`).
fn check_rough_plastic(isa: LaneIsa) {
    let lanes = isa.lanes();
    let mut rng = Rng::new(47, lanes as u64);
    let (mut shadows, mut coat, mut beckmann, mut base, mut ends, mut total) = (0, 0, 0, 0, 0, 0);
    for round in 0..4000 {
        let light_only = round % 5 == 0;
        let mut chunk = RoughPlasticChunk::default();
        let used = if round % 7 == 0 { 1 + round % lanes } else { lanes };
        let mut want = Vec::new();
        for i in 0..used {
            let v = vertex(&mut rng);
            let p = rough_plastic_params(&mut rng);
            // The lobe number at the specular probability and either side of it now and then.
            let u_lobe = plastic_u_lobe(&mut rng, &v, &PlasticParams { dist: None, ..p });
            let si = surface(&v);
            let mut sampler = Sampler::from_rng(Rng::new(5, (round * lanes + i) as u64));
            let path = PathState::new(&PathSettings::default(), &Ray::new(Vec3::ZERO, v.dir));
            let dist = p.dist.expect("a rough coating");
            chunk.push(i as u32, &path, &si, &v.frame, &p, &dist, v.light.map(|ls| (ls, v.pick_pmf)), &mut sampler);
            // The vertex's own throughput, lobe number and square, in place of a new path's
            // and the sampler's.
            put3(&mut chunk.shared.throughput, i, v.throughput.to_array());
            chunk.shared.u_lobe[i] = u_lobe;
            chunk.shared.u[0][i] = v.u[0];
            chunk.shared.u[1][i] = v.u[1];
            let coat_lobe = plastic_ps(&v, &p).is_some_and(|ps| u_lobe < ps);
            want.push((reference_scatter(&v, &Bsdf::Plastic(p), u_lobe, v.u, light_only), coat_lobe, v, p));
        }
        chunk.run(isa, if light_only { Strategy::Light } else { Strategy::Mis });
        for (i, (w, coat_lobe, v, p)) in want.iter().enumerate() {
            let c = &chunk;
            let shadow = shadow_bits(&c.shared, i);
            let next = (c.shared.next.sampled[i] != 0.0).then(|| {
                (
                    bits(get3(&c.shared.next.origin, i)),
                    bits(get3(&c.shared.next.dir, i)),
                    bits(get3(&c.shared.next.weight, i)),
                    bits1(c.shared.next.pdf[i]),
                    // A rough plastic's samples keep the index (`go_on`'s eta of 1).
                    1.0f32.to_bits(),
                )
            });
            assert_eq!(
                &(shadow, next),
                w,
                "{isa:?} lane {i}, round {round}: {v:?} {p:?} u_lobe {}",
                c.shared.u_lobe[i]
            );
            total += 1;
            shadows += w.0.is_some() as u32;
            match (w.1.is_some(), coat_lobe) {
                (false, _) => ends += 1,
                (true, true) => {
                    coat += 1;
                    beckmann += p.dist.is_some_and(|d| d.kind == MicrofacetKind::Beckmann) as u32;
                }
                (true, false) => base += 1,
            }
        }
    }
    assert!(
        shadows > total / 10 && coat > total / 20 && beckmann > total / 50 && base > total / 10 && ends > total / 10,
        "{isa:?}: {shadows} shadow rays, {coat} coating samples ({beckmann} Beckmann), {base} base samples, \
         {ends} ends of {total}"
    );
}

#[test]
fn every_lane_scatters_off_rough_plastic_as_the_one_path_code_does() {
    on_every_isa("rough plastic", check_rough_plastic);
}
