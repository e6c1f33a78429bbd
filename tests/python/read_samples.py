#!/usr/bin/env python3
"""Independent check of `polhode run --csv FILE --parquet FILE` against the run's MCAP log.

Usage:
    read_samples.py LOG.mcap TABLE.csv TABLE.parquet

Reads the log with the Foxglove `mcap` package and decodes every /telemetry,
/effectors/<name> and /orbit message from the schemas embedded in the file (no code
from the Rust side), builds one row per /telemetry sample (its fields, then each
effector's fields as `<effector>.<field>`, effectors in channel order, then, when the
log has an /orbit channel, its attitude relative to LVLH: the fields LVLH_FIELDS under
their own names), and checks that:
  - the CSV, read with Python's csv module, has the same rows, bit for bit
    (float(text) == the decoded double), and its header names are the columns
    with their units as `name [unit]`, the units being the MCAP channels' `units`
    metadata;
  - the Parquet file, read with pyarrow, has the same columns in the same order,
    the same rows bit for bit, and its key-value metadata `units` equals the
    MCAP channels' units.
Prints "rows N columns M identical" and exits 0 when everything matches, 1 on a
mismatch (printed on stderr), 2 on a usage error.
"""

from __future__ import annotations

import csv
import json
import sys

try:
    import pyarrow.parquet as pq
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
except ImportError as e:  # pragma: no cover
    print(f"read_samples: missing Python package ({e}); run scripts/python-venv.sh", file=sys.stderr)
    sys.exit(2)


# The /orbit fields the tables carry for a scenario with an orbit (docs/logs.md).
LVLH_FIELDS = (
    "q_lvlh_w", "q_lvlh_x", "q_lvlh_y", "q_lvlh_z",
    "roll_deg", "pitch_deg", "yaw_deg",
    "omega_lvlh_x", "omega_lvlh_y", "omega_lvlh_z",
)


def fail(message: str) -> None:
    print(f"read_samples: FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def from_log(path: str):
    """Columns (name, unit) and rows from the MCAP log."""
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        channels = sorted(summary.channels.values(), key=lambda c: c.id)
        telemetry = [c for c in channels if c.topic == "/telemetry"][0]
        effectors = [c for c in channels if c.topic.startswith("/effectors/")]
        orbit = [c for c in channels if c.topic == "/orbit"]
        columns: list[tuple[str, str]] = []
        for channel, prefix in [(telemetry, "")] + [
            (c, c.topic[len("/effectors/"):] + ".") for c in effectors
        ]:
            units = json.loads(channel.metadata["units"])
            for name, unit in units.items():
                if prefix and name == "sim_time":
                    continue
                columns.append((prefix + name, unit))
        for channel in orbit:
            units = json.loads(channel.metadata["units"])
            columns.extend((name, units[name]) for name in LVLH_FIELDS)
        samples: dict[int, list[float]] = {}
        extra: dict[str, dict[int, list[float]]] = {c.topic: {} for c in effectors + orbit}
        for _, channel, message, decoded in reader.iter_decoded_messages(
            topics=["/telemetry"] + [c.topic for c in effectors + orbit]
        ):
            if channel.topic == "/orbit":
                extra["/orbit"][message.log_time] = [getattr(decoded, n) for n in LVLH_FIELDS]
                continue
            values = [getattr(decoded, f.name) for f in decoded.DESCRIPTOR.fields]
            if channel.topic == "/telemetry":
                samples[message.log_time] = values
            else:
                extra[channel.topic][message.log_time] = values[1:]
    rows = []
    for log_time in sorted(samples):
        row = list(samples[log_time])
        for c in effectors + orbit:
            row.extend(extra[c.topic][log_time])
        rows.append(row)
    return columns, rows


def main() -> None:
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    log, csv_path, parquet_path = sys.argv[1:]
    columns, rows = from_log(log)
    if not rows:
        fail("the log has no /telemetry samples")

    with open(csv_path, newline="") as f:
        records = list(csv.reader(f))
    header = [f"{n} [{u}]" if u else n for n, u in columns]
    if records[0] != header:
        fail(f"CSV header {records[0][:4]}… differs from the log's columns {header[:4]}…")
    if len(records) - 1 != len(rows):
        fail(f"CSV has {len(records) - 1} rows, the log {len(rows)} samples")
    for i, (text, row) in enumerate(zip(records[1:], rows)):
        values = [float(x) for x in text]
        if values != row:
            k = next(j for j, (a, b) in enumerate(zip(values, row)) if a != b)
            fail(f"CSV row {i}, column {columns[k][0]}: {values[k]!r} against the log's {row[k]!r}")

    table = pq.read_table(parquet_path)
    names = [n for n, _ in columns]
    if table.column_names != names:
        fail(f"Parquet columns {table.column_names[:4]}… differ from {names[:4]}…")
    if table.num_rows != len(rows):
        fail(f"Parquet has {table.num_rows} rows, the log {len(rows)} samples")
    units = json.loads(table.schema.metadata[b"units"])
    if list(units.items()) != columns:
        fail("Parquet `units` metadata differs from the log's channels' units")
    data = [table.column(k).to_pylist() for k in range(table.num_columns)]
    for i, row in enumerate(rows):
        for k, value in enumerate(row):
            if data[k][i] != value:
                fail(f"Parquet row {i}, column {names[k]}: {data[k][i]!r} against the log's {value!r}")
    print(f"rows {len(rows)} columns {len(names)} identical")


if __name__ == "__main__":
    main()
