//! Resources and time (issue 35 §3): breakpoints a few ulps from the end or from each other,
//! the thread cap, SIGTERM, the memory estimate, orbits near e = 1 and physical ranges.

mod common;

use polhode::orbit::{CentralBody, Elements, Orbit, kepler};
use polhode::sim::Status;

/// A microsatellite with discrete rate-damping wheels ticking at `rate` (Hz, ticks k·(1/rate))
/// and a wheel whose torque steps at m/`rate2` (computed by division, so a step time and a tick
/// can be a few ulps apart), run for `duration` s with `method`.
fn two_clock_scene(rate: f64, rate2: f64, duration: f64, method: &str) -> String {
    let steps: Vec<String> = (1..=40)
        .map(|m| format!("[{:?}, {:?}]", m as f64 / rate2, 1e-4 * (m % 3) as f64))
        .collect();
    let steps = steps.join(", ");
    format!(
        "name: ticks
body: {{mass: 100.0, principal: [12.0, 14.0, 9.0]}}
effectors:
  - wheel:
      name: rw
      axial_inertia: 0.01
      transverse_inertia: 0.006
      axis: [0.8164966, 0.0, 0.5773503]
      max_torque: 0.02
      motor: {{rate_damping: {{gain: 0.5, sample_rate: {rate:?}}}}}
      copies: {{count: 3, about: [0, 0, 1]}}
  - wheel:
      name: aux
      axial_inertia: 0.01
      axis: [0, 0, 1]
      motor: {{torque: {{steps: [{steps}]}}}}
initial: {{omega: [0.03, -0.035, 0.025]}}
duration: {duration:?}
integrator: {{method: {method}, rtol: 1.0e-10, atol: 1.0e-12}}
output: {{rate: 10}}
"
    )
}

