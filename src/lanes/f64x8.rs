//! [`F64x8`]: eight f64 lanes in one AVX-512 register, and [`M64x8`], their mask.
//!
//! Unlike [`super::F64x4`] (a plain array that the compiler vectorises), each operation here is
//! an AVX-512F intrinsic. Plain arrays of eight were tried: compiled for AVX-512, LLVM's loop
//! vectoriser then turned the lanes' loops over state components inside out, with gathers and
//! scatters (384 `vgatherqpd` in the lockstep), and the eight lanes ran slower than four. An
//! intrinsic leaves it nothing to re-vectorise.
//!
//! Each operation rounds every lane as the f64 operation it names (`vaddpd`, `vsubpd`,
//! `vmulpd`, `vdivpd`, `vsqrtpd` are IEEE 754 binary64 operations, round to nearest, and
//! `vfmadd` rounds once, as `f64::mul_add`; nothing else is fused); `max`, `min`, `clamp` and `powf` go lane by lane through the f64 ones,
//! so their treatment of NaN and signed zeros is the scalar path's too (they run once a step).
//!
//! **Where it may run.** The operations execute AVX-512F instructions whatever function they
//! are inlined into, so an `F64x8` may only be made and used on a processor that has
//! AVX-512F. The type is private to the crate, and its one user is the engine that
//! [`super::damper`] runs after asking [`crate::cpu::avx512_available`]
//! (`lockstep_avx512`, compiled with `#[target_feature(enable = "avx512f")]` so that
//! the intrinsics inline into it).

use super::{Lane, LaneMask};
use std::arch::x86_64::{
    __m512d, __mmask8, _CMP_EQ_OQ, _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ,
    _MM_FROUND_NO_EXC, _MM_FROUND_TO_ZERO, _MM_MANT_NORM_1_2, _MM_MANT_SIGN_SRC, _mm256_and_si256,
    _mm256_set1_epi32, _mm512_add_pd, _mm512_and_epi64, _mm512_castpd_si512, _mm512_castsi512_pd,
    _mm512_cmp_pd_mask, _mm512_cvtsd_f64, _mm512_cvttpd_epi32, _mm512_div_pd, _mm512_fmadd_pd,
    _mm512_getexp_pd, _mm512_getmant_pd, _mm512_i32gather_pd, _mm512_loadu_pd,
    _mm512_mask_blend_pd, _mm512_mask_mov_pd, _mm512_mul_pd, _mm512_permutexvar_pd,
    _mm512_roundscale_pd, _mm512_scalef_pd, _mm512_set1_epi64, _mm512_set1_pd, _mm512_sqrt_pd,
    _mm512_storeu_pd, _mm512_sub_pd, _mm512_xor_epi64,
};
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Eight f64 lanes (one value of each of eight runs) in one 512-bit register.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F64x8(__m512d);

/// Eight lane truth values, one bit each (an AVX-512 mask register).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct M64x8(__mmask8);

impl F64x8 {
    /// The eight lanes as an array.
    #[inline(always)]
    fn to_array(self) -> [f64; 8] {
        let mut out = [0.0; 8];
        // SAFETY: `out` holds eight f64 (an unaligned store); AVX-512F: see the module.
        unsafe { _mm512_storeu_pd(out.as_mut_ptr(), self.0) };
        out
    }

    /// From eight lanes.
    #[inline(always)]
    fn from_array(a: [f64; 8]) -> Self {
        // SAFETY: `a` holds eight f64 (an unaligned load); AVX-512F: see the module.
        F64x8(unsafe { _mm512_loadu_pd(a.as_ptr()) })
    }

    /// Applies `f` lane by lane, through the array.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        let a = self.to_array();
        F64x8::from_array(std::array::from_fn(|i| f(a[i])))
    }

    /// Applies `f` to each pair of lanes, through the arrays.
    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let (a, b) = (self.to_array(), o.to_array());
        F64x8::from_array(std::array::from_fn(|i| f(a[i], b[i])))
    }

    /// `self` and `pattern` (a 64-bit pattern applied to every lane), bit by bit, through
    /// the integer view (`vpandq` is AVX-512F; the f64 `vandpd` would need AVX-512DQ).
    #[inline(always)]
    fn and_bits(self, pattern: u64) -> Self {
        // SAFETY: AVX-512F: see the module.
        unsafe {
            let bits = _mm512_and_epi64(
                _mm512_castpd_si512(self.0),
                _mm512_set1_epi64(pattern as i64),
            );
            F64x8(_mm512_castsi512_pd(bits))
        }
    }

    /// `self` exclusive-or `pattern` in every lane, through the integer view.
    #[inline(always)]
    fn xor_bits(self, pattern: u64) -> Self {
        // SAFETY: AVX-512F: see the module.
        unsafe {
            let bits = _mm512_xor_epi64(
                _mm512_castpd_si512(self.0),
                _mm512_set1_epi64(pattern as i64),
            );
            F64x8(_mm512_castsi512_pd(bits))
        }
    }
}

