"""Writes the tables of docs/reliability.md (called by scripts/reliability.sh).

usage: tables.py ROWS_DIR POLHODE_BINARY DOC

ROWS_DIR holds corpus.tsv, faults.tsv and numerical.tsv written by the tests (case, what,
exit code, message, what was left). This script adds two measurements of its own: peak memory
against run length, and the log-size estimate against the size of real uncompressed logs.
"""
import os
import re
import resource
import subprocess
import sys
import tempfile

rows_dir, binary, doc = sys.argv[1:4]
binary = os.path.abspath(binary)


def read(table):
    path = os.path.join(rows_dir, f"{table}.tsv")
    with open(path, encoding="utf-8") as f:
        rows = [line.rstrip("\n").split("\t") for line in f if line.strip()]
    return sorted(rows, key=lambda r: r[0])


def cell(text):
    # Scratch directories differ from run to run; show them as <tmp>.
    text = re.sub(r"/tmp/polhode-hard-[0-9]+-[A-Za-z0-9-]+", "<tmp>", text)
    return text.replace("|", "\\|")


def outcome_table(table, with_left):
    head = "| case | what is tried | exit | what the user sees |"
    rule = "|---|---|---|---|"
    if with_left:
        head += " left on disk |"
        rule += "---|"
    out = [head, rule]
    for case, what, code, message, left in read(table):
        row = f"| {cell(case)} | {cell(what)} | {code} | `{cell(message)}` |"
        if with_left:
            row += f" {cell(left)} |"
        out.append(row)
    return "\n".join(out)


def peak_kib(args):
    """Peak resident memory (KiB) of one polhode process, measured by a fresh interpreter so
    that no earlier child's peak masks it."""
    probe = ("import resource, subprocess, sys; "
             "subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL); "
             "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    out = subprocess.run([sys.executable, "-c", probe] + args, check=True,
                         capture_output=True, text=True)
    return int(out.stdout.strip())


def memory_table():
    out = ["| simulated duration | samples | peak memory, with log | peak memory, `--no-log` |",
           "|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for duration in ["1e3", "1e4", "1e5"]:
            base = [binary, "run", "scenarios/minor-axis-spin.yaml", "--duration", duration, "-q"]
            logged = peak_kib(base + ["--out", os.path.join(tmp, "m.mcap")])
            bare = peak_kib(base + ["--no-log"])
            samples = int(float(duration) * 20) + 1
            out.append(f"| {float(duration):.0f} s | {samples:,} | {logged / 1024:.1f} MiB | "
                       f"{bare / 1024:.1f} MiB |")
    return "\n".join(out)


def estimate_table():
    out = ["| scenario (first 30 s, uncompressed) | estimate | actual | actual / estimate |",
           "|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for name in sorted(os.listdir("scenarios")):
            with open(os.path.join("scenarios", name), encoding="utf-8") as f:
                text = f.read()
            text = re.sub(r"^montecarlo:.*", "", text, flags=re.M | re.S)
            if "compression" in text:
                text = re.sub(r"compression: *\w+", "compression: none", text)
            elif re.search(r"^output:\s*\{", text, re.M):
                text = re.sub(r"^output:\s*\{", "output: {compression: none, ", text, flags=re.M)
            else:
                text = re.sub(r"^output:\s*\n", "output:\n  compression: none\n", text, flags=re.M)
            scenario = os.path.join(tmp, name)
            with open(scenario, "w", encoding="utf-8") as f:
                f.write(text)
            log = os.path.join(tmp, "x.mcap")
            common = [binary, "run", scenario, "--duration", "30", "--out", log, "-q"]
            refused = subprocess.run(common + ["--max-log-mb", "1e-9"], capture_output=True,
                                     text=True)
            m = re.search(r"about ([0-9.]+) MB", refused.stderr)
            run = subprocess.run(common, capture_output=True, text=True)
            if not m or run.returncode not in (0,) or not os.path.exists(log):
                continue
            estimate = float(m.group(1))
            actual = os.path.getsize(log) / 1e6
            stopped = " (stops early)" if actual / estimate < 0.5 else ""
            out.append(f"| {name}{stopped} | {estimate:.3g} MB | {actual:.3g} MB | "
                       f"{actual / estimate:.2f} |")
            os.remove(log)
    return "\n".join(out)


tables = {
    "corpus": outcome_table("corpus", with_left=False),
    "faults": outcome_table("faults", with_left=True),
    "numerical": outcome_table("numerical", with_left=True),
    "memory": memory_table(),
    "estimate": estimate_table(),
}

with open(doc, encoding="utf-8") as f:
    text = f.read()
for name, table in tables.items():
    pattern = re.compile(rf"(<!-- table:{name} -->\n)(?:.*?\n)?(<!-- end:{name} -->)", re.S)
    if not pattern.search(text):
        sys.exit(f"{doc}: no <!-- table:{name} --> ... <!-- end:{name} --> markers")
    text = pattern.sub(lambda m: m.group(1) + table + "\n" + m.group(2), text)
with open(doc, "w", encoding="utf-8") as f:
    f.write(text)
