//! The IGRF-14 main field to degree 13, with its secular variation, over its whole validity
//! (1900.0–2030.0). See `docs/environment.md`, section "The IGRF-14 main field to degree 13".
//!
//! The potential (Alken et al. 2021, *Earth Planets Space* 73:49, eq. 1; the definition is
//! unchanged in IGRF-14) at the geocentric point (r, θ, φ) — radius, colatitude, east
//! longitude — is
//!
//! ```text
//! V(r, θ, φ, t) = a Σ_{n=1}^{13} (a/r)^{n+1} Σ_{m=0}^{n} [g_n^m(t) cos mφ + h_n^m(t) sin mφ] P_n^m(cos θ)
//! ```
//!
//! with `a = 6371.2 km` ([`REFERENCE_RADIUS`]) and `P_n^m` the Schmidt semi-normalised
//! associated Legendre functions (no Condon–Shortley phase): `P_n^0 = P_n` and
//! `P_n^m = √(2 (n−m)!/(n+m)!) sin^m θ d^m P_n/d(cos θ)^m` for m ≥ 1. The field is
//! `B = −∇V`:
//!
//! ```text
//! B_r = Σ (n+1) (a/r)^{n+2} Σ (g cos mφ + h sin mφ) P_n^m
//! B_θ = −Σ (a/r)^{n+2} Σ (g cos mφ + h sin mφ) dP_n^m/dθ
//! B_φ = Σ (a/r)^{n+2} Σ m (g sin mφ − h cos mφ) P_n^m / sin θ
//! ```
//!
//! given here as north `X = −B_θ`, east `Y = B_φ` and down `Z = −B_r` (geocentric, i.e.
//! on the sphere, not the ellipsoid), or in ECEF Cartesian components.
//!
//! **Poles.** `P_n^m` carries a factor `sin^m θ`, so the recursion is run on
//! `Q_n^m = P_n^m / sin θ` for m ≥ 1 (the same three-term recursion in n, started from
//! `Q_1^1 = 1`, `Q_m^m = √((2m−1)/(2m)) sin θ Q_{m−1}^{m−1}`): `B_φ` is `Σ m (…) Q_n^m`
//! with no division, finite and exact at θ = 0 and π (the limit along the meridian φ), and
//! the derivative is `dP_n^m/dθ = n cos θ Q_n^m − √(n²−m²) Q_{n−1}^m` (m ≥ 1),
//! `dP_n^0/dθ = −√(n(n+1)/2) sin θ Q_n^1`, again without a division.
//!
//! **Time.** The coefficient file gives models every five years from 1900.0 to 2025.0
//! (degree 10 up to 1995.0, 13 from 2000.0; the missing degrees are zeros) and the
//! predicted secular variation (SV) for 2025.0–2030.0. Between two models the coefficients
//! are linear in the decimal year; from 2025.0 to 2030.0 they are the 2025.0 model plus
//! `(t − 2025) SV`. Epochs outside [`FIRST_YEAR`]..=[`LAST_YEAR`] are refused, never
//! extrapolated.
//!
//! **Data.** `data/igrf14coeffs.txt`, the IGRF-14 coefficient file (IAGA Division V,
//! Working Group V-MOD, released November 2024; IAGA (2024), *IGRF-14*, Zenodo,
//! doi:10.5281/zenodo.14012302), unmodified, embedded with `include_str!` and parsed once.
//! `data/README.md` says where the copy came from and how it was checked.
//!
//! **Units.** Positions in m, angles in rad, time in decimal years (UTC, as
//! [`super::magnetic::decimal_year`] counts it), Gauss coefficients in nT as in the file,
//! the field in T and the potential in T·m — the units of [`super::magnetic`].

use super::magnetic::{Dipole, REFERENCE_RADIUS};
use nalgebra::Vector3;
use std::sync::OnceLock;

