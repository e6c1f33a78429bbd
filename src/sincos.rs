//! `sin x` and `cos x` together (the orbit angle of a circular orbit, a hinged rod's joint
//! angles), cheaper than the C library's `sincos` (which handles every `f64` and rounds
//! correctly in nearly all cases), within one unit in the last place of it.
//!
//! Method (the table-driven scheme of P. T. P. Tang, "Table-driven implementation of the
//! exponential function in IEEE floating-point arithmetic", ACM TOMS 15(2), 1989, applied to
//! sine and cosine as in S. Gal & B. Bachelis, "An accurate elementary mathematical library
//! for the IEEE floating point standard", ACM TOMS 17(1), 1991):
//! 1. `x = k·d + r` with `d = 2π/256`, `k = round(x/d)`, `|r| ≤ d/2 ≈ 0.0123`. The product
//!    `k·d` is formed by the method of W. J. Cody & W. Waite (*Software Manual for the
//!    Elementary Functions*, 1980) with `d` split into three parts, the first two
//!    with 25 significant bits so that `k·d₁` and `k·d₂` are exact for `|k| < 2²⁷` (|x| below
//!    about 3.3·10⁶ rad, half a million turns); larger arguments go to the library.
//! 2. `sin r` and `cos r − 1` by their Taylor polynomials to `r⁷` and `r⁸`: the first
//!    neglected terms are below 2·10⁻²³ of one.
//! 3. `sin x = s_j + (s_j (cos r − 1) + c_j sin r)` and `cos x = c_j + (c_j (cos r − 1) −
//!    s_j sin r)` with `(s_j, c_j) = (sin, cos)(2πj/256)`, `j = k mod 256`, from a table
//!    filled once by the library's `sin_cos`, corrected to first order for the difference
//!    between the node and its `f64` value.
//!
//! The tests compare it with the library over 10⁶ arguments: the largest difference is
//! 1.1·10⁻¹⁶, one unit in the last place of a number in [0.5, 1).

use crate::lanes::{Lane, LaneMask};
use std::f64::consts::TAU;
use std::sync::OnceLock;

/// Table size: a power of two, so that `j = k mod 256` is a mask.
const STEPS: usize = 256;

/// The low part of 2π: `2π − TAU` (TAU rounded to `f64`).
const TAU_LO: f64 = 2.449_293_598_294_706_4e-16;

/// Largest |k| for which `k·d₁` and `k·d₂` are exact (25-bit parts).
const K_MAX: f64 = (1u64 << 27) as f64;

struct Table {
    /// `sin(2πj/256)`.
    sines: [f64; STEPS],
    /// `cos(2πj/256)`.
    cosines: [f64; STEPS],
    /// `d = 2π/256` in three parts: `d₁ + d₂ + d₃`.
    d1: f64,
    d2: f64,
    d3: f64,
}

/// `x` with its significand cut to 25 bits (toward zero).
fn truncate_25_bits(x: f64) -> f64 {
    f64::from_bits(x.to_bits() & !((1u64 << 28) - 1))
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut values = [(0.0, 1.0); STEPS];
        for (j, v) in values.iter_mut().enumerate() {
            // The node 2πj/256 is a + δ: a = fl(j·TAU)/256 (the division is exact) and δ
            // what rounding and TAU's own error left out (the fused product is exact).
            let jf = j as f64;
            let product = jf * TAU;
            let delta = (jf.mul_add(TAU, -product) + jf * TAU_LO) / STEPS as f64;
            let (s, c) = (product / STEPS as f64).sin_cos();
            // First order in |δ| < 1e-13: the second-order terms are below 1e-26.
            *v = (s + c * delta, c - s * delta);
        }
        // TAU/256 is exact (a power-of-two scaling); its parts are exact differences.
        let d = TAU / STEPS as f64;
        let d1 = truncate_25_bits(d);
        let d2 = truncate_25_bits(d - d1);
        let d3 = (d - d1 - d2) + TAU_LO / STEPS as f64;
        Table {
            sines: values.map(|v| v.0),
            cosines: values.map(|v| v.1),
            d1,
            d2,
            d3,
        }
    })
}

