#!/usr/bin/env python3
"""Convert a polhode MCAP log into a native Rerun recording (.rrd) that opens ready to use.

    python mcap_to_rrd.py run.mcap -o run.rrd [--play-state following]

Rerun opens polhode's MCAP directly, but only turns `/tf` into transforms and `/log` into text;
it draws no `foxglove.SceneUpdate` geometry and plots no custom protobuf. This script reads the
file with the `mcap` reader and the protobuf schemas embedded in it, and writes:

- `/world/<frame>`: a Transform3D per `/tf` sample (frames nest as in `/tf`: `world` -> `body`);
- under the frame of each `/scene` entity, its primitives as Rerun archetypes: cubes -> Boxes3D,
  cylinders -> Cylinders3D, spheres -> Ellipsoids3D, lines -> LineStrips3D, arrows -> Arrows3D
  (polhode's `spacecraft` entity carries two arrows, omega then H: they get their own entities);
- every numeric field of every other protobuf channel (`/telemetry`, `/effectors/<name>`) as a
  Scalars series at `<topic>/<field>`;
- `/log` (`foxglove.Log`) as TextLog; the metadata and text attachments as TextDocuments;
- a blueprint: the 3D view, plots of omega, nutation, T and |H|, energies, and tabs for the log,
  drifts, angles, each effector and the scenario. For a log with the orbit view (`/earth` and
  `/orbit_scene`, a scenario with an orbit), a second 3D view in the Earth-centred frame `eci`
  (the Earth to scale, the orbit path, the spacecraft marker and axes), and a plot of the
  attitude relative to LVLH (roll, pitch, yaw) in place of the energies, which go to a tab.

Timelines: `sim_time` (a duration: log time minus the run's epoch) and `message_log_time` (the
MCAP log time, as Rerun names it when it opens an MCAP itself). Topics under a prefix (the
`/worst`, `/median`, `/best` runs of a campaign file) are converted alike, one layout tab each.
"""

from __future__ import annotations

import argparse
import hashlib
import math
import re
import sys
import time
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb
from google.protobuf.descriptor import FieldDescriptor
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

SIM = "sim_time"
LOG = "message_log_time"

# polhode's `spacecraft` scene entity draws omega then H (docs/logs.md).
ARROW_NAMES = {"spacecraft": [("omega", "ω"), ("H", "H")]}

# Labels and colours of the main series, as in the Foxglove layout (docs/viewers); other fields
# are labelled by name with Rerun's colours.
SERIES_STYLE = {
    "omega_x": ("ω_x", "#e5484d"),
    "omega_y": ("ω_y", "#30a46c"),
    "omega_z": ("ω_z", "#3e8ee8"),
    "nutation_angle_deg": ("nutation", "#a56eff"),
    "kinetic_energy": ("T (J)", "#f59e0b"),
    "h_norm": ("|H| (N m s)", "#3e8ee8"),
    "dissipated_energy": ("dissipated (J)", "#e5484d"),
    "elastic_energy": ("elastic (J)", "#12a594"),
}

# The attitude relative to LVLH (`/orbit`), coloured as omega's components.
ORBIT_STYLE = {
    "roll_deg": ("roll", "#e5484d"),
    "pitch_deg": ("pitch", "#30a46c"),
    "yaw_deg": ("yaw", "#3e8ee8"),
}

# Scene topics of the orbit view (docs/logs.md): drawn in the orbit view, not the body's.
ORBIT_SCENE_LEAVES = ("earth", "orbit_scene")

NUMERIC = {
    FieldDescriptor.CPPTYPE_DOUBLE,
    FieldDescriptor.CPPTYPE_FLOAT,
    FieldDescriptor.CPPTYPE_INT32,
    FieldDescriptor.CPPTYPE_INT64,
    FieldDescriptor.CPPTYPE_UINT32,
    FieldDescriptor.CPPTYPE_UINT64,
    FieldDescriptor.CPPTYPE_BOOL,
}

LOG_LEVELS = {1: "DEBUG", 2: "INFO", 3: "WARN", 4: "ERROR", 5: "CRITICAL"}


# ---------------------------------------------------------------------------------------------
# Small geometry helpers (quaternions are x, y, z, w as in Foxglove).


IDENTITY = (0.0, 0.0, 0.0, 1.0)


