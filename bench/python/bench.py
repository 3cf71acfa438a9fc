"""Benchmarks of the Python package (see docs/python.md). Build it in release mode first:

    cd crates/pdyn-py && maturin develop --release && cd ../..
    python bench/python/bench.py            # needs numpy, scipy

Prints a Markdown table: pdyn.solve_ivp (compiled expressions, and a Python callable) vs
scipy.integrate.solve_ivp on the Arenstorf orbit at equal error, the per-evaluation cost of
a Python callable, a sweep of the building model vs a Python loop over SciPy, import time.
"""

import subprocess
import sys
import time

import numpy as np

import pdyn

MU = 0.012277471
MP = 1 - MU
Y0 = [0.994, 0.0, 0.0, -2.00158510637908252240537862224]
T = 17.0652165601579625588917206249
EXPR = [
    "y2", "y3",
    "y0 + 2*y3 - mp*(y0 + mu)/((y0 + mu)^2 + y1^2)^(3/2) - mu*(y0 - mp)/((y0 - mp)^2 + y1^2)^(3/2)",
    "y1 - 2*y2 - mp*y1/((y0 + mu)^2 + y1^2)^(3/2) - mu*y1/((y0 - mp)^2 + y1^2)^(3/2)",
]


def f(t, y):
    d1 = ((y[0] + MU) ** 2 + y[1] ** 2) ** 1.5
    d2 = ((y[0] - MP) ** 2 + y[1] ** 2) ** 1.5
    return [y[2], y[3],
            y[0] + 2 * y[3] - MP * (y[0] + MU) / d1 - MU * (y[0] - MP) / d2,
            y[1] - 2 * y[2] - MP * y[1] / d1 - MU * y[1] / d2]


def best(fn, repeat=5):
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    from scipy.integrate import solve_ivp as scipy_ivp

    rows = []
    tol = 1e-10
    for name, fn in [
        ("pdyn.solve_ivp, compiled expressions", lambda: pdyn.solve_ivp(
            EXPR, (0, T), Y0, method="DOP853", rtol=tol, atol=tol, args={"mu": MU, "mp": MP})),
        ("pdyn.solve_ivp, Python callable", lambda: pdyn.solve_ivp(
            f, (0, T), Y0, method="DOP853", rtol=tol, atol=tol)),
        ("scipy solve_ivp DOP853", lambda: scipy_ivp(
            f, (0, T), Y0, method="DOP853", rtol=tol, atol=tol)),
    ]:
        secs, sol = best(fn, 3)
        err = float(np.max(np.abs(sol.y[:, -1] - Y0)))
        rows.append((f"Arenstorf, one period, rtol=atol=1e-10: {name}",
                     f"{secs * 1e3:.2f} ms, nfev {sol.nfev}, error at T {err:.1e}, "
                     f"{secs / sol.nfev * 1e6:.2f} µs per f-evaluation"))

    # The building model's sweep vs a Python loop over SciPy on the same equations is only
    # meaningful for a model whose equations are written out; here: the projectile with drag.
    m = pdyn.Model.from_file("examples/projectile_drag.toml")
    values = np.linspace(0.1, 1.0, 1000)
    secs, sw = best(lambda: m.sweep("c", values, measures={"zmin": ("z", "min")}), 1)
    rows.append(("Model.sweep, projectile with drag, 1000 runs (all cores)",
                 f"{secs:.3f} s ({sw.runs / secs:.0f} runs/s, {sw.threads} threads)"))

    def drag(c):
        def rhs(t, w):
            v = np.sqrt(w[3] ** 2 + w[4] ** 2 + w[5] ** 2)
            return [w[3], w[4], w[5], -c * v * w[3], -c * v * w[4], -9.81 - c * v * w[5]]
        return rhs

    t0 = time.perf_counter()
    zmins = [scipy_ivp(drag(c), (0, 5), [0, 0, 0, 10, 10, 20], method="DOP853",
                       rtol=1e-10, atol=1e-12).y[2].min() for c in values[:100]]
    loop = (time.perf_counter() - t0) * 10
    rows.append(("Python loop over scipy solve_ivp, same 1000 runs (100 timed, x10)",
                 f"{loop:.3f} s ({1000 / loop:.0f} runs/s, 1 thread)"))

    code = "import time; t=time.perf_counter(); import pdyn; print(time.perf_counter()-t)"
    imp = min(float(subprocess.run([sys.executable, "-c", code], capture_output=True,
                                   text=True, check=True).stdout) for _ in range(5))
    rows.append(("import pdyn", f"{imp * 1e3:.1f} ms"))

    print("| benchmark | result |\n|---|---|")
    for k, v in rows:
        print(f"| {k} | {v} |")


if __name__ == "__main__":
    main()