/// `(sin x, cos x)`.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let t = table();
    let y = x * (STEPS as f64 / TAU);
    if y.is_nan() || y.abs() >= K_MAX {
        // Huge or non-finite arguments.
        return x.sin_cos();
    }
    // Round to the nearest integer (halves away from zero) by truncating y ± ½: two
    // conversion instructions, where `f64::round` is a library call without SSE4.1.
    let k_int = (y + 0.5f64.copysign(y)) as i64;
    let k = k_int as f64;
    let r = ((x - k * t.d1) - k * t.d2) - k * t.d3;
    let j = (k_int & (STEPS as i64 - 1)) as usize;
    let (s_j, c_j) = (t.sines[j], t.cosines[j]);
    let r2 = r * r;
    let sin_r = r + r * r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0)));
    let cos_r_minus_1 =
        r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40320.0))));
    (
        s_j + (s_j * cos_r_minus_1 + c_j * sin_r),
        c_j + (c_j * cos_r_minus_1 - s_j * sin_r),
    )
}

/// `(sin x, cos x)` of each of `N` arguments: [`sin_cos`]'s operations on each, bit for bit,
/// arranged so that the compiler evaluates the reductions and polynomials of several
/// arguments with each vector instruction (only the table's loads stay one by one).
#[inline(always)]
pub fn sin_cos_lanes<const N: usize>(x: [f64; N]) -> ([f64; N], [f64; N]) {
    if x.iter()
        .any(|v| v.is_nan() || (v * (STEPS as f64 / TAU)).abs() >= K_MAX)
    {
        let mut out = ([0.0; N], [0.0; N]);
        for (i, v) in x.iter().enumerate() {
            (out.0[i], out.1[i]) = sin_cos(*v);
        }
        return out;
    }
    let t = table();
    let mut k = [0.0; N];
    let mut k_int = [0i32; N];
    for i in 0..N {
        let y = x[i] * (STEPS as f64 / TAU);
        // |y| < 2²⁷: the integer fits 32 bits, whose conversions take several lanes at once.
        k_int[i] = (y + 0.5f64.copysign(y)) as i32;
        k[i] = k_int[i] as f64;
    }
    let (mut s_j, mut c_j) = ([0.0; N], [0.0; N]);
    for i in 0..N {
        let j = (k_int[i] & (STEPS as i32 - 1)) as usize;
        (s_j[i], c_j[i]) = (t.sines[j], t.cosines[j]);
    }
    let mut out = ([0.0; N], [0.0; N]);
    for i in 0..N {
        let r = ((x[i] - k[i] * t.d1) - k[i] * t.d2) - k[i] * t.d3;
        let r2 = r * r;
        let sin_r = r + r * r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0)));
        let cos_r_minus_1 =
            r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40320.0))));
        out.0[i] = s_j[i] + (s_j[i] * cos_r_minus_1 + c_j[i] * sin_r);
        out.1[i] = c_j[i] + (c_j[i] * cos_r_minus_1 - s_j[i] * sin_r);
    }
    out
}