def quat(q) -> tuple[float, float, float, float]:
    """A Foxglove Quaternion message as a unit (x, y, z, w) tuple (identity if zero)."""
    x, y, z, w = q.x, q.y, q.z, q.w
    n = math.sqrt(x * x + y * y + z * z + w * w)
    return (x / n, y / n, z / n, w / n) if n > 0 else IDENTITY


def rotate(q, v) -> tuple[float, float, float]:
    """Rotates the 3-vector v by the unit quaternion q = (x, y, z, w): v + w t + u x t, t = 2 u x v.

    Plain floats: the vectors come one by one and numpy is slow on tiny arrays."""
    x, y, z, w = q
    a, b, c = v
    tx, ty, tz = 2 * (y * c - z * b), 2 * (z * a - x * c), 2 * (x * b - y * a)
    return (a + w * tx + y * tz - z * ty, b + w * ty + z * tx - x * tz, c + w * tz + x * ty - y * tx)


def vec3(v) -> tuple[float, float, float]:
    return (v.x, v.y, v.z)


def rgba(c, has: bool) -> tuple[int, int, int, int]:
    """A Foxglove Color (floats 0..1) as RGBA bytes; white if unset."""
    if not has:
        return (255, 255, 255, 255)
    return tuple(int(round(255 * min(max(x, 0.0), 1.0))) for x in (c.r, c.g, c.b, c.a))


def pose_of(p):
    """(position, quaternion) of a Foxglove Pose, identity parts where unset."""
    pos = vec3(p.position) if p.HasField("position") else (0.0, 0.0, 0.0)
    q = quat(p.orientation) if p.HasField("orientation") else IDENTITY
    return pos, q


def half(v) -> tuple[float, float, float]:
    return (v[0] / 2, v[1] / 2, v[2] / 2)


def part(name: str) -> str:
    """A string made safe as one entity-path part."""
    return re.sub(r"[^A-Za-z0-9_\-.]", "_", name) or "_"


# ---------------------------------------------------------------------------------------------
# Accumulators: rows are gathered per entity and sent as columns at the end (fast, and a row
# with no instances clears what an earlier row drew).


@dataclass
class Rows:
    """Rows of one archetype at one entity: times plus per-instance component arrays."""

    kind: str
    epoch: int
    times: list[int] = field(default_factory=list)
    lengths: list[int] = field(default_factory=list)
    data: dict[str, list] = field(default_factory=lambda: defaultdict(list))

    def add(self, t: int, instances: list[dict]) -> None:
        self.times.append(t)
        self.lengths.append(len(instances))
        for inst in instances:
            for k, v in inst.items():
                self.data[k].append(v)


def scene_instances(entity) -> dict[str, list[dict]]:
    """The primitives of one Foxglove SceneEntity, grouped by the sub-entity they go to."""
    out: dict[str, list[dict]] = defaultdict(list)
    for c in entity.cubes:
        pos, q = pose_of(c.pose)
        out["cubes"].append(
            dict(centers=pos, half_sizes=half(vec3(c.size)), quaternions=q, colors=rgba(c.color, c.HasField("color")))
        )
    for c in entity.cylinders:
        pos, q = pose_of(c.pose)
        size = vec3(c.size)
        out["cylinders"].append(
            dict(
                centers=pos,
                lengths=size[2],
                radii=max(size[0], size[1]) / 2,
                quaternions=q,
                colors=rgba(c.color, c.HasField("color")),
            )
        )
    for s in entity.spheres:
        pos, q = pose_of(s.pose)
        out["spheres"].append(
            dict(centers=pos, half_sizes=half(vec3(s.size)), quaternions=q, colors=rgba(s.color, s.HasField("color")))
        )
    for line in entity.lines:
        pos, q = pose_of(line.pose)
        pts = [(p.x, p.y, p.z) for p in line.points]
        if len(line.indices):
            pts = [pts[i] for i in line.indices]
        pts = [tuple(r + o for r, o in zip(rotate(q, p), pos)) for p in pts]
        color = line.color if line.HasField("color") else (line.colors[0] if len(line.colors) else None)
        col = rgba(color, color is not None)
        # Foxglove thickness is a diameter, in pixels when scale-invariant (negative radius in Rerun).
        radius = line.thickness / 2 if not line.scale_invariant else -line.thickness / 2
        if line.type == 2:  # LINE_LIST: pairs of points
            strips = [pts[i : i + 2] for i in range(0, len(pts) - 1, 2)]
        elif line.type == 1 and len(pts):  # LINE_LOOP: close it
            strips = [pts + pts[:1]]
        else:
            strips = [pts]
        for s in strips:
            out["lines"].append(dict(strips=s, radii=radius, colors=col))
    names = ARROW_NAMES.get(entity.id)
    arrows = list(entity.arrows)
    for i, a in enumerate(arrows):
        pos, q = pose_of(a.pose)
        vector = rotate(q, (a.shaft_length + a.head_length, 0.0, 0.0))
        inst = dict(vectors=vector, origins=pos, radii=a.shaft_diameter / 2, colors=rgba(a.color, a.HasField("color")))
        key = f"arrows/{names[i][0]}" if names and len(arrows) == len(names) else "arrows"
        out[key].append(inst)
    return out


