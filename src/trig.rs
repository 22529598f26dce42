//! `sin`, `cos`, `atan2` and `acos`: one implementation for every backend.
//!
//! The kernels are written once over one trait of operations (`Ops`) and run as
//! - `f64` ([`sin_cos`], [`sin`], [`cos`], [`atan2`], [`acos`]): what [`crate::kinematics`]
//!   computes with for `f64` and what the expression interpreter and constant folding use;
//! - four lanes of AVX2 (or that `f64` code in a loop without AVX2) in [`trig_batch`], which
//!   the JIT calls once per group of independent transcendentals
//!   ([`crate::compile::Math::Batch`]);
//! - Cranelift IR inlined into generated code ([`crate::compile::Math::Inline`], the
//!   self-contained ahead-of-time library).
//!
//! Every operation is a single IEEE operation or a bit manipulation and nothing is fused,
//! so the three compute the same bits and the compiled models agree with the `f64`
//! kinematics as exactly as the order of their operations allows (1e-13 where the model
//! amplifies rounding most: near-degenerate vertex triangles). With the C library's
//! functions on one side and anything else on the other, a 1-ulp difference there grows to
//! 1e-11; that is why there is one implementation.
//!
//! The kernels are FreeBSD msun's (fdlibm): `__kernel_sin`/`__kernel_cos` on `|r| ≤ π/4`
//! and `atan`'s degree-11 odd polynomial on `|t| ≤ 7/16`. The argument handling is
//! branch-free:
//! - sin/cos: `n = round(2x/π)` by the `1.5·2⁵²` trick, `r = x − n·π/2` with π/2 in three
//!   pieces of which the first two have 33 significant bits (so `n·piece` is exact for
//!   `|n| < 2²⁰`), the quadrant from the low bits of `n` selecting and negating by masks.
//!   For `|x| >` [`SIN_COS_MAX_ARG`] (where that reduction stops being exact) the C
//!   library's `sin` and `cos` are used instead (rare: the kinematics' angles stay within
//!   a few turns);
//! - atan2: `a = min(|x|,|y|)/max(|x|,|y|)` in one division that also applies
//!   `atan a = π/4 + atan((a−1)/(a+1))` above `tan(π/8)`, then `π/2 − ·`, `π − ·` and the
//!   sign of `y` by masks and `copysign`. Signed zeros give the C library's results
//!   (`atan2(±0, −0) = ±π`); `atan2(±∞, ±∞)` is NaN (the C library: odd multiples of
//!   π/4); above `|x|, |y| ≈ 9·10³⁰⁷` accuracy is lost (never NaN for finite input);
//! - acos: `atan2(√((1−c)(1+c)), c)` of the argument clamped to `[−1, 1]` (both factors
//!   exact where it matters).
//!
//! Error against the C library (glibc, itself within 1 ulp of the exact value), measured
//! by the tests on dense samples: at most [`MAX_ULP`] units in the last place of its
//! result. NaN in gives NaN out; results stay in the ranges the expression graph's range
//! analysis assumes (`|sin|, |cos| ≤ 1`, `acos ∈ [0, π]`, `atan2 ∈ [−π, π]`).

// The coefficients are fdlibm's published decimals, kept digit for digit so they can be
// checked against its source; each rounds to the double fdlibm uses.
#![allow(clippy::excessive_precision)]

/// Largest `|x|` that the kernel reduces; beyond it `sin` and `cos` are the C library's.
pub const SIN_COS_MAX_ARG: f64 = 1.0e6;

/// The documented error bound of every function here, in ulps of the C library's result.
pub const MAX_ULP: f64 = 2.0;

// 2/π and π/2 = P1 + P2 + P2T (P1, P2: 33 significant bits): fdlibm's `invpio2`,
// `pio2_1`, `pio2_2`, `pio2_2t`.
const TWO_OVER_PI: f64 = f64::from_bits(0x3FE4_5F30_6DC9_C883);
const P1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
const P2: f64 = f64::from_bits(0x3DD0_B461_1A60_0000);
const P2T: f64 = f64::from_bits(0x3BA3_198A_2E03_7073);
/// `1.5·2⁵²`: adding and subtracting it rounds to the nearest integer (|v| < 2⁵¹), and
/// the low bits of the sum are that integer's.
const ROUND: f64 = 6_755_399_441_055_744.0;

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

