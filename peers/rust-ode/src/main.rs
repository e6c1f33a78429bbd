//! Peer benchmark: the `differential-equations` crate's DOP853 and DOPRI5 integrating
//! polhode's own right-hand side (`Spacecraft` as an `OdeSystem`), so the only difference from
//! `polhode bench point` is the integrator.
//!
//! Usage: `rust-ode-peer SCENARIO [--method dop853|dopri5] [--rtol R] [--atol A]
//! [--duration D] [--repeats N]`. Prints one JSON object on stdout, in the shape of
//! `polhode bench point`'s (cpu_seconds is, like polhode's, the wall-clock time of the
//! integration alone, minimum over repeats: solver set-up, stepping and the final state; the
//! output handler keeps only the last point).

use differential_equations::interpolate::Interpolation;
use differential_equations::prelude::*;
use differential_equations::solout::Solout;
use differential_equations::solution::Solution;
use polhode::integrate::OdeSystem;
use polhode::model::Spacecraft;
use polhode::scenario::{self, Overrides};
use std::cell::Cell;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// polhode's right-hand side behind the crate's `ODE` trait, on a fixed-size state.
struct Rhs<'a, const N: usize> {
    sc: &'a Spacecraft,
    evals: Cell<u64>,
}

impl<const N: usize> ODE<f64, [f64; N]> for Rhs<'_, N> {
    #[inline(always)]
    fn diff(&self, t: f64, y: &[f64; N], dydt: &mut [f64; N]) {
        self.evals.set(self.evals.get() + 1);
        self.sc.rhs(t, y, dydt);
    }
}

/// Keeps only the last accepted point (no per-step storage, so the timing is the stepping).
struct LastPoint<'a, const N: usize> {
    t: &'a Cell<f64>,
    y: &'a Cell<[f64; N]>,
}

impl<const N: usize> Solout<f64, [f64; N]> for LastPoint<'_, N> {
    fn solout<I>(
        &mut self,
        t_curr: f64,
        _t_prev: f64,
        y_curr: &[f64; N],
        _y_prev: &[f64; N],
        _interpolator: &mut I,
        _solution: &mut Solution<f64, [f64; N]>,
    ) -> ControlFlag<f64, [f64; N]>
    where
        I: Interpolation<f64, [f64; N]> + ?Sized,
    {
        self.t.set(t_curr);
        self.y.set(*y_curr);
        ControlFlag::Continue
    }
}

struct Args {
    scenario: PathBuf,
    method: String,
    rtol: Option<f64>,
    atol: Option<f64>,
    duration: Option<f64>,
    repeats: usize,
}

fn parse_args() -> Result<Args, String> {
    let mut it = std::env::args().skip(1);
    let mut a = Args {
        scenario: PathBuf::new(),
        method: "dop853".into(),
        rtol: None,
        atol: None,
        duration: None,
        repeats: 3,
    };
    let mut scenario = None;
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        let num = |s: String, name: &str| s.parse::<f64>().map_err(|e| format!("{name}: {e}"));
        match arg.as_str() {
            "--method" => a.method = value("--method")?,
            "--rtol" => a.rtol = Some(num(value("--rtol")?, "--rtol")?),
            "--atol" => a.atol = Some(num(value("--atol")?, "--atol")?),
            "--duration" => a.duration = Some(num(value("--duration")?, "--duration")?),
            "--repeats" => {
                a.repeats = value("--repeats")?
                    .parse()
                    .map_err(|e| format!("--repeats: {e}"))?
            }
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            s => scenario = Some(PathBuf::from(s)),
        }
    }
    a.scenario = scenario.ok_or("usage: rust-ode-peer SCENARIO [--method dop853|dopri5] [--rtol R] [--atol A] [--duration D] [--repeats N]")?;
    if a.repeats == 0 {
        return Err("--repeats must be at least 1".into());
    }
    Ok(a)
}

struct Outcome {
    t: f64,
    y: Vec<f64>,
    steps: u64,
    rejected: u64,
    evals: u64,
    cpu_all: Vec<f64>,
}

