//! The check every lane type passes (tests only): each lane of every [`Lane`] operation is
//! the f64 operation on that lane, bit for bit.

use super::{Lane, LaneMask};

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// A vector of `L` holding `xs` (one per lane).
fn vector<L: Lane>(xs: &[f64]) -> L {
    (0..L::WIDTH).fold(L::splat(0.0), |v, i| v.with_lane(i, xs[i]))
}

/// Each lane of every operation of `L` equals the f64 operation on that lane, bit for bit,
/// on values that include signed zeros, subnormals, infinities and NaN; each lane is read
/// back alone (`lane`, `gather_lane`) and written alone (`with_lane`). Inlined, so that it
/// runs in the instruction set of the test that calls it.
#[inline(always)]
pub(crate) fn every_lane_is_the_f64_operation<L: Lane>() {
    let values = [
        0.0,
        -0.0,
        1.5,
        -2.25,
        1e-310,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        3.0e300,
        7.0,
    ];
    for (k, &x0) in values.iter().enumerate() {
        let xs: Vec<f64> = (0..L::WIDTH)
            .map(|i| {
                if i == 0 {
                    x0
                } else {
                    values[(k + 2 * i + 1) % 10]
                }
            })
            .collect();
        for &y0 in &values {
            let ys: Vec<f64> = (0..L::WIDTH)
                .map(|i| match i {
                    0 => y0,
                    2 => x0,
                    _ => values[(k + 3 * i + 1) % 10],
                })
                .collect();
            let (x, y) = (vector::<L>(&xs), vector::<L>(&ys));
            for i in 0..L::WIDTH {
                let (a, b) = (xs[i], ys[i]);
                assert!(same((x + y).lane(i), a + b));
                assert!(same((x - y).lane(i), a - b));
                assert!(same((x * y).lane(i), a * b));
                assert!(same((x / y).lane(i), a / b));
                assert!(same((-x).lane(i), -a));
                assert!(same(x.abs().lane(i), a.abs()));
                assert!(same(x.sqrt().lane(i), a.sqrt()));
                assert!(same(x.max(y).lane(i), a.max(b)));
                assert!(same(x.min(y).lane(i), a.min(b)));
                assert!(same(x.clamp(0.1, 5.0).lane(i), a.clamp(0.1, 5.0)));
                assert!(same(x.powf(0.17).lane(i), a.powf(0.17)));
                if a > 0.0 && a.is_finite() {
                    let (m, k) = x.mantissa_exponent();
                    let expected = super::scalar_mantissa_exponent(a);
                    assert!(same(m.lane(i), expected.0) && same(k.lane(i), expected.1));
                    assert!((1.0..2.0).contains(&expected.0));
                    assert_eq!(expected.0 * 2f64.powf(expected.1), a);
                }
                assert_eq!(x.less_than(y).test(i), a < b);
                assert_eq!(x.at_most(y).test(i), a <= b);
                assert_eq!(x.greater_than(y).test(i), a > b);
                assert_eq!(x.at_least(y).test(i), a >= b);
                assert_eq!(x.equals(y).test(i), a == b);
                assert_eq!(x.is_finite().test(i), a.is_finite());
                let chosen = if a < b { a } else { b };
                assert!(same(L::select(x.less_than(y), x, y).lane(i), chosen));
                assert!(same(x.with_lane(i, b).lane(i), b));
                let mut one = [0.0];
                L::gather_lane(&[x], i, &mut one);
                assert!(same(one[0], a));
            }
        }
    }
}

/// 2^k for every integer k in [−1022, 1023], exactly, in every lane.
#[inline(always)]
pub(crate) fn powers_of_two_are_exact<L: Lane>() {
    for k in -1022..=1023 {
        let ks: Vec<f64> = (0..L::WIDTH)
            .map(|i| (k - i as i32).max(-1022) as f64)
            .collect();
        let p = vector::<L>(&ks).pow2();
        for (i, &kf) in ks.iter().enumerate() {
            assert_eq!(p.lane(i), 2f64.powi(kf as i32), "2^{kf}");
        }
    }
}

/// Masks combine lane by lane, and `any` and `all` read every lane.
#[inline(always)]
pub(crate) fn masks_combine_lane_by_lane<L: Lane>() {
    let pattern = |bits: [bool; 4]| -> L::Mask {
        (0..L::WIDTH).fold(L::Mask::splat(false), |m, i| m.with_lane(i, bits[i % 4]))
    };
    let a = pattern([true, false, true, false]);
    let b = pattern([true, true, false, false]);
    for i in 0..L::WIDTH {
        assert_eq!((a & b).test(i), [true, false, false, false][i % 4]);
        assert_eq!((a | b).test(i), [true, true, true, false][i % 4]);
        assert_eq!((!a).test(i), [false, true, false, true][i % 4]);
    }
    assert!(a.any() && !a.all());
    assert!(L::Mask::splat(true).all() && !L::Mask::splat(false).any());
    let last = L::Mask::splat(false).with_lane(L::WIDTH - 1, true);
    assert!(last.any() && !last.all() && last.test(L::WIDTH - 1));
}
