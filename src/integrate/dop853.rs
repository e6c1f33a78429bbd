//! Dormand–Prince 8(5,3) ("DOP853") with Hairer's step-size control and seventh-order dense
//! output.
//!
//! The method: twelve stages give an eighth-order solution; the local error is estimated from
//! an embedded fifth-order and an embedded third-order solution, combined as
//! `err = err₅² / √(err₅² + 0.01·err₃²)`, which is of order eight for small steps but does
//! not collapse when the fifth-order estimate happens to vanish. The stage evaluated at the
//! new point (number 13) is the first stage of the next step (FSAL). Three more stages
//! (14–16) give a continuous extension of order seven.
//!
//! Sources: P. J. Prince & J. R. Dormand, "High order embedded Runge–Kutta formulae",
//! J. Comput. Appl. Math. 7 (1981); Hairer, Nørsett & Wanner, *Solving Ordinary Differential
//! Equations I* (2nd ed., Springer 1993), §II.10 (the method, its coefficients and its
//! error estimate) and §II.6 (dense output); the decimal coefficient values are those of
//! Hairer & Wanner's published Fortran code `dop853.f` (the same values SciPy transcribes in
//! `scipy/integrate/_ivp/dop853_coefficients.py`), written out below with all their digits.
//! The starting step is that code's `HINIT` with order 8,
//! with root-mean-square norms as in the error estimate.
//!
//! Right-hand-side evaluations: 11 per attempted step (stages 2–12), plus 1 for stage 13 at
//! the new point when the step is accepted (reused as stage 1 of the next step), plus 3 for
//! the dense-output stages of an accepted step (unless switched off with
//! [`Dop853::with_dense_output`], or deferred to the steps that are interpolated with
//! [`Dop853::with_lazy_dense_output`]); the first step adds 1 for `f(t0, y0)` and, without a
//! given first step, 1 for the starting-step estimate. So a run costs
//! `1 [+ 1] + 15·accepted + 11·rejected` evaluations (12 instead of 15 for a step without
//! dense output).

// The coefficients keep all the digits of the published tables so that they can be checked
// against the source by eye; the compiler rounds them to the nearest `f64`.
#![allow(clippy::excessive_precision)]

use super::dopri5::{StageRhs, SystemRhs, non_finite_step_size};
use super::{OdeSystem, Stats, StepControl, StepError, Stepper, Tolerances, combine_on};
use crate::lanes::Lane;

// Nodes (c₁ = 0, c₁₂ = c₁₃ = 1).
const C2: f64 = 0.526001519587677318785587544488e-01;
const C3: f64 = 0.789002279381515978178381316732e-01;
const C4: f64 = 0.118350341907227396726757197510e+00;
const C5: f64 = 0.281649658092772603273242802490e+00;
const C6: f64 = 0.333333333333333333333333333333e+00;
const C7: f64 = 0.25e+00;
const C8: f64 = 0.307692307692307692307692307692e+00;
const C9: f64 = 0.651282051282051282051282051282e+00;
const C10: f64 = 0.6e+00;
const C11: f64 = 0.857142857142857142857142857142e+00;
const C14: f64 = 0.1e+00;
const C15: f64 = 0.2e+00;
const C16: f64 = 0.777777777777777777777777777778e+00;

// Stage matrix, `A{i}_{j}` = a_ij (stage i uses stage j); zero entries are left out.
const A2_1: f64 = 5.26001519587677318785587544488e-2;
const A3_1: f64 = 1.97250569845378994544595329183e-2;
const A3_2: f64 = 5.91751709536136983633785987549e-2;
const A4_1: f64 = 2.95875854768068491816892993775e-2;
const A4_3: f64 = 8.87627564304205475450678981324e-2;
const A5_1: f64 = 2.41365134159266685502369798665e-1;
const A5_3: f64 = -8.84549479328286085344864962717e-1;
const A5_4: f64 = 9.24834003261792003115737966543e-1;
const A6_1: f64 = 3.7037037037037037037037037037e-2;
const A6_4: f64 = 1.70828608729473871279604482173e-1;
const A6_5: f64 = 1.25467687566822425016691814123e-1;
const A7_1: f64 = 3.7109375e-2;
const A7_4: f64 = 1.70252211019544039314978060272e-1;
const A7_5: f64 = 6.02165389804559606850219397283e-2;
const A7_6: f64 = -1.7578125e-2;
const A8_1: f64 = 3.70920001185047927108779319836e-2;
const A8_4: f64 = 1.70383925712239993810214054705e-1;
const A8_5: f64 = 1.07262030446373284651809199168e-1;
const A8_6: f64 = -1.53194377486244017527936158236e-2;
const A8_7: f64 = 8.27378916381402288758473766002e-3;
const A9_1: f64 = 6.24110958716075717114429577812e-1;
const A9_4: f64 = -3.36089262944694129406857109825e0;
const A9_5: f64 = -8.68219346841726006818189891453e-1;
const A9_6: f64 = 2.75920996994467083049415600797e1;
const A9_7: f64 = 2.01540675504778934086186788979e1;
const A9_8: f64 = -4.34898841810699588477366255144e1;
const A10_1: f64 = 4.77662536438264365890433908527e-1;
const A10_4: f64 = -2.48811461997166764192642586468e0;
const A10_5: f64 = -5.90290826836842996371446475743e-1;
const A10_6: f64 = 2.12300514481811942347288949897e1;
const A10_7: f64 = 1.52792336328824235832596922938e1;
const A10_8: f64 = -3.32882109689848629194453265587e1;
const A10_9: f64 = -2.03312017085086261358222928593e-2;
const A11_1: f64 = -9.3714243008598732571704021658e-1;
const A11_4: f64 = 5.18637242884406370830023853209e0;
const A11_5: f64 = 1.09143734899672957818500254654e0;
const A11_6: f64 = -8.14978701074692612513997267357e0;
const A11_7: f64 = -1.85200656599969598641566180701e1;
const A11_8: f64 = 2.27394870993505042818970056734e1;
const A11_9: f64 = 2.49360555267965238987089396762e0;
const A11_10: f64 = -3.0467644718982195003823669022e0;
const A12_1: f64 = 2.27331014751653820792359768449e0;
const A12_4: f64 = -1.05344954667372501984066689879e1;
const A12_5: f64 = -2.00087205822486249909675718444e0;
const A12_6: f64 = -1.79589318631187989172765950534e1;
const A12_7: f64 = 2.79488845294199600508499808837e1;
const A12_8: f64 = -2.85899827713502369474065508674e0;
const A12_9: f64 = -8.87285693353062954433549289258e0;
const A12_10: f64 = 1.23605671757943030647266201528e1;
const A12_11: f64 = 6.43392746015763530355970484046e-1;

// Weights of the eighth-order solution (stages 1, 6–12); also row 13 of the stage matrix.
const B1: f64 = 5.42937341165687622380535766363e-2;
const B6: f64 = 4.45031289275240888144113950566e0;
const B7: f64 = 1.89151789931450038304281599044e0;
const B8: f64 = -5.8012039600105847814672114227e0;
const B9: f64 = 3.1116436695781989440891606237e-1;
const B10: f64 = -1.52160949662516078556178806805e-1;
const B11: f64 = 2.01365400804030348374776537501e-1;
const B12: f64 = 4.47106157277725905176885569043e-2;

// Third-order embedded weights (stages 1, 9, 12): err₃ = Σ b·k − (BHH1 k₁ + BHH2 k₉ + BHH3 k₁₂).
const BHH1: f64 = 0.244094488188976377952755905512e+00;
const BHH2: f64 = 0.733846688281611857341361741547e+00;
const BHH3: f64 = 0.220588235294117647058823529412e-01;

// Fifth-order error weights (stages 1, 6–12): err₅ = Σ ER·k.
const ER1: f64 = 0.1312004499419488073250102996e-01;
const ER6: f64 = -0.1225156446376204440720569753e+01;
const ER7: f64 = -0.4957589496572501915214079952e+00;
const ER8: f64 = 0.1664377182454986536961530415e+01;
const ER9: f64 = -0.3503288487499736816886487290e+00;
const ER10: f64 = 0.3341791187130174790297318841e+00;
const ER11: f64 = 0.8192320648511571246570742613e-01;
const ER12: f64 = -0.2235530786388629525884427845e-01;

// Dense-output stages 14–16.
const A14_1: f64 = 5.61675022830479523392909219681e-2;
const A14_7: f64 = 2.53500210216624811088794765333e-1;
const A14_8: f64 = -2.46239037470802489917441475441e-1;
const A14_9: f64 = -1.24191423263816360469010140626e-1;
const A14_10: f64 = 1.5329179827876569731206322685e-1;
const A14_11: f64 = 8.20105229563468988491666602057e-3;
const A14_12: f64 = 7.56789766054569976138603589584e-3;
const A14_13: f64 = -8.298e-3;
const A15_1: f64 = 3.18346481635021405060768473261e-2;
const A15_6: f64 = 2.83009096723667755288322961402e-2;
const A15_7: f64 = 5.35419883074385676223797384372e-2;
const A15_8: f64 = -5.49237485713909884646569340306e-2;
const A15_11: f64 = -1.08347328697249322858509316994e-4;
const A15_12: f64 = 3.82571090835658412954920192323e-4;
const A15_13: f64 = -3.40465008687404560802977114492e-4;
const A15_14: f64 = 1.41312443674632500278074618366e-1;
const A16_1: f64 = -4.28896301583791923408573538692e-1;
const A16_6: f64 = -4.69762141536116384314449447206e0;
const A16_7: f64 = 7.68342119606259904184240953878e0;
const A16_8: f64 = 4.06898981839711007970213554331e0;
const A16_9: f64 = 3.56727187455281109270669543021e-1;
const A16_13: f64 = -1.39902416515901462129418009734e-3;
const A16_14: f64 = 2.9475147891527723389556272149e0;
const A16_15: f64 = -9.15095847217987001081870187138e0;

