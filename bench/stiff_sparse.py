"""Radau and BDF with a sparse Jacobian pattern: `pdyn.solve_ivp` against SciPy's `solve_ivp`,
the same call on both sides (issue 33, item 3: stiff many-particle systems).

The problem: the 2-D heat equation u_t = Δu on the unit square, m × m interior points, zero
on the boundary, 5-point Laplacian as a scipy.sparse matrix; `fun(t, u) = lap @ u`;
`jac_sparsity = lap != 0`; rtol 1e-8, atol 1e-10, t = 0..0.02 from the lowest mode
sin(πx) sin(πy), whose exact decay is known: both errors are printed. SciPy factors with
SuperLU (`scipy.sparse.linalg.splu`), pdyn with its own nested-dissection LU
(`pdyn_ode::sparse_lu`). Each call is timed whole (the Python call: finite-difference
Jacobians through `fun`, factorizations, steps), best of REPEAT, the two alternating.

    python3 -m venv /tmp/venv-bench && /tmp/venv-bench/bin/pip install numpy scipy
    (cd crates/pdyn-py && VIRTUAL_ENV=/tmp/venv-bench /tmp/venv-bench/bin/maturin develop --release)
    REPEAT=3 /tmp/venv-bench/bin/python bench/stiff_sparse.py 50 100 200
    METHODS=BDF REPEAT=3 /tmp/venv-bench/bin/python bench/stiff_sparse.py 50 100   # one method
"""
import os
import sys
import time

import numpy as np
import scipy.integrate
from scipy import sparse as sp

import pdyn


def problem(m):
    h = 1.0 / (m + 1)
    x = np.arange(1, m + 1) * h
    u0 = np.outer(np.sin(np.pi * x), np.sin(np.pi * x)).ravel()
    rate = 8.0 / h**2 * np.sin(np.pi * h / 2) ** 2
    lap1 = sp.diags([1.0, -2.0, 1.0], [-1, 0, 1], shape=(m, m))
    lap = (sp.kron(sp.eye(m), lap1) + sp.kron(lap1, sp.eye(m))).tocsr() / h**2
    return lap, u0, rate


def main():
    repeat = int(os.environ.get("REPEAT", "3"))
    sizes = [int(a) for a in sys.argv[1:]] or [50, 100]
    methods = os.environ.get("METHODS", "Radau,BDF").split(",")
    t_end = 0.02
    print("| method | m × m | states | solver | best s | nfev | njev | nlu | max error vs closed form |")
    print("|---|---|---|---|---|---|---|---|---|")
    for method in methods:
        for m in sizes:
            run(method, m, t_end, repeat)


def run(method, m, t_end, repeat):
    """One method on one grid, both solvers, a table row each."""
    lap, u0, rate = problem(m)
    exact = np.exp(-rate * t_end) * u0
    pattern = lap != 0

    def fun(t, u):
        return lap @ u

    best = {}
    results = {}
    for _ in range(repeat):
        for name, solve in (("pdyn", pdyn.solve_ivp), ("scipy", scipy.integrate.solve_ivp)):
            t0 = time.perf_counter()
            r = solve(fun, (0, t_end), u0, method=method, rtol=1e-8, atol=1e-10,
                      jac_sparsity=pattern)
            dt = time.perf_counter() - t0
            assert r.success, (name, r.message)
            best[name] = min(best.get(name, float("inf")), dt)
            results[name] = r
    for name in ("pdyn", "scipy"):
        r = results[name]
        err = np.max(np.abs(r.y[:, -1] - exact))
        print(f"| {method} | {m} × {m} | {m * m} | {name} | {best[name]:.3f} | {r.nfev} | "
              f"{r.njev} | {r.nlu} | {err:.1e} |")
    print(f"<!-- {method}, m = {m}: SciPy / pdyn = {best['scipy'] / best['pdyn']:.1f}x -->")


if __name__ == "__main__":
    main()
