//! Where methods fail: invariant drift over long horizons, the stability map of a stiff
//! effector, and error growth near the separatrix (docs/choosing-a-method.md).

use super::{MethodSpec, attitude_error, load_with, svg_and_png};
use crate::exact::TorqueFreeSolution;
use crate::model::Observation;
use crate::plot::{Chart, Scale, Series, Style};
use crate::scenario::{self, Overrides, Scenario};
use crate::sim::{self, Control, EventRecord, NullSink, Reference, Sink, Status};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Running maxima of (|ΔE|/E, |Δ|H||/|H|, ||q| − 1|) at sample times.
type DriftCurve = Vec<(f64, [f64; 3])>;

/// Keeps every output sample's time and state.
#[derive(Default)]
struct Recorder {
    samples: Vec<(f64, Vec<f64>)>,
    /// Running maxima of |ΔE|/E, |Δ|H||/|H|, ||q| − 1| at each sample.
    drift: DriftCurve,
    worst: [f64; 3],
}

impl Sink for Recorder {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> std::io::Result<()> {
        let q = (y[3] * y[3] + y[4] * y[4] + y[5] * y[5] + y[6] * y[6]).sqrt();
        let now = [inv.energy_rel(o).abs(), inv.h_rel(o).abs(), (q - 1.0).abs()];
        for (w, n) in self.worst.iter_mut().zip(now) {
            *w = w.max(n);
        }
        self.drift.push((o.t, self.worst));
        self.samples.push((o.t, y.to_vec()));
        Ok(())
    }
    fn event(&mut self, _: &EventRecord, _: &Observation) -> std::io::Result<()> {
        Ok(())
    }
}

fn run_into(s: &Scenario, sink: &mut dyn Sink) -> Result<sim::Outcome, String> {
    let interrupt = AtomicBool::new(false);
    sim::run(
        s,
        sink,
        Control {
            interrupt: &interrupt,
            progress: None,
        },
    )
    .map_err(|e| e.to_string())
}

/// A method at one setting, for the fixed-setting charts.
struct Setting {
    method: MethodSpec,
    knob: Option<f64>,
}

fn setting(label: &str, knob: Option<f64>) -> Setting {
    Setting {
        method: MethodSpec::by_label(label).expect("known method"),
        knob,
    }
}

fn legend(s: &Setting) -> String {
    match s.knob {
        Some(k) if s.method.fixed_step => format!("{} (dt {k} s)", s.method.label),
        Some(k) => format!("{} (rtol {k:e})", s.method.label),
        None => s.method.label.to_string(),
    }
}