// Dense-output coefficients d₄…d₇ (Hairer's d41…d716), each over stages
// 1, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16 in that order.
const D4: [f64; 12] = [
    -0.84289382761090128651353491142e+01,
    0.56671495351937776962531783590e+00,
    -0.30689499459498916912797304727e+01,
    0.23846676565120698287728149680e+01,
    0.21170345824450282767155149946e+01,
    -0.87139158377797299206789907490e+00,
    0.22404374302607882758541771650e+01,
    0.63157877876946881815570249290e+00,
    -0.88990336451333310820698117400e-01,
    0.18148505520854727256656404962e+02,
    -0.91946323924783554000451984436e+01,
    -0.44360363875948939664310572000e+01,
];
const D5: [f64; 12] = [
    0.10427508642579134603413151009e+02,
    0.24228349177525818288430175319e+03,
    0.16520045171727028198505394887e+03,
    -0.37454675472269020279518312152e+03,
    -0.22113666853125306036270938578e+02,
    0.77334326684722638389603898808e+01,
    -0.30674084731089398182061213626e+02,
    -0.93321305264302278729567221706e+01,
    0.15697238121770843886131091075e+02,
    -0.31139403219565177677282850411e+02,
    -0.93529243588444783865713862664e+01,
    0.35816841486394083752465898540e+02,
];
const D6: [f64; 12] = [
    0.19985053242002433820987653617e+02,
    -0.38703730874935176555105901742e+03,
    -0.18917813819516756882830838328e+03,
    0.52780815920542364900561016686e+03,
    -0.11573902539959630126141871134e+02,
    0.68812326946963000169666922661e+01,
    -0.10006050966910838403183860980e+01,
    0.77771377980534432092869265740e+00,
    -0.27782057523535084065932004339e+01,
    -0.60196695231264120758267380846e+02,
    0.84320405506677161018159903784e+02,
    0.11992291136182789328035130030e+02,
];
const D7: [f64; 12] = [
    -0.25693933462703749003312586129e+02,
    -0.15418974869023643374053993627e+03,
    -0.23152937917604549567536039109e+03,
    0.35763911791061412378285349910e+03,
    0.93405324183624310003907691704e+02,
    -0.37458323136451633156875139351e+02,
    0.10409964950896230045147246184e+03,
    0.29840293426660503123344363579e+02,
    -0.43533456590011143754432175058e+02,
    0.96324553959188282948394950600e+02,
    -0.39177261675615439165231486172e+02,
    -0.14972683625798562581422125276e+03,
];

// Step-size control, with the defaults of dop853.f.
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.333; // the step shrinks by at most 1/0.333 ≈ 3×
const FAC_MAX: f64 = 6.0; // and grows by at most 6×
/// PI-control stabilisation; 0 (Hairer's default for DOP853) makes it the classical
/// controller `h·(1/err)^{1/8}`. The code keeps the PI form so the term can be tuned.
const BETA: f64 = 0.0;
/// The step-size controller with these settings.
pub(crate) const CONTROL: StepControl = StepControl {
    safety: SAFETY,
    fac_min: FAC_MIN,
    fac_max: FAC_MAX,
    beta: BETA,
};
const EXPO: f64 = 1.0 / 8.0 - 0.2 * BETA;
const MAX_REJECTIONS_IN_A_ROW: u32 = 100;

// The step's arithmetic, generic over the lane type: at `f64` it is the scalar `Dop853`'s,
// at a wider lane one run per lane (crate::lanes). Each function rounds as the scalar method
// always has, so a lane's numbers are the scalar run's.

/// How a step's stage arguments `base + h·Σⱼ a[j]·k[j]` are formed: by [`combine`] in every
/// case, through its AVX2 build on the scalar path ([`combine_on`], the same bits), plainly in
/// lanes.
pub(crate) trait Combine<L: Lane> {
    /// `out = base + h·Σⱼ a[j]·k[j]`.
    fn combine<const M: usize>(&self, out: &mut [L], base: &[L], h: L, a: [f64; M], k: [&[L]; M]);
}

/// The scalar path's [`Combine`]: [`combine_on`], through its AVX2 build when the field is
/// true (the processor has AVX2).
struct ScalarCombine(bool);

impl Combine<f64> for ScalarCombine {
    #[inline(always)]
    fn combine<const M: usize>(
        &self,
        out: &mut [f64],
        base: &[f64],
        h: f64,
        a: [f64; M],
        k: [&[f64]; M],
    ) {
        combine_on(self.0, out, base, h, a, k)
    }
}

/// The lanes' [`Combine`]: [`combine`] itself, compiled with the caller (the lockstep
/// engines' instruction set).
pub(crate) struct PlainCombine;

impl<L: Lane> Combine<L> for PlainCombine {
    #[inline(always)]
    fn combine<const M: usize>(&self, out: &mut [L], base: &[L], h: L, a: [f64; M], k: [&[L]; M]) {
        super::combine::<L, M>(out, base, h, a, k)
    }
}

/// Starting step (s) by Hairer's `HINIT` (order 8, RMS norms) from `(t, y)` with
/// `k1 = f(t, y)`, for a span `span` (s) and a cap `h_max` (s); evaluates `rhs` once (into
/// `k2`, with `stage` as scratch).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn initial_step<L: Lane>(
    rhs: &mut impl StageRhs<L>,
    comb: &impl Combine<L>,
    t: L,
    y: &[L],
    k1: &[L],
    k2: &mut [L],
    stage: &mut [L],
    (atol, rtol): (L, L),
    h_max: L,
    span: L,
) -> L {
    let n = y.len();
    let (k1, k2, stage) = (&k1[..n], &mut k2[..n], &mut stage[..n]);
    let c = L::splat;
    let count = c(n as f64);
    let sc = |yi: L| atol + rtol * yi.abs();
    let (mut dny, mut dnf) = (c(0.0), c(0.0));
    for i in 0..n {
        let (a, b) = (y[i] / sc(y[i]), k1[i] / sc(y[i]));
        dny += a * a;
        dnf += b * b;
    }
    let (dny, dnf) = ((dny / count).sqrt(), (dnf / count).sqrt());
    let tiny = c(1e-10);
    let h = L::select(
        dny.less_than(tiny) | dnf.less_than(tiny),
        c(1e-6),
        c(0.01) * dny / dnf,
    );
    let h = h.min(h_max).min(span);
    comb.combine(stage, y, h, [1.0], [k1]);
    rhs.eval(t + h, stage, k2);
    let mut der2 = c(0.0);
    for i in 0..n {
        let a = (k2[i] - k1[i]) / sc(y[i]);
        der2 += a * a;
    }
    let der12 = ((der2 / count).sqrt() / h).max(dnf);
    let h1 = L::select(
        der12.at_most(c(1e-15)),
        (h * c(1e-3)).max(c(1e-6)),
        (c(0.01) / der12).powf(1.0 / 8.0),
    );
    let h = (c(100.0) * h).min(h1).min(h_max).min(span);
    // Scaled norms can overflow (tiny atol, huge states): fall back to a small step and let
    // the controller find its way from there.
    L::select(
        h.is_finite() & h.greater_than(c(0.0)),
        h,
        (c(1e-6) * span).min(h_max),
    )
}

