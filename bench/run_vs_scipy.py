#!/usr/bin/env python3
"""Whole-process timing, in one run: `pdyn run` (parse, derive, compile, integrate, write CSV)
vs a Python script solving the same equations with SciPy's solve_ivp (DOP853), both on the
satellite for 100 periods at rtol = atol = 1e-10. Also: a 1000-run sweep of the 2-storey
building on 1 and 2 threads. Build first: cargo build --release -p pdyn-cli."""
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PDYN = os.path.join(ROOT, "target", "release", "pdyn")


def best_of(cmd, n):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - t0)
    return min(times), sorted(times)[len(times) // 2]


def main():
    try:
        import scipy  # noqa: F401
    except ImportError:
        subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet", "scipy"])
    out = tempfile.mkdtemp()
    pdyn_cmd = [PDYN, "run", os.path.join(ROOT, "examples", "satellite.toml"), "--method", "dop853",
                "--rtol", "1e-10", "--atol", "1e-10", "--t-end", "628.3185307179587", "--out", out]
    py_cmd = [sys.executable, os.path.join(ROOT, "bench", "satellite_scipy.py"), os.path.join(out, "scipy.csv")]
    p_best, p_med = best_of(pdyn_cmd, 7)
    s_best, s_med = best_of(py_cmd, 5)
    print(f"satellite, 100 periods, rtol=atol=1e-10, whole process:")
    print(f"  pdyn run          best {p_best*1e3:8.1f} ms  median {p_med*1e3:8.1f} ms")
    print(f"  scipy solve_ivp   best {s_best*1e3:8.1f} ms  median {s_med*1e3:8.1f} ms")
    print(f"  ratio (median)    {s_med / p_med:.1f}x")
    summary = json.load(open(os.path.join(out, "summary.json")))
    print(f"  pdyn: {summary['stats']['accepted']} steps, {summary['stats']['fevals']} f-evaluations")
    print(subprocess.run(py_cmd, capture_output=True, text=True).stdout.strip())

    sweep_model = os.path.join(out, "building_sweep.toml")
    src = open(os.path.join(ROOT, "examples", "building.toml")).read().replace("steps = 281", "steps = 1000")
    open(sweep_model, "w").write(src)
    for threads in (1, 2):
        t0 = time.perf_counter()
        r = subprocess.run([PDYN, "sweep", sweep_model, "--threads", str(threads), "--json"],
                           check=True, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        v = json.loads(r.stdout)
        print(f"building sweep, 1000 runs, {threads} thread(s): {v['runs_per_second']:.0f} runs/s "
              f"(sweep {v['seconds']:.2f} s, whole process {wall:.2f} s)")


if __name__ == "__main__":
    main()
