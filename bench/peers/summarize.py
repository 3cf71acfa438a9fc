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
    cols = ["pdyn/dopri5", "ode_solvers/dopri5", "scipy_solve_ivp/rk45",
            "pdyn/dop853", "ode_solvers/dop853", "scipy_ode_fortran/dop853", "scipy_solve_ivp/dop853",
            "pdyn/tsit5"]
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

print("\n#### Robertson to t = 1e11 (atol = 1e-6·rtol): time (s) / f-evaluations / max relative error\n")
cols = ["pdyn/radau5", "scipy_solve_ivp/radau", "scipy_solve_ivp/bdf", "scipy_solve_ivp/lsoda"]
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