/// Evaluates stages 2–12 of a step `h` (s) from `(t, y)` with `k[0] = f(t, y)`, into
/// `k[1..12]`, with `stage` as scratch.
#[inline(always)]
pub(crate) fn stages<L: Lane, K: AsMut<[L]>>(
    rhs: &mut impl StageRhs<L>,
    comb: &impl Combine<L>,
    t: L,
    h: L,
    y: &[L],
    k: &mut [K; 16],
    stage: &mut [L],
) {
    let n = y.len();
    let [k1, k2, k3, k4, k5, k6, k7, k8, k9, k10, k11, k12, ..] = k;
    let (k1, k2, k3, k4) = (k1.as_mut(), k2.as_mut(), k3.as_mut(), k4.as_mut());
    let (k5, k6, k7, k8) = (k5.as_mut(), k6.as_mut(), k7.as_mut(), k8.as_mut());
    let (k9, k10, k11, k12) = (k9.as_mut(), k10.as_mut(), k11.as_mut(), k12.as_mut());
    let s = &mut stage[..n];
    let at = |c: f64| t + L::splat(c) * h;
    comb.combine(s, y, h, [A2_1], [k1]);
    rhs.eval(at(C2), s, k2);
    comb.combine(s, y, h, [A3_1, A3_2], [k1, k2]);
    rhs.eval(at(C3), s, k3);
    comb.combine(s, y, h, [A4_1, A4_3], [k1, k3]);
    rhs.eval(at(C4), s, k4);
    comb.combine(s, y, h, [A5_1, A5_3, A5_4], [k1, k3, k4]);
    rhs.eval(at(C5), s, k5);
    comb.combine(s, y, h, [A6_1, A6_4, A6_5], [k1, k4, k5]);
    rhs.eval(at(C6), s, k6);
    comb.combine(s, y, h, [A7_1, A7_4, A7_5, A7_6], [k1, k4, k5, k6]);
    rhs.eval(at(C7), s, k7);
    comb.combine(
        s,
        y,
        h,
        [A8_1, A8_4, A8_5, A8_6, A8_7],
        [k1, k4, k5, k6, k7],
    );
    rhs.eval(at(C8), s, k8);
    comb.combine(
        s,
        y,
        h,
        [A9_1, A9_4, A9_5, A9_6, A9_7, A9_8],
        [k1, k4, k5, k6, k7, k8],
    );
    rhs.eval(at(C9), s, k9);
    comb.combine(
        s,
        y,
        h,
        [A10_1, A10_4, A10_5, A10_6, A10_7, A10_8, A10_9],
        [k1, k4, k5, k6, k7, k8, k9],
    );
    rhs.eval(at(C10), s, k10);
    comb.combine(
        s,
        y,
        h,
        [A11_1, A11_4, A11_5, A11_6, A11_7, A11_8, A11_9, A11_10],
        [k1, k4, k5, k6, k7, k8, k9, k10],
    );
    rhs.eval(at(C11), s, k11);
    comb.combine(
        s,
        y,
        h,
        [
            A12_1, A12_4, A12_5, A12_6, A12_7, A12_8, A12_9, A12_10, A12_11,
        ],
        [k1, k4, k5, k6, k7, k8, k9, k10, k11],
    );
    rhs.eval(t + h, s, k12);
}

/// Evaluates the dense-output stages 14–16 of a step `h` (s) from `(t, y)`, its stages 1–12
/// and `k[12]` = f at its end in place, into `k[13..16]`, with `stage` as scratch.
#[inline(always)]
pub(crate) fn dense_stages<L: Lane, K: AsMut<[L]>>(
    rhs: &mut impl StageRhs<L>,
    comb: &impl Combine<L>,
    t: L,
    h: L,
    y: &[L],
    k: &mut [K; 16],
    stage: &mut [L],
) {
    let n = y.len();
    let [
        k1,
        _,
        _,
        _,
        _,
        k6,
        k7,
        k8,
        k9,
        k10,
        k11,
        k12,
        k13,
        k14,
        k15,
        k16,
    ] = k;
    let (k1, k6, k7, k8) = (k1.as_mut(), k6.as_mut(), k7.as_mut(), k8.as_mut());
    let (k9, k10, k11, k12) = (k9.as_mut(), k10.as_mut(), k11.as_mut(), k12.as_mut());
    let (k13, k14, k15, k16) = (k13.as_mut(), k14.as_mut(), k15.as_mut(), k16.as_mut());
    let s = &mut stage[..n];
    let at = |c: f64| t + L::splat(c) * h;
    comb.combine(
        s,
        y,
        h,
        [A14_1, A14_7, A14_8, A14_9, A14_10, A14_11, A14_12, A14_13],
        [k1, k7, k8, k9, k10, k11, k12, k13],
    );
    rhs.eval(at(C14), s, k14);
    comb.combine(
        s,
        y,
        h,
        [A15_1, A15_6, A15_7, A15_8, A15_11, A15_12, A15_13, A15_14],
        [k1, k6, k7, k8, k11, k12, k13, k14],
    );
    rhs.eval(at(C15), s, k15);
    comb.combine(
        s,
        y,
        h,
        [A16_1, A16_6, A16_7, A16_8, A16_9, A16_13, A16_14, A16_15],
        [k1, k6, k7, k8, k9, k13, k14, k15],
    );
    rhs.eval(at(C16), s, k16);
}

/// The eighth-order solution `y_new` of a step `h` from `y` and, per component, its
/// third- and fifth-order error estimates over the component's scale `atol + rtol·max(|y|,
/// |y_new|)` (Hairer, §II.10), from `stages` = k₁, k₆ … k₁₂. Element by element, so each
/// component's arithmetic is the same whichever vector width runs it.
#[inline(always)]
pub(crate) fn solution_and_errors<L: Lane>(
    (h, atol, rtol): (L, L, L),
    y: &[L],
    stages: [&[L]; 8],
    y_new: &mut [L],
    scaled3: &mut [L],
    scaled5: &mut [L],
) {
    let n = y.len();
    let [k1, k6, k7, k8, k9, k10, k11, k12] = stages.map(|k| &k[..n]);
    let (y_new, scaled3, scaled5) = (&mut y_new[..n], &mut scaled3[..n], &mut scaled5[..n]);
    let c = L::splat;
    for i in 0..n {
        let slope = c(B1) * k1[i]
            + c(B6) * k6[i]
            + c(B7) * k7[i]
            + c(B8) * k8[i]
            + c(B9) * k9[i]
            + c(B10) * k10[i]
            + c(B11) * k11[i]
            + c(B12) * k12[i];
        y_new[i] = y[i] + h * slope;
        let sk = atol + rtol * y[i].abs().max(y_new[i].abs());
        let e3 = slope - c(BHH1) * k1[i] - c(BHH2) * k9[i] - c(BHH3) * k12[i];
        let e5 = c(ER1) * k1[i]
            + c(ER6) * k6[i]
            + c(ER7) * k7[i]
            + c(ER8) * k8[i]
            + c(ER9) * k9[i]
            + c(ER10) * k10[i]
            + c(ER11) * k11[i]
            + c(ER12) * k12[i];
        scaled3[i] = e3 / sk;
        scaled5[i] = e5 / sk;
    }
}

/// The step's error from its components' scaled errors ([`solution_and_errors`]), summed in
/// order: h·err₅²/√(n (err₅² + 0.01·err₃²)) with RMS norms (Hairer, §II.10). A step is
/// accepted where it is at most 1; non-finite if the stages were.
#[inline(always)]
pub(crate) fn error_estimate<L: Lane>(h: L, scaled3: &[L], scaled5: &[L]) -> L {
    let c = L::splat;
    let (mut err5, mut err3) = (c(0.0), c(0.0));
    for (&e3, &e5) in scaled3.iter().zip(scaled5) {
        err3 += e3 * e3;
        err5 += e5 * e5;
    }
    let deno = err5 + c(0.01) * err3;
    let deno = L::select(deno.at_most(c(0.0)), c(1.0), deno);
    h.abs() * err5 / (c(scaled3.len() as f64) * deno).sqrt()
}

/// `err^(1/8 − 0.2 β)`, the error's factor in the step-size control (by square roots when
/// β = 0: a fraction of the cost of `powf`).
#[inline(always)]
pub(crate) fn error_factor<L: Lane>(err: L) -> L {
    if BETA == 0.0 {
        err.sqrt().sqrt().sqrt()
    } else {
        err.powf(EXPO)
    }
}

/// The seventh-order dense-output coefficients of an accepted step `h` (s) from `y` to
/// `y_new` with stages `k` (1–16, `k[12]` = f at its end), into `cont`.
#[inline(always)]
pub(crate) fn dense_coefficients<L: Lane, K: AsRef<[L]>, C: AsMut<[L]>>(
    h: L,
    y: &[L],
    y_new: &[L],
    k: &[K; 16],
    cont: &mut [C; 8],
) {
    let n = y.len();
    let y_new = &y_new[..n];
    let [c0, c1, c2, c3, c4, c5, c6, c7] = cont;
    let (k1, k13) = (&k[0].as_ref()[..n], &k[12].as_ref()[..n]);
    let (c0, c1, c2, c3) = (
        &mut c0.as_mut()[..n],
        &mut c1.as_mut()[..n],
        &mut c2.as_mut()[..n],
        &mut c3.as_mut()[..n],
    );
    for i in 0..n {
        let dy = y_new[i] - y[i];
        let bspl = h * k1[i] - dy;
        c0[i] = y[i];
        c1[i] = dy;
        c2[i] = bspl;
        c3[i] = dy - h * k13[i] - bspl;
    }
    // Stages 1, 6–16, in the order of the rows D4…D7. One pass for the four rows, so each
    // stage value is loaded once.
    let ks = dense_stage_values(k, n);
    let (c4, c5, c6, c7) = (
        &mut c4.as_mut()[..n],
        &mut c5.as_mut()[..n],
        &mut c6.as_mut()[..n],
        &mut c7.as_mut()[..n],
    );
    for i in 0..n {
        let [s4, s5, s6, s7] = dense_sums(&ks, i);
        c4[i] = h * s4;
        c5[i] = h * s5;
        c6[i] = h * s6;
        c7[i] = h * s7;
    }
}