fn run<const N: usize>(
    sc: &Spacecraft,
    y0: &[f64],
    tf: f64,
    method: &str,
    rtol: f64,
    atol: f64,
    repeats: usize,
) -> Result<Outcome, String> {
    let mut y0a = [0.0; N];
    y0a.copy_from_slice(y0);
    let mut out = None;
    let mut cpu_all = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let ode = Rhs::<N> {
            sc,
            evals: Cell::new(0),
        };
        let t_last = Cell::new(0.0);
        let y_last = Cell::new(y0a);
        let last = LastPoint::<N> {
            t: &t_last,
            y: &y_last,
        };
        let max_steps = usize::MAX / 2;
        // Wall clock of the solve, as `polhode bench point` measures (std::time::Instant).
        let c0 = Instant::now();
        let sol = match method {
            "dop853" => {
                let m = ExplicitRungeKutta::dop853()
                    .rtol(rtol)
                    .atol(atol)
                    .max_steps(max_steps);
                IVP::ode(&ode, 0.0, tf, y0a).solout(last).method(m).solve()
            }
            "dopri5" => {
                let m = ExplicitRungeKutta::dopri5()
                    .rtol(rtol)
                    .atol(atol)
                    .max_steps(max_steps);
                IVP::ode(&ode, 0.0, tf, y0a).solout(last).method(m).solve()
            }
            other => return Err(format!("unknown method {other} (dop853 or dopri5)")),
        };
        let elapsed = c0.elapsed().as_secs_f64();
        let sol = sol.map_err(|e| format!("the solver failed: {e:?}"))?;
        cpu_all.push(elapsed);
        out = Some(Outcome {
            t: t_last.get(),
            y: y_last.get().to_vec(),
            steps: sol.steps.accepted as u64,
            rejected: sol.steps.rejected as u64,
            evals: ode.evals.get(),
            cpu_all: Vec::new(),
        });
    }
    let mut o = out.expect("at least one repeat");
    o.cpu_all = cpu_all;
    Ok(o)
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("rust-ode-peer: {e}");
            return ExitCode::from(2);
        }
    };
    let overrides = Overrides {
        duration: args.duration,
        ..Overrides::default()
    };
    let sc = match scenario::load(&args.scenario, &overrides) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    let rtol = args.rtol.unwrap_or(1e-10);
    let atol = args.atol.unwrap_or(rtol * 1e-2);
    let y0 = sc.spacecraft.initial_state(&sc.omega0, &sc.attitude0);
    let dim = sc.spacecraft.dim();
    let tf = sc.duration;
    let r = match dim {
        7 => run::<7>(
            &sc.spacecraft,
            &y0,
            tf,
            &args.method,
            rtol,
            atol,
            args.repeats,
        ),
        10 => run::<10>(
            &sc.spacecraft,
            &y0,
            tf,
            &args.method,
            rtol,
            atol,
            args.repeats,
        ),
        27 => run::<27>(
            &sc.spacecraft,
            &y0,
            tf,
            &args.method,
            rtol,
            atol,
            args.repeats,
        ),
        n => Err(format!(
            "no fixed-size instance for {n} states (add it to the match in main)"
        )),
    };
    let o = match r {
        Ok(o) => o,
        Err(e) => {
            eprintln!("rust-ode-peer: {e}");
            return ExitCode::from(3);
        }
    };
    let cpu = o.cpu_all.iter().cloned().fold(f64::INFINITY, f64::min);
    let json = serde_json::json!({
        "peer": "differential-equations 0.7.0",
        "scenario": sc.name,
        "method": args.method,
        "settings": {"rtol": rtol, "atol": atol},
        "duration": tf,
        "final_time": o.t,
        "dim": dim,
        "initial_state": y0,
        "final_state": o.y,
        "cpu_seconds": cpu,
        "cpu_seconds_all": o.cpu_all,
        "steps": o.steps,
        "rejected_steps": o.rejected,
        "rhs_evaluations": o.evals,
    });
    println!("{json}");
    ExitCode::SUCCESS
}