/// Every (rate, duration) pair of ordinary values completes with dop853 and radau5: a
/// controller tick a few ulps before the end (or two clocks' ticks a few ulps apart) is
/// merged with it instead of asking the integrator for a step below the resolution of t.
/// Before the fix, `sample_rate: 3.0` with `duration: 1.6666666666666667` failed with a step
/// size underflow, as did dozens of the pairs below.
#[test]
fn ticks_within_ulps_of_the_end_or_of_each_other_are_merged() {
    let rates = [
        1.0, 2.0, 3.0, 4.0, 6.0, 7.0, 9.0, 10.0, 11.0, 12.0, 13.0, 0.3, 0.7, 1.1, 2.9, 4.4, 6.6,
        7.7, 9.9, 17.0,
    ];
    let mut durations = Vec::new();
    for q in [3.0, 6.0, 7.0, 9.0, 11.0, 13.0] {
        for m in 1..=6 {
            durations.push(m as f64 / q);
        }
    }
    for m in 1..=6 {
        durations.push(0.1 * m as f64);
    }
    durations.push(1.6666666666666667);
    let mut failed = Vec::new();
    let mut runs = 0;
    for method in ["dop853", "radau5"] {
        for (i, &rate) in rates.iter().enumerate() {
            let rate2 = rates[(i * 7 + 3) % rates.len()];
            for &duration in &durations {
                let s = common::scenario(&two_clock_scene(rate, rate2, duration, method));
                let (out, _) = common::run(&s);
                runs += 1;
                if !matches!(out.status, Status::Complete) {
                    failed.push(format!(
                        "{method} rate {rate:?} & {rate2:?} Hz, duration {duration:?} s: {}",
                        out.status.diagnosis().unwrap_or("")
                    ));
                }
            }
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {runs} runs failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
}

/// A double-double number `hi + lo` (about 32 significant digits), for the test's independent
/// high-precision evaluation of the orbit near e = 1.
#[derive(Clone, Copy, Debug)]
struct Dd(f64, f64);

impl Dd {
    fn of(x: f64) -> Dd {
        Dd(x, 0.0)
    }
    fn add(self, b: Dd) -> Dd {
        let s = self.0 + b.0;
        let bb = s - self.0;
        let err = (self.0 - (s - bb)) + (b.0 - bb);
        let lo = err + self.1 + b.1;
        let hi = s + lo;
        Dd(hi, lo - (hi - s))
    }
    fn neg(self) -> Dd {
        Dd(-self.0, -self.1)
    }
    fn sub(self, b: Dd) -> Dd {
        self.add(b.neg())
    }
    fn mul(self, b: Dd) -> Dd {
        let p = self.0 * b.0;
        let err = self.0.mul_add(b.0, -p);
        let lo = err + self.0 * b.1 + self.1 * b.0;
        let hi = p + lo;
        Dd(hi, lo - (hi - p))
    }
    fn div(self, b: Dd) -> Dd {
        let q = self.0 / b.0;
        let r = self.sub(b.mul(Dd::of(q)));
        Dd::of(q).add(Dd::of(r.0 / b.0))
    }
}

/// `x − sin x` and `1 − cos x` for |x| < 1 by their series, in double-double.
fn dd_x_minus_sin_and_one_minus_cos(x: Dd) -> (Dd, Dd) {
    let x2 = x.mul(x);
    let (mut xs, mut oc) = (Dd::of(0.0), Dd::of(0.0));
    // Terms x^(2k+1)/(2k+1)! and x^(2k)/(2k)!, alternating from k = 1.
    let mut even = x2.div(Dd::of(2.0));
    let mut odd = x2.mul(x).div(Dd::of(6.0));
    for k in 1..30 {
        let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
        oc = oc.add(even.mul(Dd::of(sign)));
        xs = xs.add(odd.mul(Dd::of(sign)));
        let n = 2.0 * k as f64;
        even = even.mul(x2).div(Dd::of((n + 1.0) * (n + 2.0)));
        odd = odd.mul(x2).div(Dd::of((n + 2.0) * (n + 3.0)));
    }
    (xs, oc)
}

/// The perifocal x = a(cos E − e) and the radius r = a(1 − e cos E) for mean anomaly `m`
/// (small) and `e ≥ ½`, from Kepler's equation solved by Newton's method in double-double.
fn dd_perifocal_x_and_r(a: f64, e: f64, m: f64) -> (f64, f64) {
    let one_minus_e = Dd::of(1.0).sub(Dd::of(e));
    let e_dd = Dd::of(e);
    let mut x = Dd::of(kepler::eccentric_anomaly(m, e));
    for _ in 0..8 {
        let (xs, oc) = dd_x_minus_sin_and_one_minus_cos(x);
        let f = one_minus_e.mul(x).add(e_dd.mul(xs)).sub(Dd::of(m));
        let fp = one_minus_e.add(e_dd.mul(oc));
        x = x.sub(f.div(fp));
    }
    let (_, oc) = dd_x_minus_sin_and_one_minus_cos(x);
    let px = Dd::of(a).mul(one_minus_e.sub(oc));
    let r = Dd::of(a).mul(one_minus_e.add(e_dd.mul(oc)));
    (px.0 + px.1, r.0 + r.1)
}

/// As e → 1 with a huge semi-major axis, the perigee position keeps its digits: a(cos E − e)
/// is formed as a((1 − e) − (1 − cos E)), not from cos E, which rounds to 1 and leaves
/// noise of a·ε in a difference of size a(1 − e). Checked against an independent
/// double-double solution of Kepler's equation.
#[test]
fn the_position_near_e_one_matches_a_high_precision_evaluation() {
    let mut worst: f64 = 0.0;
    for (a, one_minus_e) in [(1e16, 2f64.powi(-30)), (1e13, 2f64.powi(-20)), (1e10, 1e-3)] {
        let e = 1.0 - one_minus_e;
        let orbit = Orbit::new(
            CentralBody::EARTH,
            Elements::new(a, e, 0.0, 0.0, 0.0, 0.0),
            false,
        )
        .unwrap();
        let n = orbit.mean_motion();
        for m in [1e-15, 1e-13, 1e-11, 1e-9, 3e-8, 1e-6, 1e-4, 1e-3] {
            let t = m / n;
            let m_used = orbit.mean_anomaly(t);
            let (x_ref, r_ref) = dd_perifocal_x_and_r(a, e, m_used);
            let (pos, _) = orbit.state(t);
            let radius = orbit.radius(t);
            // The axes are P̂ = x̂, Q̂ = ŷ (Ω = ω = i = 0).
            let ex = (pos.x - x_ref).abs() / r_ref;
            let er = (radius - r_ref).abs() / r_ref;
            assert!(
                ex < 1e-13 && er < 1e-13,
                "a {a:e} m, 1 − e = {one_minus_e:e}, M = {m_used:e}: x {} vs {x_ref} \
                 (relative {ex:e}), r {radius} vs {r_ref} (relative {er:e})",
                pos.x
            );
            worst = worst.max(ex).max(er);
        }
    }
    assert!(worst < 1e-13, "{worst:e}");
}

fn polhode() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_polhode"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-limits", name)
}