/// Invariant drift of every method over `duration` s of torque-free tumbling
/// (`scenarios/generic-tumble.yaml`): running maxima of the relative energy and |H| drift and
/// of ||q| − 1| against simulated time. Writes `drift-{energy,momentum,quaternion}.svg|png`
/// and `drift.csv`.
pub fn drift(
    root: &Path,
    duration: f64,
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<Vec<PathBuf>, String> {
    let settings = [
        setting("rk4", Some(0.05)),
        setting("dopri5", Some(1e-8)),
        setting("dop853", Some(1e-8)),
        setting("radau5", Some(1e-8)),
        setting("gauss-1", Some(0.02)),
        setting("gauss-2", Some(0.2)),
        setting("lie", Some(0.05)),
        setting("splitting-2", Some(1.0)),
        setting("splitting-4", Some(1.0)),
        setting("exact", None),
    ];
    let path = root.join("scenarios/generic-tumble.yaml");
    let mut curves: Vec<(String, DriftCurve)> = Vec::new();
    let mut table = String::from(
        "method,steps,rhs_evaluations,wall_s,final_energy_rel,final_h_rel,final_q_norm\n",
    );
    for s in &settings {
        let mut sc = load_with(&path, &s.method, s.knob, Some(duration))?;
        sc.output_rate = 200.0 / duration;
        sc.events.clear();
        sc.stop.clear();
        let mut rec = Recorder::default();
        let o = run_into(&sc, &mut rec)?;
        let name = legend(s);
        progress(&format!(
            "drift: {name}: energy {:.2e}, |H| {:.2e}, |q| {:.2e} ({} steps, {:.2} s)",
            rec.worst[0], rec.worst[1], rec.worst[2], o.stats.steps, o.wall_time
        ));
        let _ = writeln!(
            table,
            "{name},{},{},{:.3},{:e},{:e},{:e}",
            o.stats.steps,
            o.stats.rhs_evaluations,
            o.wall_time,
            rec.worst[0],
            rec.worst[1],
            rec.worst[2]
        );
        curves.push((name, rec.drift));
    }
    let mut files = Vec::new();
    for (k, (what, file)) in [
        ("relative energy drift |ΔT|/T", "drift-energy"),
        ("relative momentum drift |Δ|H||/|H|", "drift-momentum"),
        ("quaternion norm error ||q| − 1|", "drift-quaternion"),
    ]
    .into_iter()
    .enumerate()
    {
        let mut c = Chart::new(
            format!("Long horizon, torque-free tumble: {what} (running maximum)"),
            "simulated time (s)",
            what,
        );
        c.x_scale = Scale::Log10;
        c.y_scale = Scale::Log10;
        for (i, (name, pts)) in curves.iter().enumerate() {
            let p: Vec<(f64, f64)> = pts
                .iter()
                .filter(|(t, _)| *t > 0.0)
                .map(|(t, d)| (*t, d[k].max(1e-17)))
                .collect();
            let style = if i < 8 { Style::Line } else { Style::Dashed };
            c.series.push(Series::new(name.clone(), p, style));
        }
        c.y_range = Some((1e-17, 1.0));
        files.extend(svg_and_png(&c, &out.join(file))?);
    }
    let p = out.join("drift.csv");
    crate::outputs::write_atomically(&p, table.as_bytes())
        .map_err(|e| format!("{}: {e}", p.display()))?;
    files.push(p);
    Ok(files)
}

/// The stiff scene of the stability map: a spinning hub with a 1 kg spring-mass damper of
/// stiffness `k` (N/m) and damping 2√k N s/m (critical for the particle alone; coupled to the
/// hub the mode is overdamped, its fastest eigenvalue ≈ 1.21 √k 1/s), started off its rest
/// position by 1 mm·√(100/k): its own mode carries the same small energy (5e-5 J, against the
/// hub's 7.5 J) at every stiffness, so that integration error in the dissipated-energy
/// bookkeeping of a stiff, stable run cannot trip the divergence guard.
fn stiff_scene(k: f64, duration: f64, ov: Overrides) -> Result<Scenario, String> {
    let c = 2.0 * k.sqrt();
    let yaml = format!(
        "name: stiff-damper-k{k:e}
body: {{mass: 100.0, principal: [10.0, 12.0, 15.0], spin_axis: [0, 0, 1]}}
effectors:
  - spring_mass_damper:
      {{name: damper, mass: 1.0, position: [0.5, 0, 0], direction: [0, 0, 1],
       stiffness: {k:e}, damping: {c:e}, initial_offset: {x0:e}}}
initial: {{omega: [0.05, 0.0, 1.0]}}
duration: {duration:e}
output: {{rate: {rate:e}}}
",
        rate = 4.0 / duration,
        x0 = 1e-3 * (100.0 / k).sqrt()
    );
    scenario::parse(Path::new("stiff-damper.yaml"), yaml, &ov).map_err(|e| e.to_string())
}

fn overrides(m: &MethodSpec, knob: Option<f64>) -> Overrides {
    Overrides {
        method: Some(m.name.into()),
        dt: knob.filter(|_| m.fixed_step),
        rtol: knob.filter(|_| m.adaptive),
        atol: knob.filter(|_| m.adaptive).map(|r| 1e-3 * r),
        stages: m.stages,
        order: m.order,
        duration: None,
        mcap: None,
        max_log_mb: None,
    }
}

/// Whether `m` at fixed step `dt` runs 200 steps of the stiff scene stably: it completes, and
/// the damper's own mode has not grown (its elastic energy at the end is at most its initial
/// one: a stable step damps it, an unstable one amplifies it by |R(hλ)|² per step, however
/// small its share of the total energy).
fn stable(k: f64, m: &MethodSpec, dt: f64) -> bool {
    let Ok(s) = stiff_scene(k, 200.0 * dt, overrides(m, Some(dt))) else {
        return false;
    };
    let mut sink = NullSink;
    match run_into(&s, &mut sink) {
        Ok(o) => {
            o.status == Status::Complete
                && o.final_observation.elastic_energy.is_finite()
                && o.final_observation.elastic_energy <= o.initial_observation.elastic_energy
        }
        Err(_) => false,
    }
}

/// Largest step up to which the stability map searches (s).
pub const STABILITY_CAP: f64 = 10.0;

/// The stability map: for stiffness swept over decades, the largest stable fixed step of each
/// fixed-step method (bisection in log h), and the mean accepted step of each adaptive method
/// at rtol 1e-6. Writes `stability-map.svg|png` and `stability-map.csv`.
pub fn stability(out: &Path, mut progress: impl FnMut(&str)) -> Result<Vec<PathBuf>, String> {
    let stiffnesses: Vec<f64> = (0..=8).map(|e| 10f64.powi(2 + e)).collect();
    let fixed: Vec<MethodSpec> = super::METHODS
        .iter()
        .filter(|m| m.fixed_step)
        .copied()
        .collect();
    let adaptive: Vec<MethodSpec> = super::METHODS
        .iter()
        .filter(|m| m.adaptive)
        .copied()
        .collect();
    let mut csv = String::from("method,stiffness_N_per_m,largest_abs_lambda,step_s,kind\n");
    let mut series: Vec<Series> = Vec::new();
    for m in &fixed {
        let mut pts = Vec::new();
        for &k in &stiffnesses {
            let lam = lambda(k)?;
            // Bracket: stable well below the explicit bound, then bisect in log h.
            let mut lo = 0.05 / lam;
            if !stable(k, m, lo) {
                progress(&format!(
                    "stability: {} k {k:e}: unstable even at {lo:e} s",
                    m.label
                ));
                continue;
            }
            let mut hi = STABILITY_CAP;
            let h = if stable(k, m, hi) {
                hi
            } else {
                for _ in 0..14 {
                    let mid = (lo * hi).sqrt();
                    if stable(k, m, mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                lo
            };
            progress(&format!(
                "stability: {} k {k:e} (|λ| {lam:.3e}): largest stable step {h:.3e} s (h·|λ| = {:.3})",
                m.label,
                h * lam
            ));
            let kind = if h >= STABILITY_CAP {
                "no limit up to the cap"
            } else {
                "largest stable step"
            };
            let _ = writeln!(csv, "{},{k:e},{lam:e},{h:e},{kind}", m.label);
            pts.push((lam, h));
        }
        series.push(Series::new(m.label, pts, Style::LineMarkers));
    }
    for m in &adaptive {
        let mut pts = Vec::new();
        for &k in &stiffnesses {
            let lam = lambda(k)?;
            let duration = 2.0;
            let s = stiff_scene(k, duration, overrides(m, Some(1e-6)))?;
            let Ok(solve) = sim::integrate_only(&s, duration) else {
                continue;
            };
            let h = duration / solve.stats.steps.max(1) as f64;
            progress(&format!(
                "stability: {} k {k:e} (|λ| {lam:.3e}): mean step {h:.3e} s at rtol 1e-6",
                m.label
            ));
            let _ = writeln!(csv, "{},{k:e},{lam:e},{h:e},mean accepted step", m.label);
            pts.push((lam, h));
        }
        series.push(Series::new(
            format!("{} (mean step)", m.label),
            pts,
            Style::Dashed,
        ));
    }
    let mut c = Chart::new(
        "Stability map: stiff spring-mass damper on a spinning hub",
        "fastest eigenvalue |λ| (1/s)",
        "largest stable step, or mean adaptive step (s)",
    );
    c.x_scale = Scale::Log10;
    c.y_scale = Scale::Log10;
    c.series.extend(series);
    let lams: Vec<f64> = stiffnesses
        .iter()
        .map(|&k| lambda(k).unwrap_or(f64::NAN))
        .collect();
    c.series.push(Series::new(
        "h·|λ| = 2.785 (RK4 bound)",
        lams.iter().map(|&l| (l, 2.785 / l)).collect(),
        Style::Dashed,
    ));
    let mut files = svg_and_png(&c, &out.join("stability-map"))?;
    let p = out.join("stability-map.csv");
    crate::outputs::write_atomically(&p, csv.as_bytes())
        .map_err(|e| format!("{}: {e}", p.display()))?;
    files.push(p);
    Ok(files)
}

/// The fastest eigenvalue of the stiff scene at stiffness `k`.
fn lambda(k: f64) -> Result<f64, String> {
    let s = stiff_scene(k, 1.0, Overrides::default())?;
    let y0 = s.spacecraft.initial_state(&s.omega0, &s.attitude0);
    Ok(crate::linearize::stiffness(&s.spacecraft, 0.0, &y0, 1.0).spectral_radius)
}

/// Error growth near the separatrix (`scenarios/near-separatrix.yaml`): the attitude error of
/// each method against the exact solution at 1 Hz, and the problem's own conditioning: the
/// exact solution from initial rates perturbed across the spin by 1e-12·|ω₀| (which moves the
/// polhode, hence the flip times) against the exact one.
/// Writes `separatrix-error.svg|png` and `separatrix-error.csv`.
pub fn separatrix(
    root: &Path,
    duration: f64,
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<Vec<PathBuf>, String> {
    let path = root.join("scenarios/near-separatrix.yaml");
    let base = scenario::load(
        &path,
        &Overrides {
            duration: Some(duration),
            ..Overrides::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let inertia = base.spacecraft.hub.inertia;
    let exact = TorqueFreeSolution::new(&inertia, &base.omega0, &base.attitude0)
        .map_err(|e| e.to_string())?;
    let settings = [
        setting("rk4", Some(0.01)),
        setting("dopri5", Some(1e-10)),
        setting("dop853", Some(1e-10)),
        setting("radau5", Some(1e-10)),
        setting("gauss-2", Some(0.02)),
        setting("lie", Some(0.01)),
        setting("splitting-4", Some(0.5)),
    ];
    let error_at = |t: f64, y: &[f64]| {
        let (_, q) = exact.state_at(t);
        let qr = [q.w, q.i, q.j, q.k];
        attitude_error(&qr, &y[3..7]).max(1e-17)
    };
    let mut c = Chart::new(
        format!("Error growth near the separatrix ({duration} s)"),
        "simulated time (s)",
        "attitude error against the exact solution (rad)",
    );
    c.y_scale = Scale::Log10;
    let mut csv = String::from("method,t_s,attitude_error_rad\n");
    for (i, s) in settings.iter().enumerate() {
        let mut sc = load_with(&path, &s.method, s.knob, Some(duration))?;
        sc.output_rate = 1.0;
        sc.events.clear();
        let mut rec = Recorder::default();
        run_into(&sc, &mut rec)?;
        let name = legend(s);
        let pts: Vec<(f64, f64)> = rec
            .samples
            .iter()
            .map(|(t, y)| (*t, error_at(*t, y)))
            .collect();
        progress(&format!(
            "separatrix: {name}: final error {:.2e} rad",
            pts.last().map_or(f64::NAN, |p| p.1)
        ));
        for (t, e) in &pts {
            let _ = writeln!(csv, "{name},{t},{e:e}");
        }
        let style = if i < 8 { Style::Line } else { Style::Dashed };
        c.series.push(Series::new(name, pts, style));
    }
    // Conditioning: the exact solution itself, from rates perturbed by one part in 1e12
    // across the spin (a perturbation along ω would only rescale time, not move the polhode).
    let nudge = nalgebra::Vector3::x() * 1e-12 * base.omega0.norm();
    let perturbed = TorqueFreeSolution::new(&inertia, &(base.omega0 + nudge), &base.attitude0)
        .map_err(|e| e.to_string())?;
    let pts: Vec<(f64, f64)> = (0..=duration as usize)
        .map(|k| {
            let t = k as f64;
            let (_, q) = perturbed.state_at(t);
            (t, error_at(t, &[0.0, 0.0, 0.0, q.w, q.i, q.j, q.k]))
        })
        .collect();
    for (t, e) in &pts {
        let _ = writeln!(csv, "conditioning,{t},{e:e}");
    }
    c.series.push(Series::new(
        "conditioning: exact from ω₀ + 1e-12·|ω₀|·x̂",
        pts,
        Style::Dashed,
    ));
    let mut files = svg_and_png(&c, &out.join("separatrix-error"))?;
    let p = out.join("separatrix-error.csv");
    crate::outputs::write_atomically(&p, csv.as_bytes())
        .map_err(|e| format!("{}: {e}", p.display()))?;
    files.push(p);
    Ok(files)
}
