#!/usr/bin/env python3
"""Reference values of the IGRF-14 main field from two independent implementations, for
tests/igrf.rs (polhode::orbit::igrf).

References (igrf-requirements.txt pins them):
  * pyIGRF14 1.0.4: `calculate.igrf12syn(year, 2, r_km, lat, lon)`, the Python port of the
    IAGA Fortran synthesis routine, geocentric mode (itype = 2: `alt` is the radius in km,
    `lat` the geocentric latitude), reading igrf14coeffs.txt (the same file as
    data/igrf14coeffs.txt, byte for byte: checked below). Returns geocentric north, east,
    down (nT). Linear in the decimal year between models, 2025 model + SV after 2025.
  * ppigrf 2.1.0: `igrf_gc(r_km, colatitude_deg, lon_deg, datetime)`, its own Legendre
    recursion (Wertz) and its own coefficient packaging IGRF14.shc (with a 2030.0 column =
    2025.0 + 5 SV). Returns B_r, B_theta (south), B_phi (east) in nT; north = -B_theta,
    down = -B_r. Its time dependence is linear in *time* (pandas 'time' interpolation of
    datetimes) between the columns, so each epoch is drawn as a decimal year t, turned
    into the datetime at the same fraction of its five-year interval (rounded to the
    microsecond), and t is then recomputed from that datetime: both references and polhode
    see the same coefficients. ppigrf divides by sin(theta) for B_phi, so at an exact pole
    it gives NaN and is left out (null) there.

Everything is geocentric (spherical Earth of the IGRF, r from the Earth's centre): no
geodetic conversion is involved. Points: hand-placed ones (exact poles, within 0.01 deg of
both poles, the model epochs 1900.0, 1995.0, 2000.0, 2025.0, 2030.0, the SV interval,
0 and 2000 km), then random ones (seeded), uniform in area, altitude 0-2000 km above the
reference sphere (r = 6371.2 km + h), epoch 1900-2030.

The script also checks that the three packagings of the coefficients it can see agree:
data/igrf14coeffs.txt, pyIGRF14's igrf14coeffs.txt, ppigrf's IGRF14.shc, and the NCEI
geomaglib 1.2.4 IGRF14_sv.COF (exactly, and 2030 = 2025 + 5 SV to rounding).

Usage: python tests/reference/igrf_points.py   Writes tests/data/igrf14_reference.json.
"""
import datetime as dt
import hashlib
import json
import math
import os
import warnings
from importlib.metadata import version

import numpy as np
import ppigrf
import pyIGRF14
from pyIGRF14 import calculate

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(ROOT, "data", "igrf14coeffs.txt")
OUT = os.path.join(ROOT, "tests", "data", "igrf14_reference.json")
A_KM = 6371.2


def read_txt(path):
    lines = open(path).read().splitlines()
    epochs = [float(w) for w in next(l for l in lines if l.startswith("g/h")).split()[3:-1]]
    rows = {}
    for l in lines:
        w = l.split()
        if w and w[0] in ("g", "h"):
            rows[(w[0], int(w[1]), int(w[2]))] = [float(x) for x in w[3:]]
    return epochs, rows


def check_packagings():
    """Returns a summary of the agreement between the coefficient files."""
    ours = open(DATA, "rb").read()
    theirs_path = os.path.join(os.path.dirname(pyIGRF14.__file__), "src", "igrf14coeffs.txt")
    theirs = open(theirs_path, "rb").read()
    assert ours == theirs, "data/igrf14coeffs.txt differs from pyIGRF14's copy"
    epochs, txt = read_txt(DATA)
    assert epochs == [1900.0 + 5 * k for k in range(26)]
    assert len(txt) == 195
    # ppigrf's SHC: columns 1900..2030, key (n, m) with m < 0 for h.
    shc_rows = [l for l in open(ppigrf.ppigrf.shc_fn) if not l.startswith("#")]
    shc_years = [float(x) for x in shc_rows[1].split()]
    assert shc_years == [1900.0 + 5 * k for k in range(27)]
    worst_shc = 0.0
    for l in shc_rows[2:]:
        w = l.split()
        n, m = int(w[0]), int(w[1])
        v = [float(x) for x in w[2:]]
        t = txt[("g" if m >= 0 else "h", n, abs(m))]
        worst_shc = max(worst_shc, max(abs(v[i] - t[i]) for i in range(26)))
        worst_shc = max(worst_shc, abs(v[26] - (t[25] + 5 * t[26])))
    assert worst_shc < 1e-9, worst_shc
    # geomaglib's COF (NCEI): one block per epoch, "n m g h gdot hdot".
    import geomaglib

    cof_path = os.path.join(os.path.dirname(geomaglib.__file__), "cof", "IGRF14_sv.COF")
    cof, epoch = {}, None
    for l in open(cof_path):
        w = l.split()
        if not w:
            continue
        if not w[0].isdigit():
            epoch = float(w[1])
            cof[epoch] = {}
        elif len(w) >= 6:
            cof[epoch][(int(w[0]), int(w[1]))] = [float(x) for x in w[2:6]]
    assert sorted(cof) == epochs
    worst_cof, count = 0.0, 0
    for i, e in enumerate(epochs):
        for (n, m), (g, h, gd, hd) in cof[e].items():
            count += 1
            worst_cof = max(worst_cof, abs(g - txt[("g", n, m)][i]))
            if m > 0:
                worst_cof = max(worst_cof, abs(h - txt[("h", n, m)][i]))
            if e == 2025.0:
                worst_cof = max(worst_cof, abs(gd - txt[("g", n, m)][26]))
                if m > 0:
                    worst_cof = max(worst_cof, abs(hd - txt[("h", n, m)][26]))
    assert worst_cof == 0.0, worst_cof
    return {
        "data/igrf14coeffs.txt sha256": hashlib.sha256(ours).hexdigest(),
        "pyIGRF14 src/igrf14coeffs.txt": "byte-identical",
        "ppigrf IGRF14.shc": f"equal at 1900-2025, 2030 column = 2025 + 5 SV, "
        f"max |difference| {worst_shc:.1e} nT",
        "geomaglib 1.2.4 cof/IGRF14_sv.COF": f"equal ({count} (n, m, epoch) rows and the "
        f"2025-2030 SV), max |difference| {worst_cof} nT",
    }


