"""Python's overhead on a run: `polhode run FILE --no-log` (the CLI, a subprocess) against
`polhode.load(FILE).run()` in this process, timed alternately, best of N each.

    python python/benchmarks/overhead.py [SCENARIO] [--repeat N] [--bin PATH]

The CLI's time includes its process start and the scenario's loading; Python's includes the
loading (`load`) and the result's conversion (arrays, events, summary as a dict), not the
interpreter's start nor `import polhode`. Prints both times and their ratio. Default
scenario: scenarios/explorer1.yaml (README's, Explorer 1 with hinged antennas).
"""

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import polhode

REPO = Path(__file__).resolve().parents[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default=str(REPO / "scenarios/explorer1.yaml"))
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument(
        "--bin",
        default=os.environ.get("POLHODE_BIN", str(REPO / "target/release/polhode")),
        help="the CLI binary (default $POLHODE_BIN or target/release/polhode)",
    )
    args = parser.parse_args()
    cli, py = [], []
    for _ in range(args.repeat):
        start = time.perf_counter()
        subprocess.run([args.bin, "run", args.scenario, "--no-log", "--quiet"], check=True)
        cli.append(time.perf_counter() - start)
        start = time.perf_counter()
        result = polhode.load(args.scenario).run()
        py.append(time.perf_counter() - start)
        del result
    best_cli, best_py = min(cli), min(py)
    print(f"scenario: {args.scenario}")
    print(f"cli    (polhode run --no-log): best {best_cli:.3f} s of {args.repeat}")
    print(f"python (load + run):           best {best_py:.3f} s of {args.repeat}")
    print(f"python / cli: {best_py / best_cli:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
