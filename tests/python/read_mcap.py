#!/usr/bin/env python3
"""Independent reader and checker for polhode's MCAP run logs.

Usage:
    read_mcap.py FILE.mcap [--expect-samples N] [--expect-spin-z RATE_RAD_S] [--quiet]

Exit status: 0 when every check passes, 1 when a check fails or the file cannot
be read (each problem is printed on stderr as "read_mcap: FAIL: ..."), 2 on a
usage error or when the Python packages are missing (run scripts/python-venv.sh
and use .venv/bin/python). Unless --quiet is given, a one-line JSON summary
(topics with message counts, metadata names, attachment names, ok) is printed
on stdout, also when checks fail.

Why this is independent of polhode: polhode writes MCAP in Rust with the `mcap`
and `foxglove` crates and prost-generated protobuf code. This reader is Python,
uses the Foxglove `mcap` Python package to parse the container, and decodes
every message with `mcap-protobuf-support` + Google's `protobuf` runtime, from
the FileDescriptorSets embedded in the file's Schema records only: no generated
code, no shared .proto files, nothing imported from the Rust side. A file that
passes here is therefore readable by a third party from its own contents.

What it checks:
  Container
    - the file parses twice: once linearly from the first byte to the trailing
      magic (chunk and data-section CRCs validated), once through the summary
      section and its indexes (what a viewer does to seek); both passes see the
      same message count per topic, and the summary statistics agree with them.
      A truncated or corrupted file fails here.
  Channels (in the summary section), each exactly once, message encoding and
  schema encoding "protobuf":
      /tf -> foxglove.FrameTransforms     /scene -> foxglove.SceneUpdate
      /telemetry -> polhode.Telemetry     /log -> foxglove.Log
  Units (every channel whose schema is a polhode.* one: /telemetry, /effectors/*)
    - every field of the schema's FileDescriptorSet has a leading comment in its
      source_code_info (path [4, message, 2, field]) ending in "(<unit>).", and
      the unit equals that of the channel's "units" metadata (a JSON object);
    - the units are in the JSON summary under "units", by schema name.
  Effector schemas
    - named per kind and field set: channels with the same schema name have the
      same fields, and each schema name is registered once.
  Every message
    - decodes with its embedded schema; publish_time == log_time; log times are
      non-decreasing per topic in file order.
  Metadata and attachments
    - a metadata record "polhode" with keys version, scenario, integrator,
      epoch, quaternion_convention, status; if `epoch` is an ISO 8601 date-time,
      the first /telemetry log time must equal it (sim time 0 at the epoch), or,
      for an epoch before 1970 and only then, `log_time_origin` must be present,
      be 1970-01-01T00:00:00Z and be the first log time;
    - an attachment "scenario.yaml" with non-empty UTF-8 data.
  /tf (foxglove.FrameTransforms)
    - exactly one transform, parent_frame_id "world", child_frame_id "body",
      | |q| - 1 | <= 1e-9, and timestamp (seconds, nanos) == the log time;
      in a log with an /orbit channel, a second transform "world" -> "lvlh",
      likewise a unit quaternion stamped at the log time, then "eci" -> "world"
      (no rotation; translation = the /orbit position r_eci x 1000 m within
      1e-9 relative) and "eci" -> "ecef" (zero translation, a unit rotation
      about z only).
  /earth and /orbit_scene (foxglove.SceneUpdate), only with an /orbit channel
    - /earth: one message, at the first /tf log time, entity "earth" in frame
      "ecef", frame-locked, with a sphere of diameter 2 x 6378137 m at the
      origin;
    - /orbit_scene: entity "orbit_path" in "eci" whose first point is the
      "eci" -> "world" translation at the same log time (1e-9 relative) and
      whose points all lie between the perigee and apogee radii computed from
      the /orbit position and velocity at that time (vis-viva, mu of WGS-84;
      1e-9 relative), and entity "spacecraft_marker" in "world" with a sphere
      at the origin (so the marker is at r(t)).
  /orbit (polhode.Orbit), only in the log of a scenario with an orbit
    - the fields listed in ORBIT_FIELDS exist, all finite, one message per
      /telemetry sample at the same log times;
    - q_NB (the /tf body rotation) == q_NO (the /tf lvlh rotation) x q_OB
      (q_lvlh_w, q_lvlh_x, q_lvlh_y, q_lvlh_z) up to sign within 1e-9, with
      q_lvlh_w >= 0.
  /telemetry (polhode.Telemetry)
    - the scalar numeric fields listed in TELEMETRY_FIELDS exist, all finite;
    - (log_time - first /telemetry log_time) == sim_time within 1 us;
    - a /tf message exists at the same log time and its rotation (w,x,y,z)
      equals (q_w,q_x,q_y,q_z) to the precision of the telemetry fields;
    - physics consistency: |h_body| == |h_inertial| == h_norm and
      h_inertial == R(q) h_body, where R(q) maps body to world coordinates as
      the /tf world->body transform does (relative tolerance 1e-8). This ties
      the telemetry numbers to what the 3D view shows.
  /scene (foxglove.SceneUpdate)
    - some entity has frame_id "body", frame_locked true, at least one cube or
      cylinder and at least two arrows (omega and H).
  /log (foxglove.Log)
    - decodes; a non-zero timestamp must equal the log time (sim time, not
      wall clock).
  --expect-samples N
    - /tf and /telemetry each hold exactly N messages.
  --expect-spin-z RATE
    - for a pure spin about body z at RATE rad/s from the identity attitude:
      /tf rotation (x,y,z,w) == (0, 0, sin(RATE t/2), cos(RATE t/2)) up to
      overall sign within 1e-8, t being the telemetry sim_time at that log time;
      omega == (0, 0, RATE) and h_inertial points along sign(RATE) * z.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import io
import json
import math
import sys
from collections import Counter, defaultdict
from typing import Any

try:
    from google.protobuf import descriptor_pb2
    from google.protobuf.descriptor import FieldDescriptor
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
except ImportError as exc:  # pragma: no cover - environment problem, not a check
    print(
        f"read_mcap: missing Python package ({exc}); run scripts/python-venv.sh "
        "and use .venv/bin/python",
        file=sys.stderr,
    )
    sys.exit(2)

PROG = "read_mcap"

# topic -> schema name. Message and schema encodings must both be "protobuf".
REQUIRED_CHANNELS = {
    "/tf": "foxglove.FrameTransforms",
    "/scene": "foxglove.SceneUpdate",
    "/telemetry": "polhode.Telemetry",
    "/log": "foxglove.Log",
}
ORBIT_FIELDS = (
    "sim_time",
    "r_eci_x", "r_eci_y", "r_eci_z",
    "v_eci_x", "v_eci_y", "v_eci_z",
    "altitude", "argument_of_latitude_deg",
    "q_lvlh_w", "q_lvlh_x", "q_lvlh_y", "q_lvlh_z",
    "roll_deg", "pitch_deg", "yaw_deg",
    "omega_lvlh_x", "omega_lvlh_y", "omega_lvlh_z",
)
ORBIT_Q_TOL = 1e-9
ORBIT_POS_TOL = 1e-9  # relative, orbit-view positions against /orbit
MU_EARTH = 3.986004418e14  # m^3/s^2, WGS-84 GM
R_EARTH = 6378137.0  # m, WGS-84 semi-major axis
METADATA_NAME = "polhode"
METADATA_KEYS = ("version", "scenario", "integrator", "epoch", "quaternion_convention", "status")
ATTACHMENT_NAME = "scenario.yaml"

TELEMETRY_FIELDS = (
    "sim_time",
    "omega_x", "omega_y", "omega_z",
    "q_w", "q_x", "q_y", "q_z",
    "h_body_x", "h_body_y", "h_body_z",
    "h_inertial_x", "h_inertial_y", "h_inertial_z",
    "h_norm",
    "kinetic_energy",
    "nutation_angle_deg",
    "angle_to_principal_1_deg", "angle_to_principal_2_deg", "angle_to_principal_3_deg",
    "drift_h_rel", "drift_energy_rel",
    "q_norm_error",
    "elastic_energy", "dissipated_energy", "dissipation_power",
)

NUMERIC_TYPES = {
    FieldDescriptor.TYPE_DOUBLE, FieldDescriptor.TYPE_FLOAT,
    FieldDescriptor.TYPE_INT32, FieldDescriptor.TYPE_INT64,
    FieldDescriptor.TYPE_UINT32, FieldDescriptor.TYPE_UINT64,
    FieldDescriptor.TYPE_SINT32, FieldDescriptor.TYPE_SINT64,
    FieldDescriptor.TYPE_FIXED32, FieldDescriptor.TYPE_FIXED64,
    FieldDescriptor.TYPE_SFIXED32, FieldDescriptor.TYPE_SFIXED64,
}

UNIT_QUAT_TOL = 1e-9          # | |q| - 1 | on /tf
SIM_TIME_TOL_S = 1e-6         # log time vs sim_time
Q_MATCH_TOL_DOUBLE = 1e-12    # /telemetry q vs /tf rotation, double fields
Q_MATCH_TOL_FLOAT = 1e-6      # same, if the telemetry fields are 32-bit floats
H_REL_TOL = 1e-8              # angular momentum consistency, relative to |H|
SPIN_TOL = 1e-8               # --expect-spin-z quaternion tolerance
MAX_REPORTS_PER_CHECK = 5     # further failures of one check are only counted

NS = 1_000_000_000


class Fatal(Exception):
    """The file cannot be read further; later checks would be meaningless."""


class Checks:
    """Collects failures, grouped by check, so one bad field does not flood stderr."""

    def __init__(self) -> None:
        self._failures: dict[str, list[str]] = defaultdict(list)
        self._counts: Counter = Counter()

    def fail(self, check: str, message: str) -> None:
        self._counts[check] += 1
        if self._counts[check] <= MAX_REPORTS_PER_CHECK:
            self._failures[check].append(message)

    def messages(self) -> list[str]:
        out: list[str] = []
        for check, msgs in self._failures.items():
            out.extend(msgs)
            extra = self._counts[check] - len(msgs)
            if extra > 0:
                out.append(f"... and {extra} more failure(s) of check '{check}'")
        return out

    @property
    def ok(self) -> bool:
        return not self._counts

    @property
    def total(self) -> int:
        return sum(self._counts.values())


class _ForwardOnly(io.RawIOBase):
    """Hides seekability so that make_reader returns its linear (non-seeking) reader."""

    def __init__(self, raw: io.BufferedReader) -> None:
        super().__init__()
        self._raw = raw

    def readable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return False

    def readinto(self, buffer) -> int:  # type: ignore[override]
        return self._raw.readinto(buffer)


def _is_repeated(field: Any) -> bool:
    # protobuf >= 5.28 has is_repeated; `label` was removed in protobuf 7.
    if hasattr(field, "is_repeated"):
        return bool(field.is_repeated)
    return field.label == FieldDescriptor.LABEL_REPEATED


def _ts_ns(ts: Any) -> int:
    return int(ts.seconds) * NS + int(ts.nanos)


def _fmt_t(log_time: int) -> str:
    return f"log_time={log_time}"


def _rotate(q: tuple[float, float, float, float], v: tuple[float, float, float]):
    """Rotate v by unit quaternion q = (w, x, y, z): returns q v q*."""
    w, x, y, z = q
    vx, vy, vz = v
    # t = 2 (q_vec x v); v' = v + w t + q_vec x t
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def _parse_epoch_ns(text: str) -> int | None:
    """Epoch as Unix nanoseconds if it is an ISO 8601 date-time, else None."""
    s = text.strip()
    if "T" not in s:
        return None
    if s.endswith(("Z", "z")):
        s = s[:-1] + "+00:00"
    frac_ns = 0
    # datetime only keeps microseconds: split off the fraction ourselves.
    head, dot, rest = s.partition(".")
    if dot:
        digits = ""
        while rest and rest[0].isdigit():
            digits, rest = digits + rest[0], rest[1:]
        if not digits:
            return None
        frac_ns = int((digits + "000000000")[:9])
        s = head + rest
    try:
        when = _dt.datetime.fromisoformat(s)
    except ValueError:
        return None
    if when.tzinfo is None:
        when = when.replace(tzinfo=_dt.timezone.utc)
    delta = when - _dt.datetime(1970, 1, 1, tzinfo=_dt.timezone.utc)
    return (delta.days * 86400 + delta.seconds) * NS + delta.microseconds * 1000 + frac_ns


class McapCheck:
    def __init__(self, path: str, expect_samples: int | None, spin_z: float | None):
        self.path = path
        self.expect_samples = expect_samples
        self.spin_z = spin_z
        self.checks = Checks()
        self.topic_counts: Counter = Counter()
        self.effector_samples: dict[str, int] = {}
        self.channel_topics: list[str] = []  # every topic in the summary, even without messages
        self.units: dict[str, dict[str, str]] = {}  # schema name -> {field: unit}
        self.metadata_names: list[str] = []
        self.attachment_names: list[str] = []
        self.polhode_metadata: dict[str, str] = {}
        # log_time -> list of (w, x, y, z) of /tf rotations at that time
        self.tf_by_time: dict[int, list[tuple[float, float, float, float]]] = defaultdict(list)
        self.tf_times: list[int] = []
        # (log_time, {field: value}) of /telemetry messages
        self.telemetry: list[tuple[int, dict[str, float]]] = []
        self.telemetry_q_tol = Q_MATCH_TOL_DOUBLE
        self.telemetry_schema_checked = False
        self.telemetry_schema_ok = False
        self.scene_messages = 0
        self.scene_body_entity = False
        self.scene_seen_partial: list[str] = []
        self.has_orbit = False
        # log_time -> (w, x, y, z) of the /tf lvlh rotation, and the /orbit samples
        self.lvlh_by_time: dict[int, tuple[float, float, float, float]] = {}
        self.orbit: list[tuple[int, dict[str, float]]] = []
        # log_time -> eci -> world translation (m); the orbit-view scene messages
        self.eci_world_by_time: dict[int, tuple[float, float, float]] = {}
        self.earth_messages: list[tuple[int, Any]] = []
        self.orbit_scenes: list[tuple[int, Any]] = []

    # ------------------------------------------------------------------ driver
    def run(self) -> None:
        try:
            try:
                f = open(self.path, "rb")
            except OSError as exc:
                raise Fatal(f"cannot open {self.path}: {exc}") from exc
            with f:
                try:
                    reader = make_reader(
                        f, validate_crcs=True, decoder_factories=[DecoderFactory()]
                    )
                except Exception as exc:
                    raise Fatal(
                        f"{self.path}: not an MCAP file: {type(exc).__name__}: {exc}"
                    ) from exc
                summary = self._read_summary(reader)
                self._check_channels(summary)
                self.has_orbit = any(
                    ch.topic == "/orbit" for ch in getattr(summary, "channels", {}).values()
                )
                self._linear_pass()
                self._indexed_pass(reader, summary)
                self._read_metadata(reader)
                self._read_attachments(reader)
        except Fatal as exc:
            self.checks.fail("readable", str(exc))
            return
        self._check_metadata()
        self._check_counts()
        self._check_tf_telemetry()
        self._check_orbit()
        self._check_orbit_view()
        self._check_scene()
        if self.spin_z is not None:
            self._check_spin_z(self.spin_z)

    def _reading(self, what: str, records):
        """Iterate a reader's records, turning parse errors into Fatal.

        Only the reader's own work is guarded: exceptions raised by this script's
        checks while the caller handles a record are not caught here.
        """
        iterator = iter(records)
        while True:
            try:
                record = next(iterator)
            except StopIteration:
                return
            except Exception as exc:  # any parse error of a damaged file
                raise Fatal(
                    f"{self.path}: not a complete, valid MCAP file: {what} failed: "
                    f"{type(exc).__name__}: {exc}"
                ) from exc
            yield record

    # ------------------------------------------------------------- container
    def _read_summary(self, reader):
        try:
            summary = reader.get_summary()
        except Exception as exc:
            raise Fatal(
                f"{self.path}: cannot read the footer/summary section "
                f"(truncated or damaged file?): {type(exc).__name__}: {exc}"
            ) from exc
        if summary is None:
            raise Fatal(f"{self.path}: the file has no summary section")
        return summary

    def _check_channels(self, summary) -> None:
        by_topic: dict[str, list] = defaultdict(list)
        for channel in summary.channels.values():
            by_topic[channel.topic].append(channel)
        self.channel_topics = sorted(by_topic)
        for topic, schema_name in REQUIRED_CHANNELS.items():
            channels = by_topic.get(topic, [])
            if len(channels) != 1:
                self.checks.fail(
                    "channels",
                    f"summary lists {len(channels)} channel(s) for topic {topic}, "
                    "expected exactly 1",
                )
                continue
            channel = channels[0]
            if channel.message_encoding != "protobuf":
                self.checks.fail(
                    "channels",
                    f"{topic}: message encoding {channel.message_encoding!r}, expected 'protobuf'",
                )
            schema = summary.schemas.get(channel.schema_id)
            if schema is None:
                self.checks.fail(
                    "channels", f"{topic}: schema id {channel.schema_id} not in the summary"
                )
                continue
            if schema.name != schema_name:
                self.checks.fail(
                    "channels", f"{topic}: schema name {schema.name!r}, expected {schema_name!r}"
                )
            if schema.encoding != "protobuf":
                self.checks.fail(
                    "channels",
                    f"{topic}: schema encoding {schema.encoding!r}, expected 'protobuf'",
                )
            if not schema.data:
                self.checks.fail("channels", f"{topic}: schema {schema.name!r} has no data")
        self._check_units(summary)

    def _check_units(self, summary) -> None:
        """Every field of the polhode schemas documents its unit (see the module docstring)."""
        names = [s.name for s in summary.schemas.values()]
        for name in sorted(set(n for n in names if names.count(n) > 1)):
            self.checks.fail("schemas", f"schema {name!r} is registered {names.count(name)} times")
        for channel in sorted(summary.channels.values(), key=lambda c: c.topic):
            schema = summary.schemas.get(channel.schema_id)
            if schema is None or not schema.name.startswith("polhode."):
                continue
            where = f"{channel.topic} ({schema.name})"
            try:
                files = descriptor_pb2.FileDescriptorSet.FromString(schema.data).file
                message = files[0].message_type[0]
            except Exception as exc:
                self.checks.fail("units", f"{where}: schema does not parse: {exc}")
                continue
            comments = {
                tuple(loc.path): loc.leading_comments
                for loc in files[0].source_code_info.location
            }
            try:
                meta = json.loads(channel.metadata.get("units", ""))
            except ValueError:
                meta = None
            if not isinstance(meta, dict):
                self.checks.fail("units", f"{where}: no JSON 'units' channel metadata")
                meta = {}
            units: dict[str, str] = {}
            for i, field in enumerate(message.field):
                text = comments.get((4, 0, 2, i), "").strip()
                unit = None
                if text.endswith(").") and "(" in text:
                    unit = text[text.rfind("(") + 1 : -2].strip()
                if not unit:
                    self.checks.fail(
                        "units", f"{where}: field {field.name} has no unit in its comment {text!r}"
                    )
                    continue
                if meta.get(field.name) != unit:
                    self.checks.fail(
                        "units",
                        f"{where}: field {field.name}: comment unit {unit!r}, channel metadata "
                        f"{meta.get(field.name)!r}",
                    )
                units[field.name] = unit
            known = self.units.setdefault(schema.name, units)
            if known != units:
                self.checks.fail("units", f"{where}: fields or units differ between channels")

    def _linear_pass(self) -> None:
        """Read every record from start to end magic, decode every message, dispatch."""
        last_time: dict[str, int] = {}
        with open(self.path, "rb") as raw:
            reader = make_reader(
                _ForwardOnly(raw), validate_crcs=True, decoder_factories=[DecoderFactory()]
            )
            position = "before the first message"
            try:
                # Wrapped by hand rather than with _reading() to say where it broke.
                decoded_messages = iter(reader.iter_decoded_messages(log_time_order=False))
            except Exception as exc:
                raise Fatal(f"{self.path}: not an MCAP file: {type(exc).__name__}: {exc}") from exc
            index = 0
            while True:
                try:
                    _schema, channel, message, decoded = next(decoded_messages)
                except StopIteration:
                    break
                except Exception as exc:
                    raise Fatal(
                        f"{self.path}: not a complete, valid MCAP file: linear read/decode "
                        f"failed {position}: {type(exc).__name__}: {exc}"
                    ) from exc
                topic = channel.topic
                position = f"after message #{index} ({topic}, {_fmt_t(message.log_time)})"
                self.topic_counts[topic] += 1
                if message.publish_time != message.log_time:
                    self.checks.fail(
                        "publish_time",
                        f"{topic} {_fmt_t(message.log_time)}: publish_time "
                        f"{message.publish_time} != log_time",
                    )
                previous = last_time.get(topic)
                if previous is not None and message.log_time < previous:
                    self.checks.fail(
                        "time order",
                        f"{topic}: log time goes back from {previous} to {message.log_time} "
                        f"(message #{index} in file order)",
                    )
                last_time[topic] = message.log_time
                self._dispatch(topic, message.log_time, decoded)
                index += 1

    def _indexed_pass(self, reader, summary) -> None:
        """Messages reachable through the chunk indexes == messages in the file."""
        indexed: Counter = Counter()
        for _schema, channel, _message in self._reading(
            "indexed read", reader.iter_messages(log_time_order=False)
        ):
            indexed[channel.topic] += 1
        if indexed != self.topic_counts:
            self.checks.fail(
                "index",
                f"messages reachable through the summary indexes {dict(indexed)} differ from "
                f"those in the file {dict(self.topic_counts)}",
            )
        stats = summary.statistics
        if stats is None:
            return
        if stats.message_count != sum(self.topic_counts.values()):
            self.checks.fail(
                "statistics",
                f"statistics message_count {stats.message_count} != "
                f"{sum(self.topic_counts.values())} messages read",
            )
        for channel_id, count in stats.channel_message_counts.items():
            channel = summary.channels.get(channel_id)
            topic = channel.topic if channel else f"<channel {channel_id}>"
            if count != self.topic_counts.get(topic, 0):
                self.checks.fail(
                    "statistics",
                    f"statistics count {count} for {topic} != "
                    f"{self.topic_counts.get(topic, 0)} messages read",
                )

    # ------------------------------------------------- metadata, attachments
    def _read_metadata(self, reader) -> None:
        for record in self._reading("metadata read", reader.iter_metadata()):
            self.metadata_names.append(record.name)
            if record.name == METADATA_NAME:
                self.polhode_metadata.update(record.metadata)

    def _read_attachments(self, reader) -> None:
        found = False
        for attachment in self._reading(
            "attachment read", reader.iter_attachments()
        ):
            self.attachment_names.append(attachment.name)
            if attachment.name != ATTACHMENT_NAME:
                continue
            found = True
            if not attachment.data:
                self.checks.fail("attachment", f"attachment {ATTACHMENT_NAME} is empty")
                continue
            try:
                attachment.data.decode("utf-8")
            except UnicodeDecodeError as exc:
                self.checks.fail("attachment", f"attachment {ATTACHMENT_NAME} is not UTF-8: {exc}")
        if not found:
            self.checks.fail(
                "attachment",
                f"no attachment named {ATTACHMENT_NAME} (found {self.attachment_names})",
            )

    def _check_metadata(self) -> None:
        if METADATA_NAME not in self.metadata_names:
            self.checks.fail(
                "metadata",
                f"no metadata record named {METADATA_NAME!r} (found {self.metadata_names})",
            )
            return
        missing = [k for k in METADATA_KEYS if k not in self.polhode_metadata]
        if missing:
            self.checks.fail(
                "metadata",
                f"metadata {METADATA_NAME!r} lacks key(s) {missing} "
                f"(has {sorted(self.polhode_metadata)})",
            )
        epoch = self.polhode_metadata.get("epoch")
        epoch_ns = _parse_epoch_ns(epoch) if epoch else None
        # An epoch before 1970 cannot be an (unsigned) log time: the log is stamped from
        # `log_time_origin` (1970-01-01) instead, and only then.
        origin = self.polhode_metadata.get("log_time_origin")
        if epoch_ns is not None and (epoch_ns < 0) != (origin is not None):
            self.checks.fail(
                "epoch",
                f"metadata epoch {epoch!r} with log_time_origin {origin!r}: expected the "
                "origin exactly when the epoch precedes 1970",
            )
        stamp_ns = _parse_epoch_ns(origin) if origin is not None else epoch_ns
        if origin is not None and stamp_ns != 0:
            self.checks.fail("epoch", f"log_time_origin {origin!r} is not 1970-01-01T00:00:00Z")
        if stamp_ns is not None and self.telemetry:
            first = self.telemetry[0][0]
            if first != stamp_ns:
                self.checks.fail(
                    "epoch",
                    f"first /telemetry log time {first} ns != metadata epoch {epoch!r} "
                    f"(log time origin {stamp_ns} ns)",
                )

    # ------------------------------------------------------ per-message checks
    def _dispatch(self, topic: str, log_time: int, msg: Any) -> None:
        if topic == "/tf":
            self._on_tf(log_time, msg)
        elif topic == "/telemetry":
            self._on_telemetry(log_time, msg)
        elif topic == "/scene":
            self._on_scene(log_time, msg)
        elif topic == "/log":
            self._on_log(log_time, msg)
        elif topic == "/orbit":
            self._on_orbit(log_time, msg)
        elif topic == "/earth":
            self.earth_messages.append((log_time, msg))
        elif topic == "/orbit_scene":
            self.orbit_scenes.append((log_time, msg))
        elif topic.startswith("/effectors/"):
            self._on_effector(topic, log_time, msg)

    def _on_effector(self, topic: str, log_time: int, msg: Any) -> None:
        """Per-effector telemetry: flat doubles, `sim_time` first, every value finite."""
        fields = [f.name for f in msg.DESCRIPTOR.fields]
        if not fields or fields[0] != "sim_time":
            self.checks.fail("effector schema", f"{topic}: first field is not sim_time: {fields}")
            return
        bad = [f for f in fields if not math.isfinite(float(getattr(msg, f)))]
        if bad:
            self.checks.fail("effector finite", f"{topic} {_fmt_t(log_time)}: non-finite {bad}")
        self.effector_samples[topic] = self.effector_samples.get(topic, 0) + 1

    def _on_tf(self, log_time: int, msg: Any) -> None:
        where = f"/tf {_fmt_t(log_time)}"
        self.tf_times.append(log_time)
        transforms = list(msg.transforms)
        expected = 4 if self.has_orbit else 1
        if len(transforms) != expected:
            self.checks.fail("tf", f"{where}: {len(transforms)} transforms, expected {expected}")
            if not transforms:
                return
        if self.has_orbit and len(transforms) >= 2:
            lvlh = transforms[1]
            if lvlh.parent_frame_id != "world" or lvlh.child_frame_id != "lvlh":
                self.checks.fail(
                    "tf frames",
                    f"{where}: {lvlh.parent_frame_id!r} -> {lvlh.child_frame_id!r}, "
                    "expected 'world' -> 'lvlh'",
                )
            if _ts_ns(lvlh.timestamp) != log_time:
                self.checks.fail("tf timestamp", f"{where}: lvlh timestamp != log time")
            r = lvlh.rotation
            q = (r.w, r.x, r.y, r.z)
            norm = math.sqrt(sum(c * c for c in q))
            if not math.isfinite(norm) or abs(norm - 1.0) > UNIT_QUAT_TOL:
                self.checks.fail("tf unit", f"{where}: lvlh |q| = {norm!r}")
            self.lvlh_by_time[log_time] = q
        if self.has_orbit and len(transforms) >= 4:
            world, ecef = transforms[2], transforms[3]
            if (world.parent_frame_id, world.child_frame_id) != ("eci", "world") or (
                ecef.parent_frame_id,
                ecef.child_frame_id,
            ) != ("eci", "ecef"):
                self.checks.fail(
                    "tf frames",
                    f"{where}: transforms 3 and 4 are {world.parent_frame_id!r} -> "
                    f"{world.child_frame_id!r} and {ecef.parent_frame_id!r} -> "
                    f"{ecef.child_frame_id!r}, expected 'eci' -> 'world' and 'eci' -> 'ecef'",
                )
            r = world.rotation
            if (r.x, r.y, r.z, r.w) != (0.0, 0.0, 0.0, 1.0):
                self.checks.fail("tf eci", f"{where}: eci -> world is rotated")
            e = ecef.rotation
            t = ecef.translation
            if e.x != 0.0 or e.y != 0.0 or abs(e.z * e.z + e.w * e.w - 1.0) > UNIT_QUAT_TOL:
                self.checks.fail("tf ecef", f"{where}: eci -> ecef is not a unit rotation about z")
            if (t.x, t.y, t.z) != (0.0, 0.0, 0.0):
                self.checks.fail("tf ecef", f"{where}: eci -> ecef is translated")
            p = world.translation
            self.eci_world_by_time[log_time] = (p.x, p.y, p.z)
        tf = transforms[0]
        if tf.parent_frame_id != "world" or tf.child_frame_id != "body":
            self.checks.fail(
                "tf frames",
                f"{where}: {tf.parent_frame_id!r} -> {tf.child_frame_id!r}, "
                "expected 'world' -> 'body'",
            )
        if _ts_ns(tf.timestamp) != log_time:
            self.checks.fail(
                "tf timestamp",
                f"{where}: transform timestamp {_ts_ns(tf.timestamp)} ns != log time",
            )
        r = tf.rotation
        q = (r.w, r.x, r.y, r.z)
        norm = math.sqrt(sum(c * c for c in q))
        if not math.isfinite(norm) or abs(norm - 1.0) > UNIT_QUAT_TOL:
            self.checks.fail("tf unit", f"{where}: |q| = {norm!r}, not 1 within {UNIT_QUAT_TOL}")
        self.tf_by_time[log_time].append(q)

    def _check_telemetry_schema(self, msg: Any) -> None:
        self.telemetry_schema_checked = True
        fields = msg.DESCRIPTOR.fields_by_name
        problems = []
        for name in TELEMETRY_FIELDS:
            field = fields.get(name)
            if field is None:
                problems.append(f"{name}: missing")
            elif field.type not in NUMERIC_TYPES:
                problems.append(f"{name}: not numeric (protobuf type {field.type})")
            elif _is_repeated(field):
                problems.append(f"{name}: repeated, expected a scalar")
        if problems:
            self.checks.fail("telemetry fields", "polhode.Telemetry fields: " + "; ".join(problems))
            return
        self.telemetry_schema_ok = True
        if any(fields[n].type == FieldDescriptor.TYPE_FLOAT for n in ("q_w", "q_x", "q_y", "q_z")):
            self.telemetry_q_tol = Q_MATCH_TOL_FLOAT

    def _on_telemetry(self, log_time: int, msg: Any) -> None:
        if not self.telemetry_schema_checked:
            self._check_telemetry_schema(msg)
        if not self.telemetry_schema_ok:
            return
        values = {name: float(getattr(msg, name)) for name in TELEMETRY_FIELDS}
        bad = [name for name, v in values.items() if not math.isfinite(v)]
        if bad:
            self.checks.fail("telemetry finite", f"/telemetry {_fmt_t(log_time)}: non-finite {bad}")
        self.telemetry.append((log_time, values))

    def _on_orbit(self, log_time: int, msg: Any) -> None:
        fields = msg.DESCRIPTOR.fields_by_name
        missing = [n for n in ORBIT_FIELDS if n not in fields]
        if missing:
            self.checks.fail("orbit fields", f"polhode.Orbit: missing {missing}")
            return
        values = {name: float(getattr(msg, name)) for name in ORBIT_FIELDS}
        bad = [name for name, v in values.items() if not math.isfinite(v)]
        if bad:
            self.checks.fail("orbit finite", f"/orbit {_fmt_t(log_time)}: non-finite {bad}")
        self.orbit.append((log_time, values))

    def _on_scene(self, log_time: int, msg: Any) -> None:
        self.scene_messages += 1
        if self.scene_body_entity:
            return
        for entity in msg.entities:
            solids = len(entity.cubes) + len(entity.cylinders)
            arrows = len(entity.arrows)
            if entity.frame_id == "body" and entity.frame_locked and solids >= 1 and arrows >= 2:
                self.scene_body_entity = True
                return
            if len(self.scene_seen_partial) < 5:
                self.scene_seen_partial.append(
                    f"id={entity.id!r} frame_id={entity.frame_id!r} "
                    f"frame_locked={entity.frame_locked} cubes+cylinders={solids} arrows={arrows}"
                )

    def _on_log(self, log_time: int, msg: Any) -> None:
        ts = _ts_ns(msg.timestamp)
        if ts != 0 and ts != log_time:
            self.checks.fail(
                "log timestamp", f"/log {_fmt_t(log_time)}: timestamp {ts} ns != log time"
            )

    # ------------------------------------------------------- cross-topic checks
    def _check_counts(self) -> None:
        if self.expect_samples is None:
            return
        for topic in ("/tf", "/telemetry"):
            n = self.topic_counts.get(topic, 0)
            if n != self.expect_samples:
                self.checks.fail(
                    "samples", f"{topic}: {n} messages, expected {self.expect_samples}"
                )

    def _check_orbit(self) -> None:
        if not self.has_orbit:
            return
        orbit_times = [t for t, _ in self.orbit]
        telemetry_times = [t for t, _ in self.telemetry]
        if orbit_times != telemetry_times:
            self.checks.fail(
                "orbit samples",
                f"/orbit at {len(orbit_times)} log times, /telemetry at {len(telemetry_times)}; "
                "not the same",
            )
        for log_time, v in self.orbit:
            where = f"/orbit {_fmt_t(log_time)}"
            q_ob = (v["q_lvlh_w"], v["q_lvlh_x"], v["q_lvlh_y"], v["q_lvlh_z"])
            if q_ob[0] < 0.0:
                self.checks.fail("orbit quaternion", f"{where}: q_lvlh_w < 0")
            q_no = self.lvlh_by_time.get(log_time)
            tfs = self.tf_by_time.get(log_time)
            if q_no is None or not tfs:
                self.checks.fail("orbit tf", f"{where}: no /tf body and lvlh at the same log time")
                continue
            w1, x1, y1, z1 = q_no
            w2, x2, y2, z2 = q_ob
            q_nb = (
                w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
            )
            dot = abs(sum(a * b for a, b in zip(q_nb, tfs[0])))
            if 1.0 - dot > ORBIT_Q_TOL:
                self.checks.fail(
                    "orbit quaternion",
                    f"{where}: q_NO x q_OB differs from the /tf body rotation (1 - |dot| = {1.0 - dot:.1e})",
                )

    def _check_orbit_view(self) -> None:
        if not self.has_orbit:
            return
        first_tf = self.tf_times[0] if self.tf_times else None
        if len(self.earth_messages) != 1 or self.earth_messages[0][0] != first_tf:
            self.checks.fail(
                "earth", f"/earth: {len(self.earth_messages)} messages, expected one at the first /tf"
            )
        for _, msg in self.earth_messages[:1]:
            earth = [e for e in msg.entities if e.id == "earth"]
            ok = (
                len(earth) == 1
                and earth[0].frame_id == "ecef"
                and earth[0].frame_locked
                and any(
                    s.size.x == s.size.y == s.size.z == 2.0 * R_EARTH
                    and (s.pose.position.x, s.pose.position.y, s.pose.position.z) == (0.0, 0.0, 0.0)
                    for s in earth[0].spheres
                )
            )
            if not ok:
                self.checks.fail("earth", "/earth: no frame-locked 'earth' sphere of the Earth's size in 'ecef'")
        orbit_by_time = dict(self.orbit)
        if not self.orbit_scenes:
            self.checks.fail("orbit scene", "/orbit_scene: no message")
        for log_time, msg in self.orbit_scenes:
            where = f"/orbit_scene {_fmt_t(log_time)}"
            by_id = {e.id: e for e in msg.entities}
            path, marker = by_id.get("orbit_path"), by_id.get("spacecraft_marker")
            r_tf = self.eci_world_by_time.get(log_time)
            v = orbit_by_time.get(log_time)
            if path is None or path.frame_id != "eci" or not path.lines or r_tf is None or v is None:
                self.checks.fail("orbit scene", f"{where}: no orbit_path in 'eci', or no /tf and /orbit then")
                continue
            if (
                marker is None
                or marker.frame_id != "world"
                or not marker.frame_locked
                or not any(
                    (s.pose.position.x, s.pose.position.y, s.pose.position.z) == (0.0, 0.0, 0.0)
                    for s in marker.spheres
                )
            ):
                self.checks.fail("orbit scene", f"{where}: no marker sphere at the origin of 'world'")
            points = [(p.x, p.y, p.z) for p in path.lines[0].points]
            r_norm = math.sqrt(sum(c * c for c in r_tf))
            d0 = math.sqrt(sum((a - b) ** 2 for a, b in zip(points[0], r_tf)))
            if d0 > ORBIT_POS_TOL * r_norm:
                self.checks.fail("orbit scene", f"{where}: the path starts {d0:.3e} m from r(t)")
            # r(t) and v(t) from /orbit (km, km/s) -> a and e (vis-viva, eccentricity vector).
            r = [v[f"r_eci_{c}"] * 1e3 for c in "xyz"]
            vel = [v[f"v_eci_{c}"] * 1e3 for c in "xyz"]
            rn = math.sqrt(sum(c * c for c in r))
            if abs(rn - r_norm) > ORBIT_POS_TOL * rn:
                self.checks.fail("orbit tf", f"{where}: |eci -> world| {r_norm} m, /orbit |r| {rn} m")
            v2 = sum(c * c for c in vel)
            a = 1.0 / (2.0 / rn - v2 / MU_EARTH)
            rv = sum(x * y for x, y in zip(r, vel))
            e_vec = [((v2 - MU_EARTH / rn) * ri - rv * vi) / MU_EARTH for ri, vi in zip(r, vel)]
            e = math.sqrt(sum(c * c for c in e_vec))
            r_min, r_max = a * (1.0 - e), a * (1.0 + e)
            for p in points:
                n = math.sqrt(sum(c * c for c in p))
                if not (r_min * (1 - ORBIT_POS_TOL) <= n <= r_max * (1 + ORBIT_POS_TOL)):
                    self.checks.fail(
                        "orbit scene",
                        f"{where}: path point at {n} m outside [{r_min}, {r_max}] m",
                    )
                    break
        for log_time, v in self.orbit:
            r_tf = self.eci_world_by_time.get(log_time)
            r = [v[f"r_eci_{c}"] * 1e3 for c in "xyz"]
            rn = math.sqrt(sum(c * c for c in r))
            if r_tf is None or math.sqrt(sum((a - b) ** 2 for a, b in zip(r, r_tf))) > ORBIT_POS_TOL * rn:
                self.checks.fail(
                    "orbit tf", f"/orbit {_fmt_t(log_time)}: eci -> world translation != r_eci x 1000"
                )

    def _check_tf_telemetry(self) -> None:
        if not self.telemetry:
            return
        first = self.telemetry[0][0]
        tol = self.telemetry_q_tol
        for log_time, v in self.telemetry:
            where = f"/telemetry {_fmt_t(log_time)}"
            elapsed = (log_time - first) / NS
            if abs(elapsed - v["sim_time"]) > SIM_TIME_TOL_S:
                self.checks.fail(
                    "sim_time",
                    f"{where}: log time - first log time = {elapsed!r} s but sim_time = "
                    f"{v['sim_time']!r} s",
                )
            q_tel = (v["q_w"], v["q_x"], v["q_y"], v["q_z"])
            tfs = self.tf_by_time.get(log_time)
            if not tfs:
                self.checks.fail("tf match", f"{where}: no /tf message at the same log time")
                q_ref = q_tel
            else:
                q_ref = tfs[0]  # double precision even if the telemetry q is float32
                for q_tf in tfs:
                    diff = max(abs(a - b) for a, b in zip(q_tel, q_tf, strict=True))
                    if diff > tol:
                        self.checks.fail(
                            "tf match",
                            f"{where}: telemetry q (w,x,y,z) = {q_tel} but /tf rotation = "
                            f"{q_tf} (max diff {diff:.3g} > {tol})",
                        )
            self._check_momentum(where, v, q_ref)

    def _check_momentum(self, where: str, v: dict[str, float], q: tuple[float, ...]) -> None:
        h_body = (v["h_body_x"], v["h_body_y"], v["h_body_z"])
        h_in = (v["h_inertial_x"], v["h_inertial_y"], v["h_inertial_z"])
        n_body = math.sqrt(sum(c * c for c in h_body))
        n_in = math.sqrt(sum(c * c for c in h_in))
        scale = max(abs(v["h_norm"]), n_body, n_in)
        tol = H_REL_TOL * scale + 1e-300
        if abs(n_body - v["h_norm"]) > tol or abs(n_in - v["h_norm"]) > tol:
            self.checks.fail(
                "momentum norm",
                f"{where}: |h_body| = {n_body!r}, |h_inertial| = {n_in!r}, "
                f"h_norm = {v['h_norm']!r}",
            )
        rotated = _rotate(q, h_body)  # type: ignore[arg-type]
        diff = max(abs(a - b) for a, b in zip(rotated, h_in, strict=True))
        if diff > tol:
            self.checks.fail(
                "momentum frame",
                f"{where}: R(q) h_body = {rotated} but h_inertial = {h_in} "
                f"(max diff {diff:.3g}); q must map body to world coordinates as /tf does",
            )

    def _check_scene(self) -> None:
        if self.scene_messages == 0:
            self.checks.fail("scene", "/scene has no messages")
        elif not self.scene_body_entity:
            self.checks.fail(
                "scene",
                "no /scene entity with frame_id 'body', frame_locked true, >= 1 cube or "
                f"cylinder and >= 2 arrows; entities seen: {self.scene_seen_partial}",
            )

    def _check_spin_z(self, rate: float) -> None:
        sim_time_at = {log_time: v["sim_time"] for log_time, v in self.telemetry}
        if not self.tf_times:
            self.checks.fail("spin-z", "--expect-spin-z: no /tf messages")
            return
        # Sim time of a /tf message: the telemetry sim_time logged with it (exact), else
        # the log time elapsed since the first sample (to the nanosecond).
        t0 = self.telemetry[0][0] if self.telemetry else min(self.tf_times)
        for log_time, quats in self.tf_by_time.items():
            t = sim_time_at.get(log_time, (log_time - t0) / NS)
            half = 0.5 * rate * t
            expected = (math.cos(half), 0.0, 0.0, math.sin(half))  # (w, x, y, z)
            for q in quats:
                diff = min(
                    max(abs(a - b) for a, b in zip(q, expected, strict=True)),
                    max(abs(a + b) for a, b in zip(q, expected, strict=True)),
                )
                if diff > SPIN_TOL:
                    self.checks.fail(
                        "spin-z rotation",
                        f"/tf {_fmt_t(log_time)} t={t!r}: rotation (x,y,z,w) = "
                        f"({q[1]!r}, {q[2]!r}, {q[3]!r}, {q[0]!r}), expected +/-(0, 0, "
                        f"{expected[3]!r}, {expected[0]!r}) (diff {diff:.3g} > {SPIN_TOL})",
                    )
        omega_tol = SPIN_TOL * max(1.0, abs(rate))
        for log_time, v in self.telemetry:
            where = f"/telemetry {_fmt_t(log_time)}"
            omega = (v["omega_x"], v["omega_y"], v["omega_z"] - rate)
            if max(abs(c) for c in omega) > omega_tol:
                self.checks.fail(
                    "spin-z omega",
                    f"{where}: omega = ({v['omega_x']!r}, {v['omega_y']!r}, {v['omega_z']!r}), "
                    f"expected (0, 0, {rate!r})",
                )
            hx, hy, hz = v["h_inertial_x"], v["h_inertial_y"], v["h_inertial_z"]
            h = math.sqrt(hx * hx + hy * hy + hz * hz)
            sign = 1.0 if rate >= 0 else -1.0
            if rate != 0 and (math.hypot(hx, hy) > SPIN_TOL * h or sign * hz <= 0):
                self.checks.fail(
                    "spin-z momentum",
                    f"{where}: h_inertial = ({hx!r}, {hy!r}, {hz!r}), expected along "
                    f"{'+' if sign > 0 else '-'}z",
                )

    # ---------------------------------------------------------------- output
    def summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "file": self.path,
            "ok": self.checks.ok,
            "topics": {
                topic: self.topic_counts.get(topic, 0)
                for topic in sorted(set(self.topic_counts) | set(self.channel_topics))
            },
            "metadata": self.metadata_names,
            "attachments": self.attachment_names,
            "units": self.units,
        }
        if not self.checks.ok:
            out["failures"] = self.checks.total
        return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="read_mcap.py",
        description="Independent checker for polhode MCAP run logs (see the module docstring).",
    )
    parser.add_argument("file", metavar="FILE.mcap", help="MCAP file written by polhode")
    parser.add_argument(
        "--expect-samples", type=int, metavar="N",
        help="require exactly N messages on /tf and on /telemetry",
    )
    parser.add_argument(
        "--expect-spin-z", type=float, metavar="RATE_RAD_S",
        help="the run is a pure spin about body z at RATE rad/s from the identity attitude",
    )
    parser.add_argument(
        "--quiet", action="store_true", help="do not print the JSON summary on stdout"
    )
    args = parser.parse_args(argv)
    if args.expect_samples is not None and args.expect_samples < 0:
        parser.error("--expect-samples must be >= 0")
    if args.expect_spin_z is not None and not math.isfinite(args.expect_spin_z):
        parser.error("--expect-spin-z must be finite")

    check = McapCheck(args.file, args.expect_samples, args.expect_spin_z)
    check.run()
    for message in check.checks.messages():
        print(f"{PROG}: FAIL: {message}", file=sys.stderr)
    if not args.quiet:
        print(json.dumps(check.summary(), separators=(",", ":")))
    return 0 if check.checks.ok else 1


if __name__ == "__main__":
    sys.exit(main())