const AT: [f64; 11] = [
    3.333_333_333_333_293_180_27e-1,
    -1.999_999_999_987_648_324_76e-1,
    1.428_571_427_250_346_637_11e-1,
    -1.111_111_040_546_235_578_80e-1,
    9.090_887_133_436_506_561_96e-2,
    -7.691_876_205_044_829_994_95e-2,
    6.661_073_137_387_531_206_69e-2,
    -5.833_570_133_790_573_486_45e-2,
    4.976_877_994_615_932_360_17e-2,
    -3.653_157_274_421_691_552_70e-2,
    1.628_582_011_536_578_236_23e-2,
];
/// tan(π/8): above it, atan is reduced around π/4.
const TAN_PI_8: f64 = 0.414_213_562_373_095_03;
const PIO4_HI: f64 = f64::from_bits(0x3FE9_21FB_5444_2D18);
const PIO4_LO: f64 = f64::from_bits(0x3C81_A626_3314_5C07);
const PIO2_HI: f64 = f64::from_bits(0x3FF9_21FB_5444_2D18);
const PIO2_LO: f64 = f64::from_bits(0x3C91_A626_3314_5C07);
const PI_HI: f64 = f64::from_bits(0x4009_21FB_5444_2D18);
const PI_LO: f64 = f64::from_bits(0x3CA1_A626_3314_5C07);

/// The operations the kernels are written in. Each is one IEEE operation or a bit
/// manipulation, so every backend computes the same bits. Constants come second in
/// `add`/`mul` where the order is free (x86 folds a second operand from memory).
pub(crate) trait Ops {
    /// A value (one lane or several).
    type V: Copy;
    /// A constant.
    fn c(&mut self, x: f64) -> Self::V;
    /// `a + b`.
    fn add(&mut self, a: Self::V, b: Self::V) -> Self::V;
    /// `a − b`.
    fn sub(&mut self, a: Self::V, b: Self::V) -> Self::V;
    /// `a · b`.
    fn mul(&mut self, a: Self::V, b: Self::V) -> Self::V;
    /// `a / b`.
    fn div(&mut self, a: Self::V, b: Self::V) -> Self::V;
    /// `√a`.
    fn sqrt(&mut self, a: Self::V) -> Self::V;
    /// `|a|`.
    fn abs(&mut self, a: Self::V) -> Self::V;
    /// `|a|` with the sign of `b`.
    fn copysign(&mut self, a: Self::V, b: Self::V) -> Self::V;
    /// `if a < b { x } else { y }` (NaN: `y`). In the IR this may be a branch: only for
    /// `min`/`max` shapes (which become `minsd`/`maxsd`) and rare cases.
    fn lt_select(&mut self, a: Self::V, b: Self::V, x: Self::V, y: Self::V) -> Self::V;
    /// `if a == b { x } else { y }` (may be a branch: for rare cases).
    fn eq_select(&mut self, a: Self::V, b: Self::V, x: Self::V, y: Self::V) -> Self::V;
    /// `if m's sign bit is set { x } else { y }`, branch-free.
    fn sign_select(&mut self, m: Self::V, x: Self::V, y: Self::V) -> Self::V;
    /// A value whose sign bit is bit `bit` (0 or 1) of the bits of `v`.
    fn bit_to_sign(&mut self, v: Self::V, bit: u32) -> Self::V;
    /// `a` with its sign bit XORed with the sign bit of `m`.
    fn flip_sign(&mut self, a: Self::V, m: Self::V) -> Self::V;
}

/// `c[0] + z·(c[1] + z·(…))`.
#[inline(always)]
fn horner<O: Ops>(o: &mut O, z: O::V, cs: &[f64]) -> O::V {
    let mut acc = o.c(cs[cs.len() - 1]);
    for &c in cs[..cs.len() - 1].iter().rev() {
        let m = o.mul(acc, z);
        let c = o.c(c);
        acc = o.add(m, c);
    }
    acc
}

