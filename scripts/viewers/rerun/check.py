#!/usr/bin/env python3
"""Checks that a polhode log reaches Rerun whole, raw and converted, and that a screenshot shows it.

    python check.py run.mcap [--rrd run.rrd] [--png shot.png] [--fields src/log/telemetry.rs]

The reference is the MCAP decoded with the `mcap` reader and the protobuf schemas embedded in
it. Against it, this compares what Rerun itself reads (its own chunk readers, `rerun.chunk`):

- the raw MCAP as the Rerun viewer opens it: every `/tf` sample becomes a Transform3D with the
  same rotation, every telemetry and effector channel a struct column with all the schema's
  fields and the same values, `/log` a TextLog;
- the converted .rrd (mcap_to_rrd.py): a recording and a blueprint; per `/tf` frame a
  Transform3D per sample (same rotation), per numeric field a Scalars series with the same
  values on the `sim_time` and `message_log_time` timelines (`sim_time` equal to the field
  `sim_time`), the scene's body and omega/H arrows once per `/scene` update, the text log;
- with --fields, that the telemetry schema lists `FIELDS` of telemetry.rs, in order;
- with --png, a screenshot of the converted recording with its blueprint (window 1600x1000):
  not blank, the body in the 3D view (solid blocks of its grey), and a line across each of the
  four plots (their series colours over most of the width); with --orbit as well, the orbit
  view under the body's: the Earth (solid blue blocks), the orbit path (its cyan) and the
  spacecraft marker (magenta);
- with --effectors N, at least N pixels of the effectors' red in the body's view (wheel discs
  seen through the translucent body);
- with --omega-decays F, that |ω| at the end of the log is at most F times |ω| at its start
  (what the ω plot of a detumbling or rate-damping run shows);
- for a log with the orbit view, the Earth's sphere at the one `/earth` update and the orbit
  path and marker at every `/orbit_scene` update.

Prints one line per check and exits 1 if any failed.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import rerun.chunk as rc
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

LOG = "message_log_time"
SIM = "sim_time"

failures: list[str] = []


def report(ok: bool, what: str) -> bool:
    print(f"  {'ok  ' if ok else 'FAIL'} {what}")
    if not ok:
        failures.append(what)
    return ok


# ---------------------------------------------------------------------------------------------
# Reference: the MCAP through the mcap reader.


def reference(path: Path) -> dict:
    ref = dict(tf=defaultdict(lambda: ([], [])), series={}, fields={}, scene=defaultdict(int), logs=defaultdict(int))
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, ch, msg, dec in reader.iter_decoded_messages(log_time_order=False):
            name = schema.name
            if name == "foxglove.FrameTransforms":
                for t in dec.transforms:
                    times, quats = ref["tf"][t.child_frame_id]
                    times.append(msg.log_time)
                    r = t.rotation
                    quats.append((r.x, r.y, r.z, r.w))
            elif name == "foxglove.SceneUpdate":
                ref["scene"][ch.topic] += 1
            elif name == "foxglove.Log":
                ref["logs"][ch.topic] += 1
            elif not name.startswith("foxglove."):
                fields = ref["fields"].setdefault(ch.topic, [fd.name for fd in dec.DESCRIPTOR.fields])
                times, rows = ref["series"].setdefault(ch.topic, ([], []))
                times.append(msg.log_time)
                rows.append([getattr(dec, k) for k in fields])
    for k, (t, q) in list(ref["tf"].items()):
        o = np.argsort(t, kind="stable")
        ref["tf"][k] = (np.array(t, np.int64)[o], np.array(q, float)[o])
    for k, (t, v) in list(ref["series"].items()):
        o = np.argsort(t, kind="stable")
        ref["series"][k] = (np.array(t, np.int64)[o], np.array(v, float).reshape(len(t), -1)[o])
    return ref


# ---------------------------------------------------------------------------------------------
# Rerun's side: chunks grouped by entity, one column read back in log-time order.


def by_entity(chunks) -> dict[str, list[pa.RecordBatch]]:
    out = defaultdict(list)
    for ch in chunks:
        if not ch.is_static:
            out[ch.entity_path].append(ch.to_record_batch())
    return out


def column(batches: list[pa.RecordBatch], name: str, index: str = LOG):
    """(index values as int64 ns, list array of the column) over the rows where it is set."""
    times, values = [], []
    for rb in batches:
        if name not in rb.schema.names or index not in rb.schema.names:
            continue
        col = rb.column(name)
        keep = pc.is_valid(col)
        times.append(pc.filter(rb.column(index), keep).cast(pa.int64()).to_numpy())
        values.append(pc.filter(col, keep))
    if not times:
        return np.zeros(0, np.int64), None
    t = np.concatenate(times)
    v = pa.concat_arrays([a.combine_chunks() if isinstance(a, pa.ChunkedArray) else a for a in values])
    o = np.argsort(t, kind="stable")
    return t[o], v.take(pa.array(o))


def quats(arr: pa.Array) -> np.ndarray:
    """list<fixed_size_list<float, 4>> with one quaternion per row -> (n, 4)."""
    inner = pc.list_flatten(arr)
    return np.asarray(pc.list_flatten(inner).to_numpy(zero_copy_only=False), float).reshape(-1, 4)


def same_rotation(a: np.ndarray, b: np.ndarray) -> float:
    """Largest difference between rotations (q and -q are the same), as 1 - |q_a . q_b|."""
    if len(a) != len(b) or not len(a):
        return float("inf")
    return float(np.max(1.0 - np.abs(np.sum(a * b, axis=1))))


# ---------------------------------------------------------------------------------------------


def check_fields(ref: dict, rs_path: Path) -> None:
    print(f"telemetry fields vs {rs_path}")
    text = rs_path.read_text()
    m = re.search(r"pub const FIELDS: \[&str; (\d+)\] = \[(.*?)\];", text, re.S)
    if not report(m is not None, "FIELDS found in telemetry.rs"):
        return
    fields = re.findall(r'"([^"]+)"', m.group(2))
    report(len(fields) == int(m.group(1)), f"{len(fields)} names for [&str; {m.group(1)}]")
    for topic, names in ref["fields"].items():
        if topic.endswith("/telemetry") or topic == "/telemetry":
            report(names == fields, f"{topic} schema fields == FIELDS ({len(names)})")


def check_raw(mcap: Path, ref: dict) -> None:
    print(f"raw MCAP as Rerun opens it: {mcap}")
    ents = by_entity(rc.McapReader(str(mcap)).stream())
    for frame, (t_ref, q_ref) in ref["tf"].items():
        topic = next((p for p in ents if p.endswith("/tf") and frame.startswith(p[1:-3])), "/tf")
        batches = ents.get(topic, [])
        if not batches:
            # A frame the runs of a campaign file share (`world`, `ecef`): in every run's /tf.
            batches = [b for p in ents if p.endswith("/tf") for b in ents[p]]
        t, arr = column(batches, "Transform3D:quaternion")
        # A /tf message with several transforms (body and lvlh, for a scenario with an orbit)
        # gives one row per transform: keep this frame's rows.
        _, child = column(batches, "Transform3D:child_frame")
        if arr is not None and child is not None and len(child) == len(arr):
            keep = np.array([bool(c) and c[0] == frame for c in child.to_pylist()], bool)
            t, arr = t[keep], arr.filter(pa.array(keep))
        n = 0 if arr is None else len(arr)
        if report(n == len(t_ref), f"{topic}: {n} Transform3D rows for {len(t_ref)} samples of frame {frame}"):
            report(np.array_equal(t, t_ref), f"{topic}: same log times")
            d = same_rotation(quats(arr), q_ref)
            report(d < 1e-6, f"{topic}: same rotations (max 1-|q.q'| = {d:.1e})")
    for topic, (t_ref, v_ref) in ref["series"].items():
        batches = ents.get(topic, [])
        names = [n for rb in batches for n in rb.schema.names if n.endswith(":message")]
        if not report(bool(names), f"{topic}: decoded as a struct column ({names[:1] or 'none'})"):
            continue
        t, arr = column(batches, names[0])
        structs = pc.list_flatten(arr)
        fields = [structs.type.field(i).name for i in range(structs.type.num_fields)]
        want = ref["fields"][topic]
        report(all(f in fields for f in want), f"{topic}: all {len(want)} schema fields present")
        got = np.column_stack([structs.field(f).to_numpy(zero_copy_only=False) for f in want])
        report(
            len(got) == len(v_ref) and np.array_equal(got, v_ref),
            f"{topic}: {len(got)} rows, values identical to the mcap reader's",
        )
    for topic, n_ref in ref["logs"].items():
        t, arr = column(ents.get(topic, []), "TextLog:text")
        report(arr is not None and len(arr) == n_ref, f"{topic}: {0 if arr is None else len(arr)} TextLog rows of {n_ref}")


def check_rrd(rrd: Path, ref: dict) -> None:
    print(f"converted recording: {rrd}")
    reader = rc.RrdReader(str(rrd))
    recs, bps = reader.recordings(), reader.blueprints()
    report(len(recs) == 1, f"{len(recs)} recording ({recs[0].application_id if recs else '-'})")
    report(len(bps) >= 1, f"{len(bps)} blueprint embedded")
    ents = by_entity(reader.stream())

    for frame, (t_ref, q_ref) in ref["tf"].items():
        path = next((p for p in ents if p.endswith("/" + frame.split("/")[-1]) and _frame_match(p, frame)), None)
        t, arr = column(ents.get(path, []), "Transform3D:quaternion")
        n = 0 if arr is None else len(arr)
        if report(n == len(t_ref), f"{path}: {n} Transform3D rows for {len(t_ref)} /tf samples of {frame}"):
            report(np.array_equal(t, t_ref), f"{path}: log times equal to the MCAP's")
            d = same_rotation(quats(arr), q_ref)
            report(d < 1e-6, f"{path}: same rotations (float32; max 1-|q.q'| = {d:.1e})")

    n_fields = 0
    for topic, (t_ref, v_ref) in ref["series"].items():
        fields = ref["fields"][topic]
        bad = []
        for j, f in enumerate(fields):
            t, arr = column(ents.get(f"{topic}/{f}", []), "Scalars:scalars")
            if arr is None or len(arr) != len(t_ref) or not np.array_equal(t, t_ref):
                bad.append(f)
                continue
            v = pc.list_flatten(arr).to_numpy(zero_copy_only=False)
            if len(v) != len(v_ref) or not np.array_equal(v, v_ref[:, j]):
                bad.append(f)
        n_fields += len(fields) - len(bad)
        report(not bad, f"{topic}: {len(fields) - len(bad)}/{len(fields)} fields as Scalars, {len(t_ref)} samples, identical" + (f" (bad: {bad[:5]})" if bad else ""))
        if "sim_time" in fields:
            ts, arr = column(ents.get(f"{topic}/sim_time", []), "Scalars:scalars", index=SIM)
            if arr is not None and len(arr):
                err = np.max(np.abs(ts * 1e-9 - pc.list_flatten(arr).to_numpy(zero_copy_only=False)))
                report(err < 2e-9, f"{topic}: sim_time timeline equals the sim_time field (max {err:.1e} s)")
            else:
                report(False, f"{topic}: sim_time timeline")

    for topic, n_scene in ref["scene"].items():
        if topic.endswith(("/earth", "/orbit_scene")):
            # The orbit view (docs/logs.md): the Earth's sphere once; per update the orbit path
            # and the spacecraft marker.
            # (A campaign run's entities in the shared frames carry the run's name.)
            run = topic[: topic.rfind("/")].strip("/")
            tag = f"_{run}" if run else ""
            want = {
                "/earth": [f"/earth{tag}/spheres"],
                "/orbit_scene": [f"/orbit_path{tag}/lines", f"/spacecraft_marker{tag}/spheres"],
            }
            for leaf in want[topic[topic.rfind("/"):]]:
                p = next((p for p in ents if p.endswith(leaf)), None)
                col = next((c for c in ents[p][0].schema.names if c.endswith((":centers", ":strips"))), None) if p else None
                n = len(column(ents.get(p, []), col)[0]) if col else 0
                report(n == n_scene, f"{topic}: {leaf.strip('/')} at {p} in {n} of {n_scene} updates")
            continue
        bodies = [p for p in ents if p.endswith(("/cubes", "/cylinders"))]
        rows = {p: len(column(ents[p], next(c for c in ents[p][0].schema.names if c.endswith((":centers"))))[0]) for p in bodies}
        report(bool(bodies) and all(n == n_scene for n in rows.values()), f"{topic}: body drawn at {sorted(rows.items())} of {n_scene} updates")
        for name in ("omega", "H"):
            p = next((p for p in ents if p.endswith(f"/arrows/{name}")), None)
            n = len(column(ents.get(p, []), "Arrows3D:vectors")[0])
            report(n == n_scene, f"{topic}: {name} arrow at {p} in {n} of {n_scene} updates")

    for topic, n_ref in ref["logs"].items():
        t, arr = column(ents.get(topic, []), "TextLog:text")
        report(arr is not None and len(arr) == n_ref, f"{topic}: {0 if arr is None else len(arr)} TextLog rows of {n_ref}")


def _frame_match(path: str, frame: str) -> bool:
    return path.rstrip("/").endswith("/" + "/".join(x for x in frame.split("/") if x))


# ---------------------------------------------------------------------------------------------
# The screenshot. Regions are fractions of the image for the blueprint of mcap_to_rrd.py
# (3D view at the top left, four plots stacked on the right).

PLOTS = [
    ("ω", (0.06, 0.26), (62, 142, 232)),  # ω_z
    ("nutation", (0.29, 0.49), (165, 110, 255)),
    ("T", (0.52, 0.73), (245, 158, 11)),
    ("dissipated", (0.755, 0.965), (229, 72, 77)),  # roll, in the same red, with an orbit
]

# With an orbit (--orbit): the body's view and the orbit view share the left column.
BODY_VIEW = (0.08, 0.72)
BODY_VIEW_ORBIT = (0.06, 0.40)
ORBIT_VIEW = (0.44, 0.80)
PATH_RGB = (77, 242, 242)  # the orbit path, (0.3, 0.95, 0.95) in src/log/orbit_scene.rs


def check_png(png: Path, orbit: bool = False, min_effector: int = 0) -> dict:
    from PIL import Image

    print(f"screenshot: {png}")
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    h, w, _ = img.shape
    stats = dict(size=f"{w}x{h}")
    gray = img.mean(axis=2)
    colors = len(np.unique((img // 8).reshape(-1, 3), axis=0))
    stats.update(std=round(float(gray.std()), 1), colors=colors)
    report(gray.std() > 12 and colors > 200, f"not blank: grey std {gray.std():.1f}, {colors} distinct colours (/8)")

    def region(y0, y1, x0, x1):
        return img[int(y0 * h) : int(y1 * h), int(x0 * w) : int(x1 * w)]

    # Solid blocks of the body's light grey and of the H arrow's blue: text and thin lines
    # (tables, labels, grid) fill no whole block.
    view = region(*(BODY_VIEW_ORBIT if orbit else BODY_VIEW), 0.01, 0.54)
    k = max(2, w // 400)  # block side: 8 px in a 3200 px wide image

    def blocks(mask):
        hh, ww = (mask.shape[0] // k) * k, (mask.shape[1] // k) * k
        return int(mask[:hh, :ww].reshape(hh // k, k, ww // k, k).all(axis=(1, 3)).sum())

    r, g, b = view[..., 0], view[..., 1], view[..., 2]
    lo, hi = view.min(axis=2), view.max(axis=2)
    body = blocks((lo > 140) & (hi - lo < 45))
    stats.update(body_blocks=body)
    # In orbit the body's view is shorter and the gravity-gradient smallsat a slim box.
    min_body = 15 if orbit else 30
    report(body >= min_body, f"3D view: body, {body} solid light-grey {k}x{k} blocks (>= {min_body})")
    # Arrows can be thin or short (omega in a flat spin): counted, not required.
    blue = np.mean((b > 170) & (b - r > 90) & (g > 70) & (g < 200))
    orange = np.mean((r > 190) & (g > 90) & (g < 190) & (b < 90))
    stats.update(blue_pct=round(100 * blue, 3), orange_pct=round(100 * orange, 3))
    print(f"  info 3D view: H-arrow blue on {100 * blue:.3f}%, omega-arrow orange on {100 * orange:.3f}% of it")
    if min_effector:
        # The effectors' red, rgb(217, 51, 64) in src/log/mod.rs, alone or through the body's
        # translucent grey: red over green, a little blue over green (the omega arrow's orange
        # has less blue than green).
        r, g, b = view[..., 0], view[..., 1], view[..., 2]
        eff = int(((r >= 100) & (r - g >= 12) & (b - g >= 4) & (r - b >= 5)).sum())
        stats.update(effector_pixels=eff)
        report(eff >= min_effector, f"3D view: effectors, {eff} pixels of their red (>= {min_effector})")

    if orbit:
        ov = region(*ORBIT_VIEW, 0.01, 0.54)
        r, g, b = ov[..., 0], ov[..., 1], ov[..., 2]
        earth = blocks((b >= 70) & (b - r >= 40) & (b - g >= 15))
        path = int((np.abs(ov - np.array(PATH_RGB)).max(axis=2) <= 40).sum())
        marker = int(((r >= 150) & (b >= 110) & (r - g >= 90) & (b - g >= 60)).sum())
        stats.update(earth_blocks=earth, path_pixels=path, marker_pixels=marker)
        report(earth >= 100, f"orbit view: Earth, {earth} solid blue {k}x{k} blocks (>= 100)")
        report(path >= 200, f"orbit view: orbit path, {path} pixels of its cyan (>= 200)")
        report(marker >= 20, f"orbit view: spacecraft marker, {marker} magenta pixels (>= 20)")

    for name, (y0, y1), rgb in PLOTS:
        plot = region(y0, y1, 0.57, 0.995)
        near = np.sqrt(((plot - np.array(rgb)) ** 2).sum(axis=2)) < 60
        cols = np.flatnonzero(near.any(axis=0))
        span = (cols.max() - cols.min()) / plot.shape[1] if len(cols) else 0.0
        stats[f"plot_{name}"] = dict(pct=round(100 * near.mean(), 2), span=round(span, 2))
        report(
            near.mean() > 0.002 and span > 0.6,
            f"plot '{name}': series colour {rgb} on {100 * near.mean():.2f}% of it, across {100 * span:.0f}% of its width",
        )
    return stats


def check_omega_decays(ref: dict, factor: float) -> None:
    print("omega decays")
    t, v = ref["series"].get("/telemetry", (None, None))
    fields = ref["fields"].get("/telemetry", [])
    if not report(t is not None and len(t) > 1 and "omega_x" in fields, "/telemetry has omega"):
        return
    j = fields.index("omega_x")
    w = np.linalg.norm(v[:, j : j + 3], axis=1)
    report(w[-1] <= factor * w[0], f"|ω| from {w[0]:.4g} to {w[-1]:.4g} rad/s (<= {factor} of the start)")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mcap", type=Path)
    ap.add_argument("--rrd", type=Path, help="converted recording to check")
    ap.add_argument("--png", type=Path, help="screenshot to check")
    ap.add_argument("--fields", type=Path, help="src/log/telemetry.rs, to check FIELDS")
    ap.add_argument("--no-raw", action="store_true", help="skip the raw MCAP through Rerun")
    ap.add_argument("--orbit", action="store_true", help="the screenshot has the orbit view (--png)")
    ap.add_argument("--effectors", type=int, default=0, help="least pixels of the effectors' red (--png)")
    ap.add_argument("--omega-decays", type=float, help="|ω| at the end at most this times the start")
    args = ap.parse_args()
    ref = reference(args.mcap)
    if args.fields:
        check_fields(ref, args.fields)
    if not args.no_raw:
        check_raw(args.mcap, ref)
    if args.rrd:
        check_rrd(args.rrd, ref)
    if args.png:
        check_png(args.png, args.orbit, args.effectors)
    if args.omega_decays is not None:
        check_omega_decays(ref, args.omega_decays)
    print(f"check: {'FAIL (' + str(len(failures)) + ')' if failures else 'PASS'} {args.mcap.name}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