impl std::fmt::Debug for F64x8 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("F64x8").field(&self.to_array()).finish()
    }
}

impl PartialEq for F64x8 {
    fn eq(&self, o: &Self) -> bool {
        self.to_array() == o.to_array()
    }
}

macro_rules! binary_op {
    ($trait:ident, $method:ident, $assign:ident, $assign_method:ident, $intrinsic:ident) => {
        impl $trait for F64x8 {
            type Output = F64x8;
            #[inline(always)]
            fn $method(self, o: F64x8) -> F64x8 {
                // SAFETY: AVX-512F: see the module.
                F64x8(unsafe { $intrinsic(self.0, o.0) })
            }
        }
        impl $assign for F64x8 {
            #[inline(always)]
            fn $assign_method(&mut self, o: F64x8) {
                *self = $trait::$method(*self, o);
            }
        }
    };
}
binary_op!(Add, add, AddAssign, add_assign, _mm512_add_pd);
binary_op!(Sub, sub, SubAssign, sub_assign, _mm512_sub_pd);
binary_op!(Mul, mul, MulAssign, mul_assign, _mm512_mul_pd);

impl Div for F64x8 {
    type Output = F64x8;
    #[inline(always)]
    fn div(self, o: F64x8) -> F64x8 {
        // SAFETY: AVX-512F: see the module.
        F64x8(unsafe { _mm512_div_pd(self.0, o.0) })
    }
}

impl Neg for F64x8 {
    type Output = F64x8;
    /// The sign bit flipped, as `-x` on an f64.
    #[inline(always)]
    fn neg(self) -> F64x8 {
        self.xor_bits(1 << 63)
    }
}

impl BitAnd for M64x8 {
    type Output = M64x8;
    #[inline(always)]
    fn bitand(self, o: M64x8) -> M64x8 {
        M64x8(self.0 & o.0)
    }
}

impl BitOr for M64x8 {
    type Output = M64x8;
    #[inline(always)]
    fn bitor(self, o: M64x8) -> M64x8 {
        M64x8(self.0 | o.0)
    }
}

impl Not for M64x8 {
    type Output = M64x8;
    #[inline(always)]
    fn not(self) -> M64x8 {
        M64x8(!self.0)
    }
}

impl LaneMask for M64x8 {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        M64x8(if b { 0xff } else { 0 })
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0 != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.0 == 0xff
    }
    #[inline(always)]
    fn test(self, i: usize) -> bool {
        self.0 & (1 << i) != 0
    }
    #[inline(always)]
    fn with_lane(self, i: usize, b: bool) -> Self {
        M64x8(if b {
            self.0 | (1 << i)
        } else {
            self.0 & !(1 << i)
        })
    }
}

/// The lanes where `$predicate` (an ordered comparison: false where either is NaN) holds.
macro_rules! compare {
    ($a:expr, $b:expr, $predicate:ident) => {
        // SAFETY: AVX-512F: see the module.
        M64x8(unsafe { _mm512_cmp_pd_mask::<$predicate>($a.0, $b.0) })
    };
}