/// Highest degree of the IGRF-14 models (from 2000.0; 10 before).
pub const MAX_DEGREE: usize = 13;
/// First decimal year of IGRF-14's validity (the 1900.0 model).
pub const FIRST_YEAR: f64 = 1900.0;
/// Last decimal year of IGRF-14's validity (the end of the 2025.0–2030.0 secular variation).
pub const LAST_YEAR: f64 = 2030.0;
/// Years between two tabulated models.
const MODEL_INTERVAL: f64 = 5.0;
/// Number of (n, m) pairs with 0 ≤ m ≤ n ≤ [`MAX_DEGREE`] (n = 0 included, unused).
const COUNT: usize = (MAX_DEGREE + 1) * (MAX_DEGREE + 2) / 2;

/// The IGRF-14 coefficient file, as distributed (see `data/README.md`).
pub const COEFFICIENT_FILE: &str = include_str!("../../data/igrf14coeffs.txt");

/// Index of (n, m) in the flat coefficient and Legendre arrays.
#[inline(always)]
const fn idx(n: usize, m: usize) -> usize {
    n * (n + 1) / 2 + m
}

/// The parsed coefficient file and the recursion constants.
struct Table {
    /// The model epochs (1900.0, 1905.0, …, 2025.0).
    epochs: Vec<f64>,
    /// The main-field models at those epochs (nT).
    models: Vec<Coefficients>,
    /// The predicted secular variation for 2025.0–2030.0 (nT/yr), in the same layout.
    sv: Coefficients,
    /// `(2n−1)/√(n²−m²)` and `√((n−1)²−m²)/√(n²−m²)`: the recursion in n at fixed m.
    rec_a: [f64; COUNT],
    rec_b: [f64; COUNT],
    /// `√(n²−m²)`, for dP_n^m/dθ.
    root: [f64; COUNT],
    /// `√((2m−1)/(2m))`, the sectoral step (m ≥ 2).
    sectoral: [f64; MAX_DEGREE + 1],
    /// `√(n(n+1)/2)`, for dP_n^0/dθ.
    zonal: [f64; MAX_DEGREE + 1],
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let (epochs, models, sv) =
            parse(COEFFICIENT_FILE).expect("the shipped data/igrf14coeffs.txt parses");
        let mut rec_a = [0.0; COUNT];
        let mut rec_b = [0.0; COUNT];
        let mut root = [0.0; COUNT];
        let mut sectoral = [0.0; MAX_DEGREE + 1];
        let mut zonal = [0.0; MAX_DEGREE + 1];
        for n in 1..=MAX_DEGREE {
            let nf = n as f64;
            zonal[n] = (nf * (nf + 1.0) / 2.0).sqrt();
            for m in 0..=n {
                let mf = m as f64;
                root[idx(n, m)] = ((nf - mf) * (nf + mf)).sqrt();
                if m < n {
                    rec_a[idx(n, m)] = (2.0 * nf - 1.0) / root[idx(n, m)];
                    rec_b[idx(n, m)] = ((nf - 1.0 - mf) * (nf - 1.0 + mf)).sqrt() / root[idx(n, m)];
                }
            }
        }
        for (m, s) in sectoral.iter_mut().enumerate().skip(2) {
            *s = ((2.0 * m as f64 - 1.0) / (2.0 * m as f64)).sqrt();
        }
        Table {
            epochs,
            models,
            sv,
            rec_a,
            rec_b,
            root,
            sectoral,
            zonal,
        }
    })
}

