"""Benchmarks of pdyn.study (issue 16): per-task overhead of the Dask backend vs the local
one, and a large Kremlin Monte Carlo vs a loop over SciPy. Build the extension in release
mode first (docs/benchmarks-python.md), then, from the repository root:

    python bench/python/bench_study.py            # needs dask[distributed], pandas, scipy

Prints Markdown tables. RUNS (default 10000) building runs (t_end = 2, so that the per-task
cost shows) for chunk sizes 10..RUNS: local (one process, the Rust ensemble on all cores),
Dask LocalCluster with 1 worker process (each task on every core) and with 2 worker
processes (each task on one thread). KREMLIN (default 10^6) Kremlin samples locally vs a
Python loop over SciPy solve_ivp timed on 1000 and extrapolated.
"""

import math
import os
import sys
import time

import numpy as np

import pdyn
from pdyn.study import Samples, Sets, Study, normal

RUNS = int(os.environ.get("RUNS", 10_000))
KREMLIN = int(os.environ.get("KREMLIN", 1_000_000))


BUILDING = pdyn.Model.from_file("examples/building.toml")


def building_study(chunk):
    # One model object: it derives and compiles once (in this process; each Dask worker
    # does so once per process), so the table shows the per-task cost.
    m = BUILDING
    design = Sets({"omega": np.linspace(2, 30, RUNS)})
    return Study(m, design, measures={"top": ("y2 - (2*L - 3*m*g/(2*k))", "max_abs")},
                 settings={"t_end": 2.0, "points": 201}, chunk_size=chunk)


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def overhead_table():
    from distributed import Client, LocalCluster
    chunks = [c for c in (10, 100, 1000, 10_000) if c <= RUNS]
    rows = []
    secs, ref = timed(lambda: building_study(RUNS).run().table)
    print(f"first local run (derives and compiles the model once): {secs:.2f} s")
    local = {}
    for c in chunks:
        secs, res = timed(lambda: building_study(c).run())
        local[c] = secs
        assert res.table.equals(ref)
        rows.append(("local", c, math.ceil(RUNS / c), secs))
    for workers, threads in ((1, None), (2, 1)):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cl, Client(cl) as client:
            building_study(RUNS).run(client=client)  # warm the workers (imports)
            for c in chunks:
                secs, res = timed(lambda: building_study(c).run(client=client, threads=threads))
                assert res.table.equals(ref), "Dask and local differ"
                rows.append((f"Dask, {workers} worker{'s' if workers > 1 else ''}"
                             f" x {threads or os.cpu_count()} thread{'s' if (threads or os.cpu_count()) > 1 else ''}",
                             c, math.ceil(RUNS / c), secs))
    best_local = min(local.values())
    print(f"\n{RUNS} building runs (t_end = 2, 201 points), {os.cpu_count()} cores\n")
    print("| backend | chunk size | tasks | wall time | runs/s | overhead per task vs best local |")
    print("|---|---|---|---|---|---|")
    for backend, c, tasks, secs in rows:
        over = (secs - best_local) / tasks
        print(f"| {backend} | {c} | {tasks} | {secs:.2f} s | {RUNS / secs:.0f} | "
              f"{over * 1e3:.1f} ms |")


def kremlin_table():
    from scipy.integrate import solve_ivp
    m = pdyn.Model.from_file("examples/kremlin_stone.toml")
    v0, th = 11.176, math.radians(45)
    design = Samples(KREMLIN, seed=1, v0=normal(v0, 1.0), theta=normal(th, math.radians(5)))
    study = Study(m, design, measures={"range": ("x", "final")}, chunk_size=100_000)
    secs, res = timed(study.run)
    p = res.probability("range > 40")

    def hit(t, w):
        return w[1]
    hit.terminal, hit.direction = True, -1
    x = study.matrix()[:1000]
    t0 = time.perf_counter()
    ranges = []
    for v, a in x:
        s = solve_ivp(lambda t, w: [w[2], w[3], 0.0, -9.81], (0, 10),
                      [0.0, 71.0, v * math.cos(a), v * math.sin(a)], method="DOP853",
                      rtol=1e-10, atol=1e-12, events=hit)
        ranges.append(s.y_events[0][0, 0])
    loop = (time.perf_counter() - t0) * KREMLIN / 1000
    agree = float(np.max(np.abs(np.array(ranges) - res.table["range"][:1000])))
    print(f"\nKremlin Monte Carlo, {KREMLIN} samples (rtol 1e-10, atol 1e-12, DOP853/auto)\n")
    print("| | wall time | runs/s |\n|---|---|---|")
    print(f"| pdyn.study local ({os.cpu_count()} cores, chunks of 100000) | {secs:.2f} s | "
          f"{KREMLIN / secs:.0f} |")
    print(f"| Python loop over scipy solve_ivp (1000 timed, extrapolated) | {loop:.0f} s | "
          f"{KREMLIN / loop:.0f} |")
    print(f"\nratio {loop / secs:.0f}x; ranges agree to {agree:.1e} m; {p}")


if __name__ == "__main__":
    what = sys.argv[1:] or ["overhead", "kremlin"]
    if "overhead" in what:
        overhead_table()
    if "kremlin" in what:
        kremlin_table()