impl Lane for F64x8 {
    type Mask = M64x8;
    const WIDTH: usize = 8;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: AVX-512F: see the module.
        F64x8(unsafe { _mm512_set1_pd(x) })
    }
    /// Lane `i` moved to the bottom by a permutation, in registers (a store of the whole
    /// vector and a load of one lane would wait on store forwarding).
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        assert!(i < 8);
        // SAFETY: AVX-512F: see the module.
        unsafe { _mm512_cvtsd_f64(_mm512_permutexvar_pd(_mm512_set1_epi64(i as i64), self.0)) }
    }
    /// `x` blended into lane `i` under a one-bit mask.
    #[inline(always)]
    fn with_lane(self, i: usize, x: f64) -> Self {
        assert!(i < 8);
        // SAFETY: AVX-512F: see the module.
        F64x8(unsafe { _mm512_mask_mov_pd(self.0, 1 << i, _mm512_set1_pd(x)) })
    }
    /// `x + copysign(½, x)` (the sign bit of x on ½), truncated by `vrndscalepd`, plus +0
    /// (which turns a −0 into +0, as `as i64 as f64` gives, and leaves the rest).
    #[inline(always)]
    fn nearest_integer(self) -> Self {
        // SAFETY: AVX-512F: see the module.
        unsafe {
            let sign = _mm512_and_epi64(_mm512_castpd_si512(self.0), _mm512_set1_epi64(i64::MIN));
            let half = _mm512_xor_epi64(_mm512_castpd_si512(_mm512_set1_pd(0.5)), sign);
            let t = _mm512_add_pd(self.0, _mm512_castsi512_pd(half));
            let k = _mm512_roundscale_pd::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(t);
            F64x8(_mm512_add_pd(k, _mm512_set1_pd(0.0)))
        }
    }
    /// Two gathers by the lanes' integers, converted (exact below 2³¹) and reduced mod 256.
    #[inline(always)]
    fn lookup_256(self, tables: [&[f64; 256]; 2]) -> [Self; 2] {
        // SAFETY: AVX-512F (which implies AVX2): see the module. Every index is in 0..256, so
        // every gathered address is inside its table.
        unsafe {
            let index = _mm256_and_si256(_mm512_cvttpd_epi32(self.0), _mm256_set1_epi32(255));
            tables.map(|table| F64x8(_mm512_i32gather_pd::<8>(index, table.as_ptr() as _)))
        }
    }
    #[inline(always)]
    fn gather_lane(values: &[Self], i: usize, out: &mut [f64]) {
        assert!(i < 8);
        for (o, v) in out.iter_mut().zip(values) {
            // SAFETY: an `F64x8` is eight f64 in memory (`repr(transparent)` over __m512d),
            // and i < 8.
            *o = unsafe { *(v as *const F64x8).cast::<f64>().add(i) };
        }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.and_bits(!(1u64 << 63))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: AVX-512F: see the module.
        F64x8(unsafe { _mm512_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: AVX-512F (whose fused multiply–add rounds once, as `f64::mul_add`): see
        // the module.
        F64x8(unsafe { _mm512_fmadd_pd(self.0, a.0, b.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.zip(o, f64::max)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        self.zip(o, f64::min)
    }
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        self.map(|a| a.clamp(lo, hi))
    }
    #[inline(always)]
    fn powf(self, e: f64) -> Self {
        self.map(|a| a.powf(e))
    }
    /// `vgetmantpd` (normalised to [1, 2)) and `vgetexppd`: both exact, subnormals included.
    #[inline(always)]
    fn mantissa_exponent(self) -> (Self, Self) {
        // SAFETY: AVX-512F: see the module.
        unsafe {
            (
                F64x8(_mm512_getmant_pd::<_MM_MANT_NORM_1_2, _MM_MANT_SIGN_SRC>(
                    self.0,
                )),
                F64x8(_mm512_getexp_pd(self.0)),
            )
        }
    }
    /// `vscalefpd` of 1: 1·2^⌊k⌋, exact in the range.
    #[inline(always)]
    fn pow2(self) -> Self {
        // SAFETY: AVX-512F: see the module.
        F64x8(unsafe { _mm512_scalef_pd(_mm512_set1_pd(1.0), self.0) })
    }
    #[inline(always)]
    fn less_than(self, o: Self) -> M64x8 {
        compare!(self, o, _CMP_LT_OQ)
    }
    #[inline(always)]
    fn at_most(self, o: Self) -> M64x8 {
        compare!(self, o, _CMP_LE_OQ)
    }
    #[inline(always)]
    fn greater_than(self, o: Self) -> M64x8 {
        compare!(self, o, _CMP_GT_OQ)
    }
    #[inline(always)]
    fn at_least(self, o: Self) -> M64x8 {
        compare!(self, o, _CMP_GE_OQ)
    }
    #[inline(always)]
    fn equals(self, o: Self) -> M64x8 {
        compare!(self, o, _CMP_EQ_OQ)
    }
    /// |x| < ∞: false for infinities and NaN.
    #[inline(always)]
    fn is_finite(self) -> M64x8 {
        let infinity = F64x8::splat(f64::INFINITY);
        compare!(self.abs(), infinity, _CMP_LT_OQ)
    }
    #[inline(always)]
    fn select(mask: M64x8, a: Self, b: Self) -> Self {
        // SAFETY: AVX-512F: see the module. The blend takes its second operand where the
        // mask bit is set.
        F64x8(unsafe { _mm512_mask_blend_pd(mask.0, b.0, a.0) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::operations_check::{
        every_lane_is_the_f64_operation, masks_combine_lane_by_lane, powers_of_two_are_exact,
    };

    /// Lane i is bit i of a comparison's mask.
    #[target_feature(enable = "avx512f")]
    fn lane_i_is_bit_i() {
        let x = F64x8::from_array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        assert_eq!(x.less_than(F64x8::splat(4.5)), M64x8(0b0000_1111));
    }

    /// Each operation on values that include signed zeros, subnormals, infinities and NaN.
    #[test]
    fn eight_lanes_are_the_f64_operations_where_the_processor_has_avx512() {
        #[target_feature(enable = "avx512f")]
        fn check() {
            every_lane_is_the_f64_operation::<F64x8>();
            powers_of_two_are_exact::<F64x8>();
            masks_combine_lane_by_lane::<F64x8>();
        }
        if !crate::cpu::avx512_available() {
            eprintln!("no AVX-512F on this processor: nothing to test");
            return;
        }
        // SAFETY: the processor has AVX-512F.
        unsafe {
            check();
            lane_i_is_bit_i();
        }
    }
}