/// Parses an IGRF coefficient file in the layout of `igrf14coeffs.txt`: `#` comment lines,
/// a `c/s deg ord …` line, a `g/h n m <epochs…> <SV label>` line, then one row per
/// coefficient, `g|h n m <value at each epoch…> <SV>`. Refuses anything else: epochs not
/// 5 years apart, a missing, repeated or out-of-range (n, m), a row of the wrong length.
fn parse(text: &str) -> Result<(Vec<f64>, Vec<Coefficients>, Coefficients), String> {
    let mut epochs: Option<Vec<f64>> = None;
    let mut models: Vec<Coefficients> = Vec::new();
    let mut sv = Coefficients::zero();
    let mut seen = [[false; COUNT]; 2];
    for (line_no, line) in text.lines().enumerate() {
        let at = |what: String| format!("IGRF coefficient file, line {}: {what}", line_no + 1);
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            None => continue,
            Some(w) if w.starts_with('#') || *w == "c/s" => continue,
            Some(&"g/h") => {
                if epochs.is_some() {
                    return Err(at("a second g/h header".into()));
                }
                if words.len() < 5 {
                    return Err(at("no epochs in the g/h header".into()));
                }
                let e: Vec<f64> = words[3..words.len() - 1]
                    .iter()
                    .map(|w| w.parse::<f64>().map_err(|_| at(format!("epoch {w:?}"))))
                    .collect::<Result<_, _>>()?;
                for (k, y) in e.iter().enumerate() {
                    if *y != FIRST_YEAR + MODEL_INTERVAL * k as f64 {
                        return Err(at(format!("epoch {y} is not {FIRST_YEAR} + 5 × {k}")));
                    }
                }
                if FIRST_YEAR + MODEL_INTERVAL * e.len() as f64 != LAST_YEAR {
                    return Err(at(format!(
                        "the last model is {}, not {}",
                        e[e.len() - 1],
                        LAST_YEAR - MODEL_INTERVAL
                    )));
                }
                models = vec![Coefficients::zero(); e.len()];
                epochs = Some(e);
            }
            Some(&kind @ ("g" | "h")) => {
                let Some(e) = &epochs else {
                    return Err(at("a coefficient before the g/h header".into()));
                };
                if words.len() != 3 + e.len() + 1 {
                    return Err(at(format!(
                        "{} values, expected {} epochs and the SV",
                        words.len().saturating_sub(3),
                        e.len()
                    )));
                }
                let n: usize = words[1].parse().map_err(|_| at("degree".into()))?;
                let m: usize = words[2].parse().map_err(|_| at("order".into()))?;
                if !(1..=MAX_DEGREE).contains(&n) || m > n || (kind == "h" && m == 0) {
                    return Err(at(format!("{kind} n = {n}, m = {m} is out of range")));
                }
                let s = usize::from(kind == "h");
                if std::mem::replace(&mut seen[s][idx(n, m)], true) {
                    return Err(at(format!("{kind} n = {n}, m = {m} repeated")));
                }
                let values: Vec<f64> = words[3..]
                    .iter()
                    .map(|w| w.parse::<f64>().map_err(|_| at(format!("value {w:?}"))))
                    .collect::<Result<_, _>>()?;
                for (model, v) in models.iter_mut().zip(&values) {
                    model.coefficient_mut(kind, n, m)[0] = *v;
                }
                sv.coefficient_mut(kind, n, m)[0] = values[values.len() - 1];
            }
            Some(w) => return Err(at(format!("unexpected {w:?}"))),
        }
    }
    let epochs = epochs.ok_or("IGRF coefficient file: no g/h header")?;
    for n in 1..=MAX_DEGREE {
        for m in 0..=n {
            if !seen[0][idx(n, m)] || (m > 0 && !seen[1][idx(n, m)]) {
                return Err(format!("IGRF coefficient file: n = {n}, m = {m} missing"));
            }
        }
    }
    for model in models.iter_mut().chain(std::iter::once(&mut sv)) {
        model.degree = model.highest_nonzero_degree();
    }
    Ok((epochs, models, sv))
}

/// Schmidt semi-normalised Gauss coefficients g_n^m, h_n^m (nT) of one main-field model
/// (degrees 1 to [`MAX_DEGREE`]), and the field and potential they define.
#[derive(Debug, Clone, PartialEq)]
pub struct Coefficients {
    /// Highest degree with a nonzero coefficient; the sums stop there.
    degree: usize,
    g: [f64; COUNT],
    h: [f64; COUNT],
}

impl Coefficients {
    fn zero() -> Coefficients {
        Coefficients {
            degree: 0,
            g: [0.0; COUNT],
            h: [0.0; COUNT],
        }
    }

    fn coefficient_mut(&mut self, kind: &str, n: usize, m: usize) -> &mut [f64] {
        let i = idx(n, m);
        if kind == "g" {
            &mut self.g[i..=i]
        } else {
            &mut self.h[i..=i]
        }
    }