def timelines(log_times, epoch: int) -> list[rr.TimeColumn]:
    """The two time columns for MCAP log times (ns): sim time (log time - epoch) and log time."""
    t = np.asarray(log_times, dtype=np.int64)
    return [
        rr.TimeColumn(SIM, duration=(t - epoch).astype("timedelta64[ns]")),
        rr.TimeColumn(LOG, timestamp=t.astype("datetime64[ns]")),
    ]


def send_rows(rec: rr.RecordingStream, path: str, rows: Rows) -> None:
    """Sends the gathered rows of one primitive kind as partitioned columns."""
    index = timelines(rows.times, rows.epoch)
    d = rows.data
    if rows.kind == "lines":
        cols = rr.LineStrips3D.columns(strips=d["strips"] or [], radii=d["radii"], colors=d["colors"])
    else:
        arr = {k: np.array(v) for k, v in d.items()}
        empty3 = np.zeros((0, 3))
        if rows.kind == "cubes":
            cols = rr.Boxes3D.columns(
                centers=arr.get("centers", empty3),
                half_sizes=arr.get("half_sizes", empty3),
                quaternions=arr.get("quaternions", np.zeros((0, 4))),
                colors=arr.get("colors", np.zeros((0, 4), np.uint8)).astype(np.uint8),
            )
        elif rows.kind == "cylinders":
            cols = rr.Cylinders3D.columns(
                centers=arr.get("centers", empty3),
                lengths=arr.get("lengths", np.zeros(0)),
                radii=arr.get("radii", np.zeros(0)),
                quaternions=arr.get("quaternions", np.zeros((0, 4))),
                colors=arr.get("colors", np.zeros((0, 4), np.uint8)).astype(np.uint8),
            )
        elif rows.kind == "spheres":
            cols = rr.Ellipsoids3D.columns(
                centers=arr.get("centers", empty3),
                half_sizes=arr.get("half_sizes", empty3),
                quaternions=arr.get("quaternions", np.zeros((0, 4))),
                colors=arr.get("colors", np.zeros((0, 4), np.uint8)).astype(np.uint8),
            )
        else:  # arrows
            cols = rr.Arrows3D.columns(
                vectors=arr.get("vectors", empty3),
                origins=arr.get("origins", empty3),
                radii=arr.get("radii", np.zeros(0)),
                colors=arr.get("colors", np.zeros((0, 4), np.uint8)).astype(np.uint8),
            )
    rec.send_columns(path, indexes=index, columns=cols.partition(rows.lengths))


# ---------------------------------------------------------------------------------------------


@dataclass
class Channel:
    topic: str
    fields: list[str]
    times: list[int] = field(default_factory=list)
    values: list[list[float]] = field(default_factory=list)


def prefix_of(topic: str, leaf: str) -> str | None:
    """'/worst/tf' -> '/worst' for leaf 'tf'; '' for '/tf'; None if the topic is not that leaf."""
    if topic == "/" + leaf or topic.endswith("/" + leaf):
        return topic[: -len(leaf) - 1]
    return None


def effector_prefix(topic: str) -> tuple[str, str] | None:
    """'/worst/effectors/rod' -> ('/worst', 'rod')."""
    m = re.fullmatch(r"(.*)/effectors/([^/]+)", topic)
    return (m.group(1), m.group(2)) if m else None