/// `(sin x, cos x)` for `|x| ≤ SIN_COS_MAX_ARG` (beyond: see the module docs).
// Always inlined: the AVX2 callers need the operations in their own body (their
// target feature), where the intrinsics can be inlined.
#[inline(always)]
pub(crate) fn emit_sin_cos<O: Ops>(o: &mut O, x: O::V) -> (O::V, O::V) {
    // n = round(2x/π); t keeps n in its low bits.
    let k = {
        let c = o.c(TWO_OVER_PI);
        o.mul(x, c)
    };
    let round = o.c(ROUND);
    let t = o.add(k, round);
    let n = o.sub(t, round);
    // r = x − n·π/2 (the first two products exact).
    let mut r = x;
    for p in [P1, P2, P2T] {
        let p = o.c(p);
        let np = o.mul(n, p);
        r = o.sub(r, np);
    }
    // fdlibm's kernels on |r| ≤ π/4 (k_sin.c, k_cos.c, without the tail).
    let z = o.mul(r, r);
    let w = o.mul(z, z);
    let s = {
        // r + v·(S1 + z·(S2 + z(S3 + z S4) + z w (S5 + z S6))), v = z r
        let a = horner(o, z, &[S2, S3, S4]);
        let b = horner(o, z, &[S5, S6]);
        let zw = o.mul(z, w);
        let zwb = o.mul(zw, b);
        let rr = o.add(a, zwb);
        let zrr = o.mul(z, rr);
        let s1 = o.c(S1);
        let inner = o.add(zrr, s1);
        let v = o.mul(z, r);
        let vi = o.mul(v, inner);
        let s = o.add(r, vi);
        // sin r has the sign of r on |r| ≤ π/4; this keeps sin(−0) = −0.
        o.copysign(s, r)
    };
    let c = {
        // z(C1 + z(C2 + z C3)) + w²(C4 + z(C5 + z C6)); hz = z/2; w' = 1 − hz;
        // w' + (((1 − w') − hz) + z·rr)
        let a = horner(o, z, &[C1, C2, C3]);
        let a = o.mul(a, z);
        let b = horner(o, z, &[C4, C5, C6]);
        let ww = o.mul(w, w);
        let b = o.mul(b, ww);
        let rr = o.add(a, b);
        let half = o.c(0.5);
        let hz = o.mul(z, half);
        let one = o.c(1.0);
        let w1 = o.sub(one, hz);
        let d = o.sub(one, w1);
        let d = o.sub(d, hz);
        let zrr = o.mul(z, rr);
        let d = o.add(d, zrr);
        o.add(w1, d)
    };
    // Quadrant q = n mod 4: odd q swaps sin and cos; sin is negated for q ∈ {2, 3}, cos
    // for q ∈ {1, 2} (bit 1 XOR bit 0).
    let odd = o.bit_to_sign(t, 0);
    let second = o.bit_to_sign(t, 1);
    let s1 = o.sign_select(odd, c, s);
    let c1 = o.sign_select(odd, s, c);
    let sin = o.flip_sign(s1, second);
    let cos = o.flip_sign(c1, second);
    let cos = o.flip_sign(cos, odd);
    (sin, cos)
}

/// `atan2(y, x)` (see the module docs).
// Always inlined: the AVX2 callers need the operations in their own body (their
// target feature), where the intrinsics can be inlined.
#[inline(always)]
pub(crate) fn emit_atan2<O: Ops>(o: &mut O, y: O::V, x: O::V) -> O::V {
    let ax = o.abs(x);
    let ay = o.abs(y);
    // min and max; on NaN, min gives ay and max gives ax, so NaN reaches the quotient.
    let num = o.lt_select(ax, ay, ax, ay);
    let den = o.lt_select(ax, ay, ay, ax);
    // big: num > tan(π/8)·den, then atan(num/den) = π/4 + atan((num − den)/(num + den)).
    let big = {
        let k = o.c(TAN_PI_8);
        let kd = o.mul(den, k);
        o.sub(kd, num)
    };
    let nmd = o.sub(num, den);
    let npd = o.add(num, den);
    let tn = o.sign_select(big, nmd, num);
    let td = o.sign_select(big, npd, den);
    let q = o.div(tn, td);
    // Both zero: atan 0.
    let zero = o.c(0.0);
    let t = o.eq_select(den, zero, zero, q);
    // fdlibm's atan polynomial: s1 + s2 = z·P(z).
    let z = o.mul(t, t);
    let w = o.mul(z, z);
    let even = horner(o, w, &[AT[0], AT[2], AT[4], AT[6], AT[8], AT[10]]);
    let odd = horner(o, w, &[AT[1], AT[3], AT[5], AT[7], AT[9]]);
    let s1 = o.mul(z, even);
    let s2 = o.mul(w, odd);
    let s = o.add(s1, s2);
    let u = o.mul(t, s);
    // hi − ((u − lo) − t): with (hi, lo) = π/4 when big, else 0 (then it is t − u).
    let hi = {
        let c = o.c(PIO4_HI);
        o.sign_select(big, c, zero)
    };
    let lo = {
        let c = o.c(PIO4_LO);
        o.sign_select(big, c, zero)
    };
    let r = o.sub(u, lo);
    let r = o.sub(r, t);
    let r = o.sub(hi, r);
    // |y| > |x|: π/2 − r.
    let swap = o.sub(ax, ay);
    let r2 = {
        let hi = o.c(PIO2_HI);
        let lo = o.c(PIO2_LO);
        let d = o.sub(hi, r);
        o.add(d, lo)
    };
    let r = o.sign_select(swap, r2, r);
    // x negative (−0 included): π − r. Except x = ±0 with y ≠ 0, whose angle is ±π/2
    // either way: π − π/2 would round to one ulp above π/2, so acos(−0) ≠ acos(+0).
    let r3 = {
        let hi = o.c(PI_HI);
        let lo = o.c(PI_LO);
        let d = o.sub(hi, r);
        o.add(d, lo)
    };
    let side = {
        let y_zero = o.eq_select(ay, zero, x, zero);
        o.eq_select(ax, zero, y_zero, x)
    };
    let r = o.sign_select(side, r3, r);
    o.copysign(r, y)
}

