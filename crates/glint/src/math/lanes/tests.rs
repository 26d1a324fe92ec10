//! Each operation of each lane implementation the CPU has against [`One`], lane by lane, on
//! random values and on the special ones (NaN of both signs, ±0, ±infinity, subnormals, the
//! extremes), bit for bit.

use super::*;

/// SplitMix64: a few lines of its own, so that `math` imports nothing above it.
struct Rng(u64);

impl Rng {
    fn new(seed: u64, stream: u64) -> Rng {
        Rng(seed ^ stream.wrapping_mul(0x9e37_79b9_7f4a_7c15))
    }
    fn next_u32(&mut self) -> u32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 32) as u32
    }
    fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }
}

const SPECIAL: [f32; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
    -f32::NAN,
    f32::MIN_POSITIVE,
    -f32::MIN_POSITIVE,
    1.0e-40, // subnormal
    -1.0e-40,
    f32::MAX,
    f32::MIN,
    0.5,
    3.0,
];

/// Values for one lane: special ones, random bit patterns (any float, NaNs included) and
/// random moderate values (where arithmetic is not dominated by overflow).
fn value(rng: &mut Rng) -> f32 {
    match rng.next_u32() % 3 {
        0 => SPECIAL[(rng.next_u32() % 16) as usize],
        1 => f32::from_bits(rng.next_u32()),
        _ => (rng.next_f32() - 0.5) * 8.0,
    }
}

/// An operation's name, its result on the lanes, and the one-lane operation it must match.
type Unary<'a, F> = (&'a str, F, fn(f32) -> f32);
type Binary<'a, F> = (&'a str, F, fn(f32, f32) -> f32);
type Predicate<'a, M> = (&'a str, M, fn(f32, f32) -> bool);

fn check<L: Lanes>(l: L, name: &str) {
    let n = L::N;
    let mut rng = Rng::new(17, n as u64);
    let mut out = [0.0f32; MAX_LANES];
    for round in 0..20_000 {
        let a: Vec<f32> = (0..n).map(|_| value(&mut rng)).collect();
        // Every other round `b` repeats `a` in some lanes: equal operands matter for min/max
        // and the comparisons.
        let b: Vec<f32> = (0..n).map(|i| if round % 2 == 0 && i % 3 == 0 { a[i] } else { value(&mut rng) }).collect();
        let (va, vb) = (l.load(&a), l.load(&b));
        let unary: [Unary<L::F>; 3] = [
            ("sqrt", l.sqrt(va), |x| One.sqrt(x)),
            ("neg", l.neg(va), |x| One.neg(x)),
            ("abs", l.abs(va), |x| One.abs(x)),
        ];
        let binary: [Binary<L::F>; 6] = [
            ("add", l.add(va, vb), |x, y| One.add(x, y)),
            ("sub", l.sub(va, vb), |x, y| One.sub(x, y)),
            ("mul", l.mul(va, vb), |x, y| One.mul(x, y)),
            ("div", l.div(va, vb), |x, y| One.div(x, y)),
            ("max", l.max(va, vb), |x, y| One.max(x, y)),
            ("min", l.min(va, vb), |x, y| One.min(x, y)),
        ];
        for (op, v, f) in unary {
            l.store(v, &mut out);
            for i in 0..n {
                assert_eq!(out[i].to_bits(), f(a[i]).to_bits(), "{name} {op}({:?}) lane {i}", a[i]);
            }
        }
        for (op, v, f) in binary {
            l.store(v, &mut out);
            for i in 0..n {
                assert_eq!(out[i].to_bits(), f(a[i], b[i]).to_bits(), "{name} {op}({:?}, {:?}) lane {i}", a[i], b[i]);
            }
        }
        let masks: [Predicate<L::M>; 7] = [
            ("lt", l.lt(va, vb), |x, y| One.lt(x, y)),
            ("le", l.le(va, vb), |x, y| One.le(x, y)),
            ("gt", l.gt(va, vb), |x, y| One.gt(x, y)),
            ("ge", l.ge(va, vb), |x, y| One.ge(x, y)),
            ("eq", l.eq(va, vb), |x, y| One.eq(x, y)),
            ("ne", l.ne(va, vb), |x, y| One.ne(x, y)),
            ("sign", l.sign(va), |x, _| One.sign(x)),
        ];
        for (op, m, f) in masks {
            let bits = l.bits(m);
            for i in 0..n {
                assert_eq!(bits >> i & 1 == 1, f(a[i], b[i]), "{name} {op}({:?}, {:?}) lane {i}", a[i], b[i]);
            }
            assert_eq!(bits >> n, 0, "{name} {op}: bits beyond the lanes");
        }
        // Mask logic and selection, on two of the masks above.
        let (p, q) = (l.lt(va, vb), l.sign(vb));
        let (pb, qb) = (l.bits(p), l.bits(q));
        assert_eq!(l.bits(l.and(p, q)), pb & qb, "{name} and");
        assert_eq!(l.bits(l.or(p, q)), pb | qb, "{name} or");
        assert_eq!(l.bits(l.and_not(p, q)), pb & !qb, "{name} and_not");
        assert_eq!(l.bits(l.not(p)), !pb & ((1u32 << n) - 1), "{name} not");
        l.store(l.select(p, va, vb), &mut out);
        for i in 0..n {
            let want = One.select(pb >> i & 1 == 1, a[i], b[i]);
            assert_eq!(out[i].to_bits(), want.to_bits(), "{name} select lane {i}");
        }
        l.store(l.splat(a[0]), &mut out);
        assert!(out[..n].iter().all(|x| x.to_bits() == a[0].to_bits()), "{name} splat");
    }
}

#[test]
fn every_lane_computes_what_one_lane_computes() {
    check(One, "one");
    #[cfg(target_arch = "x86_64")]
    {
        match Avx2x8::new() {
            Some(l) => check(l, "avx2x8"),
            None => eprintln!("no AVX2 on this CPU: the eight-lane implementation is not tested here"),
        }
        match Avx512x16::new() {
            Some(l) => check(l, "avx512x16"),
            None => eprintln!("no AVX-512F on this CPU: the sixteen-lane implementation is not tested here"),
        }
    }
}
