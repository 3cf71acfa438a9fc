#!/usr/bin/env python3
"""The outer Solar System at the example's own output density, pdyn against REBOUND doing
the same outputs (issue 28, item 4).

Usage (from the repository root, after `cargo build --release -p pdyn-cli`):

    python3 bench/nbody/outputs.py [YEARS] [REPEAT]      # default 100000 years, 3 repeats

The case is `examples/nbody/outer_solar_system.toml` as shipped: WHFast, dt = P_J/20 with
P_J = 4332.59 d, the 11th-order corrector, an output every other step (P_J/10), over YEARS.
Every output has the positions and velocities of the five bodies, the Jacobi orbital
elements of the four planets, the energy and the angular momentum.

- pdyn: the whole command `pdyn run examples/nbody/outer_solar_system.toml --t-end T --out DIR`
  (process start to exit; it writes trajectory.csv, elements.csv, conservation.csv).
- REBOUND 5.2.2 (PyPI, its C core), the same system and settings (safe_mode = 0, corrector
  11, exact_finish_time = 0 so that outputs fall on the step grid as pdyn's do); at each
  output `serialize_particle_data`, `orbits()` (Jacobi), `energy()`, `angular_momentum()`
  into preallocated NumPy arrays; no files written (REBOUND's side is given the cheaper task).
  Timed three times: `keep_unsynchronized = 0` (REBOUND's default: each output undoes the
  corrector and the next step applies it again) and `= 1` (the output synchronises a copy,
  as pdyn now always does), and with `keep_unsynchronized = 1` calling `integrate` at each
  output time and reading nothing (the floor of REBOUND's cost for these output times: what
  its C core does, without the Python-side reading).

Runs alternate (the machine is shared); the table gives medians.
"""
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
VENV = os.path.join(HERE, ".venv")
PDYN = os.path.join(ROOT, "target", "release", "pdyn")
MODEL = os.path.join(ROOT, "examples", "nbody", "outer_solar_system.toml")


def ensure_venv():
    py = os.path.join(VENV, "bin", "python")
    if not os.path.exists(py):
        venv.create(VENV, with_pip=True)
        subprocess.check_call([py, "-m", "pip", "install", "-q", "rebound==5.2.2", "numpy"])
    if os.path.realpath(sys.prefix) != os.path.realpath(VENV):
        os.execv(py, [py] + sys.argv)


ensure_venv()
import numpy as np  # noqa: E402
import rebound  # noqa: E402

# examples/nbody/outer_solar_system.toml (Applegate et al. 1986 epoch), as run.py has them.
sys.path.insert(0, HERE)
from run import MASS, POS, VEL  # noqa: E402
P_J = 4332.59
YEAR = 365.25


def rebound_run(t_end, keep_unsynchronized, what="all"):
    sim = rebound.Simulation()
    sim.G = 0.01720209895 ** 2
    for m, r, v in zip(MASS, POS, VEL):
        sim.add(m=m, x=r[0], y=r[1], z=r[2], vx=v[0], vy=v[1], vz=v[2])
    sim.move_to_com()
    sim.integrator = "whfast"
    sim.integrator.safe_mode = 0
    sim.integrator.corrector = 11
    sim.integrator.keep_unsynchronized = keep_unsynchronized
    sim.dt = P_J / 20
    # pdyn's output times: the grid of P_J/10, then t_end itself (a shortened last step).
    times = [k * (P_J / 10) for k in range(int(t_end / (P_J / 10)) + 1)]
    if times[-1] < t_end:
        times.append(t_end)
    n_out = len(times)
    states = np.empty((n_out, 5, 6))
    elements = np.empty((n_out, 4, 8))
    conservation = np.empty((n_out, 5))
    xyz = np.empty((5, 3))
    vxyz = np.empty((5, 3))
    t0 = time.perf_counter()
    for k, t in enumerate(times):
        if k:
            sim.integrate(t, exact_finish_time=int(k == n_out - 1))
        if what == "integrate":
            continue
        sim.serialize_particle_data(xyz=xyz, vxvyvz=vxyz)
        states[k, :, :3] = xyz
        states[k, :, 3:] = vxyz
        for j, o in enumerate(sim.orbits()):
            elements[k, j] = (o.a, o.e, o.inc, o.Omega, o.omega, o.f, o.M, o.P)
        conservation[k, 0] = sim.t
        conservation[k, 1] = sim.energy()
        conservation[k, 2:] = sim.angular_momentum()
    seconds = time.perf_counter() - t0
    sim.serialize_particle_data(xyz=xyz)
    return seconds, sim.steps_done, n_out, xyz.copy()


