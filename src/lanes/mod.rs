//! Lanes: the same arithmetic on one number (`f64`) or on several independent runs at once
//! ([`F64x4`], four f64 lanes; eight on AVX-512).
//!
//! A [`Lane`] is a value of one run (`f64`, width 1) or of W runs side by side, one per lane.
//! Every operation acts lane by lane with the rounding of the f64 operation it names (IEEE 754
//! binary64, round to nearest): no lane ever sees another, and no operation is contracted
//! (Rust never fuses `a * b + c` into an FMA unless `mul_add` is written; where it is written,
//! [`Lane::mul_add`], it rounds once, as `f64::mul_add` does at every width), so a lane's result
//! is bit for bit the result of the same code at `f64`.
//! Decisions that differ between lanes (accept or reject a step, a lane that has finished)
//! are taken under a [`LaneMask`] and applied with [`Lane::select`].
//!
//! The right-hand sides and the stepper arithmetic that the ensemble integrators share with
//! the scalar path are written once, generic over `Lane`: at `f64` they are the code the
//! scalar path runs (the spring–mass damper's closed form, the hub's quaternion kinematics,
//! dopri5's and dop853's stages, error estimates and step-size control), at `F64x4` (and the eight-lane AVX-512
//! type) the code of the lanes.
//!
//! Layout: [`f64x4`] (four lanes as a plain array, and its mask), `f64x8` (eight lanes in an
//! AVX-512 register, x86-64 only, crate-private), [`linalg`] (3-vectors,
//! 3 × 3 products, the SPD inverse and the quaternion rate, in lanes), [`elementary`] (the
//! arctangent and the power that the monitor and the step-size control call every step, in
//! lanes and at f64 alike), [`ensemble`] (the lockstep ensemble, with the AVX2 and
//! AVX-512 dispatch, generic over the class of runs it integrates: [`ensemble::LaneRun`] and
//! [`ensemble::LaneSystem`]), `methods` (dopri5 and dop853 in lanes), [`damper`] (the
//! nutation-damper class), [`energy_sink`] (a rigid body with an energy sink), [`hinged_rods`]
//! (a hub with four flap–lag hinged rods), [`wheel`] (a hub with a wheel whose motor holds a
//! stepped profile's or a rate-damping law's command: the class with breakpoints). docs/montecarlo.md,
//! "Lanes: the foundation", says what is tested and measured.

pub mod damper;
pub mod elementary;
pub mod energy_sink;
pub mod ensemble;
pub mod f64x4;
#[cfg(target_arch = "x86_64")]
pub(crate) mod f64x8;
pub mod hinged_rods;
pub mod linalg;
pub(crate) mod methods;
#[cfg(test)]
mod operations_check;
pub mod wheel;

pub use f64x4::{F64x4, M64x4};

use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Per-lane truth values: the result of a comparison of lanes, and what [`Lane::select`]
/// chooses by.
pub trait LaneMask:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> + std::fmt::Debug
{
    /// The same value in every lane.
    fn splat(b: bool) -> Self;
    /// Whether any lane is true.
    fn any(self) -> bool;
    /// Whether every lane is true.
    fn all(self) -> bool;
    /// Lane `i` (`i` < the width).
    fn test(self, i: usize) -> bool;
    /// A copy with lane `i` set to `b`.
    fn with_lane(self, i: usize, b: bool) -> Self;
}