/// A campaign of `runs` short rigid-body runs.
fn campaign_yaml(runs: u64, duration: f64) -> String {
    format!(
        "name: camp
body: {{principal: [1.0, 2.0, 3.0]}}
initial: {{omega: [0.1, 0.0, 1.0]}}
duration: {duration:?}
integrator: {{method: dop853, rtol: 1.0e-10, atol: 1.0e-12}}
output: {{rate: 1}}
montecarlo:
  runs: {runs}
  seed: 1
  dispersions:
    - {{path: \"initial.omega[0]\", normal: {{sd: 0.01}}}}
"
    )
}

/// Waits for `child` at most `limit`; kills it (by its own id) and returns `None` past that.
fn wait_at_most(
    child: &mut std::process::Child,
    limit: std::time::Duration,
) -> Option<std::process::ExitStatus> {
    let start = std::time::Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return Some(s);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// `--threads 100000` is capped at a small multiple of the logical cores, with a message, and
/// the campaign runs at once (before: a pool of 10⁵ threads took minutes to start).
#[test]
fn threads_are_capped_with_a_message() {
    let dir = scratch("threads");
    let file = dir.join("camp.yaml");
    std::fs::write(&file, campaign_yaml(4, 1.0)).unwrap();
    let mut child = polhode()
        .args([
            "montecarlo",
            file.to_str().unwrap(),
            "--threads",
            "100000",
            "--out",
        ])
        .arg(dir.join("out"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let status = wait_at_most(&mut child, std::time::Duration::from_secs(60));
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(status.is_some_and(|s| s.success()), "{status:?}: {err}");
    let cap = polhode::montecarlo::max_threads();
    assert!(
        err.contains(&format!("--threads 100000: capped at {cap} (4 × ")),
        "{err}"
    );
    assert!(err.contains(&format!("on {cap} thread(s)")), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// SIGTERM stops a campaign as promptly as Ctrl-C, also one asked for 10⁵ threads: exit 130
/// within seconds, the runs finished so far written.
#[test]
fn sigterm_stops_a_campaign_promptly() {
    let dir = scratch("sigterm");
    let file = dir.join("camp.yaml");
    std::fs::write(&file, campaign_yaml(200_000, 200.0)).unwrap();
    for threads in ["1", "100000"] {
        let mut child = polhode()
            .args([
                "montecarlo",
                file.to_str().unwrap(),
                "--threads",
                threads,
                "--out",
            ])
            .arg(dir.join(format!("out-{threads}")))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(1500));
        // SAFETY: signals our own child process by its id.
        unsafe {
            libc::kill(child.id() as libc::pid_t, libc::SIGTERM);
        }
        let status = wait_at_most(&mut child, std::time::Duration::from_secs(20));
        assert_eq!(
            status.and_then(|s| s.code()),
            Some(130),
            "--threads {threads}: SIGTERM did not stop the campaign within 20 s"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

const RIGID: &str = "name: rigid
body: {principal: [1.0, 2.0, 3.0]}
initial: {omega: [0.1, 0.0, 1.0]}
duration: 2.0
integrator: {method: dopri5, rtol: 1.0e-10, atol: 1.0e-12}
output: {rate: 10}
";

/// `polhode check` on `yaml` (written to DIR/s.yaml): exit code and stderr.
fn check(name: &str, yaml: &str) -> (Option<i32>, String) {
    let dir = scratch(name);
    let file = dir.join("s.yaml");
    std::fs::write(&file, yaml).unwrap();
    let out = polhode().arg("check").arg(&file).output().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Absurd sizes are refused at load with file, line, field and the bound (before: `check`
/// passed them and the run failed at t = 0 with a generic "non-finite" message).
#[test]
fn absurd_sizes_are_refused_at_load() {
    let cases = [
        (
            RIGID.replace(
                "principal: [1.0, 2.0, 3.0]}",
                "principal: [1.0, 2.0, 3.0], shape: {box: {size: [1e200, 1, 1]}}}",
            ),
            "s.yaml:2:",
            "size",
        ),
        (
            format!("{RIGID}orbit: {{semi_major_axis_km: 1e300, eccentricity: 0.5}}\n"),
            "s.yaml:7:",
            "orbit.semi_major_axis_km",
        ),
        (
            format!(
                "{RIGID}effectors:\n  - wheel:\n      name: w\n      axial_inertia: 0.01\n      \
                 axis: [0, 0, 1]\n      motor: {{torque: {{constant: 1e300}}}}\n"
            ),
            "s.yaml:12:",
            "constant",
        ),
    ];
    for (yaml, at, field) in cases {
        let (code, err) = check("absurd", &yaml);
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains(at) && err.contains(field),
            "{at} {field}: {err}"
        );
        assert!(err.contains("beyond any plausible value"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// Vectors are normalised by their largest component first: [1e200, 1e200, 0] does not
/// overflow and [1e-300, 1e-300, 0] is not zero.
#[test]
fn huge_and_tiny_vectors_normalise() {
    for axis in ["[1e11, 1e11, 0]", "[1e-300, 1e-300, 0]"] {
        let yaml = RIGID.replace(
            "principal: [1.0, 2.0, 3.0]}",
            &format!("principal: [1.0, 2.0, 3.0], spin_axis: {axis}}}"),
        );
        let (code, err) = check("vectors", &yaml);
        assert_eq!(code, Some(0), "spin_axis {axis}: {err}");
    }
    for v in [
        [1e200, 1e200, 0.0],
        [1e-300, 1e-300, 0.0],
        [5e-324, 0.0, 0.0],
    ] {
        let u = polhode::scenario::unit_vector(&nalgebra::Vector3::from(v)).unwrap();
        assert!((u.norm() - 1.0).abs() < 1e-15, "{v:?}: {u:?}");
    }
}

/// A run whose stored samples would pass the memory limit is refused before it starts, with
/// the numbers (`polhode compare` keeps each row's series).
#[test]
fn stored_samples_past_the_memory_limit_are_refused() {
    let dir = scratch("memory");
    let file = dir.join("s.yaml");
    std::fs::write(&file, RIGID.replace("duration: 2.0", "duration: 1.0e6")).unwrap();
    let out = polhode()
        .arg("compare")
        .arg(&file)
        .env(polhode::resources::MAX_MEMORY_ENV, "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("would take about 160 MB (1e7 samples = rate 10 Hz × duration 1e6 s"),
        "{err}"
    );
    assert!(
        err.contains("above the limit of 1.0 MB (set by POLHODE_MAX_MEMORY_MB)"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The case through the command line: a 3 Hz controller and a duration of 5/3 s.
#[test]
fn the_reported_tick_before_the_end_completes() {
    let dir = scratch("tick");
    let file = dir.join("r.yaml");
    let yaml = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/rwa-rate-damping.yaml"
    ))
    .unwrap()
    .replace("sample_rate: 10.0", "sample_rate: 3.0");
    std::fs::write(&file, yaml).unwrap();
    for method in ["dop853", "radau5"] {
        let out = polhode()
            .args([
                "run",
                file.to_str().unwrap(),
                "--no-log",
                "-q",
                "--method",
                method,
            ])
            .args(["--duration", "1.6666666666666667"])
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{method}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
