//! The two elementary functions the run monitor and the step-size control call at every step,
//! written once over [`Lane`]: the arctangent of a half-plane ([`half_plane_atan2`], the
//! nutation angle and every angle between two vectors) and a power of a positive number
//! ([`positive_powf`], dopri5's step-size control).
//!
//! The platform's `atan2` and `pow` take one number at a time, so the lanes called them lane by
//! lane, and the two calls were a quarter of a campaign's time. These run in the lanes with
//! the lanes' operations only (add, subtract, multiply, divide, compare and select, and two
//! exact operations on the binary exponent), so a lane's result is bit for bit the result at
//! `f64`: the scalar path calls the same functions and the two paths still agree to the bit.
//! They are not the platform's functions and may differ from them in the last place:
//! `half_plane_atan2` by at most one unit in the last place from the platform's `atan2`
//! (glibc's), `positive_powf` by two where the step-size control calls it
//! (docs/montecarlo.md, "Elementary functions in the lanes", gives the bounds and the tests).
//!
//! Both are series with exact coefficients after an argument reduction: the arctangent's
//! Taylor series `atan u = u − u³/3 + u⁵/5 − …` above the largest `tan(jπ/16)` ≤ z,
//! j = 0…4, by `atan z = atan c + atan((z − c)/(1 + z c))`; the logarithm's series
//! `ln m = 2 atanh s = 2 (s + s³/3 + s⁵/5 + …)`, `s = (m − 1)/(m + 1)`, for the mantissa m in
//! [√½, √2); the exponential's Taylor series for `2^f = e^(f ln 2)`, |f| ≤ ½ (M. Abramowitz
//! and I. A. Stegun, *Handbook of Mathematical Functions*, 1964, 4.4.42, 4.4.34, 4.1.27 and
//! 4.2.1; J.-M. Muller, *Elementary Functions: Algorithms and Implementation*, 3rd ed., 2016,
//! on additive argument reduction).

use super::Lane;

/// `tan(jπ/16)` rounded to f64, j = 1…4, the reduction points of the arctangent.
const TAN_POINTS: [f64; 4] = [
    0.198912367379658,
    0.41421356237309503,
    0.6681786379192989,
    1.0,
];
/// The arctangent of each rounded reduction point, as a sum `hi + lo` of two f64 (computed in
/// 300-bit arithmetic): `jπ/16` to within the point's rounding.
const ATAN_POINTS: [(f64, f64); 4] = [
    (0.19634954084936207, 6.846802412842648e-18),
    (std::f64::consts::FRAC_PI_8, 3.060132146563891e-18),
    (0.5890486225480862, -5.412106055318847e-18),
    (std::f64::consts::FRAC_PI_4, 3.061616997868383e-17),
];
/// π/2 and π, each as `hi + lo`.
const HALF_PI: (f64, f64) = (std::f64::consts::FRAC_PI_2, 6.123233995736766e-17);
const PI: (f64, f64) = (std::f64::consts::PI, 1.2246467991473532e-16);

/// Terms of the arctangent series kept: the first left out is below 10⁻¹⁹ of the result for
/// 0 ≤ u < tan(π/16).
const ATAN_TERMS: usize = 13;
/// Terms of the atanh series kept: the first left out is below 10⁻¹⁸ for |s| ≤ 0.1716.
const ATANH_TERMS: usize = 11;
/// Terms of the exponential's series kept (powers 0…13): the first left out is below 10⁻¹⁷
/// for |f ln 2| ≤ 0.347.
const EXP_TERMS: usize = 14;

/// `1/(2n + 1)`, n = 0…: the odd series' coefficients, rounded once.
const fn odd_reciprocals<const N: usize>() -> [f64; N] {
    let mut c = [0.0; N];
    let mut n = 0;
    while n < N {
        c[n] = 1.0 / (2 * n + 1) as f64;
        n += 1;
    }
    c
}