/// `(sin x, cos x)` of each lane of `x` (one run per lane in a campaign's lanes):
/// [`sin_cos`]'s operations on each lane, bit for bit. The reduction's rounding to the table's
/// node ([`Lane::nearest_integer`]) and the table's loads ([`Lane::lookup_256`]) go lane by
/// lane, or as vector conversions and gathers in the eight AVX-512 lanes; the rest runs in
/// the lanes. A lane out of the
/// reduction's range (or not a number) sends every lane to [`sin_cos`].
#[inline(always)]
pub fn sin_cos_in_lanes<L: Lane>(x: L) -> (L, L) {
    let y = x * L::splat(STEPS as f64 / TAU);
    // Not below the limit: huge, infinite or not a number.
    if !(y.abs().less_than(L::splat(K_MAX))).all() {
        let (mut s, mut c) = (x, x);
        for i in 0..L::WIDTH {
            let (si, ci) = sin_cos(x.lane(i));
            s = s.with_lane(i, si);
            c = c.with_lane(i, ci);
        }
        return (s, c);
    }
    let t = table();
    let k = y.nearest_integer();
    let [s_j, c_j] = k.lookup_256([&t.sines, &t.cosines]);
    let c = L::splat;
    let r = ((x - k * c(t.d1)) - k * c(t.d2)) - k * c(t.d3);
    let r2 = r * r;
    let sin_r = r + r * r2 * (c(-1.0 / 6.0) + r2 * (c(1.0 / 120.0) + r2 * c(-1.0 / 5040.0)));
    let cos_r_minus_1 =
        r2 * (c(-0.5) + r2 * (c(1.0 / 24.0) + r2 * (c(-1.0 / 720.0) + r2 * c(1.0 / 40320.0))));
    (
        s_j + (s_j * cos_r_minus_1 + c_j * sin_r),
        c_j + (c_j * cos_r_minus_1 - s_j * sin_r),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the library's `sin_cos` at a million arguments spread over the whole range
    /// handled here (a deterministic generator; no extra dependency) and at the table's
    /// nodes and the midpoints between them.
    #[test]
    fn agrees_with_the_library() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            // xorshift64*: uniform in [0, 1).
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst: f64 = 0.0;
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            worst = worst.max((s - s0).abs()).max((c - c0).abs());
        };
        for scale in [1e-3, 1.0, 10.0, 1e3, 1e5, 3e6] {
            for _ in 0..(1_000_000 / 6) {
                check(scale * (2.0 * next() - 1.0));
            }
        }
        for j in -600..600 {
            check(TAU * j as f64 / 256.0);
            check(TAU * (j as f64 + 0.5) / 256.0);
        }
        // Measured: 1.1e-16, one unit in the last place of a number in [0.5, 1).
        assert!(worst <= 2.3e-16, "largest difference {worst:e}");
        // Beyond the reduction's range, and non-finite: the library's values.
        for x in [4e6, -1e9, 1e300, f64::INFINITY, f64::NAN] {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            assert!(
                s.to_bits() == s0.to_bits() && c.to_bits() == c0.to_bits(),
                "{x}"
            );
        }
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }

    /// The lanes give [`sin_cos`]'s bits, argument by argument, also when one argument of
    /// the batch is out of the reduction's range.
    #[test]
    fn lanes_equal_one_at_a_time_bit_for_bit() {
        let bits = |(s, c): (f64, f64)| (s.to_bits(), c.to_bits());
        for batch in 0..2000 {
            let b = batch as f64;
            let mut x: [f64; 8] = std::array::from_fn(|i| {
                let a = b + 0.37 * i as f64;
                (3.0 * a).sin() * 10f64.powf((a % 7.0) - 1.0)
            });
            if batch % 100 == 3 {
                x[batch % 8] = [4e6, f64::NAN, -f64::INFINITY][batch % 3];
            }
            let (s, c) = sin_cos_lanes(x);
            for i in 0..8 {
                assert_eq!(bits((s[i], c[i])), bits(sin_cos(x[i])), "{}", x[i]);
            }
            if batch % 50 == 7 {
                // Signed zeros, arguments next to a node's half-way point (the rounding's
                // ties), small negatives (whose node is −0 before the +0 is added) and large
                // ones.
                let d = TAU / STEPS as f64;
                let k = (batch / 50) as f64;
                x = [
                    -0.0,
                    0.0,
                    (k + 0.5) * d,
                    -(k + 0.5) * d,
                    -1e-300,
                    -0.4 * d,
                    3.0e6 - k,
                    -(2.5e6 + 0.5 * d),
                ];
            }
            #[cfg(target_arch = "x86_64")]
            if crate::cpu::avx512_available() {
                /// Eight at a time in the AVX-512 lanes (vector rounding and gathers).
                #[target_feature(enable = "avx512f")]
                fn eight(x: [f64; 8]) -> [(f64, f64); 8] {
                    use crate::lanes::f64x8::F64x8;
                    let lanes = x
                        .iter()
                        .enumerate()
                        .fold(F64x8::splat(0.0), |l, (i, v)| l.with_lane(i, *v));
                    let (s, c) = sin_cos_in_lanes(lanes);
                    std::array::from_fn(|i| (s.lane(i), c.lane(i)))
                }
                // SAFETY: the processor has AVX-512F.
                let got = unsafe { eight(x) };
                for (g, v) in got.iter().zip(x) {
                    assert_eq!(bits(*g), bits(sin_cos(v)), "eight lanes: {v}");
                }
            }
            // The same arguments four at a time in the campaigns' lanes, and one at a time.
            for half in x.chunks(4) {
                let lanes = crate::lanes::F64x4([half[0], half[1], half[2], half[3]]);
                let (s, c) = sin_cos_in_lanes(lanes);
                for (i, &v) in half.iter().enumerate() {
                    assert_eq!(bits((s.lane(i), c.lane(i))), bits(sin_cos(v)), "{v}");
                    assert_eq!(bits(sin_cos_in_lanes(v)), bits(sin_cos(v)), "{v}");
                }
            }
        }
    }
}
