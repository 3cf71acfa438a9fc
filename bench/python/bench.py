"""Benchmarks of the Python package (see docs/python.md). Build it in release mode first:

    cd crates/pdyn-py && maturin develop --release && cd ../..
    python bench/python/bench.py            # needs numpy, scipy

Prints a Markdown table: pdyn.solve_ivp (compiled expressions, and a Python callable) vs
scipy.integrate.solve_ivp on the Arenstorf orbit and the Pleiades at equal tolerance, the
per-evaluation cost of a Python callable, a sweep and an ensemble of 1000 runs of the
building model vs a Python loop over SciPy on its derived equations, import time.
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


# Pleiades (Hairer, Norsett & Wanner II.10): 7 bodies in the plane, masses 1..7.
PX = [3, 3, -1, -3, 2, -2, 2]
PY = [3, -3, 2, 0, 0, -4, 4]
PVX = [0, 0, 0, 0, 0, 1.75, -1.5]
PVY = [0, 0, 0, -1.25, 1, 0, 0]
PLEIADES_Y0 = [float(v) for v in PX + PY + PVX + PVY]


def pleiades_exprs():
    # r_ij^3 is written the same way for (i, j) and (j, i), so that the compiler shares it
    # (as a hand-written right-hand side would compute each pair once).
    def r3(i, j):
        a, b = min(i, j), max(i, j)
        return f"((y{a} - y{b})^2 + (y{7 + a} - y{7 + b})^2)^(3/2)"
    out = [f"y{14 + i}" for i in range(7)] + [f"y{21 + i}" for i in range(7)]
    for axis in (0, 7):
        for i in range(7):
            terms = [f"{j + 1}*(y{axis + j} - y{axis + i})/{r3(i, j)}" for j in range(7)
                     if j != i]
            out.append(" + ".join(terms))
    return out


PM = np.arange(1, 8, dtype=float)


def pleiades(t, w):
    x, y = w[:7], w[7:14]
    dx = x[None, :] - x[:, None]
    dy = y[None, :] - y[:, None]
    r3 = (dx * dx + dy * dy) ** 1.5
    np.fill_diagonal(r3, np.inf)
    return np.concatenate([w[14:], (PM[None, :] * dx / r3).sum(1), (PM[None, :] * dy / r3).sum(1)])


def building_rhs(omega, k=100.0, m=1.0, L=10.0, d0=0.1, g=9.81):
    # The building's equations as pdyn derives them (m.derive().solution).
    def rhs(t, w):
        y1, y2 = w[0], w[1]
        return [w[2], w[3],
                (2 * d0 * k * np.sin(omega * t) - g * m - 4 * k * y1 + 2 * k * y2) / m,
                (2 * L * k - g * m + 2 * k * y1 - 2 * k * y2) / m]
    return rhs


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
    # Compiled expressions run natively (Cranelift JIT; compiled on the first call and
    # cached, so "best of" times the integration); jit=False is pdyn's interpreter.
    times = {}
    for key, name, fn in [
        ("jit", "pdyn.solve_ivp, compiled expressions (native code)", lambda: pdyn.solve_ivp(
            EXPR, (0, T), Y0, method="DOP853", rtol=tol, atol=tol, args={"mu": MU, "mp": MP})),
        ("interp", "pdyn.solve_ivp, compiled expressions, jit=False (interpreter)",
         lambda: pdyn.solve_ivp(EXPR, (0, T), Y0, method="DOP853", rtol=tol, atol=tol,
                                args={"mu": MU, "mp": MP}, jit=False)),
        ("py", "pdyn.solve_ivp, Python callable", lambda: pdyn.solve_ivp(
            f, (0, T), Y0, method="DOP853", rtol=tol, atol=tol)),
        ("scipy", "scipy solve_ivp DOP853", lambda: scipy_ivp(
            f, (0, T), Y0, method="DOP853", rtol=tol, atol=tol)),
    ]:
        secs, sol = best(fn, 5)
        times[key] = secs
        err = float(np.max(np.abs(sol.y[:, -1] - Y0)))
        rows.append((f"Arenstorf, one period, rtol=atol=1e-10: {name}",
                     f"{secs * 1e3:.3f} ms, nfev {sol.nfev}, error at T {err:.1e}, "
                     f"{secs / sol.nfev * 1e6:.3f} µs per f-evaluation"))
    rows.append(("Arenstorf: SciPy / pdyn compiled",
                 f"**{times['scipy'] / times['jit']:.0f}x** native "
                 f"({times['scipy'] / times['interp']:.0f}x interpreter)"))

    pl = pleiades_exprs()
    ref_pl = scipy_ivp(pleiades, (0, 3), PLEIADES_Y0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    for key, name, fn in [
        ("jit", "pdyn.solve_ivp, compiled expressions (native code)", lambda: pdyn.solve_ivp(
            pl, (0, 3), PLEIADES_Y0, method="DOP853", rtol=tol, atol=tol)),
        ("interp", "pdyn.solve_ivp, compiled expressions, jit=False (interpreter)",
         lambda: pdyn.solve_ivp(pl, (0, 3), PLEIADES_Y0, method="DOP853", rtol=tol, atol=tol,
                                jit=False)),
        ("scipy", "scipy solve_ivp DOP853 (NumPy right-hand side)", lambda: scipy_ivp(
            pleiades, (0, 3), PLEIADES_Y0, method="DOP853", rtol=tol, atol=tol)),
    ]:
        secs, sol = best(fn, 5)
        times[key] = secs
        err = float(np.max(np.abs(sol.y[:, -1] - ref_pl)))
        rows.append((f"Pleiades, t = 0..3, rtol=atol=1e-10: {name}",
                     f"{secs * 1e3:.3f} ms, nfev {sol.nfev}, error at 3 {err:.1e}"))
    rows.append(("Pleiades: SciPy / pdyn compiled",
                 f"**{times['scipy'] / times['jit']:.0f}x** native "
                 f"({times['scipy'] / times['interp']:.0f}x interpreter)"))
    fresh = [pl[0] + " + 0*t"] + pl[1:]  # not in the cache: parsed, compiled, JIT-compiled
    t0 = time.perf_counter()
    pdyn.solve_ivp(fresh, (0, 1e-9), PLEIADES_Y0, method="DOP853")
    rows.append(("first call with new expressions (parse, compile, JIT; then cached)",
                 f"Pleiades: {(time.perf_counter() - t0) * 1e3:.1f} ms"))

    # 1000 runs of the building (chapter 3.3.3): omega from 2 to 30, t = 0..20, DOP853 at
    # the file's rtol 1e-8, atol 1e-10, 2001 output points; measure max |deflection|.
    m = pdyn.Model.from_file("examples/building.toml")
    values = np.linspace(2, 30, 1000)
    meas = {"top": ("y2 - (2*L - 3*m*g/(2*k))", "max_abs")}
    m.sweep("omega", values[:4], measures=meas)  # warm-up (thread pool, page faults)
    secs, sw = best(lambda: m.sweep("omega", values, measures=meas), 3)
    rows.append(("Model.sweep, building, 1000 runs (all cores)",
                 f"{secs:.3f} s ({sw.runs / secs:.0f} runs/s, {sw.threads} threads)"))
    esecs, ens = best(lambda: m.ensemble(params={"omega": values}, measures=meas), 3)
    rows.append(("Model.ensemble, the same 1000 runs (all cores)",
                 f"{esecs:.3f} s ({len(ens) / esecs:.0f} runs/s, {ens.threads} threads)"))
    te = np.linspace(0, 20, 2001)
    y2eq = 2 * 10.0 - 3 * 1.0 * 9.81 / (2 * 100.0)
    y0 = [10.0 - 9.81 / 100.0, y2eq, 0.0, 0.0]
    n_loop = 50

    def scipy_loop():
        return [np.max(np.abs(scipy_ivp(building_rhs(w), (0, 20), y0, method="DOP853",
                                        rtol=1e-8, atol=1e-10, t_eval=te).y[1] - y2eq))
                for w in values[::1000 // n_loop]]

    loop_secs, tops = best(scipy_loop, 2)  # best of 2, as pdyn's are best of 3
    loop = loop_secs * (1000 / n_loop)
    agree = float(np.max(np.abs(np.array(tops) - sw.measures["top"][::1000 // n_loop])
                         / np.array(tops)))
    rows.append((f"Python loop over scipy solve_ivp, same 1000 runs ({n_loop} timed, "
                 f"x{1000 // n_loop})",
                 f"{loop:.2f} s ({1000 / loop:.0f} runs/s, 1 thread); measures agree to "
                 f"{agree:.1e} relative; sweep speed-up {loop / secs:.0f}x, ensemble "
                 f"{loop / esecs:.0f}x"))

    for what, code in [
        ("import pdyn (NumPy not imported until used)",
         "import time; t=time.perf_counter(); import pdyn; print(time.perf_counter()-t)"),
        ("import numpy",
         "import time; t=time.perf_counter(); import numpy; print(time.perf_counter()-t)"),
        ("import pdyn, numpy; first call (Model.from_toml + run)",
         "import time; t=time.perf_counter(); import pdyn, numpy; "
         "pdyn.Model.from_toml(open('examples/kremlin_stone.toml').read()).run(); "
         "print(time.perf_counter()-t)"),
    ]:
        imp = sorted(float(subprocess.run([sys.executable, "-c", code], capture_output=True,
                                          text=True, check=True).stdout) for _ in range(7))
        rows.append((what, f"{imp[0] * 1e3:.1f} ms (best of 7; median {imp[3] * 1e3:.1f} ms)"))

    print("| benchmark | result |\n|---|---|")
    for k, v in rows:
        print(f"| {k} | {v} |")


if __name__ == "__main__":
    main()