/// `1/i!`, i = 0…, each a product of exact reciprocals' roundings (the last digits of these
/// coefficients are far below the series' truncation).
const fn inverse_factorials<const N: usize>() -> [f64; N] {
    let mut c = [0.0; N];
    let mut i = 0;
    let mut f = 1.0;
    while i < N {
        c[i] = f;
        i += 1;
        f /= i as f64;
    }
    c
}

const ODD: [f64; ATAN_TERMS] = odd_reciprocals();
const _: () = assert!(ATANH_TERMS <= ATAN_TERMS);
const EXP: [f64; EXP_TERMS] = inverse_factorials();

/// `Σₙ ±s^n/(2n + 1)`, n = 1…terms − 1, by Horner's rule (the signs alternating from −
/// where `alternating`): the odd series `u(1 + this(u²))` without its first term.
#[inline(always)]
fn odd_series_tail<L: Lane>(s: L, terms: usize, alternating: bool) -> L {
    let coefficient = |n: usize| {
        if alternating && n % 2 == 1 {
            -ODD[n]
        } else {
            ODD[n]
        }
    };
    let mut p = L::splat(coefficient(terms - 1));
    for n in (1..terms - 1).rev() {
        p = p * s + L::splat(coefficient(n));
    }
    p * s
}

/// The angle (rad, in [0, π]) of the point (x, y) of the upper half-plane, y ≥ 0:
/// `y.atan2(x)` for such points, within one unit in the last place of glibc's `atan2`
/// (tested; the quotient's rounding is corrected and the sum rounded once).
/// `half_plane_atan2(|a × b|, a · b)` is the angle between a and b. NaN gives NaN;
/// (0, 0) gives 0 whatever the sign of its zero (`atan2` gives π for (+0, −0)).
#[inline(always)]
pub fn half_plane_atan2<L: Lane>(y: L, x: L) -> L {
    let ax = x.abs();
    // Reduce to z = small/big in [0, 1]; steep: the angle is measured from the y axis.
    let steep = y.greater_than(ax);
    let big = L::select(steep, y, ax);
    let small = L::select(steep, ax, y);
    let zero = L::splat(0.0);
    let z = L::select(big.equals(zero), zero, small / big);
    // The quotient's rounding error, z_exact − z = (small − z·big)/big, from the exact
    // product (its rounding error by Dekker's two-product), and its effect on the angle,
    // d(atan z) = dz/(1 + z²). Zero where the split overflows or big is 0.
    let (product, product_error) = two_product(z, big);
    let z_error = ((small - product) - product_error) / big;
    let z_error = L::select(z_error.is_finite(), z_error, zero);
    let angle_of_z_error = z_error / (L::splat(1.0) + z * z);
    // atan z = atan c + atan u, u = (z − c)/(1 + z c) in [0, tan(π/16)), c the largest
    // tan(jπ/16) ≤ z: u ≥ 0, so that nothing cancels.
    let (mut c, mut a_hi, mut a_lo) = (zero, zero, zero);
    for j in 0..4 {
        let from_here = z.at_least(L::splat(TAN_POINTS[j]));
        c = L::select(from_here, L::splat(TAN_POINTS[j]), c);
        a_hi = L::select(from_here, L::splat(ATAN_POINTS[j].0), a_hi);
        a_lo = L::select(from_here, L::splat(ATAN_POINTS[j].1), a_lo);
    }
    let u = (z - c) / (L::splat(1.0) + z * c);
    let atan_u = u + u * odd_series_tail(u * u, ATAN_TERMS, true);
    // Back to the half-plane: base ± (atan c + atan u) with base 0, π/2 or π: the angle is
    // base − … where steep and right, or flat and left. The sum is carried as hi + lo
    // (Knuth's exact two-sum of the high parts), so that it is rounded once, at the end.
    let left = x.less_than(zero);
    let base_hi = L::select(
        steep,
        L::splat(HALF_PI.0),
        L::select(left, L::splat(PI.0), zero),
    );
    let base_lo = L::select(
        steep,
        L::splat(HALF_PI.1),
        L::select(left, L::splat(PI.1), zero),
    );
    let subtract = (steep & !left) | (!steep & left);
    let sign = L::select(subtract, L::splat(-1.0), L::splat(1.0));
    let (hi, hi_error) = two_sum(base_hi, sign * a_hi);
    let lo = ((hi_error + base_lo) + sign * a_lo) + sign * (atan_u + angle_of_z_error);
    hi + lo
}