def pdyn_run(t_end):
    out = tempfile.mkdtemp(prefix="pdyn-oss-")
    try:
        t0 = time.perf_counter()
        subprocess.run([PDYN, "run", MODEL, "--t-end", repr(t_end), "--out", out],
                       check=True, stdout=subprocess.DEVNULL)
        seconds = time.perf_counter() - t0
        with open(os.path.join(out, "conservation.csv")) as f:
            rows = sum(1 for _ in f) - 1
        final = {}
        with open(os.path.join(out, "trajectory.csv")) as f:
            for line in f:
                cells = line.split(",")
                final[cells[1]] = [float(c) for c in cells[2:5]] if cells[0] != "t" else None
        return seconds, rows, final
    finally:
        shutil.rmtree(out, ignore_errors=True)


def main():
    years = float(sys.argv[1]) if len(sys.argv) > 1 else 1e5
    repeat = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    t_end = years * YEAR
    ours, rb0, rb1, rbi = [], [], [], []
    for _ in range(repeat):
        s, rows, final = pdyn_run(t_end)
        ours.append(s)
        r0 = rebound_run(t_end, 0)
        rb0.append(r0[0])
        r1 = rebound_run(t_end, 1)
        rb1.append(r1[0])
        ri = rebound_run(t_end, 1, "integrate")
        rbi.append(ri[0])
    names = ["Sun", "Jupiter", "Saturn", "Uranus", "Neptune"]
    # Against the default run: with keep_unsynchronized = 1, REBOUND 5.2.2's last,
    # shortened step (exact_finish_time = 1) is lost (its final positions are those of the
    # last full step; checked against a single `integrate(t_end)` call, which agrees with
    # the default run and with pdyn).
    dev = max(np.linalg.norm(np.array(final[n]) - r0[3][i]) / np.linalg.norm(r0[3][i])
              for i, n in enumerate(names))
    load = os.getloadavg()[0]
    a, b0, b1, bi = (statistics.median(x) for x in (ours, rb0, rb1, rbi))
    print(f"outer Solar System, {years:g} yr, output every other step "
          f"(pdyn {rows} output rows, REBOUND {r1[2]}; REBOUND steps {r1[1]}), "
          f"medians of {repeat}, load {load:.1f}")
    print("| run | seconds | µs per output | pdyn / this |")
    print("|---|---|---|---|")
    print(f"| pdyn, whole command, writing 3 CSV files | {a:.3f} | {1e6 * a / rows:.2f} | 1 |")
    print(f"| REBOUND, keep_unsynchronized = 0 (default), arrays only | {b0:.3f} | "
          f"{1e6 * b0 / r0[2]:.2f} | {a / b0:.2f} |")
    print(f"| REBOUND, keep_unsynchronized = 1, arrays only | {b1:.3f} | "
          f"{1e6 * b1 / r1[2]:.2f} | {a / b1:.2f} |")
    print(f"| REBOUND, keep_unsynchronized = 1, `integrate` to each output time and nothing "
          f"else | {bi:.3f} | {1e6 * bi / ri[2]:.2f} | {a / bi:.2f} |")
    print(f"final positions, pdyn vs REBOUND (keep_unsynchronized = 0), max relative "
          f"difference: {dev:.2e}")


if __name__ == "__main__":
    main()