/// `acos(clamp(x, −1, 1))` (see the module docs).
// Always inlined: the AVX2 callers need the operations in their own body (their
// target feature), where the intrinsics can be inlined.
#[inline(always)]
pub(crate) fn emit_acos<O: Ops>(o: &mut O, x: O::V) -> O::V {
    let one = o.c(1.0);
    let mone = o.c(-1.0);
    // The clamp of `f64::clamp` (NaN stays NaN).
    let c = o.lt_select(x, mone, mone, x);
    let c = o.lt_select(one, c, one, c);
    let a = o.sub(one, c);
    let b = o.add(c, one);
    let p = o.mul(a, b);
    let s = o.sqrt(p);
    emit_atan2(o, s, c)
}

/// The `f64` backend.
struct F64;

const SIGN: u64 = 1 << 63;

impl Ops for F64 {
    type V = f64;
    #[inline(always)]
    fn c(&mut self, x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn add(&mut self, a: f64, b: f64) -> f64 {
        a + b
    }
    #[inline(always)]
    fn sub(&mut self, a: f64, b: f64) -> f64 {
        a - b
    }
    #[inline(always)]
    fn mul(&mut self, a: f64, b: f64) -> f64 {
        a * b
    }
    #[inline(always)]
    fn div(&mut self, a: f64, b: f64) -> f64 {
        a / b
    }
    #[inline(always)]
    fn sqrt(&mut self, a: f64) -> f64 {
        a.sqrt()
    }
    #[inline(always)]
    fn abs(&mut self, a: f64) -> f64 {
        a.abs()
    }
    #[inline(always)]
    fn copysign(&mut self, a: f64, b: f64) -> f64 {
        a.copysign(b)
    }
    #[inline(always)]
    fn lt_select(&mut self, a: f64, b: f64, x: f64, y: f64) -> f64 {
        if a < b { x } else { y }
    }
    #[inline(always)]
    fn eq_select(&mut self, a: f64, b: f64, x: f64, y: f64) -> f64 {
        if a == b { x } else { y }
    }
    #[inline(always)]
    fn sign_select(&mut self, m: f64, x: f64, y: f64) -> f64 {
        if m.to_bits() & SIGN != 0 { x } else { y }
    }
    #[inline(always)]
    fn bit_to_sign(&mut self, v: f64, bit: u32) -> f64 {
        f64::from_bits(v.to_bits() << (63 - bit))
    }
    #[inline(always)]
    fn flip_sign(&mut self, a: f64, m: f64) -> f64 {
        f64::from_bits(a.to_bits() ^ (m.to_bits() & SIGN))
    }
}

/// Whether `x` is beyond the kernel's reduction (±∞ included; NaN is not).
#[inline(always)]
fn beyond(x: f64) -> bool {
    x.abs() > SIN_COS_MAX_ARG
}

/// `(sin x, cos x)`.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if beyond(x) {
        (x.sin(), x.cos())
    } else {
        emit_sin_cos(&mut F64, x)
    }
}

/// `sin x`.
#[inline]
pub fn sin(x: f64) -> f64 {
    sin_cos(x).0
}

