#!/usr/bin/env python3
"""E-folding times of Larets' spin in scenarios/larets-spin-down.yaml (docs/effectors.md,
"Larets and Stella"): runs the scenario to a CSV table and fits ln|ω| against time by least
squares over the first two days, the whole 20 days and the last five. Standard library only.

    python3 scripts/larets-fit.py [path/to/polhode] [extra polhode arguments...]
"""
import csv
import math
import subprocess
import sys
import tempfile
from pathlib import Path

root = Path(__file__).resolve().parent.parent
polhode = sys.argv[1] if len(sys.argv) > 1 else str(root / "target/release/polhode")
with tempfile.TemporaryDirectory() as tmp:
    table = Path(tmp) / "larets.csv"
    subprocess.run(
        [polhode, "run", str(root / "scenarios/larets-spin-down.yaml"), "--no-log", "--csv",
         str(table), *sys.argv[2:]],
        check=True, stdout=subprocess.DEVNULL)
    rows = list(csv.DictReader(table.open()))
day = 86400.0
t = [float(r["sim_time [s]"]) / day for r in rows]
w = [math.log(math.sqrt(sum(float(r[f"omega_{c} [rad/s]"]) ** 2 for c in "xyz"))) for r in rows]


def efold(lo, hi):
    pts = [(a, b) for a, b in zip(t, w) if lo <= a <= hi]
    n = len(pts)
    mt = sum(a for a, _ in pts) / n
    mw = sum(b for _, b in pts) / n
    slope = sum((a - mt) * (b - mw) for a, b in pts) / sum((a - mt) ** 2 for a, _ in pts)
    return -1.0 / slope


print(f"e-folding time of the spin (days): first 2 days {efold(0, 2):.2f}, "
      f"all 20 days {efold(0, 20):.2f}, last 5 days {efold(15, 20):.2f}")