    fn highest_nonzero_degree(&self) -> usize {
        (1..=MAX_DEGREE)
            .rev()
            .find(|&n| (0..=n).any(|m| self.g[idx(n, m)] != 0.0 || self.h[idx(n, m)] != 0.0))
            .unwrap_or(0)
    }

    /// The IGRF-14 coefficients at the decimal year `year` (UTC): linear between the
    /// five-yearly models from 1900.0 to 2025.0, the 2025.0 model plus `(year − 2025)` times
    /// the predicted secular variation from 2025.0 to 2030.0. A year outside
    /// [`FIRST_YEAR`]..=[`LAST_YEAR`] (or NaN) is refused with a message naming the range.
    pub fn igrf14(year: f64) -> Result<Coefficients, String> {
        if !(FIRST_YEAR..=LAST_YEAR).contains(&year) {
            return Err(format!(
                "IGRF-14 is defined from {FIRST_YEAR:.1} to {LAST_YEAR:.1} (decimal years); \
                 {year} is outside it, and the model is not extrapolated"
            ));
        }
        let t = table();
        let last = t.epochs.len() - 1;
        let x = (year - FIRST_YEAR) / MODEL_INTERVAL;
        let mut c = Coefficients::zero();
        if x >= last as f64 {
            let dt = year - t.epochs[last];
            let (base, sv) = (&t.models[last], &t.sv);
            for i in 0..COUNT {
                c.g[i] = base.g[i] + sv.g[i] * dt;
                c.h[i] = base.h[i] + sv.h[i] * dt;
            }
        } else {
            // As `Dipole::igrf14` forms it: c_k + f (c_{k+1} − c_k), exact at the epochs.
            let k = (x.floor() as usize).min(last - 1);
            let f = x - k as f64;
            let (a, b) = (&t.models[k], &t.models[k + 1]);
            for i in 0..COUNT {
                c.g[i] = a.g[i] + f * (b.g[i] - a.g[i]);
                c.h[i] = a.h[i] + f * (b.h[i] - a.h[i]);
            }
        }
        c.degree = c.highest_nonzero_degree();
        Ok(c)
    }

    /// The highest degree with a nonzero coefficient (10 before 1995.0, 13 from then on;
    /// at most the degree given to [`Coefficients::truncated`]).
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// g_n^m (nT), 1 ≤ n ≤ [`MAX_DEGREE`], m ≤ n. Panics outside that range.
    pub fn g(&self, n: usize, m: usize) -> f64 {
        assert!((1..=MAX_DEGREE).contains(&n) && m <= n, "no g({n}, {m})");
        self.g[idx(n, m)]
    }

    /// h_n^m (nT), 1 ≤ n ≤ [`MAX_DEGREE`], m ≤ n (h_n^0 = 0). Panics outside that range.
    pub fn h(&self, n: usize, m: usize) -> f64 {
        assert!((1..=MAX_DEGREE).contains(&n) && m <= n, "no h({n}, {m})");
        self.h[idx(n, m)]
    }

    /// The same model with the degrees above `degree` set to zero.
    pub fn truncated(&self, degree: usize) -> Coefficients {
        let mut c = self.clone();
        for n in degree + 1..=MAX_DEGREE {
            for m in 0..=n {
                c.g[idx(n, m)] = 0.0;
                c.h[idx(n, m)] = 0.0;
            }
        }
        c.degree = c.highest_nonzero_degree();
        c
    }

    /// The degree-1 part as [`Dipole`] (g₁⁰, g₁¹, h₁¹), the model of [`super::magnetic`].
    pub fn dipole(&self) -> Dipole {
        Dipole {
            g10: self.g[idx(1, 0)],
            g11: self.g[idx(1, 1)],
            h11: self.h[idx(1, 1)],
        }
    }