/// `cos x`.
#[inline]
pub fn cos(x: f64) -> f64 {
    sin_cos(x).1
}

/// `atan2(y, x)`: the angle of the vector `(x, y)` in `[−π, π]`.
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    emit_atan2(&mut F64, y, x)
}

/// `acos(clamp(x, −1, 1))`.
#[inline]
pub fn acos(x: f64) -> f64 {
    emit_acos(&mut F64, x)
}

/// The batch the JIT's generated code hands over ([`crate::compile::Math::Batch`]):
/// `buf` holds the inputs `x[n_sc]`, `y[n_at]`, `x[n_at]`, `a[n_ac]`, followed by room for
/// the outputs `sin[n_sc]`, `cos[n_sc]`, `atan2[n_at]`, `acos[n_ac]`.
///
/// # Safety
/// `buf` must be valid for reads and writes of `3·n_sc + 3·n_at + 2·n_ac` f64s.
pub unsafe extern "C" fn trig_batch(buf: *mut f64, n_sc: usize, n_at: usize, n_ac: usize) {
    let len = 3 * n_sc + 3 * n_at + 2 * n_ac;
    // SAFETY: the caller guarantees `buf` is valid for `len` f64s.
    let buf = unsafe { std::slice::from_raw_parts_mut(buf, len) };
    let (inputs, outputs) = buf.split_at_mut(n_sc + 2 * n_at + n_ac);
    let (x, rest) = inputs.split_at(n_sc);
    let (y, rest) = rest.split_at(n_at);
    let (xa, a) = rest.split_at(n_at);
    let (s, rest) = outputs.split_at_mut(n_sc);
    let (c, rest) = rest.split_at_mut(n_sc);
    let (at, ac) = rest.split_at_mut(n_at);
    batch::sin_cos(x, s, c);
    batch::atan2(y, xa, at);
    batch::acos(a, ac);
}

/// Slices of arguments at once: AVX2 four lanes at a time where the CPU has it (the same
/// operations, so the same bits), else the `f64` code in a loop.
pub mod batch {
    use super::*;

    /// `s[i], c[i] = sin_cos(x[i])`.
    pub fn sin_cos(x: &[f64], s: &mut [f64], c: &mut [f64]) {
        let done = simd::sin_cos(x, s, c);
        for i in done..x.len() {
            (s[i], c[i]) = emit_sin_cos(&mut F64, x[i]);
        }
        for i in 0..x.len() {
            if beyond(x[i]) {
                (s[i], c[i]) = (x[i].sin(), x[i].cos());
            }
        }
    }

    /// `out[i] = atan2(y[i], x[i])`.
    pub fn atan2(y: &[f64], x: &[f64], out: &mut [f64]) {
        let done = simd::atan2(y, x, out);
        for i in done..y.len() {
            out[i] = emit_atan2(&mut F64, y[i], x[i]);
        }
    }

    /// `out[i] = acos(a[i])`.
    pub fn acos(a: &[f64], out: &mut [f64]) {
        let done = simd::acos(a, out);
        for i in done..a.len() {
            out[i] = emit_acos(&mut F64, a[i]);
        }
    }

