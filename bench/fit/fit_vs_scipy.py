#!/usr/bin/env python3
"""Whole-process timing, in one run: `pdyn fit` of the drag model examples/data/drop.toml to
the 200 samples of examples/data/drop.csv (c, initial height and rate free) vs the Python +
SciPy script bench/fit/drop_scipy.py doing the same fit (least_squares + solve_ivp). Both
optima are printed and compared. Build first: cargo build --release -p pdyn-cli; SciPy from
the environment (pip install scipy)."""
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PDYN = os.path.join(ROOT, "target", "release", "pdyn")
MODEL = os.path.join(ROOT, "examples", "data", "drop.toml")
DATA = os.path.join(ROOT, "examples", "data", "drop.csv")


def timed(cmd, n):
    times, out = [], None
    for _ in range(n):
        t0 = time.perf_counter()
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[0], times[len(times) // 2], out


def main():
    pdyn_cmd = [PDYN, "fit", MODEL, "--data", DATA, "--free", "c,initial.z,rate.z", "--json"]
    py_cmd = [sys.executable, os.path.join(ROOT, "bench", "fit", "drop_scipy.py"), DATA]
    p_best, p_med, p_out = timed(pdyn_cmd, 11)
    s_best, s_med, s_out = timed(py_cmd, 5)
    p = json.loads(p_out)
    s = json.loads(s_out)
    px = [e["value"] for e in p["estimates"]]
    print("fit of a drag model (c, z0, v0) to 200 samples, whole process:")
    print(f"  pdyn fit                       best {p_best*1e3:8.1f} ms  median {p_med*1e3:8.1f} ms"
          f"  ({p['evaluations']} evaluations with sensitivities)")
    print(f"  scipy least_squares+solve_ivp  best {s_best*1e3:8.1f} ms  median {s_med*1e3:8.1f} ms"
          f"  ({s['nfev']} evaluations + finite differences)")
    print(f"  ratio (median)                 {s_med / p_med:.1f}x   (best {s_best / p_best:.1f}x)")
    print(f"  scipy's least_squares call alone (no start-up, no imports): {s['fit_seconds']*1e3:.1f} ms"
          f" = {s['fit_seconds'] / p_med:.1f}x pdyn's whole process")
    print(f"  pdyn  x = {px}")
    print(f"  scipy x = {s['x']}")
    print("  max relative difference", max(abs(a - b) / abs(b) for a, b in zip(px, s["x"])))


if __name__ == "__main__":
    main()
