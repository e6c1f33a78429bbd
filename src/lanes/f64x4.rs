//! [`F64x4`]: four f64 lanes, and [`M64x4`], their mask.
//!
//! Plain arrays with element-wise operations (`std::array::from_fn` over the four lanes): compiled inside a function with
//! `#[target_feature(enable = "avx2,fma")]` (everything here is `#[inline(always)]`), LLVM
//! turns each loop into one 256-bit instruction (vaddpd, vmulpd, vdivpd, vsqrtpd, vcmppd, a
//! blend, and `vfmadd` for [`Lane::mul_add`]); compiled for baseline x86-64 it uses two 128-bit
//! SSE2 instructions instead (and the C library's `fma` for `mul_add`). The results are the
//! same either way: each lane is rounded as the f64 operation.

use super::{Lane, LaneMask};
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Four f64 lanes (one value of each of four runs), aligned for 256-bit loads.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F64x4(pub [f64; 4]);

/// Four lane truth values: all bits set for true, all clear for false.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M64x4(pub [u64; 4]);

impl M64x4 {
    /// From one bool per lane.
    #[inline(always)]
    pub fn from_bools(b: [bool; 4]) -> Self {
        M64x4(std::array::from_fn(|i| if b[i] { !0 } else { 0 }))
    }
}

/// Applies `f` to each lane of `a` (and `b`): element-wise, one vector instruction.
#[inline(always)]
fn map(a: F64x4, f: impl Fn(f64) -> f64) -> F64x4 {
    F64x4(std::array::from_fn(|i| f(a.0[i])))
}

#[inline(always)]
fn zip(a: F64x4, b: F64x4, f: impl Fn(f64, f64) -> f64) -> F64x4 {
    F64x4(std::array::from_fn(|i| f(a.0[i], b.0[i])))
}

#[inline(always)]
fn compare(a: F64x4, b: F64x4, f: impl Fn(f64, f64) -> bool) -> M64x4 {
    M64x4(std::array::from_fn(
        |i| if f(a.0[i], b.0[i]) { !0 } else { 0 },
    ))
}

macro_rules! binary_op {
    ($trait:ident, $method:ident, $assign:ident, $assign_method:ident, $op:tt) => {
        impl $trait for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $method(self, o: F64x4) -> F64x4 {
                zip(self, o, |a, b| a $op b)
            }
        }
        impl $assign for F64x4 {
            #[inline(always)]
            fn $assign_method(&mut self, o: F64x4) {
                *self = *self $op o;
            }
        }
    };
}
binary_op!(Add, add, AddAssign, add_assign, +);
binary_op!(Sub, sub, SubAssign, sub_assign, -);
binary_op!(Mul, mul, MulAssign, mul_assign, *);

impl Div for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn div(self, o: F64x4) -> F64x4 {
        zip(self, o, |a, b| a / b)
    }
}

impl Neg for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn neg(self) -> F64x4 {
        map(self, |a| -a)
    }
}

impl BitAnd for M64x4 {
    type Output = M64x4;
    #[inline(always)]
    fn bitand(self, o: M64x4) -> M64x4 {
        M64x4(std::array::from_fn(|i| self.0[i] & o.0[i]))
    }
}

impl BitOr for M64x4 {
    type Output = M64x4;
    #[inline(always)]
    fn bitor(self, o: M64x4) -> M64x4 {
        M64x4(std::array::from_fn(|i| self.0[i] | o.0[i]))
    }
}

impl Not for M64x4 {
    type Output = M64x4;
    #[inline(always)]
    fn not(self) -> M64x4 {
        M64x4(std::array::from_fn(|i| !self.0[i]))
    }
}

impl LaneMask for M64x4 {
    #[inline(always)]
    fn splat(b: bool) -> Self {
        M64x4([if b { !0 } else { 0 }; 4])
    }
    #[inline(always)]
    fn any(self) -> bool {
        (self.0[0] | self.0[1] | self.0[2] | self.0[3]) != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        (self.0[0] & self.0[1] & self.0[2] & self.0[3]) == !0
    }
    #[inline(always)]
    fn test(self, i: usize) -> bool {
        self.0[i] != 0
    }
    #[inline(always)]
    fn with_lane(mut self, i: usize, b: bool) -> Self {
        self.0[i] = if b { !0 } else { 0 };
        self
    }
}