    /// The plain `f64` loops (what runs without AVX2), for the tests to compare with.
    pub fn sin_cos_scalar(x: &[f64], s: &mut [f64], c: &mut [f64]) {
        for i in 0..x.len() {
            (s[i], c[i]) = super::sin_cos(x[i]);
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod simd {
    use super::*;
    use std::arch::x86_64::*;

    /// The AVX2 backend (four lanes).
    struct Avx2;

    // SAFETY (every method): only reached from the `#[target_feature(enable = "avx2")]`
    // functions below, which run only after `is_x86_feature_detected!("avx2")`.
    impl Ops for Avx2 {
        type V = __m256d;
        #[inline(always)]
        fn c(&mut self, x: f64) -> __m256d {
            unsafe { _mm256_set1_pd(x) }
        }
        #[inline(always)]
        fn add(&mut self, a: __m256d, b: __m256d) -> __m256d {
            unsafe { _mm256_add_pd(a, b) }
        }
        #[inline(always)]
        fn sub(&mut self, a: __m256d, b: __m256d) -> __m256d {
            unsafe { _mm256_sub_pd(a, b) }
        }
        #[inline(always)]
        fn mul(&mut self, a: __m256d, b: __m256d) -> __m256d {
            unsafe { _mm256_mul_pd(a, b) }
        }
        #[inline(always)]
        fn div(&mut self, a: __m256d, b: __m256d) -> __m256d {
            unsafe { _mm256_div_pd(a, b) }
        }
        #[inline(always)]
        fn sqrt(&mut self, a: __m256d) -> __m256d {
            unsafe { _mm256_sqrt_pd(a) }
        }
        #[inline(always)]
        fn abs(&mut self, a: __m256d) -> __m256d {
            unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), a) }
        }
        #[inline(always)]
        fn copysign(&mut self, a: __m256d, b: __m256d) -> __m256d {
            unsafe {
                let sign = _mm256_set1_pd(-0.0);
                _mm256_or_pd(_mm256_andnot_pd(sign, a), _mm256_and_pd(sign, b))
            }
        }
        #[inline(always)]
        fn lt_select(&mut self, a: __m256d, b: __m256d, x: __m256d, y: __m256d) -> __m256d {
            unsafe { _mm256_blendv_pd(y, x, _mm256_cmp_pd::<_CMP_LT_OQ>(a, b)) }
        }
        #[inline(always)]
        fn eq_select(&mut self, a: __m256d, b: __m256d, x: __m256d, y: __m256d) -> __m256d {
            unsafe { _mm256_blendv_pd(y, x, _mm256_cmp_pd::<_CMP_EQ_OQ>(a, b)) }
        }
        #[inline(always)]
        fn sign_select(&mut self, m: __m256d, x: __m256d, y: __m256d) -> __m256d {
            // blendv picks by each lane's sign bit.
            unsafe { _mm256_blendv_pd(y, x, m) }
        }
        #[inline(always)]
        fn bit_to_sign(&mut self, v: __m256d, bit: u32) -> __m256d {
            unsafe {
                let i = _mm256_castpd_si256(v);
                let s = if bit == 0 {
                    _mm256_slli_epi64::<63>(i)
                } else {
                    _mm256_slli_epi64::<62>(i)
                };
                _mm256_castsi256_pd(s)
            }
        }
        #[inline(always)]
        fn flip_sign(&mut self, a: __m256d, m: __m256d) -> __m256d {
            unsafe { _mm256_xor_pd(a, _mm256_and_pd(m, _mm256_set1_pd(-0.0))) }
        }
    }

    fn has_avx2() -> bool {
        std::is_x86_feature_detected!("avx2")
    }

    #[target_feature(enable = "avx2")]
    fn sin_cos_avx2(x: &[f64], s: &mut [f64], c: &mut [f64]) -> usize {
        let n = x.len() / 4 * 4;
        for i in (0..n).step_by(4) {
            // SAFETY: i + 4 ≤ n ≤ the length of every slice.
            unsafe {
                let v = _mm256_loadu_pd(x.as_ptr().add(i));
                let (a, b) = emit_sin_cos(&mut Avx2, v);
                _mm256_storeu_pd(s.as_mut_ptr().add(i), a);
                _mm256_storeu_pd(c.as_mut_ptr().add(i), b);
            }
        }
        n
    }

    #[target_feature(enable = "avx2")]
    fn atan2_avx2(y: &[f64], x: &[f64], out: &mut [f64]) -> usize {
        let n = y.len() / 4 * 4;
        for i in (0..n).step_by(4) {
            // SAFETY: i + 4 ≤ n ≤ the length of every slice.
            unsafe {
                let vy = _mm256_loadu_pd(y.as_ptr().add(i));
                let vx = _mm256_loadu_pd(x.as_ptr().add(i));
                let r = emit_atan2(&mut Avx2, vy, vx);
                _mm256_storeu_pd(out.as_mut_ptr().add(i), r);
            }
        }
        n
    }

    #[target_feature(enable = "avx2")]
    fn acos_avx2(a: &[f64], out: &mut [f64]) -> usize {
        let n = a.len() / 4 * 4;
        for i in (0..n).step_by(4) {
            // SAFETY: i + 4 ≤ n ≤ the length of every slice.
            unsafe {
                let v = _mm256_loadu_pd(a.as_ptr().add(i));
                let r = emit_acos(&mut Avx2, v);
                _mm256_storeu_pd(out.as_mut_ptr().add(i), r);
            }
        }
        n
    }