def node_datetime(k):
    return dt.datetime(1900 + 5 * k, 1, 1)


def as_datetime(year):
    """The datetime at the same fraction of its five-year interval as `year`, and the
    decimal year recomputed from it (what pandas' time interpolation then uses)."""
    k = min(int((year - 1900.0) // 5), 25)
    frac = (year - (1900.0 + 5 * k)) / 5.0
    a, b = node_datetime(k), node_datetime(k + 1)
    span = b - a
    when = a + dt.timedelta(microseconds=round(frac * (span // dt.timedelta(microseconds=1))))
    frac = (when - a) / span
    return when, 1900.0 + 5 * k + 5.0 * frac


def hand_placed():
    """(year, radius_km, lat_deg, lon_deg): the edges."""
    h = lambda km: A_KM + km
    return [
        (2025.0, h(0), 90.0, 0.0),  # exact north pole, on the reference sphere
        (1965.0, h(500), -90.0, 37.0),  # exact south pole
        (2027.3, h(400), 89.995, 123.4),  # 0.005 deg from the pole, SV interval
        (1987.6, h(1500), 89.99, -60.0),
        (1900.0, h(0), -89.995, -170.0),
        (2030.0, h(2000), -89.99, 45.0),
        (2011.2, h(700), 89.9999, 10.0),
        (1995.0, h(300), 0.0, 0.0),
        (2000.0, h(0), 45.0, 90.0),
        (2025.0, h(800), -33.0, -45.0),  # model epoch, start of the SV
        (2030.0, h(0), -30.0, -60.0),  # end of validity (South Atlantic)
        (1900.0, h(2000), 60.0, 200.0),
        (1997.5, h(100), 20.0, -100.0),  # between a degree-10 and a degree-13 model
    ]


def main():
    summary = check_packagings()
    rng = np.random.default_rng(20241101)
    points = hand_placed()
    for _ in range(48):
        year = float(rng.uniform(1900.0, 2030.0))
        km = float(rng.uniform(0.0, 2000.0))
        lat = math.degrees(math.asin(rng.uniform(-1.0, 1.0)))
        lon = float(rng.uniform(-180.0, 180.0))
        points.append((year, A_KM + km, lat, lon))
    # A few more in 2025-2030 (the SV), where errors in the SV branch would show.
    for _ in range(6):
        year = float(rng.uniform(2025.0, 2030.0))
        km = float(rng.uniform(0.0, 2000.0))
        lat = math.degrees(math.asin(rng.uniform(-1.0, 1.0)))
        lon = float(rng.uniform(-180.0, 180.0))
        points.append((year, A_KM + km, lat, lon))

    out, worst = [], 0.0
    for year, r_km, lat, lon in points:
        when, year = as_datetime(year)
        colat = 90.0 - lat  # what pyIGRF14 forms internally, passed as is to ppigrf
        x, y, z, _ = calculate.igrf12syn(year, 2, r_km, lat, lon)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            br, bt, bp = ppigrf.igrf_gc(r_km, colat, lon, when)
        pp = [-float(bt.ravel()[0]), float(bp.ravel()[0]), -float(br.ravel()[0])]
        if not all(math.isfinite(v) for v in pp):
            pp = None
        else:
            worst = max(worst, max(abs(a - b) for a, b in zip(pp, (x, y, z))))
        out.append(
            {
                "year": year,
                "ppigrf_datetime": when.isoformat(),
                "radius_km": r_km,
                "lat_deg": lat,
                "lon_deg": lon,
                "pyigrf14_ned_nt": [x, y, z],
                "ppigrf_ned_nt": pp,
            }
        )
    doc = {
        "generator": "tests/reference/igrf_points.py",
        "packages": {p: version(p) for p in ("pyIGRF14", "ppigrf", "geomaglib", "numpy", "pandas")},
        "coefficients": summary,
        "conventions": "geocentric: radius_km from the Earth's centre, lat_deg geocentric "
        "latitude (colatitude = 90 - lat_deg), lon_deg east; year decimal (UTC); B as "
        "(north, east, down) = (-B_theta, B_phi, -B_r) in nT. ppigrf_ned_nt is null where "
        "ppigrf is not finite (exact poles).",
        "max_abs_difference_between_references_nt": worst,
        "points": out,
    }
    with open(OUT, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(f"{len(out)} points -> {os.path.relpath(OUT, ROOT)}; "
          f"max |pyIGRF14 - ppigrf| = {worst:.3e} nT")


if __name__ == "__main__":
    main()