/// The components of `components` of the dense output at `t` (s) strictly inside the
/// accepted step `h` (s) from `(t_prev, y)` to `(t_now, y_new)` with stages `k`, into `out`
/// (the others are left as they are): [`dense_coefficients`] and then [`dense_interior`], bit
/// for bit, one component at a time (for one time inside a step, the coefficients are not
/// worth forming and storing).
#[inline(always)]
pub(crate) fn dense_point<L: Lane, K: AsRef<[L]>>(
    h: L,
    y: &[L],
    y_new: &[L],
    k: &[K; 16],
    (t, t_prev, t_now): (L, L, L),
    components: &[bool],
    out: &mut [L],
) {
    let n = y.len();
    let (y_new, components, out) = (&y_new[..n], &components[..n], &mut out[..n]);
    let (k1, k13) = (&k[0].as_ref()[..n], &k[12].as_ref()[..n]);
    let ks = dense_stage_values(k, n);
    let c = L::splat;
    let s = (t - t_prev) / (t_now - t_prev);
    let s1 = c(1.0) - s;
    for i in 0..n {
        if !components[i] {
            continue;
        }
        let dy = y_new[i] - y[i];
        let bspl = h * k1[i] - dy;
        let c3 = dy - h * k13[i] - bspl;
        let [s4, s5, s6, s7] = dense_sums(&ks, i);
        let (c4, c5, c6, c7) = (h * s4, h * s5, h * s6, h * s7);
        let conpar = c4 + s * (c5 + s1 * (c6 + s * c7));
        out[i] = y[i] + s * (dy + s1 * (bspl + s * (c3 + s1 * conpar)));
    }
}

/// Component `i`'s sums Σⱼ D4ⱼ kⱼ … Σⱼ D7ⱼ kⱼ over the stages `ks`
/// ([`dense_stage_values`]), each from zero in the rows' order (one pass, so each stage value
/// is loaded once).
#[inline(always)]
fn dense_sums<L: Lane>(ks: &[&[L]; 12], i: usize) -> [L; 4] {
    let c = L::splat;
    let (mut s4, mut s5, mut s6, mut s7) = (c(0.0), c(0.0), c(0.0), c(0.0));
    for j in 0..12 {
        let v = ks[j][i];
        s4 += c(D4[j]) * v;
        s5 += c(D5[j]) * v;
        s6 += c(D6[j]) * v;
        s7 += c(D7[j]) * v;
    }
    [s4, s5, s6, s7]
}

/// Stages 1 and 6–16 of `k` (their first `n` components), in the order of the rows D4…D7.
/// Written out: an array's `map` and its closure may be left out of line, where a lane
/// type's operations lose the engine's instruction set.
#[inline(always)]
fn dense_stage_values<L, K: AsRef<[L]>>(k: &[K; 16], n: usize) -> [&[L]; 12] {
    let s = |j: usize| &k[j].as_ref()[..n];
    [
        s(0),
        s(5),
        s(6),
        s(7),
        s(8),
        s(9),
        s(10),
        s(11),
        s(12),
        s(13),
        s(14),
        s(15),
    ]
}

/// The dense output at `t` (s) strictly inside the accepted step from `t_prev` to `t_now`,
/// from its coefficients `cont` ([`dense_coefficients`]), into `out`.
#[inline(always)]
pub(crate) fn dense_interior<L: Lane, C: AsRef<[L]>>(
    t: L,
    t_prev: L,
    t_now: L,
    cont: &[C; 8],
    out: &mut [L],
) {
    let n = out.len();
    let s = (t - t_prev) / (t_now - t_prev);
    let s1 = L::splat(1.0) - s;
    let [c0, c1, c2, c3, c4, c5, c6, c7] = cont.each_ref().map(|c| &c.as_ref()[..n]);
    for i in 0..n {
        let conpar = c4[i] + s * (c5[i] + s1 * (c6[i] + s * c7[i]));
        out[i] = c0[i] + s * (c1[i] + s1 * (c2[i] + s * (c3[i] + s1 * conpar)));
    }
}

/// The dense output at `t` (s) of the accepted step from `t_prev` to `t_now` that ended at
/// `y_now`, from its coefficients `cont` ([`dense_coefficients`]; `cont[0]` is the state at
/// the step's start), into `out`. The step's ends are returned as stored.
#[inline(always)]
pub(crate) fn dense_value<C: AsRef<[f64]>>(
    t: f64,
    t_prev: f64,
    t_now: f64,
    y_now: &[f64],
    cont: &[C; 8],
    out: &mut [f64],
) {
    if t_now - t_prev == 0.0 || t == t_now {
        out.copy_from_slice(y_now);
    } else if t == t_prev {
        out.copy_from_slice(cont[0].as_ref());
    } else {
        dense_interior(t, t_prev, t_now, cont, out);
    }
}

/// When [`Dop853`] evaluates the dense-output stages of an accepted step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum DenseOutput {
    /// Never: interpolation at the step's ends only.
    Off,
    /// On every accepted step.
    Eager,
    /// When [`Stepper::prepare_interpolation`] asks for them.
    Lazy,
}

/// Adaptive Dormand–Prince 8(5,3) ("DOP853", the method of SciPy's `DOP853` and of Hairer's
/// `dop853.f`): eighth order, for smooth problems at tight tolerances, where it needs far
/// fewer right-hand-side evaluations than [`super::Dopri5`].
///
/// Integrates forward in time only (`t_end > t`).
///
/// Dense output is computed eagerly on every accepted step by default (3 extra evaluations,
/// 15 per step in all): [`Stepper::interpolate`] is given no system to evaluate. A caller
/// that never interpolates inside steps can switch it off with [`Dop853::with_dense_output`]
/// (12 per step); one that interpolates inside some steps only can defer it with
/// [`Dop853::with_lazy_dense_output`] and call [`Stepper::prepare_interpolation`] before it
/// interpolates inside a step (12 per step, 15 for the steps it reads).
#[derive(Debug, Clone)]
pub struct Dop853 {
    tol: Tolerances,
    h_max: f64,
    t: f64,
    t_prev: f64,
    h: f64,
    y: Vec<f64>,
    /// Candidate state at the end of the step being tried.
    y_new: Vec<f64>,
    /// Argument of the stage being evaluated.
    stage: Vec<f64>,
    /// Stages 1–16 (`k[0]` = f(t, y), kept across steps by FSAL).
    k: [Vec<f64>; 16],
    /// Dense-output coefficients of the last accepted step; `cont[0]` is the state at its
    /// start (kept even without dense output).
    cont: [Vec<f64>; 8],
    dense: DenseOutput,
    /// Whether `cont` holds the last accepted step's interpolant (the dense stages of a lazy
    /// stepper are evaluated on demand).
    dense_ready: bool,
    fac_old: f64,
    first_step: bool,
    stats: Stats,
    /// Run the stage arithmetic through its AVX2 build ([`crate::cpu`]; the same bits).
    avx2: bool,
    /// Each component's third- then fifth-order error over its scale, in the last attempt.
    scaled_errors: Vec<f64>,
}

impl Dop853 {
    /// Starts at `(t0, y0)` (t in s). `h_max` (s) caps the step (use `f64::INFINITY` for
    /// none); `h0` is the first step (s), or `None` to choose it automatically.
    pub fn new(t0: f64, y0: &[f64], tol: Tolerances, h_max: f64, h0: Option<f64>) -> Self {
        let n = y0.len();
        let z = || vec![0.0; n];
        Dop853 {
            tol,
            h_max,
            t: t0,
            t_prev: t0,
            h: h0.unwrap_or(0.0),
            y: y0.to_vec(),
            y_new: z(),
            stage: z(),
            k: std::array::from_fn(|_| z()),
            cont: std::array::from_fn(|_| y0.to_vec()),
            dense: DenseOutput::Eager,
            dense_ready: false,
            fac_old: 1e-4,
            first_step: true,
            stats: Stats::default(),
            avx2: crate::cpu::avx2_available(),
            scaled_errors: vec![0.0; 2 * n],
        }
    }

    /// Turns the seventh-order dense output on (the default) or off. Off saves the 3
    /// extra right-hand-side evaluations of each accepted step (a fifth of the cost), for
    /// callers that only need the states at the step ends; [`Stepper::interpolate`] then
    /// panics for a time strictly inside a step.
    pub fn with_dense_output(mut self, enabled: bool) -> Self {
        self.dense = if enabled {
            DenseOutput::Eager
        } else {
            DenseOutput::Off
        };
        self
    }

    /// Defers the dense-output stages of each accepted step until
    /// [`Stepper::prepare_interpolation`] asks for them: a step that is never interpolated
    /// inside costs 12 evaluations instead of 15. The interpolant is bit-for-bit the eager one
    /// (the same stages from the same values, which stay in place until the next step).
    /// Deferred stages cannot reject their step: `prepare_interpolation` reports whether they
    /// are finite, and the caller decides.
    pub fn with_lazy_dense_output(mut self) -> Self {
        self.dense = DenseOutput::Lazy;
        self
    }

    /// Step size the controller proposes next (s).
    pub fn proposed_step(&self) -> f64 {
        self.h
    }

    /// Starting step by Hairer's `HINIT` (order 8), with RMS norms; `k[0]` holds f(t, y).
    /// Costs one right-hand-side evaluation.
    fn initial_step<S: OdeSystem + ?Sized>(&mut self, sys: &S, span: f64) -> f64 {
        let [k1, k2, ..] = &mut self.k;
        let h = initial_step(
            &mut SystemRhs(sys),
            &ScalarCombine(self.avx2),
            self.t,
            &self.y,
            k1,
            k2,
            &mut self.stage,
            (self.tol.atol, self.tol.rtol),
            self.h_max,
            span,
        );
        self.stats.rhs_evaluations += 1;
        h
    }