    /// How many leading elements were done (a multiple of 4; 0 without AVX2).
    pub(super) fn sin_cos(x: &[f64], s: &mut [f64], c: &mut [f64]) -> usize {
        assert!(s.len() >= x.len() && c.len() >= x.len());
        if x.len() >= 4 && has_avx2() {
            // SAFETY: AVX2 was detected.
            unsafe { sin_cos_avx2(x, s, c) }
        } else {
            0
        }
    }

    pub(super) fn atan2(y: &[f64], x: &[f64], out: &mut [f64]) -> usize {
        assert!(x.len() >= y.len() && out.len() >= y.len());
        if y.len() >= 4 && has_avx2() {
            // SAFETY: AVX2 was detected.
            unsafe { atan2_avx2(y, x, out) }
        } else {
            0
        }
    }

    pub(super) fn acos(a: &[f64], out: &mut [f64]) -> usize {
        assert!(out.len() >= a.len());
        if a.len() >= 4 && has_avx2() {
            // SAFETY: AVX2 was detected.
            unsafe { acos_avx2(a, out) }
        } else {
            0
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod simd {
    pub(super) fn sin_cos(_: &[f64], _: &mut [f64], _: &mut [f64]) -> usize {
        0
    }
    pub(super) fn atan2(_: &[f64], _: &[f64], _: &mut [f64]) -> usize {
        0
    }
    pub(super) fn acos(_: &[f64], _: &mut [f64]) -> usize {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// |a − b| in units of the last place of `b` (the reference).
    fn ulps(a: f64, b: f64) -> f64 {
        if a == b || (a.is_nan() && b.is_nan()) {
            return 0.0;
        }
        let ulp = if b == 0.0 {
            f64::from_bits(1)
        } else {
            f64::from_bits(b.abs().to_bits() + 1) - b.abs()
        };
        (a - b).abs() / ulp
    }

    /// Arguments: uniform on several scales, near multiples of π/4, tiny and huge.
    fn samples(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut v = Vec::with_capacity(n);
        for i in 0..n {
            let x = match i % 6 {
                0 => rng.random_range(-4.0..4.0),
                1 => rng.random_range(-100.0..100.0),
                2 => rng.random_range(-SIN_COS_MAX_ARG..SIN_COS_MAX_ARG),
                3 => {
                    let k = rng.random_range(-64i32..64) as f64;
                    k * std::f64::consts::FRAC_PI_4 + rng.random_range(-1e-6..1e-6)
                }
                4 => rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(-300..0)),
                _ => rng.random_range(-1.1..1.1),
            };
            v.push(x);
        }
        v
    }

    #[test]
    fn within_the_documented_error_of_the_c_library() {
        let xs = samples(600_000, 1);
        let (mut es, mut ec, mut ea, mut eq) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for (i, &x) in xs.iter().enumerate() {
            let (s, c) = sin_cos(x);
            es = es.max(ulps(s, x.sin()));
            ec = ec.max(ulps(c, x.cos()));
            assert!(s.abs() <= 1.0 && c.abs() <= 1.0, "{x}");
            let y = xs[(i * 7 + 3) % xs.len()];
            let a = atan2(y, x);
            ea = ea.max(ulps(a, y.atan2(x)));
            assert!(a.abs() <= std::f64::consts::PI);
            let q = acos(x);
            eq = eq.max(ulps(q, x.clamp(-1.0, 1.0).acos()));
            assert!((0.0..=std::f64::consts::PI).contains(&q));
        }
        for (name, e) in [("sin", es), ("cos", ec), ("atan2", ea), ("acos", eq)] {
            assert!(e <= MAX_ULP, "{name}: {e} ulps");
        }
    }

    #[test]
    fn special_values_match_the_c_library() {
        for (y, x) in [
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (1.0, 0.0),
            (1.0, -0.0),
            (-1.0, 0.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (0.0, 1.0),
            (-0.0, 1.0),
            (1.0, f64::INFINITY),
            (-1.0, f64::NEG_INFINITY),
            (f64::INFINITY, 3.0),
            (f64::NEG_INFINITY, -3.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (1e-310, 1.0),
            (1e300, 1e-300),
        ] {
            let (a, b) = (atan2(y, x), y.atan2(x));
            assert!(ulps(a, b) <= MAX_ULP, "atan2({y}, {x}) = {a} vs {b}");
            assert_eq!(a.is_sign_negative(), b.is_sign_negative(), "({y}, {x})");
        }
        assert!(atan2(f64::INFINITY, f64::INFINITY).is_nan());
        assert!(atan2(f64::NAN, 1.0).is_nan() && atan2(1.0, f64::NAN).is_nan());
        assert!(atan2(f64::NAN, f64::NAN).is_nan() && acos(f64::NAN).is_nan());
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos(v);
            assert!(s.is_nan() && c.is_nan(), "{v}");
        }
        // Beyond the reduction: the C library's values.
        for v in [1.1e6, -3e9, 1e300] {
            assert_eq!(sin_cos(v), (v.sin(), v.cos()));
        }
        // The sign of a zero x does not move ±π/2 (the C library's exact values), so
        // acos(−0) = acos(+0): the expression graph folds −0 to +0.
        for y in [1.0, -1.0, 1e-300, 7.0] {
            assert_eq!(atan2(y, -0.0), y.atan2(-0.0), "atan2({y}, -0)");
            assert_eq!(
                atan2(y, -0.0).to_bits(),
                atan2(y, 0.0).to_bits(),
                "atan2({y}, ±0)"
            );
        }
        assert_eq!(acos(-0.0).to_bits(), acos(0.0).to_bits());
        assert_eq!(acos(0.0), std::f64::consts::FRAC_PI_2);
        assert_eq!(acos(1.0), 0.0);
        assert_eq!(acos(7.0), 0.0);
        assert_eq!(acos(-1.0), std::f64::consts::PI);
        assert_eq!(acos(-7.0), std::f64::consts::PI);
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert_eq!(sin(-0.0).to_bits(), (-0.0f64).to_bits());
        assert_eq!(sin(0.0).to_bits(), 0.0f64.to_bits());
    }

    #[test]
    fn batches_compute_the_same_bits_as_one_at_a_time() {
        let xs = samples(1003, 2);
        let n = xs.len();
        let mut buf: Vec<f64> = xs.clone();
        buf.extend(xs.iter().rev());
        buf.extend(xs.iter().map(|x| x * 0.5 - 0.1));
        buf.extend(xs.iter().map(|x| x.clamp(-2.0, 2.0)));
        buf.resize(3 * n + 3 * n + 2 * n, 0.0);
        // SAFETY: the buffer holds 3n + 3n + 2n values.
        unsafe { trig_batch(buf.as_mut_ptr(), n, n, n) };
        let out = &buf[4 * n..];
        for i in 0..n {
            let (s, c) = sin_cos(xs[i]);
            let y = xs[n - 1 - i];
            let x = xs[i] * 0.5 - 0.1;
            let a = xs[i].clamp(-2.0, 2.0);
            let same = |p: f64, q: f64| p.to_bits() == q.to_bits() || (p.is_nan() && q.is_nan());
            assert!(same(out[i], s) && same(out[n + i], c), "sin_cos({})", xs[i]);
            assert!(same(out[2 * n + i], atan2(y, x)), "atan2({y}, {x})");
            assert!(same(out[3 * n + i], acos(a)), "acos({a})");
        }
        let (mut s, mut c) = (vec![0.0; n], vec![0.0; n]);
        batch::sin_cos_scalar(&xs, &mut s, &mut c);
        assert_eq!(&s[..], &out[..n]);
        // Every length up to 9: whole vectors, scalar tails and batches shorter than one
        // vector (the generated code's batches are often that short).
        let same = |p: f64, q: f64| p.to_bits() == q.to_bits() || (p.is_nan() && q.is_nan());
        for start in [0, 17, 500] {
            for len in 0..=9 {
                let x = &xs[start..start + len];
                let y = &xs[start + 100..start + 100 + len];
                let (mut s, mut c, mut at, mut ac) = (
                    vec![9.0; len],
                    vec![9.0; len],
                    vec![9.0; len],
                    vec![9.0; len],
                );
                batch::sin_cos(x, &mut s, &mut c);
                batch::atan2(y, x, &mut at);
                let a: Vec<f64> = x.iter().map(|v| v.clamp(-1.5, 1.5)).collect();
                batch::acos(&a, &mut ac);
                for i in 0..len {
                    let (s1, c1) = sin_cos(x[i]);
                    assert!(same(s[i], s1) && same(c[i], c1), "sin_cos({})", x[i]);
                    assert!(same(at[i], atan2(y[i], x[i])), "atan2({}, {})", y[i], x[i]);
                    assert!(same(ac[i], acos(a[i])), "acos({})", a[i]);
                }
            }
        }
    }
}