def parse_epoch(text: str) -> int | None:
    """'2008-02-01T03:47:56.000000000Z' -> Unix ns (None if unparsable)."""
    try:
        return int(np.datetime64(text.strip().rstrip("Z"), "ns").astype(np.int64))
    except ValueError:
        return None


def convert(src: Path, dst: Path, play_state: str | None = None) -> dict:
    t0 = time.perf_counter()
    digest = hashlib.sha256(src.read_bytes()).hexdigest()

    tf: dict[str, dict] = {}  # child frame -> {parent, times, translations, quaternions}
    scenes: list[tuple[int, object]] = []  # (log time, SceneUpdate)
    logs: dict[str, list[tuple[int, object]]] = defaultdict(list)  # topic -> [(log time, Log)]
    channels: dict[str, Channel] = {}
    metadata: dict[str, dict[str, str]] = {}
    attachments: list[tuple[str, str, bytes]] = []
    skipped: dict[str, str] = {}

    factory = DecoderFactory()
    decoders: dict[int, object] = {}  # channel id -> decode function, None to skip
    with open(src, "rb") as f:
        reader = make_reader(f)
        for m in reader.iter_metadata():
            metadata[m.name] = dict(m.metadata)
        for a in reader.iter_attachments():
            attachments.append((a.name, a.media_type, bytes(a.data)))
        # File order (cheaper than a merge by time); each series is put in time order below.
        for schema, ch, msg in reader.iter_messages(log_time_order=False):
            if ch.id not in decoders:
                decode = factory.decoder_for(ch.message_encoding, schema)
                decoders[ch.id] = decode
                if decode is None:
                    skipped[ch.topic] = f"{schema.name if schema else 'no schema'}, {ch.message_encoding}"
            decode = decoders[ch.id]
            if decode is None:
                continue
            dec = decode(msg.data)
            name = schema.name
            if name == "foxglove.FrameTransforms":
                items = list(dec.transforms)
            elif name == "foxglove.FrameTransform":
                items = [dec]
            elif name == "foxglove.SceneUpdate":
                scenes.append((msg.log_time, dec, ch.topic))
                continue
            elif name == "foxglove.Log":
                logs[ch.topic].append((msg.log_time, dec))
                continue
            else:
                c = channels.get(ch.topic)
                if c is None:
                    fields = [
                        fd.name
                        for fd in dec.DESCRIPTOR.fields
                        if fd.cpp_type in NUMERIC and not _repeated(fd)
                    ]
                    if not fields:
                        skipped[ch.topic] = f"{name}: no numeric fields"
                        decoders[ch.id] = None
                        continue
                    c = channels[ch.topic] = Channel(ch.topic, fields)
                c.times.append(msg.log_time)
                c.values.append([float(getattr(dec, k)) for k in c.fields])
                continue
            for t in items:
                e = tf.setdefault(
                    t.child_frame_id,
                    dict(parent=t.parent_frame_id, times=[], translations=[], quaternions=[]),
                )
                e["times"].append(msg.log_time)
                e["translations"].append(vec3(t.translation))
                e["quaternions"].append(quat(t.rotation) if t.HasField("rotation") else IDENTITY)
    scenes.sort(key=lambda x: x[0])
    for items in logs.values():
        items.sort(key=lambda x: x[0])
    for c in channels.values():
        order = np.argsort(np.array(c.times, dtype=np.int64), kind="stable")
        c.times = [c.times[i] for i in order]
        c.values = [c.values[i] for i in order]
    for e in tf.values():
        order = np.argsort(np.array(e["times"], dtype=np.int64), kind="stable")
        for k in ("times", "translations", "quaternions"):
            e[k] = [e[k][i] for i in order]
    t_read = time.perf_counter() - t0

    # Runs: one per topic prefix ('' for polhode run, '/worst' etc. for a campaign file).
    # In order of appearance: a campaign file holds /worst, then /median, then /best.
    found = [prefix_of(t, "telemetry") for t in channels] + [prefix_of(t, "log") for t in logs]
    prefixes = list(dict.fromkeys(p for p in found if p is not None)) or [""]

    # Each run's epoch: log time minus sim time of its first /telemetry sample, else the
    # metadata `epoch`, else the first log time in the file.
    meta_epoch = parse_epoch(metadata.get("polhode", {}).get("epoch", ""))
    first_time = min(
        [c.times[0] for c in channels.values() if c.times]
        + [e["times"][0] for e in tf.values() if e["times"]]
        + [x[0] for x in scenes[:1]],
        default=0,
    )
    epochs: dict[str, int] = {}
    for p in prefixes:
        c = channels.get(f"{p}/telemetry")
        if c and c.times and "sim_time" in c.fields:
            epochs[p] = c.times[0] - int(round(c.values[0][c.fields.index("sim_time")] * 1e9))
        else:
            epochs[p] = meta_epoch if meta_epoch is not None else first_time

    def run_of_topic(topic: str) -> str:
        best = ""
        for p in prefixes:
            if p and topic.startswith(p + "/") and len(p) > len(best):
                best = p
        return best

    def run_of_frame(frame: str) -> str:
        best = ""
        for p in prefixes:
            if p and (frame + "/").startswith(p.strip("/") + "/") and len(p) > len(best):
                best = p
        return best

    def entity_root(ent, topic: str) -> str:
        """The entity path of a scene entity: under its frame, named by its id; an entity of a
        campaign run drawn in a frame the runs share (`eci`, `world`) also gets the run's name,
        so the runs' entities stay apart."""
        name = part(ent.id or "entity")
        run = run_of_topic(topic)
        if run and run_of_frame(ent.frame_id) != run:
            name += "_" + part(run.strip("/"))
        return frame_path(ent.frame_id) + "/" + name

    # Frames -> entity paths, following the /tf tree (roots at the top level).
    def frame_path(frame: str, seen: tuple = ()) -> str:
        e = tf.get(frame)
        parts = "/".join(part(x) for x in frame.split("/") if x)
        if e is None or e["parent"] in seen or e["parent"] == frame:
            return "/" + parts
        return frame_path(e["parent"], seen + (frame,)) + "/" + parts

    # One application id for all polhode recordings (the viewer keys blueprints by it), and a
    # recording id from the file's content, so converting the same log again gives the same id.
    # The entity roots of each run's scenes, split between the body's view (`/scene`) and the
    # orbit view (`/earth`, `/orbit_scene`), and the orbit's size (to place the camera).
    views: dict[str, dict] = defaultdict(lambda: dict(body=set(), orbit=set(), radius=0.0))
    for _, su, topic in scenes:
        v = views[run_of_topic(topic)]
        orbit_topic = any(prefix_of(topic, leaf) is not None for leaf in ORBIT_SCENE_LEAVES)
        for ent in su.entities:
            root = entity_root(ent, topic)
            v["orbit" if orbit_topic else "body"].add(root)
            if orbit_topic:
                for line in ent.lines:
                    for q in line.points:
                        v["radius"] = max(v["radius"], math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z))

    rec = rr.RecordingStream("polhode", recording_id=f"polhode-{digest[:16]}")
    rec.set_log_time_enabled(False)
    rec.set_log_tick_enabled(False)
    scen_name = metadata.get("polhode", {}).get("scenario", src.stem)
    blueprint = build_blueprint(
        prefixes, channels, tf, frame_path, run_of_frame, play_state, attachments,
        body_sizes(scenes, run_of_frame), views,
    )
    rec.save(str(dst), default_blueprint=blueprint)
    rec.send_recording_name(scen_name)
    if meta_epoch is not None:
        rec.send_recording_start_time_nanos(meta_epoch)
    for name, kv in metadata.items():
        rec.send_property(part(name), rr.AnyValues(**{part(k): v for k, v in kv.items()}))

    # Static: world axes convention, metadata and attachments as documents.
    for frame in tf:
        root = frame_path(frame).split("/")[1]
        rec.log("/" + root, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    for name, kv in metadata.items():
        table = "\n".join(f"| `{k}` | {v} |" for k, v in kv.items())
        rec.log(
            f"/metadata/{part(name)}",
            rr.TextDocument(f"| {name} | |\n|---|---|\n{table}\n", media_type=rr.MediaType.MARKDOWN),
            static=True,
        )
    for name, media, data in attachments:
        if media.startswith("text/") or media.endswith(("yaml", "json", "toml")):
            rec.log(f"/attachments/{part(name)}", rr.TextDocument(data.decode("utf-8", "replace")), static=True)

    # Transforms.
    n_tf = 0
    for frame, e in tf.items():
        rec.send_columns(
            frame_path(frame),
            # Frames shared by the runs of a campaign file (`world`, and `eci`'s children with
            # an orbit) take the first run's epoch: the runs share the scenario's epoch.
            indexes=timelines(e["times"], epochs.get(run_of_frame(frame), epochs[prefixes[0]])),
            columns=rr.Transform3D.columns(
                translation=np.array(e["translations"]), quaternion=np.array(e["quaternions"])
            ),
        )
        n_tf += len(e["times"])

    # Scene primitives: every update of an entity gives a row to each of its sub-entities
    # (an empty one where a kind is absent); deletions give empty rows.
    rows: dict[str, Rows] = {}
    known: dict[str, set[str]] = defaultdict(set)  # entity root path -> sub-entity keys
    roots_by_id: dict[str, set[str]] = defaultdict(set)
    root_epoch: dict[str, int] = {}
    updates = []
    for t, su, topic in scenes:
        for d in su.deletions:
            targets = (
                [r for r in known]
                if d.type == 1
                else [r for r in roots_by_id.get(d.id, ())]
            )
            updates.append((t, targets, None))
        for ent in su.entities:
            root = entity_root(ent, topic)
            inst = scene_instances(ent)
            known[root].update(inst)
            roots_by_id[ent.id].add(root)
            root_epoch[root] = epochs.get(run_of_frame(ent.frame_id), epochs[prefixes[0]])
            updates.append((t, [root], inst))
    for t, targets, inst in updates:
        for root in targets:
            for key in known[root]:
                kind = key.split("/")[0]
                r = rows.setdefault(f"{root}/{key}", Rows(kind, root_epoch[root]))
                r.add(t, (inst or {}).get(key, []))
    for path, r in rows.items():
        send_rows(rec, path, r)
        if r.kind in ("cubes", "cylinders", "spheres"):
            arch = {"cubes": rr.Boxes3D, "cylinders": rr.Cylinders3D, "spheres": rr.Ellipsoids3D}[r.kind]
            rec.log(path, arch.from_fields(fill_mode=rr.components.FillMode.Solid), static=True)
    for root in known:
        ident = root.rsplit("/", 1)[-1]
        for name, label in ARROW_NAMES.get(ident, []):
            if f"arrows/{name}" in known[root]:
                # Labelled for hover and the selection panel; drawn labels would sit on top of
                # each other at the origin.
                rec.log(
                    f"{root}/arrows/{name}",
                    rr.Arrows3D.from_fields(labels=[label], show_labels=False),
                    static=True,
                )

    # Telemetry and effector series.
    n_scalars = 0
    for topic, c in channels.items():
        v = np.array(c.values, dtype=float).reshape(len(c.times), len(c.fields))
        index = timelines(c.times, epochs[run_of_topic(topic)])
        for j, name in enumerate(c.fields):
            path = f"{topic}/{part(name)}"
            rec.send_columns(path, indexes=index, columns=rr.Scalars.columns(scalars=v[:, j]))
            style = SERIES_STYLE if topic.endswith("/telemetry") else ORBIT_STYLE if topic.endswith("/orbit") else {}
            label, color = style.get(name, (name, None))
            rec.log(path, rr.SeriesLines(names=label, colors=[_rgb(color)] if color else None), static=True)
            n_scalars += len(c.times)

    # Text logs.
    n_logs = 0
    for topic, items in logs.items():
        rec.send_columns(
            topic,
            indexes=timelines([x[0] for x in items], epochs[run_of_topic(topic)]),
            columns=rr.TextLog.columns(
                text=[x[1].message for x in items],
                level=[LOG_LEVELS.get(x[1].level, "INFO") for x in items],
            ),
        )
        n_logs += len(items)

    rec.flush()
    rec.disconnect()
    stats = dict(
        transforms=n_tf,
        scene_updates=len(scenes),
        scene_entities=len(rows),
        scalar_series=sum(len(c.fields) for c in channels.values()),
        scalar_samples=n_scalars,
        text_logs=n_logs,
        runs=prefixes,
        skipped=skipped,
        read_s=round(t_read, 2),
        total_s=round(time.perf_counter() - t0, 2),
        bytes=dst.stat().st_size,
    )
    return stats


def body_sizes(scenes, run_of_frame) -> dict[str, float]:
    """Largest dimension of each run's first drawn cube or cylinder (to place the camera)."""
    sizes: dict[str, float] = {}
    for _, su, _ in scenes:
        for ent in su.entities:
            p = run_of_frame(ent.frame_id)
            if p not in sizes:
                dims = [max(c.size.x, c.size.y, c.size.z) for c in list(ent.cubes) + list(ent.cylinders)]
                if dims and max(dims) > 0:
                    sizes[p] = max(dims)
    return sizes


def _rgb(hex_color: str) -> tuple[int, int, int]:
    return tuple(int(hex_color[i : i + 2], 16) for i in (1, 3, 5))


def _repeated(fd) -> bool:
    # protobuf >= 5 has is_repeated; older versions only label.
    r = getattr(fd, "is_repeated", None)
    return bool(r) if r is not None else fd.label == FieldDescriptor.LABEL_REPEATED


# ---------------------------------------------------------------------------------------------


def build_blueprint(prefixes, channels, tf, frame_path, run_of_frame, play_state, attachments, sizes, views):
    """One layout per run: 3D view and main plots, with tabs for the rest; with an orbit, the
    orbit view under the body's and the attitude relative to LVLH among the main plots."""

    def series(view_name, topic, names):
        c = channels.get(topic)
        paths = [f"{topic}/{n}" for n in names if c and n in c.fields]
        if not paths:
            return None
        # The whole run on the x axis, also while following the end or playing.
        whole = rr.TimeRange(start=rr.TimeRangeBoundary.infinite(), end=rr.TimeRangeBoundary.infinite())
        return rrb.TimeSeriesView(
            name=view_name,
            origin="/",
            contents=paths,
            axis_x=rrb.TimeAxis(link="Independent", view_range=whole),
        )

    def layout(p: str):
        tel = f"{p}/telemetry"
        frames = [f for f in tf if run_of_frame(f) == p] or list(tf)
        body = [frame_path(f) for f in frames]
        size = sizes.get(p, 1.0)
        v = views.get(p, dict(body=set(), orbit=set(), radius=0.0))
        # The body's view is centred on the frame its scene is drawn in (`world`, the parent of
        # `body`), without the orbit view's entities.
        body_frames = [f for f in frames if f.split("/")[-1] == "body" and f in tf]
        every_orbit_root = sorted(r for w in views.values() for r in w["orbit"])
        if body_frames:
            world = frame_path(tf[body_frames[0]]["parent"])
            own = [b for b in body if b.startswith(world + "/")]
            origin = world
            contents = [b + "/**" for b in own] + [f"- {r}/**" for r in every_orbit_root]
        else:
            origin = "/" + (body[0].split("/")[1] if body else "world")
            contents = [b + "/**" for b in body] or ["/**"]
        view3d = rrb.Spatial3DView(
            name="Body in world frame (ω orange, H blue, effectors red)",
            origin=origin,
            contents=contents,
            line_grid=rrb.LineGrid3D(visible=True),
            # From the x-y diagonal, 30 degrees above the x-y plane, as in the Foxglove layout, at
            # a distance scaled by the body's size.
            eye_controls=rrb.EyeControls3D(
                position=(1.5 * size, 1.5 * size, 1.4 * size),
                look_target=(0.0, 0.0, 0.3 * size),
                eye_up=(0.0, 0.0, 1.0),
            ),
        )
        energies = series("Dissipated and elastic energy (J)", tel, ["dissipated_energy", "elastic_energy"])
        lvlh = series("Attitude relative to LVLH (roll, pitch, yaw; deg)", f"{p}/orbit", list(ORBIT_STYLE))
        main = [
            series("ω body components (rad/s)", tel, ["omega_x", "omega_y", "omega_z"]),
            series("Nutation angle, spin axis to H (deg)", tel, ["nutation_angle_deg"]),
            series("Kinetic energy T (J) and |H| (N m s)", tel, ["kinetic_energy", "h_norm"]),
            lvlh or energies,
        ]
        tabs = [rrb.TextLogView(name="Log", origin=f"{p}/log")]
        if lvlh:
            tabs.append(energies)
        tabs.append(series("Relative drifts", tel, ["drift_h_rel", "drift_energy_rel", "q_norm_error"]))
        tabs.append(
            series(
                "Angles ω to principal axes (deg)",
                tel,
                ["angle_to_principal_1_deg", "angle_to_principal_2_deg", "angle_to_principal_3_deg"],
            )
        )
        for topic, c in sorted(channels.items()):
            ep = effector_prefix(topic)
            if ep and ep[0] == p:
                tabs.append(series(f"Effector {ep[1]}", topic, [f for f in c.fields if f != "sim_time"]))
        if attachments:
            tabs.append(rrb.TextDocumentView(name="Scenario", origin="/attachments"))
        tabs.append(rrb.TextDocumentView(name="Metadata", origin="/metadata"))
        if v["orbit"]:
            # The Earth-centred frame: the root of the body's world frame.
            eci = "/" + origin.split("/")[1]
            a = v["radius"] or 7.0e6
            # The camera looks at the Earth's centre from over the spacecraft's last position,
            # raised toward the north, so the marker and its axes are in front of the Earth.
            world_tf = tf.get(body_frames[0] and tf[body_frames[0]]["parent"], {})
            last = world_tf.get("translations", [(a, a, a)])[-1]
            n = math.sqrt(sum(x * x for x in last)) or 1.0
            d = [last[0] / n, last[1] / n, last[2] / n + 0.5]
            m = math.sqrt(sum(x * x for x in d))
            eye = tuple(2.9 * a * x / m for x in d)
            orbit3d = rrb.Spatial3DView(
                name="Orbit in eci: Earth to scale, path (cyan), spacecraft (magenta), body axes",
                origin=eci,
                # This run's orbit entities; no body geometry (metres across), no other run's.
                contents=[eci + "/**"]
                + [f"- {r}/**" for w in views.values() for r in sorted(w["body"])]
                + [f"- {r}/**" for r in every_orbit_root if r not in v["orbit"]],
                line_grid=rrb.LineGrid3D(visible=False),
                eye_controls=rrb.EyeControls3D(
                    position=eye,
                    look_target=(0.0, 0.0, 0.0),
                    eye_up=(0.0, 0.0, 1.0),
                ),
            )
            left = rrb.Vertical(view3d, orbit3d, rrb.Tabs(*[t for t in tabs if t]), row_shares=[5, 5, 2])
        else:
            left = rrb.Vertical(view3d, rrb.Tabs(*[t for t in tabs if t]), row_shares=[3, 1])
        right = rrb.Vertical(*[v for v in main if v])
        return rrb.Horizontal(left, right, column_shares=[55, 45], name=p.strip("/") or "run")

    root = layout(prefixes[0]) if len(prefixes) == 1 else rrb.Tabs(*[layout(p) for p in prefixes])
    return rrb.Blueprint(
        root,
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline=SIM, play_state=play_state),
        auto_views=False,
        auto_layout=False,
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mcap", type=Path, help="polhode MCAP log")
    ap.add_argument("-o", "--out", type=Path, help="output .rrd (default: beside the input)")
    ap.add_argument(
        "--play-state",
        choices=["paused", "playing", "following"],
        help="initial playback in the blueprint ('following' puts the time cursor at the end)",
    )
    ap.add_argument("-q", "--quiet", action="store_true")
    args = ap.parse_args()
    out = args.out or args.mcap.with_suffix(".rrd")
    out.parent.mkdir(parents=True, exist_ok=True)
    # Write beside the target and rename, so the final name never holds a partial file.
    tmp = out.with_name(f".{out.name}.tmp")
    try:
        stats = convert(args.mcap, tmp, args.play_state)
        tmp.replace(out)
    finally:
        tmp.unlink(missing_ok=True)
    if not args.quiet:
        print(
            f"mcap_to_rrd: {args.mcap} -> {out}: {stats['transforms']} transforms, "
            f"{stats['scene_updates']} scene updates ({stats['scene_entities']} primitive entities), "
            f"{stats['scalar_series']} series ({stats['scalar_samples']} samples), "
            f"{stats['text_logs']} log lines; {stats['total_s']} s, {stats['bytes'] / 1e6:.1f} MB"
        )
    for topic, why in stats["skipped"].items():
        print(f"mcap_to_rrd: skipped {topic} ({why})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
