"""Explorer 1's flat spin from Python: the nutation angle of one run, and a campaign's
histogram of the flat-spin time. Writes two PNG files into the directory given.

    python python/examples/explorer1.py OUT_DIR [--runs 200] [--seed 7]

1. ``scenarios/explorer1-energy-sink.yaml``: Explorer 1 (1958) spun about its minor axis at
   78.54 rad/s, its whip antennas dissipating energy (an energy sink with the 2117 s time
   constant of the hinged-antenna model). The nutation angle (deg) grows from about 3 deg
   to a flat spin (near 90 deg) over four hours of sim time; the run takes a few seconds.
   -> ``explorer1_nutation.png``
2. A 200-run Monte Carlo campaign of the flat spin. Explorer 1's own campaign (the
   ``montecarlo:`` block of the same file) takes about 7 minutes for 200 runs on two cores,
   too long for an example that the test suite runs, so the campaign is that of
   ``tests/data/montecarlo-sink.yaml``: the same physics (a minor-axis spinner with an energy
   sink, 10 s time constant, 200 s of sim time) with dispersed rates, inertia, attitude and
   time constant, 200 runs in about a second. The histogram is of the time each run reaches
   80 deg of nutation (its flat-spin event; s).
   -> ``campaign_flat_spin_time.png``

Needs matplotlib and pyarrow (and polhode); the Agg backend draws without a display.
"""

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 (after the backend is chosen)
import numpy as np  # noqa: E402

import polhode  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
EXPLORER1 = REPO / "scenarios/explorer1-energy-sink.yaml"
CAMPAIGN = REPO / "tests/data/montecarlo-sink.yaml"


def nutation_plot(out):
    """Runs Explorer 1 and plots its nutation angle (deg) against time (h)."""
    result = polhode.load(EXPLORER1).run()
    hours = result.t / 3600.0
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=100)
    ax.plot(hours, result.telemetry["nutation_angle_deg"], lw=1.0, color="tab:blue")
    for k, event in enumerate(result.events):
        ax.axvline(event["t"] / 3600.0, color="tab:red", lw=0.8, ls="--")
        ax.annotate(
            f"{event['condition']}\nt = {event['t'] / 60:.0f} min",
            (event["t"] / 3600.0, 5.0 + 12.0 * k),
            xytext=(4, 0),
            textcoords="offset points",
            fontsize=8,
            color="tab:red",
        )
    ax.set_xlabel("sim time (h)")
    ax.set_ylabel("nutation angle (deg)")
    ax.set_ylim(0, 95)
    ax.set_title("Explorer 1 with an energy sink: minor-axis spin to flat spin")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    path = out / "explorer1_nutation.png"
    fig.savefig(path)
    plt.close(fig)
    return path, result


def campaign_histogram(out, runs, seed):
    """Runs the campaign and draws the histogram of the flat-spin time (s)."""
    campaign = polhode.montecarlo(polhode.load(CAMPAIGN), runs=runs, seed=seed)
    column = campaign.summary["ranking"]["by"]  # the flat-spin event's column, t_<condition>
    times = np.array(campaign.table.column(column).to_pylist(), dtype=float)
    reached = times[~np.isnan(times)]
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=100)
    ax.hist(reached, bins=25, color="tab:orange", edgecolor="black", lw=0.5)
    ax.set_xlabel(f"flat-spin time, {column} (s)")
    ax.set_ylabel("runs")
    ax.set_title(
        f"{campaign.summary['scenario']}: {len(reached)} of {campaign.runs} runs reach the "
        f"flat spin (seed {campaign.summary['seed']})"
    )
    ax.grid(alpha=0.3)
    fig.tight_layout()
    path = out / "campaign_flat_spin_time.png"
    fig.savefig(path)
    plt.close(fig)
    return path, campaign, reached


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="directory for the PNG files")
    parser.add_argument("--runs", type=int, default=200, help="campaign runs (default 200)")
    parser.add_argument("--seed", type=int, default=7, help="campaign seed (default 7)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    path, result = nutation_plot(args.out)
    final = result.telemetry["nutation_angle_deg"][-1]
    print(f"{path}: {len(result.t)} samples, final nutation {final:.2f} deg")
    path, campaign, reached = campaign_histogram(args.out, args.runs, args.seed)
    print(
        f"{path}: {campaign.runs} runs, flat spin in {len(reached)}, "
        f"median {np.median(reached):.1f} s"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