    /// Evaluates stages 2–12 for step `h` from `(t, y)` with `k[0] = f(t, y)`, writes the
    /// eighth-order solution to `y_new`, and returns the scaled error estimate of the step
    /// (≤ 1 to accept; non-finite if the stages were).
    fn attempt<S: OdeSystem + ?Sized>(&mut self, sys: &S, h: f64) -> f64 {
        let n = self.y.len();
        let combine = ScalarCombine(self.avx2);
        stages(
            &mut SystemRhs(sys),
            &combine,
            self.t,
            h,
            &self.y,
            &mut self.k,
            &mut self.stage,
        );
        self.stats.rhs_evaluations += 11;

        // New state and both error estimates: the element-wise part first (in vector
        // instructions), then the two sums in order.
        let k = &self.k;
        let stages = [0, 5, 6, 7, 8, 9, 10, 11].map(|j| &k[j][..]);
        let (scaled3, scaled5) = self.scaled_errors.split_at_mut(n);
        let arguments = (h, self.tol.atol, self.tol.rtol);
        let y = &self.y[..];
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is true only where the processor has AVX2.
            unsafe {
                solution_and_errors_avx2(arguments, y, stages, &mut self.y_new, scaled3, scaled5)
            };
        } else {
            solution_and_errors(arguments, y, stages, &mut self.y_new, scaled3, scaled5);
        }
        #[cfg(not(target_arch = "x86_64"))]
        solution_and_errors(arguments, y, stages, &mut self.y_new, scaled3, scaled5);
        error_estimate(h, scaled3, scaled5)
    }

    /// For a step that passed the error test: evaluates stage 13 = f(t + h, y_new) (the next
    /// step's first stage) and, with dense output on, stages 14–16. Returns whether all
    /// were finite (if not, the step is rejected as having left the model's domain).
    fn end_stages<S: OdeSystem + ?Sized>(&mut self, sys: &S, h: f64, t_new: f64) -> bool {
        let all_finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        sys.rhs(t_new, &self.y_new, &mut self.k[12]);
        self.stats.rhs_evaluations += 1;
        if !all_finite(&self.k[12]) {
            return false;
        }
        if self.dense != DenseOutput::Eager {
            return true;
        }
        self.dense_stages(sys, h)
    }

    /// Evaluates the dense-output stages 14–16 of the step `h` from `y` (`k[0]` its first
    /// stage, `k[12]` f at its end). Returns whether they are finite.
    fn dense_stages<S: OdeSystem + ?Sized>(&mut self, sys: &S, h: f64) -> bool {
        dense_stages(
            &mut SystemRhs(sys),
            &ScalarCombine(self.avx2),
            self.t,
            h,
            &self.y,
            &mut self.k,
            &mut self.stage,
        );
        self.stats.rhs_evaluations += 3;
        self.k[13..16]
            .iter()
            .all(|v| v.iter().all(|x| x.is_finite()))
    }

    /// Fills `cont` for the accepted step `h` from `y` to `y_new` (before they are swapped).
    fn store_dense_output(&mut self, h: f64) {
        dense_coefficients(h, &self.y, &self.y_new, &self.k, &mut self.cont);
    }
}

/// [`solution_and_errors`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn solution_and_errors_avx2(
    arguments: (f64, f64, f64),
    y: &[f64],
    stages: [&[f64]; 8],
    y_new: &mut [f64],
    scaled3: &mut [f64],
    scaled5: &mut [f64],
) {
    solution_and_errors(arguments, y, stages, y_new, scaled3, scaled5)
}

impl Stepper for Dop853 {
    fn t(&self) -> f64 {
        self.t
    }

    fn y(&self) -> &[f64] {
        &self.y
    }

    fn t_prev(&self) -> f64 {
        self.t_prev
    }

    fn stats(&self) -> Stats {
        self.stats
    }

    fn step<S: OdeSystem + ?Sized>(&mut self, sys: &S, t_end: f64) -> Result<f64, StepError> {
        let span = t_end - self.t;
        if self.first_step {
            sys.rhs(self.t, &self.y, &mut self.k[0]);
            self.stats.rhs_evaluations += 1;
            if !self.k[0].iter().all(|v| v.is_finite()) {
                return Err(StepError::NonFiniteDerivative { t: self.t });
            }
            if self.h <= 0.0 {
                self.h = self.initial_step(sys, span);
            }
            self.first_step = false;
        }
        let mut rejected_in_a_row = 0;
        let mut saw_non_finite = false;
        loop {
            let super::StepEnd {
                t_new,
                h,
                last,
                underflow,
            } = super::adaptive_step_end(self.t, self.h.min(self.h_max), t_end);
            if underflow {
                return Err(if saw_non_finite {
                    StepError::NonFiniteDerivative { t: self.t }
                } else {
                    StepError::StepSizeUnderflow { t: self.t, h }
                });
            }
            let err = self.attempt(sys, h);
            // Stage 13 (and the dense stages) only for a step that passes the error test.
            let finite = err.is_finite() && (err > 1.0 || self.end_stages(sys, h, t_new));
            if !finite {
                saw_non_finite = true;
                self.stats.rejected_steps += 1;
                self.h = non_finite_step_size(h);
                rejected_in_a_row += 1;
                if rejected_in_a_row > MAX_REJECTIONS_IN_A_ROW {
                    return Err(StepError::NonFiniteDerivative { t: self.t });
                }
                continue;
            }
            let fac11 = error_factor(err);
            if err <= 1.0 {
                // Accepted: (PI) controller for the next step.
                let (h_new, fac_old) =
                    CONTROL.accepted_step_size(err, fac11, h, self.fac_old, rejected_in_a_row > 0);
                self.fac_old = fac_old;
                if self.dense == DenseOutput::Eager {
                    self.store_dense_output(h);
                } else {
                    self.cont[0].copy_from_slice(&self.y);
                }
                self.dense_ready = self.dense == DenseOutput::Eager;
                std::mem::swap(&mut self.y, &mut self.y_new);
                // FSAL: stage 13 is f at the new point.
                self.k.swap(0, 12);
                self.t_prev = self.t;
                self.t = t_new;
                self.stats.steps += 1;
                // Keep the proposal for the next call; a shortened last step does not shrink it.
                self.h = if last { self.h.max(h_new) } else { h_new };
                return Ok(self.t);
            }
            self.stats.rejected_steps += 1;
            rejected_in_a_row += 1;
            if rejected_in_a_row > MAX_REJECTIONS_IN_A_ROW {
                return Err(StepError::StepSizeUnderflow { t: self.t, h });
            }
            self.h = CONTROL.rejected_step_size(fac11, h);
        }
    }

    fn restart<S: OdeSystem + ?Sized>(&mut self, sys: &S, y: &[f64]) {
        // The dense output of the step before the breakpoint stays readable.
        self.prepare_interpolation(sys);
        self.y.copy_from_slice(y);
        // The first-same-as-last stage is recomputed at the next step (the step size is kept).
        self.first_step = true;
    }

    /// With lazy dense output, evaluates the last step's dense stages if it has not yet; the
    /// step's values are still in place (the previous state in `y_new`, its first stage in
    /// `k[12]` and its last in `k[0]`, swapped there by the step's end).
    fn prepare_interpolation<S: OdeSystem + ?Sized>(&mut self, sys: &S) -> bool {
        if self.dense_ready || self.dense != DenseOutput::Lazy || self.t == self.t_prev {
            return true;
        }
        let (t, h) = (self.t, self.t - self.t_prev);
        // Back to the step's start as `dense_stages` and `store_dense_output` read it.
        std::mem::swap(&mut self.y, &mut self.y_new);
        self.k.swap(0, 12);
        self.t = self.t_prev;
        let finite = self.dense_stages(sys, h);
        self.store_dense_output(h);
        std::mem::swap(&mut self.y, &mut self.y_new);
        self.k.swap(0, 12);
        self.t = t;
        self.dense_ready = true;
        finite
    }