impl Lane for F64x4 {
    type Mask = M64x4;
    const WIDTH: usize = 4;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        F64x4([x; 4])
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.0[i]
    }
    #[inline(always)]
    fn with_lane(mut self, i: usize, x: f64) -> Self {
        self.0[i] = x;
        self
    }
    #[inline(always)]
    fn gather_lane(values: &[Self], i: usize, out: &mut [f64]) {
        // Through references: no copy of each vector to index it.
        for (o, v) in out.iter_mut().zip(values) {
            *o = v.0[i];
        }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        map(self, f64::abs)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        map(self, f64::sqrt)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        let (x, a, b) = (self.0, a.0, b.0);
        F64x4([
            x[0].mul_add(a[0], b[0]),
            x[1].mul_add(a[1], b[1]),
            x[2].mul_add(a[2], b[2]),
            x[3].mul_add(a[3], b[3]),
        ])
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        zip(self, o, f64::max)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        zip(self, o, f64::min)
    }
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> Self {
        map(self, |a| a.clamp(lo, hi))
    }
    #[inline(always)]
    fn powf(self, e: f64) -> Self {
        map(self, |a| a.powf(e))
    }
    #[inline(always)]
    fn mantissa_exponent(self) -> (Self, Self) {
        let pairs = self.0.map(super::scalar_mantissa_exponent);
        (F64x4(pairs.map(|p| p.0)), F64x4(pairs.map(|p| p.1)))
    }
    #[inline(always)]
    fn pow2(self) -> Self {
        map(self, super::scalar_pow2)
    }
    #[inline(always)]
    fn less_than(self, o: Self) -> M64x4 {
        compare(self, o, |a, b| a < b)
    }
    #[inline(always)]
    fn at_most(self, o: Self) -> M64x4 {
        compare(self, o, |a, b| a <= b)
    }
    #[inline(always)]
    fn greater_than(self, o: Self) -> M64x4 {
        compare(self, o, |a, b| a > b)
    }
    #[inline(always)]
    fn at_least(self, o: Self) -> M64x4 {
        compare(self, o, |a, b| a >= b)
    }
    #[inline(always)]
    fn equals(self, o: Self) -> M64x4 {
        compare(self, o, |a, b| a == b)
    }
    #[inline(always)]
    fn is_finite(self) -> M64x4 {
        compare(self, self, |a, _| a.is_finite())
    }
    /// Bitwise, so that it compiles to a blend or and/andnot/or whatever the target.
    #[inline(always)]
    fn select(mask: M64x4, a: Self, b: Self) -> Self {
        F64x4(std::array::from_fn(|i| {
            let m = mask.0[i];
            f64::from_bits((a.0[i].to_bits() & m) | (b.0[i].to_bits() & !m))
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::operations_check::{
        every_lane_is_the_f64_operation, masks_combine_lane_by_lane, powers_of_two_are_exact,
    };

    /// On values that include signed zeros, subnormals, infinities and NaN.
    #[test]
    fn every_lane_is_the_f64_operation_in_sse2_registers() {
        every_lane_is_the_f64_operation::<F64x4>();
        powers_of_two_are_exact::<F64x4>();
    }

    /// The same compiled for AVX2, as the engine runs, where the processor has it.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn every_lane_is_the_f64_operation_in_avx2_registers() {
        #[target_feature(enable = "avx2,fma")]
        fn check() {
            every_lane_is_the_f64_operation::<F64x4>();
            powers_of_two_are_exact::<F64x4>();
        }
        if crate::cpu::avx2_available() {
            // SAFETY: the processor has AVX2.
            unsafe { check() }
        }
    }

    #[test]
    fn masks_combine_lane_by_lane_of_four() {
        masks_combine_lane_by_lane::<F64x4>();
        assert_eq!(
            M64x4::from_bools([true, false, true, false]),
            M64x4([!0, 0, !0, 0])
        );
    }
}