    /// The potential V (T·m) at radius `radius` (m), colatitude `colatitude` and east
    /// longitude `longitude` (rad), geocentric.
    pub fn potential(&self, radius: f64, colatitude: f64, longitude: f64) -> f64 {
        let (st, ct) = colatitude.sin_cos();
        let (sp, cp) = longitude.sin_cos();
        let q = legendre(self.degree, ct, st);
        let (cm, sm) = multiples(self.degree, cp, sp);
        let ratio = REFERENCE_RADIUS / radius;
        let mut power = ratio; // (a/r)^{n+1}
        let mut v = 0.0;
        for n in 1..=self.degree {
            power *= ratio;
            let mut s = self.g[idx(n, 0)] * q[idx(n, 0)];
            for m in 1..=n {
                let i = idx(n, m);
                s += (self.g[i] * cm[m] + self.h[i] * sm[m]) * st * q[i];
            }
            v += power * s;
        }
        1e-9 * REFERENCE_RADIUS * v
    }

    /// The field (T) as geocentric (north, east, down) components — `(−B_θ, B_φ, −B_r)` — at
    /// radius `radius` (m), colatitude `colatitude` and east longitude `longitude` (rad).
    /// At a pole (colatitude 0 or π) "north" and "east" are the limits along the meridian
    /// `longitude`.
    pub fn field_ned(&self, radius: f64, colatitude: f64, longitude: f64) -> Vector3<f64> {
        let (st, ct) = colatitude.sin_cos();
        let (sp, cp) = longitude.sin_cos();
        self.synthesize(radius, ct, st, cp, sp)
    }

    /// The field (T) in ECEF components at `r` (m, ECEF: z along the rotation axis, x in the
    /// Greenwich meridian), the convention of [`Dipole::field_ecef`]. On the rotation axis
    /// itself longitude 0 is used for the local axes, which leaves the ECEF vector unchanged.
    pub fn field_ecef(&self, r: &Vector3<f64>) -> Vector3<f64> {
        let radius = r.norm();
        let rho = r.x.hypot(r.y);
        let (st, ct) = (rho / radius, r.z / radius);
        let (sp, cp) = if rho > 0.0 {
            (r.y / rho, r.x / rho)
        } else {
            (0.0, 1.0)
        };
        let b = self.synthesize(radius, ct, st, cp, sp);
        let north = Vector3::new(-ct * cp, -ct * sp, st);
        let east = Vector3::new(-sp, cp, 0.0);
        let up = Vector3::new(st * cp, st * sp, ct);
        north * b.x + east * b.y - up * b.z
    }

    /// (north, east, down) in T from cos/sin of colatitude and longitude.
    #[inline]
    fn synthesize(&self, radius: f64, ct: f64, st: f64, cp: f64, sp: f64) -> Vector3<f64> {
        let t = table();
        let q = legendre(self.degree, ct, st);
        let (cm, sm) = multiples(self.degree, cp, sp);
        let ratio = REFERENCE_RADIUS / radius;
        let mut power = ratio * ratio; // (a/r)^{n+2}
        let (mut b_r, mut b_theta, mut b_phi) = (0.0, 0.0, 0.0);
        for n in 1..=self.degree {
            power *= ratio;
            let nf = n as f64;
            let i0 = idx(n, 0);
            // m = 0: P = q, dP/dθ = −√(n(n+1)/2) sin θ Q_n^1.
            let g0 = self.g[i0];
            let (mut sr, mut st_sum, mut sp_sum) =
                (g0 * q[i0], -g0 * t.zonal[n] * st * q[idx(n, 1)], 0.0);
            for m in 1..=n {
                let i = idx(n, m);
                let (g, h) = (self.g[i], self.h[i]);
                let cos_part = g * cm[m] + h * sm[m];
                // q[i − n] is Q_{n−1}^m (idx(n−1, m) = idx(n, m) − n); for m = n it is
                // another, finite entry, multiplied by root = √(n²−n²) = 0.
                let dp = nf * ct * q[i] - t.root[i] * q[i - n];
                sr += cos_part * st * q[i];
                st_sum += cos_part * dp;
                sp_sum += m as f64 * (g * sm[m] - h * cm[m]) * q[i];
            }
            b_r += (nf + 1.0) * power * sr;
            b_theta -= power * st_sum;
            b_phi += power * sp_sum;
        }
        1e-9 * Vector3::new(-b_theta, b_phi, -b_r)
    }
}