    /// Seventh-order interpolant of the last accepted step. Panics for a time strictly inside
    /// the step if dense output was switched off ([`Dop853::with_dense_output`]), or deferred
    /// ([`Dop853::with_lazy_dense_output`]) and not prepared.
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let inside = self.t != self.t_prev && t != self.t && t != self.t_prev;
        assert!(
            !inside || self.dense_ready,
            "Dop853::interpolate inside a step needs dense output, which was switched off \
             (or, lazy, not prepared by `prepare_interpolation`)"
        );
        dense_value(t, self.t_prev, self.t, &self.y, &self.cont, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::Dopri5;
    use crate::integrate::test_systems::{
        Clock, Counted, EulerBody, Exponential, Kepler, Oscillator, kepler_exact,
    };
    use std::f64::consts::PI;

    /// Tolerances so loose that every step is accepted: with `h0 = h_max = h` the step is fixed.
    const FIXED: Tolerances = Tolerances {
        rtol: 1e6,
        atol: 1e6,
    };

    fn tol(t: f64) -> Tolerances {
        Tolerances { rtol: t, atol: t }
    }

    fn run<S: OdeSystem>(s: &mut Dop853, sys: &S, t_end: f64) {
        while s.t() < t_end {
            s.step(sys, t_end).unwrap();
        }
        assert_eq!(s.t(), t_end);
    }

    fn dist(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    fn sci(pts: &[(f64, f64)]) -> String {
        let v: Vec<String> = pts
            .iter()
            .map(|(h, e)| format!("({h:.3}, {e:.2e})"))
            .collect();
        v.join(" ")
    }

    fn sci1(v: &[f64]) -> String {
        let v: Vec<String> = v.iter().map(|e| format!("{e:.2e}")).collect();
        v.join(" ")
    }

    /// Least-squares slope of log(err) against log(h).
    fn slope(points: &[(f64, f64)]) -> f64 {
        let m = points.len() as f64;
        let (xs, ys): (Vec<f64>, Vec<f64>) = points.iter().map(|&(h, e)| (h.ln(), e.ln())).unzip();
        let (mx, my) = (xs.iter().sum::<f64>() / m, ys.iter().sum::<f64>() / m);
        let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
        sxy / sxx
    }

    #[test]
    fn coefficients_satisfy_the_simplest_order_conditions() {
        // Catches a mistyped coefficient: every row sums to its node, the weights integrate
        // polynomials of degree < 8 exactly, the error weights annihilate constants.
        let rows: [(f64, &[f64]); 15] = [
            (C2, &[A2_1]),
            (C3, &[A3_1, A3_2]),
            (C4, &[A4_1, A4_3]),
            (C5, &[A5_1, A5_3, A5_4]),
            (C6, &[A6_1, A6_4, A6_5]),
            (C7, &[A7_1, A7_4, A7_5, A7_6]),
            (C8, &[A8_1, A8_4, A8_5, A8_6, A8_7]),
            (C9, &[A9_1, A9_4, A9_5, A9_6, A9_7, A9_8]),
            (C10, &[A10_1, A10_4, A10_5, A10_6, A10_7, A10_8, A10_9]),
            (
                C11,
                &[A11_1, A11_4, A11_5, A11_6, A11_7, A11_8, A11_9, A11_10],
            ),
            (
                1.0,
                &[
                    A12_1, A12_4, A12_5, A12_6, A12_7, A12_8, A12_9, A12_10, A12_11,
                ],
            ),
            (1.0, &[B1, B6, B7, B8, B9, B10, B11, B12]),
            (
                C14,
                &[A14_1, A14_7, A14_8, A14_9, A14_10, A14_11, A14_12, A14_13],
            ),
            (
                C15,
                &[A15_1, A15_6, A15_7, A15_8, A15_11, A15_12, A15_13, A15_14],
            ),
            (
                C16,
                &[A16_1, A16_6, A16_7, A16_8, A16_9, A16_13, A16_14, A16_15],
            ),
        ];
        for (i, (c, row)) in rows.iter().enumerate() {
            let sum: f64 = row.iter().sum();
            assert!((sum - c).abs() < 1e-14, "row {}: {sum} vs {c}", i + 2);
        }
        let b = [B1, B6, B7, B8, B9, B10, B11, B12];
        let c = [0.0, C6, C7, C8, C9, C10, C11, 1.0];
        for q in 1..=8 {
            let quad: f64 = b.iter().zip(&c).map(|(b, c)| b * c.powi(q - 1)).sum();
            assert!((quad - 1.0 / q as f64).abs() < 1e-13, "q = {q}: {quad}");
        }
        let er = [ER1, ER6, ER7, ER8, ER9, ER10, ER11, ER12];
        assert!(er.iter().sum::<f64>().abs() < 1e-14);
        assert!((BHH1 + BHH2 + BHH3 - 1.0).abs() < 1e-14);
    }

    /// Kepler orbit (e = 0.5) over one period with `steps` fixed steps, from mean anomaly
    /// 1 rad: error at the end.
    ///
    /// Not from periapsis: the error contributions of the two halves of a periapsis passage
    /// split across the ends then nearly cancel, and the slope approaches 8 only below the
    /// roundoff floor (7.1 measured over the same range of steps).
    fn kepler_fixed_step_error(steps: u32) -> f64 {
        let (e, t0, period) = (0.5, 1.0, 2.0 * PI);
        let h = period / steps as f64;
        let mut s = Dop853::new(t0, &kepler_exact(e, t0), FIXED, h, Some(h));
        run(&mut s, &Kepler, t0 + period);
        assert_eq!(s.stats().steps, steps as u64);
        assert_eq!(s.stats().rejected_steps, 0);
        dist(s.y(), &kepler_exact(e, t0 + period))
    }

    #[test]
    fn convergence_order_is_eight_on_the_kepler_orbit() {
        let pts: Vec<(f64, f64)> = [40, 50, 60, 80, 100, 130, 160]
            .iter()
            .map(|&n| (2.0 * PI / n as f64, kepler_fixed_step_error(n)))
            .collect();
        let p = slope(&pts);
        println!("Kepler fixed-step (h, error): {}; slope {p:.3}", sci(&pts));
        assert!(pts.iter().all(|&(_, e)| e > 1e-12), "errors near roundoff");
        assert!((p - 8.0).abs() < 0.3, "measured order {p}");
    }

    #[test]
    fn convergence_order_is_eight_on_euler_rigid_body() {
        // A tumble about the intermediate axis, against a Dopri5 reference at rtol 1e-13
        // (which agrees with one at 1e-12 to ~1e-11, so errors are kept above 1e-11).
        let (w0, t_end) = ([0.3, 1.0, 0.4], 20.0);
        let mut r = Dopri5::new(0.0, &w0, tol(1e-13), f64::INFINITY, None);
        while r.t() < t_end {
            r.step(&EulerBody([1.0, 2.0, 3.0]), t_end).unwrap();
        }
        let reference = r.y().to_vec();
        let pts: Vec<(f64, f64)> = [30, 40, 50, 64, 80]
            .iter()
            .map(|&n| {
                let h = t_end / n as f64;
                let mut s = Dop853::new(0.0, &w0, FIXED, h, Some(h));
                run(&mut s, &EulerBody([1.0, 2.0, 3.0]), t_end);
                assert_eq!(s.stats().steps, n);
                (h, dist(s.y(), &reference))
            })
            .collect();
        let p = slope(&pts);
        println!(
            "rigid body fixed-step (h, error): {}; slope {p:.3}",
            sci(&pts)
        );
        assert!(
            pts.iter().all(|&(_, e)| e > 1e-11),
            "errors near the reference's"
        );
        assert!((p - 8.0).abs() < 0.3, "measured order {p}");
    }

    #[test]
    fn one_step_errors_are_of_order_nine_at_the_end_and_eight_inside() {
        // One step of size h from the exact state just before periapsis (where the orbit is
        // fastest): the local error of the step is O(h⁹), the interpolant's worst error
        // inside the step O(h⁸).
        let (e, t0) = (0.5, -0.1);
        let (mut inside, mut end) = (vec![], vec![]);
        for h in [0.2, 0.15, 0.1, 0.07, 0.05, 0.035] {
            let mut s = Dop853::new(t0, &kepler_exact(e, t0), FIXED, h, Some(h));
            s.step(&Kepler, t0 + h).unwrap();
            let mut out = [0.0; 4];
            let mut worst: f64 = 0.0;
            for j in 1..20 {
                let t = t0 + h * j as f64 / 20.0;
                s.interpolate(t, &mut out);
                worst = worst.max(dist(&out, &kepler_exact(e, t)));
            }
            inside.push((h, worst));
            end.push((h, dist(s.y(), &kepler_exact(e, t0 + h))));
        }
        end.pop(); // 4e-14: too close to roundoff
        let (pi, pe) = (slope(&inside), slope(&end));
        println!(
            "dense output (h, worst error): {}; slope {pi:.3}",
            sci(&inside)
        );
        println!("step end (h, local error): {}; slope {pe:.3}", sci(&end));
        assert!((pi - 8.0).abs() < 0.3, "measured dense-output order {pi}");
        assert!((pe - 9.0).abs() < 0.4, "measured local-error order {pe}");
    }

    /// `y' = −2t·y²`, `y(0) = 1`: `y = 1/(1 + t²)`. Non-autonomous, so the nodes `c` count.
    struct Lorentzian;
    impl OdeSystem for Lorentzian {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -2.0 * t * y[0] * y[0];
        }
    }

    #[test]
    fn convergence_order_is_eight_on_a_non_autonomous_problem() {
        // Worst error over [0, 3] at the step ends and inside the steps (dense output):
        // the global error of the steps and of the interpolant are both O(h⁸).
        let t_end = 3.0;
        let pts: Vec<(f64, f64)> = [15, 20, 25, 32, 40]
            .iter()
            .map(|&n| {
                let h = t_end / n as f64;
                let mut s = Dop853::new(0.0, &[1.0], FIXED, h, Some(h));
                let (mut worst, mut out): (f64, _) = (0.0, [0.0]);
                while s.t() < t_end {
                    s.step(&Lorentzian, t_end).unwrap();
                    for j in 1..=10 {
                        let t = s.t_prev() + (s.t() - s.t_prev()) * j as f64 / 10.0;
                        s.interpolate(t, &mut out);
                        worst = worst.max((out[0] - 1.0 / (1.0 + t * t)).abs());
                    }
                }
                assert_eq!(s.stats().steps, n);
                (h, worst)
            })
            .collect();
        let p = slope(&pts);
        println!(
            "y' = -2ty² fixed-step (h, worst error): {}; slope {p:.3}",
            sci(&pts)
        );
        assert!(pts.iter().all(|&(_, e)| e > 1e-13), "errors near roundoff");
        assert!((p - 8.0).abs() < 0.3, "measured order {p}");
    }

    #[test]
    fn dense_output_is_as_accurate_as_the_steps() {
        let mut s = Dop853::new(0.0, &[1.0, 0.0], tol(1e-10), f64::INFINITY, None);
        let (mut worst_inside, mut worst_ends): (f64, f64) = (0.0, 0.0);
        let mut out = [0.0; 2];
        let err = |t: f64, y: &[f64]| (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs());
        while s.t() < 20.0 {
            s.step(&Oscillator, 20.0).unwrap();
            worst_ends = worst_ends.max(err(s.t(), s.y()));
            let (a, b) = (s.t_prev(), s.t());
            for j in 1..50 {
                let t = a + (b - a) * j as f64 / 50.0;
                s.interpolate(t, &mut out);
                worst_inside = worst_inside.max(err(t, &out));
            }
            // The interpolant meets the step's ends.
            s.interpolate(b - 1e-9 * (b - a), &mut out);
            assert!(dist(&out, s.y()) < 1e-8 * (b - a));
        }
        println!(
            "oscillator rtol 1e-10: worst inside {worst_inside:.2e}, at ends {worst_ends:.2e}"
        );
        assert!(worst_inside < 1e-9, "dense output error {worst_inside}");
        assert!(worst_inside < 2.0 * worst_ends + 1e-12);
    }

    #[test]
    fn global_error_follows_the_tolerance() {
        let t_end = 20.0 * PI; // ten periods
        let errs: Vec<f64> = [1e-6, 1e-8, 1e-10, 1e-12]
            .iter()
            .map(|&r| {
                let mut s = Dop853::new(0.0, &[1.0, 0.0], tol(r), f64::INFINITY, None);
                run(&mut s, &Oscillator, t_end);
                dist(s.y(), &[t_end.cos(), -t_end.sin()])
            })
            .collect();
        println!(
            "oscillator, 10 periods, rtol 1e-6..1e-12: errors {}",
            sci1(&errs)
        );
        for w in errs.windows(2) {
            // Two decades of tolerance buy about two decades of accuracy.
            let gain = w[0] / w[1];
            assert!((30.0..300.0).contains(&gain), "errors {errs:?}");
        }
        assert!(errs[3] < 1e-9, "errors {errs:?}");
    }

    #[test]
    fn meets_tolerance_on_exponential() {
        let mut s = Dop853::new(0.0, &[1.0], tol(1e-10), f64::INFINITY, None);
        run(&mut s, &Exponential(-0.7), 5.0);
        let exact = (-0.7f64 * 5.0).exp();
        assert!((s.y()[0] - exact).abs() < 1e-9 * exact);
    }

    /// y' = 1 from a large t0 with many steps: integrated time equals the label at the end,
    /// and every step lands where it says.
    #[test]
    fn integrated_time_matches_the_time_label() {
        let (t0, t_end) = (1.0e6, 1.0e6 + 1.0e4);
        let mut s = Dop853::new(t0, &[0.0], tol(1e-10), 0.1, Some(0.1));
        let mut steps = 0;
        while s.t() < t_end {
            let t = s.step(&Clock, t_end).unwrap();
            assert_eq!(t, s.t());
            steps += 1;
        }
        assert_eq!(s.t(), t_end);
        assert!((s.y()[0] - 1.0e4).abs() < 1e-9, "y = {}", s.y()[0]);
        assert_eq!(s.stats().steps, steps);
    }

    #[test]
    fn steps_land_exactly_on_intermediate_ends() {
        let mut s = Dop853::new(0.0, &[1.0, 0.0], tol(1e-8), f64::INFINITY, None);
        for j in 1..=30 {
            let t_end = 0.37 * j as f64;
            while s.t() < t_end {
                let t = s.step(&Oscillator, t_end).unwrap();
                assert!(t <= t_end);
            }
            assert_eq!(s.t(), t_end);
        }
    }

    #[test]
    fn counts_every_right_hand_side_evaluation() {
        // Independently counted calls equal the stats and the documented formula:
        // 1 (f(t0)) [+ 1 (starting step)] + 15·accepted + 11·rejected.
        for (h0, dense, per_step) in [(None, true, 15), (Some(1.0), true, 15), (None, false, 12)] {
            let sys = Counted::new(&Kepler);
            let mut s = Dop853::new(0.0, &kepler_exact(0.5, 0.0), tol(1e-10), f64::INFINITY, h0)
                .with_dense_output(dense);
            run(&mut s, &sys, 10.0);
            let st = s.stats();
            let start = if h0.is_some() { 1 } else { 2 };
            assert_eq!(st.rhs_evaluations, sys.calls.get());
            assert_eq!(
                st.rhs_evaluations,
                start + per_step * st.steps + 11 * st.rejected_steps
            );
            if h0.is_some() {
                // A first step of 1 at rtol 1e-10 is rejected at least once.
                assert!(st.rejected_steps > 0);
            }
        }
    }

    #[test]
    fn the_avx2_build_of_the_stage_arithmetic_gives_the_baseline_bits() {
        // The stepper this processor runs (AVX2 where it has it) and one held to the baseline
        // build: the same steps, states and interpolant, bit for bit, over a Kepler orbit
        // (4 states: one AVX2 vector, or two baseline ones, per stage).
        let y0 = kepler_exact(0.5, 0.0);
        let mut native = Dop853::new(0.0, &y0, tol(1e-11), f64::INFINITY, None);
        let mut baseline = Dop853::new(0.0, &y0, tol(1e-11), f64::INFINITY, None);
        baseline.avx2 = false;
        let (mut a, mut b) = ([0.0; 4], [0.0; 4]);
        while native.t() < 20.0 {
            native.step(&Kepler, 20.0).unwrap();
            baseline.step(&Kepler, 20.0).unwrap();
            assert_eq!(native.t().to_bits(), baseline.t().to_bits());
            assert_eq!(native.y(), baseline.y());
            let t = 0.5 * (native.t_prev() + native.t());
            native.interpolate(t, &mut a);
            baseline.interpolate(t, &mut b);
            assert_eq!(a, b);
        }
        assert_eq!(native.stats(), baseline.stats());
    }

    #[test]
    fn lazy_dense_output_is_the_eager_one_where_it_is_asked_for() {
        // The same steps, and the same interpolant bit for bit on every third step (the only
        // ones prepared), for 3 evaluations fewer on each of the other steps.
        let (eager_sys, lazy_sys) = (Counted::new(&Kepler), Counted::new(&Kepler));
        let y0 = kepler_exact(0.5, 0.0);
        let mut eager = Dop853::new(0.0, &y0, tol(1e-10), f64::INFINITY, None);
        let mut lazy =
            Dop853::new(0.0, &y0, tol(1e-10), f64::INFINITY, None).with_lazy_dense_output();
        let (mut prepared, mut a, mut b) = (0, [0.0; 4], [0.0; 4]);
        while eager.t() < 10.0 {
            eager.step(&eager_sys, 10.0).unwrap();
            lazy.step(&lazy_sys, 10.0).unwrap();
            assert_eq!(eager.t(), lazy.t());
            assert_eq!(eager.y(), lazy.y());
            if eager.stats().steps.is_multiple_of(3) {
                assert!(lazy.prepare_interpolation(&lazy_sys));
                // A second call does nothing.
                assert!(lazy.prepare_interpolation(&lazy_sys));
                prepared += 1;
                for s in [0.1, 0.5, 0.9] {
                    let t = eager.t_prev() + s * (eager.t() - eager.t_prev());
                    eager.interpolate(t, &mut a);
                    lazy.interpolate(t, &mut b);
                    assert_eq!(a, b, "t = {t}");
                }
            }
        }
        let (e, l) = (eager.stats(), lazy.stats());
        assert!(prepared > 10);
        assert_eq!(e.steps, l.steps);
        assert_eq!(lazy_sys.calls.get(), l.rhs_evaluations);
        assert_eq!(
            e.rhs_evaluations - l.rhs_evaluations,
            3 * (e.steps - prepared)
        );
    }

    #[test]
    #[should_panic(expected = "prepare_interpolation")]
    fn interpolating_an_unprepared_lazy_step_panics() {
        let mut s =
            Dop853::new(0.0, &[1.0, 0.0], tol(1e-8), f64::INFINITY, None).with_lazy_dense_output();
        s.step(&Oscillator, 1.0).unwrap();
        let mut out = [0.0; 2];
        s.interpolate(0.5 * s.t(), &mut out);
    }

    #[test]
    fn fewer_evaluations_than_dopri5_at_tight_tolerance() {
        let t_end = 200.0 * PI; // 100 periods
        let exact = [t_end.cos(), -t_end.sin()];
        let mut a = Dopri5::new(0.0, &[1.0, 0.0], tol(1e-10), f64::INFINITY, None);
        while a.t() < t_end {
            a.step(&Oscillator, t_end).unwrap();
        }
        let mut b = Dop853::new(0.0, &[1.0, 0.0], tol(1e-10), f64::INFINITY, None);
        run(&mut b, &Oscillator, t_end);
        let (na, nb) = (a.stats().rhs_evaluations, b.stats().rhs_evaluations);
        println!(
            "oscillator, 100 periods, rtol 1e-10: dopri5 {na} evaluations (error {:.1e}), \
             dop853 {nb} (error {:.1e}), {} without dense output",
            dist(a.y(), &exact),
            dist(b.y(), &exact),
            nb - 3 * b.stats().steps
        );
        assert!(nb < na, "dop853 {nb} vs dopri5 {na}");
    }

    /// y' = y² from y(0) = 1 blows up at t = 1.
    struct BlowUp;
    impl OdeSystem for BlowUp {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = y[0] * y[0];
        }
    }

