"""Turns the CSV of run.sh into the markdown tables of docs/benchmarks.md (pdyn-ode section).
Usage: ./run.sh > peers.csv && python3 summarize.py peers.csv"""
import csv
import sys
from collections import defaultdict

rows = [r for r in csv.reader(open(sys.argv[1])) if r and not r[0].startswith(("#", "problem"))]
data = defaultdict(dict)  # (problem, tol) -> {impl/method: (err, nfev, sec)}
for p, impl, meth, tol, err, nfev, sec in rows:
    data[(p, float(tol))][f"{impl}/{meth}"] = (float(err), int(nfev), float(sec))


def fmt(x):
    return f"{x:.2e}"


for prob in ["arenstorf", "pleiades"]:
    print(f"\n#### {prob.capitalize()}: time (s), f-evaluations, final error\n")
    cols = ["pdyn/dopri5", "ode_solvers/dopri5", "differential_equations/dopri5", "scipy_solve_ivp/rk45",
            "pdyn/dop853", "ode_solvers/dop853", "differential_equations/dop853",
            "scipy_ode_fortran/dop853", "scipy_solve_ivp/dop853", "pdyn/tsit5", "diffsol/tsit45", "pdyn/vern9"]
    print("| tol | " + " | ".join(cols) + " |")
    print("|---" * (len(cols) + 1) + "|")
    for tol in sorted({t for (p, t) in data if p == prob}, reverse=True):
        d = data[(prob, tol)]
        cells = [f"{fmt(d[c][2])} / {d[c][1]} / {fmt(d[c][0])}" if c in d else "–" for c in cols]
        print(f"| {tol:.0e} | " + " | ".join(cells) + " |")
    print("\nRatios of wall time (same method, same tolerance, same f-evaluations up to ±1):\n")
    print("| tol | pdyn/ode_solvers dopri5 | pdyn/ode_solvers dop853 | solve_ivp RK45 / pdyn dopri5 | "
          "solve_ivp DOP853 / pdyn dop853 | Fortran dop853 (scipy.ode) / pdyn dop853 |")
    print("|---|---|---|---|---|---|")
    for tol in sorted({t for (p, t) in data if p == prob}, reverse=True):
        d = data[(prob, tol)]
        r = lambda a, b: f"{d[a][2] / d[b][2]:.2f}" if a in d and b in d else "–"
        print(f"| {tol:.0e} | {r('pdyn/dopri5', 'ode_solvers/dopri5')} | {r('pdyn/dop853', 'ode_solvers/dop853')} | "
              f"{r('scipy_solve_ivp/rk45', 'pdyn/dopri5')} | {r('scipy_solve_ivp/dop853', 'pdyn/dop853')} | "
              f"{r('scipy_ode_fortran/dop853', 'pdyn/dop853')} |")

import math


def curve(prob, key):
    pts = sorted((v[key][0], v[key][2]) for (p, t), v in data.items() if p == prob and key in v)
    return [(math.log(e), math.log(t)) for e, t in pts if e > 0]


def at_error(pts, err):
    """Wall time interpolated (log–log) at final error `err`, None outside the measured range."""
    le = math.log(err)
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if min(e0, e1) <= le <= max(e0, e1) and e0 != e1:
            return math.exp(t0 + (t1 - t0) * (le - e0) / (e1 - e0))
    return None


def best(prob, keys, err):
    ts = [(at_error(curve(prob, k), err), k) for k in keys]
    ts = [x for x in ts if x[0] is not None]
    return min(ts) if ts else (None, None)


print("\n#### Work–precision at equal error (log–log interpolation between tolerances)\n")
print("Best time over each family's methods at the same final error; ratio = pdyn / peer.\n")
print("| problem | error | pdyn best | best Rust peer | ratio | best SciPy | SciPy / pdyn |")
print("|---|---|---|---|---|---|---|")
pd = ["pdyn/dopri5", "pdyn/dop853", "pdyn/tsit5", "pdyn/vern9"]
rust = ["ode_solvers/dopri5", "ode_solvers/dop853", "differential_equations/dopri5", "differential_equations/dop853",
        "diffsol/tsit45"]
sci = ["scipy_solve_ivp/rk45", "scipy_solve_ivp/dop853", "scipy_ode_fortran/dop853"]
for prob in ["arenstorf", "pleiades"]:
    for err in [1e-2, 1e-4, 1e-6, 1e-8, 1e-10]:
        tp, kp = best(prob, pd, err)
        tr, kr = best(prob, rust, err)
        ts, ks = best(prob, sci, err)
        if tp is None:
            continue
        rr = f"{tp / tr:.2f}" if tr else "–"
        rs = f"{ts / tp:.0f}" if ts else "–"
        print(f"| {prob} | {err:.0e} | {tp:.2e} ({kp}) | {f'{tr:.2e} ({kr})' if tr else '–'} | {rr} | "
              f"{f'{ts:.2e} ({ks})' if ts else '–'} | {rs} |")

print("\n#### Robertson to t = 1e11 (atol = 1e-6·rtol): time (s) / f-evaluations / max relative error\n")
cols = ["pdyn/radau5", "diffsol/bdf", "scipy_solve_ivp/radau", "scipy_solve_ivp/bdf", "scipy_solve_ivp/lsoda"]
print("| rtol | " + " | ".join(cols) + " |")
print("|---" * (len(cols) + 1) + "|")
for tol in sorted({t for (p, t) in data if p == "robertson"}, reverse=True):
    d = data[("robertson", tol)]
    cells = [f"{fmt(d[c][2])} / {d[c][1]} / {fmt(d[c][0])}" if c in d else "–" for c in cols]
    print(f"| {tol:.0e} | " + " | ".join(cells) + " |")

print("\n#### Kepler e = 0.6, 10^7 steps of h = 2π/100\n")
print("| integrator | time per step (ns) | relative energy error at the end |")
print("|---|---|---|")
for (p, t), d in data.items():
    if p != "kepler":
        continue
    for k, (err, nfev, sec) in d.items():
        print(f"| {k} | {sec / t * 1e9:.1f} | {err:.2e} |")
