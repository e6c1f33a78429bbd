"""Memory held by a Result: resident memory after a run less before, against its raw size
n x columns x 8 bytes (every array is a view of one float64 buffer of that size).

    python python/benchmarks/memory.py [SCENARIO] [--samples N]

Default: scenarios/tennis-racket.yaml (26 telemetry columns, 100 samples per second) run for
N / 100 s, N = 10^6 samples. Also prints the peak resident memory (VmHWM) during the run,
less the resident memory before it.
"""

import argparse
import sys
from pathlib import Path

import polhode

REPO = Path(__file__).resolve().parents[2]


def status_kib(key):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    raise KeyError(key)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default=str(REPO / "scenarios/tennis-racket.yaml"))
    parser.add_argument("--samples", type=int, default=1_000_000)
    args = parser.parse_args()
    scenario = polhode.load(args.scenario)
    rate = (len(scenario.run(duration=1.0).t) - 1) / 1.0  # samples per second of sim time
    scenario.run(duration=0.01)  # everything loaded once
    before = status_kib("VmRSS")
    result = scenario.run(duration=(args.samples - 1) / rate)
    held = (status_kib("VmRSS") - before) * 1024
    peak = (status_kib("VmHWM") - before) * 1024
    n, width = len(result.t), len(result.telemetry)
    raw = n * width * 8
    print(f"scenario: {args.scenario}: {n} samples x {width} columns")
    print(f"raw size (n x columns x 8 B): {raw / 1e6:.1f} MB")
    print(f"held after the run:           {held / 1e6:.1f} MB = {held / raw:.3f} x raw")
    print(f"peak during the run:          {peak / 1e6:.1f} MB = {peak / raw:.3f} x raw")
    return 0


if __name__ == "__main__":
    sys.exit(main())
