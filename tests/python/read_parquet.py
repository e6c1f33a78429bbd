"""Independent check of polhode's Parquet per-run table: read runs.parquet with pyarrow and
runs.csv with Python's csv module and compare every cell exactly.

    python read_parquet.py DIR

Prints `rows N columns M identical` and exits 0 when the two tables hold the same values
(floats compared bit for bit, empty CSV cells as nulls); prints the first difference and
exits 1 otherwise.
"""
import csv
import sys

import pyarrow.parquet as pq


def main(directory: str) -> int:
    table = pq.read_table(f"{directory}/runs.parquet")
    with open(f"{directory}/runs.csv", newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    if table.schema.names != header:
        print(f"columns differ: {table.schema.names} vs {header}")
        return 1
    if table.num_rows != len(body):
        print(f"rows differ: {table.num_rows} vs {len(body)}")
        return 1
    for j, name in enumerate(header):
        values = table.column(name).to_pylist()
        for i, cell in enumerate(body):
            got = values[i]
            text = cell[j]
            if name == "run":
                want = int(text)
            elif name in ("status", "message"):
                want = text if (text or name == "status") else None
            else:
                want = float(text) if text else None
            if got != want:
                print(f"row {i} column {name}: parquet {got!r} vs csv {want!r}")
                return 1
    print(f"rows {table.num_rows} columns {len(header)} identical")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
