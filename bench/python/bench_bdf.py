"""pdyn's BDF beside SciPy's BDF (and both Radaus) on stiff reference problems: steps,
evaluations, Jacobians, LU factorizations and the error against the published solution.
Counts, not times (issue 30: "a real BDF").

    target/venv-bench/bin/python bench/python/bench_bdf.py

(a venv with pdyn built by `maturin develop --release`, numpy and scipy). Prints a Markdown
table. Problems: Robertson to t = 1e11 (Bari test set reference), Van der Pol mu = 1000 in
the scaled form y1' = y2, y2' = ((1 - y1^2) y2 - y1)/1e-6 on [0, 2] (Bari test set
reference, RADAU5 at tol 1.1e-18), Prothero-Robinson y' = -1e5 (y - cos t) - sin t on
[0, 10] (exact cos t, finite-difference Jacobian). The Jacobian is given (analytic) except
for Prothero-Robinson. Steps: accepted steps (`len(t) - 1`).
"""

import math

import numpy as np
import scipy
import scipy.integrate as si

import pdyn


def robertson(t, y):
    return [-0.04 * y[0] + 1e4 * y[1] * y[2],
            0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] ** 2,
            3e7 * y[1] ** 2]


def robertson_jac(t, y):
    return [[-0.04, 1e4 * y[2], 1e4 * y[1]],
            [0.04, -1e4 * y[2] - 6e7 * y[1], -1e4 * y[1]],
            [0.0, 6e7 * y[1], 0.0]]


def vdp(t, y):
    return [y[1], ((1 - y[0] ** 2) * y[1] - y[0]) / 1e-6]


def vdp_jac(t, y):
    return [[0.0, 1.0], [(-2 * y[0] * y[1] - 1) / 1e-6, (1 - y[0] ** 2) / 1e-6]]


def pr(t, y):
    return [-1e5 * (y[0] - math.cos(t)) - math.sin(t)]


CASES = [
    ("Robertson, t = 0..1e11, rtol 1e-8 atol 1e-14", robertson, robertson_jac, (0, 1e11),
     [1.0, 0.0, 0.0], dict(rtol=1e-8, atol=1e-14),
     lambda t, y: np.abs(y / [0.2083340149701255e-7, 0.8333360770334713e-13,
                              0.9999999791665050] - 1).max(), "max rel. error"),
    ("Van der Pol mu=1000 (scaled), rtol=atol=1e-4", vdp, vdp_jac, (0, 2), [2.0, 0.0],
     dict(rtol=1e-4, atol=1e-4),
     lambda t, y: np.abs(y - [1.706167732170483, -0.8928097010247975]).max(), "max error"),
    ("Van der Pol mu=1000 (scaled), rtol=atol=1e-6", vdp, vdp_jac, (0, 2), [2.0, 0.0],
     dict(rtol=1e-6, atol=1e-6),
     lambda t, y: np.abs(y - [1.706167732170483, -0.8928097010247975]).max(), "max error"),
    ("Van der Pol mu=1000 (scaled), rtol=atol=1e-9", vdp, vdp_jac, (0, 2), [2.0, 0.0],
     dict(rtol=1e-9, atol=1e-9),
     lambda t, y: np.abs(y - [1.706167732170483, -0.8928097010247975]).max(), "max error"),
    ("Prothero-Robinson lambda=1e5, rtol=atol=1e-7 (FD Jacobian)", pr, None, (0, 10), [1.0],
     dict(rtol=1e-7, atol=1e-7), lambda t, y: abs(y[0] - math.cos(t)), "error"),
]


def main():
    print(f"SciPy {scipy.__version__}, NumPy {np.__version__}\n")
    print("| problem | solver | steps | nfev | njev | nlu | error at the end |")
    print("|---|---|---|---|---|---|---|")
    for name, f, jac, span, y0, tol, err, what in CASES:
        kw = dict(tol)
        if jac is not None:
            kw["jac"] = jac
        for label, solve, method in [("SciPy BDF", si.solve_ivp, "BDF"),
                                     ("pdyn BDF", pdyn.solve_ivp, "BDF"),
                                     ("SciPy Radau", si.solve_ivp, "Radau"),
                                     ("pdyn Radau", pdyn.solve_ivp, "Radau")]:
            r = solve(f, span, y0, method=method, **kw)
            e = err(r.t[-1], r.y[:, -1])
            print(f"| {name} | {label} | {len(r.t) - 1} | {r.nfev} | {r.njev} | {r.nlu} "
                  f"| {e:.1e} ({what}) |")


if __name__ == "__main__":
    main()