/// One f64 per lane; see the module documentation. Units are those of the quantity held.
pub trait Lane:
    Copy
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// The lanes' truth values.
    type Mask: LaneMask;
    /// Number of lanes.
    const WIDTH: usize;
    /// `x` in every lane.
    fn splat(x: f64) -> Self;
    /// Lane `i` (`i` < [`Lane::WIDTH`]).
    fn lane(self, i: usize) -> f64;
    /// A copy with lane `i` set to `x`.
    fn with_lane(self, i: usize, x: f64) -> Self;
    /// Lane `i` of each of `values`, into `out` (`out[j] = values[j].lane(i)`), read in place.
    #[inline(always)]
    fn gather_lane(values: &[Self], i: usize, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(values) {
            *o = v.lane(i);
        }
    }
    /// The nearest integer to each lane, halves away from zero, as [`crate::sincos::sin_cos`]
    /// rounds: `(x + copysign(½, x))` truncated toward zero, as f64, with zero as +0. For
    /// |x| < 2³¹; lane by lane through `as i64` by default.
    #[inline(always)]
    fn nearest_integer(self) -> Self {
        let mut out = self;
        for i in 0..Self::WIDTH {
            let x = self.lane(i);
            out = out.with_lane(i, (x + 0.5f64.copysign(x)) as i64 as f64);
        }
        out
    }
    /// For lanes that hold integers k (as f64, |k| < 2³¹): `table[k mod 256]` of each of the
    /// two tables, lane by lane (two's complement residue: k = −1 reads entry 255). Lane by
    /// lane through [`Lane::lane`] by default; the eight AVX-512 lanes gather.
    #[inline(always)]
    fn lookup_256(self, tables: [&[f64; 256]; 2]) -> [Self; 2] {
        let mut out = [self; 2];
        for i in 0..Self::WIDTH {
            let j = (self.lane(i) as i64 & 255) as usize;
            out[0] = out[0].with_lane(i, tables[0][j]);
            out[1] = out[1].with_lane(i, tables[1][j]);
        }
        out
    }
    /// |x| per lane.
    fn abs(self) -> Self;
    /// √x per lane (correctly rounded, as `f64::sqrt`).
    fn sqrt(self) -> Self;
    /// `self · a + b` per lane with one rounding, as `f64::mul_add` (the same bits on every
    /// processor: an FMA instruction where the engine has one, the C library's `fma`
    /// otherwise).
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// `f64::max` per lane (a NaN loses to a number).
    fn max(self, other: Self) -> Self;
    /// `f64::min` per lane (a NaN loses to a number).
    fn min(self, other: Self) -> Self;
    /// `f64::clamp(lo, hi)` per lane (`lo` ≤ `hi`; NaN stays NaN).
    fn clamp(self, lo: f64, hi: f64) -> Self;
    /// `f64::powf(e)` per lane: the platform's `pow`, one lane at a time (not vectorised, so
    /// that the bits are those of the scalar call). For the rare call (dopri5's initial step);
    /// the step-size control uses [`elementary::positive_powf`].
    fn powf(self, e: f64) -> Self;
    /// For x > 0 finite (subnormals included): the mantissa m in [1, 2) and the exponent k
    /// (an integer, as f64) with x = m·2^k exactly. Unspecified, but no fault, elsewhere.
    fn mantissa_exponent(self) -> (Self, Self);
    /// 2^k for an integer k in [−1022, 1023] (exact). Unspecified, but no fault, elsewhere.
    fn pow2(self) -> Self;
    /// `self < other` per lane (false where either is NaN).
    fn less_than(self, other: Self) -> Self::Mask;
    /// `self <= other` per lane.
    fn at_most(self, other: Self) -> Self::Mask;
    /// `self > other` per lane.
    fn greater_than(self, other: Self) -> Self::Mask;
    /// `self >= other` per lane.
    fn at_least(self, other: Self) -> Self::Mask;
    /// `self == other` per lane.
    fn equals(self, other: Self) -> Self::Mask;
    /// Finite (neither infinite nor NaN) per lane.
    fn is_finite(self) -> Self::Mask;
    /// `a` where `mask` is true, `b` elsewhere.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
}

/// [`Lane::mantissa_exponent`] of one f64, from its bits (a subnormal is scaled by 2⁵⁴ first).
#[inline(always)]
pub(crate) fn scalar_mantissa_exponent(x: f64) -> (f64, f64) {
    const TWO_TO_54: f64 = 18_014_398_509_481_984.0;
    let (x, scaled) = if x < f64::MIN_POSITIVE {
        (x * TWO_TO_54, 54.0)
    } else {
        (x, 0.0)
    };
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as f64;
    let mantissa = f64::from_bits((bits & ((1 << 52) - 1)) | (1023 << 52));
    (mantissa, biased - 1023.0 - scaled)
}

/// [`Lane::pow2`] of one f64, by writing the biased exponent.
#[inline(always)]
pub(crate) fn scalar_pow2(k: f64) -> f64 {
    f64::from_bits(((k as i64 + 1023) as u64 & 0x7ff) << 52)
}

impl LaneMask for bool {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        b
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
    #[inline(always)]
    fn test(self, _i: usize) -> bool {
        self
    }
    #[inline(always)]
    fn with_lane(self, _i: usize, b: bool) -> Self {
        b
    }
}

/// Width 1: the scalar path. Each method is the f64 operation it names.
impl Lane for f64 {
    type Mask = bool;
    const WIDTH: usize = 1;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn lane(self, _i: usize) -> f64 {
        self
    }
    #[inline(always)]
    fn with_lane(self, _i: usize, x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f64::min(self, other)
    }
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        f64::clamp(self, lo, hi)
    }
    #[inline(always)]
    fn powf(self, e: f64) -> Self {
        f64::powf(self, e)
    }
    #[inline(always)]
    fn mantissa_exponent(self) -> (Self, Self) {
        scalar_mantissa_exponent(self)
    }
    #[inline(always)]
    fn pow2(self) -> Self {
        scalar_pow2(self)
    }
    #[inline(always)]
    fn less_than(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn at_most(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn greater_than(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn at_least(self, other: Self) -> bool {
        self >= other
    }
    #[inline(always)]
    fn equals(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask { a } else { b }
    }
}