/// `a · b` rounded, and its rounding error exactly where no part over- or underflows
/// (T. J. Dekker, "A floating-point technique for extending the available precision",
/// Numerische Mathematik 18 (1971) 224–242: Veltkamp's split into 26-bit halves).
#[inline(always)]
fn two_product<L: Lane>(a: L, b: L) -> (L, L) {
    let split = |v: L| {
        let c = L::splat(134_217_729.0) * v; // 2²⁷ + 1
        let high = c - (c - v);
        (high, v - high)
    };
    let p = a * b;
    let ((ah, al), (bh, bl)) = (split(a), split(b));
    (p, (((ah * bh - p) + ah * bl) + al * bh) + al * bl)
}

/// `a + b` rounded, and its rounding error exactly (D. E. Knuth, *The Art of Computer
/// Programming*, vol. 2, 3rd ed., 1997, §4.2.2, Theorem B): `a + b = s + e` exactly.
#[inline(always)]
fn two_sum<L: Lane>(a: L, b: L) -> (L, L) {
    let s = a + b;
    let b_virtual = s - a;
    let a_virtual = s - b_virtual;
    (s, (a - a_virtual) + (b - b_virtual))
}

/// `x^e` (x ≥ 0, e a constant with |e| ≤ 2⁴⁰) as `2^(e log₂ x)`, within two units in the last
/// place where |e log₂ x| ≤ 1 (the step-size control's range) and within
/// `2.2·10⁻¹⁶ (4 + |e log₂ x|)` relative elsewhere. 0 gives 0 for e > 0, +∞ gives +∞, NaN
/// gives NaN; a result below 2⁻¹⁰²² may be flushed to 0 and one above 2¹⁰²⁴ is +∞.
#[inline(always)]
pub fn positive_powf<L: Lane>(x: L, e: f64) -> L {
    let zero = L::splat(0.0);
    let one = L::splat(1.0);
    // x = m 2^k, m in [√½, √2).
    let positive_finite = x.greater_than(zero) & x.is_finite();
    let (m, k) = L::select(positive_finite, x, one).mantissa_exponent();
    let high = m.greater_than(L::splat(std::f64::consts::SQRT_2));
    let m = L::select(high, m * L::splat(0.5), m);
    let k = L::select(high, k + one, k);
    // ln m = 2 atanh s.
    let s = (m - one) / (m + one);
    let ln_m = L::splat(2.0) * (s + s * odd_series_tail(s * s, ATANH_TERMS, false));
    let t = L::splat(e) * k + L::splat(e) * (ln_m * L::splat(std::f64::consts::LOG2_E));
    // 2^t = 2^n 2^f, n the nearest integer (by the 1.5·2⁵² rounding trick), |f| ≤ ½.
    let limit = L::splat(1100.0);
    let t = L::select(t.greater_than(limit), limit, t);
    let t = L::select(t.less_than(-limit), -limit, t);
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let n = (t + L::splat(ROUND)) - L::splat(ROUND);
    let g = (t - n) * L::splat(std::f64::consts::LN_2);
    let mut p = L::splat(EXP[EXP_TERMS - 1]);
    for i in (0..EXP_TERMS - 1).rev() {
        p = p * g + L::splat(EXP[i]);
    }
    let in_range = n.at_least(L::splat(-1022.0)) & n.at_most(L::splat(1023.0));
    let scaled = p * L::select(in_range, n, zero).pow2();
    let scaled = L::select(
        in_range,
        scaled,
        L::select(n.greater_than(zero), L::splat(f64::INFINITY), zero),
    );
    // 0^e = 0 (e > 0), ∞^e = ∞, NaN stays NaN.
    let special = L::select(x.equals(zero), zero, x);
    L::select(positive_finite, scaled, special)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Units in the last place between `a` and `b` (finite, same sign).
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    /// A reproducible stream of uniform numbers in [0, 1) (a 64-bit linear congruential
    /// generator's high bits).
    fn uniform(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Against the platform's `atan2` (glibc's): at most one unit apart on a million
    /// points of the upper half-plane spread over 40 decades of ratio, both signs of x, and
    /// the points where the reduction changes.
    #[test]
    fn half_plane_atan2_is_within_one_unit_of_the_platforms() {
        let mut state = 7u64;
        let mut worst = 0;
        for _ in 0..1_000_000 {
            let y = 10f64.powf(40.0 * uniform(&mut state) - 20.0);
            let x = 10f64.powf(40.0 * uniform(&mut state) - 20.0)
                * if uniform(&mut state) < 0.5 { -1.0 } else { 1.0 };
            let d = ulps(half_plane_atan2(y, x), y.atan2(x));
            if d > 1 {
                eprintln!("{y:e} {x:e}: {d}");
            }
            worst = worst.max(d);
        }
        for &t in &TAN_POINTS {
            for &x in &[1.0, -1.0, 3.7, -0.01] {
                for &y in &[t * x.abs(), x.abs() / t] {
                    for y in [y, y.next_up(), y.next_down()] {
                        worst = worst.max(ulps(half_plane_atan2(y, x), y.atan2(x)));
                    }
                }
            }
        }
        eprintln!("half_plane_atan2: worst {worst} unit(s) in the last place from atan2");
        assert!(worst <= 1, "worst {worst} units in the last place");
    }

    #[test]
    fn half_plane_atan2_on_the_axes_and_special_values() {
        assert_eq!(half_plane_atan2(0.0, 2.0), 0.0);
        assert_eq!(half_plane_atan2(0.0, -2.0), std::f64::consts::PI);
        assert_eq!(half_plane_atan2(2.0, 0.0), std::f64::consts::FRAC_PI_2);
        assert_eq!(half_plane_atan2(1.0, 1.0), std::f64::consts::FRAC_PI_4);
        assert_eq!(half_plane_atan2(0.0, 0.0), 0.0);
        assert_eq!(half_plane_atan2(1e-300, 1.0), 1e-300);
        assert_eq!(
            half_plane_atan2(f64::INFINITY, 1.0),
            std::f64::consts::FRAC_PI_2
        );
        assert!(half_plane_atan2(f64::NAN, 1.0).is_nan());
        assert!(half_plane_atan2(1.0, f64::NAN).is_nan());
    }

    /// Against the platform's `pow` at the step-size control's exponents: within 2 units in
    /// the last place for x in [10⁻¹⁴, 10⁴] (|e log₂ x| ≤ 1 there for e = 0.04), and within
    /// the documented relative bound over the whole positive range, subnormals included.
    #[test]
    fn positive_powf_is_near_the_platforms() {
        let mut state = 11u64;
        let mut worst_ulps = 0;
        let mut worst_excess: f64 = 0.0;
        for _ in 0..300_000 {
            let e = [0.17, 0.04, 0.2, 1.0 / 8.0][(uniform(&mut state) * 4.0) as usize];
            let x = 10f64.powf(18.0 * uniform(&mut state) - 14.0);
            let (ours, platform) = (positive_powf(x, e), x.powf(e));
            if (e * x.log2()).abs() <= 1.0 {
                worst_ulps = worst_ulps.max(ulps(ours, platform));
            }
            let wide = 2f64.powf(2000.0 * uniform(&mut state) - 1070.0);
            let (ours, platform) = (positive_powf(wide, e), wide.powf(e));
            let bound = 2.2e-16 * (4.0 + (e * wide.log2()).abs());
            worst_excess = worst_excess.max(((ours - platform) / platform).abs() / bound);
        }
        eprintln!(
            "positive_powf: worst {worst_ulps} unit(s) in the last place where |e log2 x| <= 1, \
             {worst_excess:.2} of the relative bound elsewhere"
        );
        assert!(
            worst_ulps <= 4,
            "worst {worst_ulps} units in the last place"
        );
        assert!(worst_excess <= 1.0, "worst {worst_excess} of the bound");
    }

    /// Each lane of both functions at width W is the f64 result, bit for bit, on random
    /// points and special values (inlined, so that it runs in the caller's instruction set).
    #[inline(always)]
    fn every_lane_is_the_scalar_result<L: Lane>() {
        let mut state = 3u64;
        let specials = [
            0.0,
            -0.0,
            1e-310,
            1.0,
            f64::INFINITY,
            f64::NAN,
            0.198912367379658,
        ];
        for round in 0..20_000 {
            let mut ys = vec![0.0; L::WIDTH];
            let mut xs = vec![0.0; L::WIDTH];
            for i in 0..L::WIDTH {
                ys[i] = 10f64.powf(30.0 * uniform(&mut state) - 15.0);
                xs[i] = 10f64.powf(30.0 * uniform(&mut state) - 15.0) - 1e-3;
                if round % 7 == 0 {
                    ys[i] = specials[(round + i) % specials.len()];
                    xs[i] = specials[(round + 3 * i) % specials.len()];
                }
            }
            let lanes = |v: &[f64]| (0..L::WIDTH).fold(L::splat(0.0), |l, i| l.with_lane(i, v[i]));
            let (y, x) = (lanes(&ys), lanes(&xs));
            let (angle, power) = (half_plane_atan2(y, x), positive_powf(y, 0.17));
            for i in 0..L::WIDTH {
                let same =
                    |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                assert!(same(angle.lane(i), half_plane_atan2(ys[i], xs[i])));
                assert!(same(power.lane(i), positive_powf(ys[i], 0.17)));
            }
        }
    }

    #[test]
    fn four_lanes_are_the_scalar_results() {
        every_lane_is_the_scalar_result::<crate::lanes::F64x4>();
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            fn check() {
                every_lane_is_the_scalar_result::<crate::lanes::F64x4>();
            }
            if crate::cpu::avx2_available() {
                // SAFETY: the processor has AVX2.
                unsafe { check() }
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn eight_lanes_are_the_scalar_results_where_the_processor_has_avx512() {
        #[target_feature(enable = "avx512f")]
        fn check() {
            every_lane_is_the_scalar_result::<crate::lanes::f64x8::F64x8>();
        }
        if !crate::cpu::avx512_available() {
            eprintln!("no AVX-512F on this processor: nothing to test");
            return;
        }
        // SAFETY: the processor has AVX-512F.
        unsafe { check() }
    }

    #[test]
    fn positive_powf_on_special_values() {
        assert_eq!(positive_powf(0.0, 0.17), 0.0);
        assert_eq!(positive_powf(1.0, 0.17), 1.0);
        assert_eq!(positive_powf(f64::INFINITY, 0.17), f64::INFINITY);
        assert!(positive_powf(f64::NAN, 0.17).is_nan());
        assert_eq!(positive_powf(16.0, 0.25), 2.0);
        // Results below 2⁻¹⁰²² are flushed to 0.
        assert_eq!(positive_powf(2f64.powi(-1074), 1.0), 0.0);
        assert_eq!(positive_powf(2f64.powi(-1074), 0.5), 2f64.powi(-537));
    }
}