    /// y' = 1, but the model is undefined (NaN) after `self.0`.
    struct UndefinedAfter(f64);
    impl OdeSystem for UndefinedAfter {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, t: f64, _y: &[f64], d: &mut [f64]) {
            d[0] = if t > self.0 { f64::NAN } else { 1.0 };
        }
    }

    /// y' = 1, but the `n`-th call returns infinity.
    struct FailsOnCall(u64, std::cell::Cell<u64>);
    impl OdeSystem for FailsOnCall {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, _t: f64, _y: &[f64], d: &mut [f64]) {
            self.1.set(self.1.get() + 1);
            d[0] = if self.1.get() == self.0 {
                f64::INFINITY
            } else {
                1.0
            };
        }
    }

    #[test]
    fn singularity_is_a_step_size_underflow() {
        let mut s = Dop853::new(0.0, &[1.0], tol(1e-8), f64::INFINITY, None);
        let err = loop {
            match s.step(&BlowUp, 2.0) {
                // The numerical solution blows up within ~1e-11 of t = 1.
                Ok(_) => assert!(s.t() < 1.0 + 1e-6),
                Err(e) => break e,
            }
        };
        match err {
            StepError::StepSizeUnderflow { t, h } => {
                assert!((t - 1.0).abs() < 1e-6, "t = {t}");
                assert!(h.abs() < 1e-12, "h = {h}");
            }
            e => panic!("expected StepSizeUnderflow, got {e:?}"),
        }
    }

    #[test]
    fn non_finite_derivative_is_reported() {
        // Undefined from the start.
        let mut s = Dop853::new(1.0, &[0.0], tol(1e-8), f64::INFINITY, None);
        assert_eq!(
            s.step(&UndefinedAfter(0.5), 2.0),
            Err(StepError::NonFiniteDerivative { t: 1.0 })
        );
        // Undefined after t = 0.5: the steps close in on it, then give up there.
        let mut s = Dop853::new(0.0, &[0.0], tol(1e-8), f64::INFINITY, None);
        let err = loop {
            match s.step(&UndefinedAfter(0.5), 2.0) {
                Ok(t) => assert!(t <= 0.5),
                Err(e) => break e,
            }
        };
        match err {
            StepError::NonFiniteDerivative { t } => assert!((t - 0.5).abs() < 1e-9, "t = {t}"),
            e => panic!("expected NonFiniteDerivative, got {e:?}"),
        }
    }

    #[test]
    fn non_finite_stage_at_the_new_point_rejects_the_step() {
        // Calls: 1 = f(t0), 2–12 = stages of the first try, 13 = f at its end: infinite. The
        // step is retried at a tenth of the size and accepted.
        let sys = FailsOnCall(13, std::cell::Cell::new(0));
        let mut s = Dop853::new(0.0, &[0.0], tol(1e-8), f64::INFINITY, Some(0.5));
        assert_eq!(s.step(&sys, 10.0), Ok(0.05));
        let st = s.stats();
        assert_eq!((st.steps, st.rejected_steps), (1, 1));
        assert_eq!(st.rhs_evaluations, 1 + 12 + 15);
        assert_eq!(st.rhs_evaluations, sys.1.get());
        assert!((s.y()[0] - 0.05).abs() < 1e-15);
    }

    #[test]
    #[should_panic(expected = "dense output")]
    fn interpolating_without_dense_output_panics() {
        let mut s =
            Dop853::new(0.0, &[1.0, 0.0], tol(1e-8), f64::INFINITY, None).with_dense_output(false);
        s.step(&Oscillator, 10.0).unwrap();
        let mut out = [0.0; 2];
        // The ends are still available.
        s.interpolate(s.t_prev(), &mut out);
        assert_eq!(out, [1.0, 0.0]);
        s.interpolate(s.t(), &mut out);
        assert_eq!(out, s.y());
        s.interpolate(0.5 * s.t(), &mut out);
    }

    /// A rigid body's Euler equations over any lane type: at `f64` the scalar system.
    struct LaneBody([f64; 3]);

    impl LaneBody {
        fn eval<L: Lane>(&self, w: &[L], d: &mut [L]) {
            let i = self.0.map(L::splat);
            let l = [i[0] * w[0], i[1] * w[1], i[2] * w[2]];
            d[0] = (l[1] * w[2] - l[2] * w[1]) / i[0];
            d[1] = (l[2] * w[0] - l[0] * w[2]) / i[1];
            d[2] = (l[0] * w[1] - l[1] * w[0]) / i[2];
        }
    }

    impl OdeSystem for LaneBody {
        fn dim(&self) -> usize {
            3
        }
        fn rhs(&self, _t: f64, w: &[f64], d: &mut [f64]) {
            self.eval(w, d);
        }
    }

    impl StageRhs<crate::lanes::F64x4> for &LaneBody {
        fn eval(
            &mut self,
            _t: crate::lanes::F64x4,
            w: &[crate::lanes::F64x4],
            d: &mut [crate::lanes::F64x4],
        ) {
            LaneBody::eval(self, w, d);
        }
    }

    /// The lanes' way of forming stage arguments: `combine` itself.
    #[test]
    fn a_first_step_in_four_lanes_is_each_runs_scalar_step_bit_for_bit() {
        use crate::lanes::{F64x4, LaneMask};
        let body = LaneBody([1.0, 2.0, 3.0]);
        let starts = [
            [1.0, 0.2, -0.5],
            [0.3, -1.1, 0.05],
            [-0.7, 0.4, 0.9],
            [2.0, 0.01, 0.3],
        ];
        let tol = Tolerances {
            rtol: 1e-9,
            atol: 1e-12,
        };
        let t_end = 10.0;
        // The scalar runs' first steps, and their interpolants at a third of the step.
        let scalar: Vec<_> = starts
            .iter()
            .map(|y0| {
                let mut d = Dop853::new(0.0, y0, tol, f64::INFINITY, None);
                d.step(&body, t_end).unwrap();
                let t_third = d.t_prev() + (d.t() - d.t_prev()) / 3.0;
                let mut third = [0.0; 3];
                d.interpolate(t_third, &mut third);
                (d.clone(), t_third, third)
            })
            .collect();
        for (d, _, _) in &scalar {
            // A first attempt the error test passes: the step compared is that attempt.
            assert_eq!(d.stats().rejected_steps, 0);
        }
        // The same in four lanes.
        let lane = |f: &dyn Fn(usize) -> f64| {
            F64x4::splat(0.0)
                .with_lane(0, f(0))
                .with_lane(1, f(1))
                .with_lane(2, f(2))
                .with_lane(3, f(3))
        };
        let y: [F64x4; 3] = std::array::from_fn(|j| lane(&|i| starts[i][j]));
        let zero = F64x4::splat(0.0);
        let mut k = [[zero; 3]; 16];
        let mut stage = [zero; 3];
        let mut y_new = [zero; 3];
        let (mut scaled3, mut scaled5) = ([zero; 3], [zero; 3]);
        let (atol, rtol) = (F64x4::splat(tol.atol), F64x4::splat(tol.rtol));
        let mut rhs = &body;
        body.eval(&y, &mut k[0]);
        let [k1, k2, ..] = &mut k;
        let h = initial_step(
            &mut rhs,
            &PlainCombine,
            zero,
            &y,
            k1,
            k2,
            &mut stage,
            (atol, rtol),
            F64x4::splat(f64::INFINITY),
            F64x4::splat(t_end),
        );
        stages(&mut rhs, &PlainCombine, zero, h, &y, &mut k, &mut stage);
        let stage_values = [0, 5, 6, 7, 8, 9, 10, 11].map(|j| &k[j][..]);
        solution_and_errors(
            (h, atol, rtol),
            &y,
            stage_values,
            &mut y_new,
            &mut scaled3,
            &mut scaled5,
        );
        let err = error_estimate(h, &scaled3, &scaled5);
        body.eval(&y_new, &mut k[12]);
        dense_stages(&mut rhs, &PlainCombine, zero, h, &y, &mut k, &mut stage);
        let mut cont = [[zero; 3]; 8];
        dense_coefficients(h, &y, &y_new, &k, &mut cont);
        let t_third = lane(&|i| scalar[i].1);
        let mut third = [zero; 3];
        dense_interior(t_third, zero, h, &cont, &mut third);
        let (h_next, _) = CONTROL.accepted_step_size(
            err,
            error_factor(err),
            h,
            F64x4::splat(1e-4),
            <F64x4 as Lane>::Mask::splat(false),
        );
        for (i, (d, _, scalar_third)) in scalar.iter().enumerate() {
            assert!(err.lane(i) <= 1.0);
            assert_eq!(h.lane(i).to_bits(), d.t().to_bits(), "lane {i}: step");
            for j in 0..3 {
                assert_eq!(
                    y_new[j].lane(i).to_bits(),
                    d.y()[j].to_bits(),
                    "lane {i}: y[{j}]"
                );
                assert_eq!(
                    third[j].lane(i).to_bits(),
                    scalar_third[j].to_bits(),
                    "lane {i}: interpolant[{j}]"
                );
            }
            assert_eq!(
                h_next.lane(i).to_bits(),
                d.proposed_step().to_bits(),
                "lane {i}: next step"
            );
        }
    }
}
