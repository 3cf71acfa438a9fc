#!/usr/bin/env python3
"""`pdyn run examples/building.toml --method exact` at the 26 forcing frequencies of
building.csv (each natural frequency, and 1e-2 ... 1e-12 from it on both sides), each compared
with the 60-digit reference: prints the worst error relative to the largest excursion from the
static equilibrium, per frequency and overall (issue 34, item 2; the Rust test
crates/pdyn/tests/resonance.rs asserts the same bound of 1e-8).

    cargo build -p pdyn-cli && python3 crates/pdyn/tests/resonance/sweep_cli.py [PDYN_BIN]
"""
import csv
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", "..", ".."))
PDYN = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "target", "debug", "pdyn")

ref = {}
with open(os.path.join(HERE, "building.csv")) as f:
    for row in list(csv.reader(f))[1:]:
        ref.setdefault(row[0], []).append([float(x) for x in row[1:]])
static = [10 - 0.0981, 20 - 1.5 * 0.0981]
worst_all = 0.0
for omega, rows in ref.items():
    times = ",".join(repr(r[0]) for r in rows)
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([PDYN, "run", os.path.join(ROOT, "examples", "building.toml"),
                        "--method", "exact", "--set", f"omega={omega}", "--t-eval", times,
                        "--out", d], check=True, capture_output=True)
        with open(os.path.join(d, "trajectory.csv")) as f:
            table = list(csv.reader(f))
    head, got = table[0], [[float(x) for x in r] for r in table[1:]]
    idx = [head.index(c) for c in ("y1", "y2", "y1'", "y2'")]
    worst = 0.0
    for group in ((0, 1), (2, 3)):
        scale = max(abs(r[1 + c] - (static[c] if c < 2 else 0.0)) for r in rows for c in group)
        for g, w in zip(got, rows):
            for c in group:
                worst = max(worst, abs(g[idx[c]] - w[1 + c]) / scale)
    worst_all = max(worst_all, worst)
    print(f"omega = {omega:<22} worst relative error {worst:.2e}")
print(f"worst over all {len(ref)} frequencies: {worst_all:.2e}")