/// `cos mφ`, `sin mφ` for m = 0..=`degree` by the angle-addition recurrence.
#[inline]
fn multiples(degree: usize, cp: f64, sp: f64) -> ([f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    let mut c = [0.0; MAX_DEGREE + 1];
    let mut s = [0.0; MAX_DEGREE + 1];
    c[0] = 1.0;
    for m in 1..=degree {
        c[m] = c[m - 1] * cp - s[m - 1] * sp;
        s[m] = s[m - 1] * cp + c[m - 1] * sp;
    }
    (c, s)
}

/// Schmidt semi-normalised `P_n^0(cos θ)` at `idx(n, 0)` and `Q_n^m = P_n^m(cos θ) / sin θ`
/// at `idx(n, m)` for m ≥ 1, 0 ≤ n ≤ `degree`, from `ct = cos θ`, `st = sin θ`. The recursion
/// in n at fixed m, `X_n = (2n−1)/√(n²−m²) cos θ X_{n−1} − √((n−1)²−m²)/√(n²−m²) X_{n−2}`,
/// is linear, so it holds for `Q` as for `P`; the sectoral start is `Q_1^1 = 1`,
/// `Q_m^m = √((2m−1)/(2m)) sin θ Q_{m−1}^{m−1}`.
#[inline]
fn legendre(degree: usize, ct: f64, st: f64) -> [f64; COUNT] {
    let t = table();
    let mut q = [0.0; COUNT];
    q[idx(0, 0)] = 1.0;
    for m in 0..=degree {
        if m == 1 {
            q[idx(1, 1)] = 1.0;
        } else if m >= 2 {
            q[idx(m, m)] = t.sectoral[m] * st * q[idx(m - 1, m - 1)];
        }
        if m < degree {
            q[idx(m + 1, m)] = t.rec_a[idx(m + 1, m)] * ct * q[idx(m, m)];
        }
        for n in m + 2..=degree {
            let i = idx(n, m);
            q[i] = t.rec_a[i] * ct * q[idx(n - 1, m)] - t.rec_b[i] * q[idx(n - 2, m)];
        }
    }
    q
}

/// Schmidt semi-normalised `P_n^m(cos θ)` and `dP_n^m/dθ` for 1 ≤ n ≤ [`MAX_DEGREE`],
/// m ≤ n, at colatitude `colatitude` (rad): what the field sums use, exposed for tests.
pub fn schmidt_legendre(n: usize, m: usize, colatitude: f64) -> (f64, f64) {
    assert!((1..=MAX_DEGREE).contains(&n) && m <= n, "no P({n}, {m})");
    let t = table();
    let (st, ct) = colatitude.sin_cos();
    let q = legendre(MAX_DEGREE, ct, st);
    if m == 0 {
        (q[idx(n, 0)], -t.zonal[n] * st * q[idx(n, 1)])
    } else {
        let below = if m < n { q[idx(n - 1, m)] } else { 0.0 };
        (
            st * q[idx(n, m)],
            n as f64 * ct * q[idx(n, m)] - t.root[idx(n, m)] * below,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_parses_into_26_models_and_the_sv() {
        let t = table();
        assert_eq!(t.epochs.len(), 26);
        assert_eq!((t.epochs[0], t.epochs[25]), (1900.0, 2025.0));
        // Degree 10 to 1995.0 (zeros above), 13 from 2000.0.
        assert_eq!(t.models[19].degree, 10);
        assert_eq!(t.models[20].degree, 13);
        assert_eq!(t.sv.degree, 8);
        // First and last rows of the file.
        assert_eq!(t.models[0].g[idx(1, 0)], -31543.0);
        assert_eq!(t.models[25].g[idx(1, 0)], -29350.0);
        assert_eq!(t.sv.g[idx(1, 0)], 12.6);
        assert_eq!(t.sv.h[idx(1, 1)], -21.5);
        assert_eq!(t.models[25].h[idx(13, 13)], -0.5);
        assert_eq!(t.models[20].g[idx(13, 0)], -0.2);
    }

    #[test]
    fn malformed_files_are_refused() {
        let good = COEFFICIENT_FILE;
        let drop_row: String = good
            .lines()
            .filter(|l| !l.starts_with("h  7  3"))
            .map(|l| format!("{l}\n"))
            .collect();
        assert!(
            parse(&drop_row)
                .unwrap_err()
                .contains("n = 7, m = 3 missing")
        );
        let short: String = good.replacen("g  1  0 -31543", "g  1  0", 1);
        assert!(parse(&short).unwrap_err().contains("expected 26 epochs"));
        let dup = format!("{good}g  1  0{}\n", " 1".repeat(27));
        assert!(parse(&dup).unwrap_err().contains("repeated"));
        let bad_epoch = good.replacen("1905.0", "1906.0", 1);
        assert!(parse(&bad_epoch).unwrap_err().contains("epoch 1906"));
        assert!(
            parse("g  1  0 1 2\n")
                .unwrap_err()
                .contains("before the g/h header")
        );
        let header = good.lines().find(|l| l.starts_with("g/h")).unwrap();
        let twice = good.replacen(header, &format!("{header}\n{header}"), 1);
        assert!(parse(&twice).unwrap_err().contains("second g/h header"));
    }

    #[test]
    fn legendre_functions_match_closed_forms() {
        for theta in [0.0, 1e-9, 0.3, 1.0, 1.57, 2.5, std::f64::consts::PI] {
            let (s, c) = f64::sin_cos(theta);
            let r3 = 3f64.sqrt();
            let cases = [
                ((1, 0), c, -s),
                ((1, 1), s, c),
                ((2, 0), 1.5 * c * c - 0.5, -3.0 * c * s),
                ((2, 1), r3 * c * s, r3 * (c * c - s * s)),
                ((2, 2), 0.5 * r3 * s * s, r3 * s * c),
                // P_3^3 = √(5/8) sin³θ, P_3^2 = (√15/2) cos θ sin²θ (Schmidt).
                (
                    (3, 3),
                    (5.0f64 / 8.0).sqrt() * s * s * s,
                    3.0 * (5.0f64 / 8.0).sqrt() * s * s * c,
                ),
                (
                    (3, 2),
                    0.5 * 15f64.sqrt() * c * s * s,
                    0.5 * 15f64.sqrt() * (2.0 * s * c * c - s * s * s),
                ),
            ];
            for ((n, m), p, dp) in cases {
                let (pp, dd) = schmidt_legendre(n, m, theta);
                assert!((pp - p).abs() < 1e-15, "P({n},{m})({theta}) = {pp}, {p}");
                assert!((dd - dp).abs() < 1e-14, "dP({n},{m})({theta}) = {dd}, {dp}");
            }
        }
    }

    #[test]
    fn legendre_derivatives_match_finite_differences_at_degree_13() {
        let h = 1e-5;
        for theta in [1e-3, 0.4, 1.3, 2.9, 3.1] {
            for n in 1..=MAX_DEGREE {
                for m in 0..=n {
                    let (_, dp) = schmidt_legendre(n, m, theta);
                    let f = |x| schmidt_legendre(n, m, x).0;
                    let fd = (f(theta - 2.0 * h) - 8.0 * f(theta - h) + 8.0 * f(theta + h)
                        - f(theta + 2.0 * h))
                        / (12.0 * h);
                    assert!((dp - fd).abs() < 1e-8, "dP({n},{m})({theta}): {dp} vs {fd}");
                }
            }
        }
    }

    #[test]
    fn schmidt_normalisation_sums_to_one() {
        // Σ_m (P_n^m)² = 1 for Schmidt semi-normalised functions (the addition theorem at
        // zero angular distance), at every θ and degree.
        for theta in [0.0, 0.2, 1.1, 2.0, 3.0] {
            for n in 1..=MAX_DEGREE {
                let s: f64 = (0..=n)
                    .map(|m| schmidt_legendre(n, m, theta).0.powi(2))
                    .sum();
                assert!((s - 1.0).abs() < 1e-14, "n = {n}, θ = {theta}: {s}");
            }
        }
    }
}
