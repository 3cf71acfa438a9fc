#!/usr/bin/env python3
"""Whole-process timing, side by side in one run (issue 31): `pdyn run` (parse, derive each
contact mode, compile, integrate with events, write trajectory.csv and summary.json) against
SciPy solve_ivp scripts with event restarts doing the same physics at the same tolerances
(rtol 1e-10, atol 1e-12):
  1. the bouncing ball of examples/contact/bouncing_ball.toml to rest (Zeno accumulation);
  2. 1,000 stick-slip cycles of examples/contact/belt.toml.
Build first: cargo build --release -p pdyn-cli. Usage: python3 bench/contact/contact_vs_scipy.py"""
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PDYN = os.environ.get("PDYN", os.path.join(ROOT, "target", "release", "pdyn"))
HERE = os.path.join(ROOT, "bench", "contact")
CYCLES = 1000
# One stick-slip cycle of the belt model lasts stick + slip = 2 d/V + (pi + 2 asin(V/(A w)))/w.
G, M, K, V, MU_S, MU_K = 9.81, 1.0, 50.0, 0.2, 0.6, 0.4


def cycle_time():
    import math
    w = math.sqrt(K / M)
    d = (MU_S - MU_K) * M * G / K
    a = math.hypot(d, V / w)
    return 2 * d / V + (math.pi + 2 * math.asin(V / (a * w))) / w


def best_of(cmd, n):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[0], times[len(times) // 2]


def main():
    try:
        import scipy  # noqa: F401
    except ImportError:
        subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet", "scipy"])
    out = tempfile.mkdtemp()
    # The first stick phase lasts mu_s m g/(k V); each later cycle cycle_time().
    t_end = MU_S * M * G / (K * V) + (CYCLES - 1) * cycle_time() + 0.5 * cycle_time()
    # The same method family on both sides: pdyn's dopri5 (`auto`'s) against SciPy's RK45 (the
    # same Dormand-Prince 5(4) pair), pdyn's dop853 against SciPy's DOP853.
    cases = []
    for pm, sm in (("dopri5", "RK45"), ("dop853", "DOP853")):
        cases += [
            (f"bouncing ball to rest (e = 0.5), pdyn {pm} vs SciPy {sm}",
             [PDYN, "run", os.path.join(ROOT, "examples", "contact", "bouncing_ball.toml"),
              "--method", pm, "--out", out],
             [sys.executable, os.path.join(HERE, "ball_scipy.py"), os.path.join(out, "ball.csv"), sm],
             11, 5),
            (f"{CYCLES} stick-slip cycles on a belt, pdyn {pm} vs SciPy {sm}",
             [PDYN, "run", os.path.join(ROOT, "examples", "contact", "belt.toml"), "--t-end", repr(t_end),
              "--method", pm, "--out", out],
             [sys.executable, os.path.join(HERE, "belt_scipy.py"), os.path.join(out, "belt.csv"),
              str(CYCLES), sm], 5, 3),
        ]
    for name, pdyn_cmd, py_cmd, np_, ns in cases:
        p_best, p_med = best_of(pdyn_cmd, np_)
        s_best, s_med = best_of(py_cmd, ns)
        summary = json.load(open(os.path.join(out, "summary.json")))
        h = summary["hybrid"]
        print(f"{name}, rtol 1e-10, atol 1e-12, whole process:")
        print(f"  pdyn run          best {p_best*1e3:9.1f} ms  median {p_med*1e3:9.1f} ms  "
              f"({len(h['impacts'])} impacts, {len(h['switches'])} switches, "
              f"{summary['stats']['accepted']} steps, balance drift {summary['monitors'][0]['drift']:.1e})")
        print(f"  scipy solve_ivp   best {s_best*1e3:9.1f} ms  median {s_med*1e3:9.1f} ms")
        print(f"  ratio (best)      {s_best / p_best:.0f}x   (median) {s_med / p_med:.0f}x")
        print("  " + subprocess.run(py_cmd, capture_output=True, text=True).stdout.strip()
              + f" ({sum(1 for _ in open(py_cmd[2])) - 1} rows; pdyn {summary['outputs']} rows)")


if __name__ == "__main__":
    main()
