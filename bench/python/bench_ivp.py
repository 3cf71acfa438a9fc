"""pdyn.solve_ivp against scipy.integrate.solve_ivp on the cases of issue 30 (item 3).

    target/venv-bench/bin/python bench/python/bench_ivp.py

(a venv with pdyn built by `maturin develop --release`, numpy and scipy). Prints a Markdown
table: times (best of 5), nfev, and the dense-output error of each method against a
reference (SciPy's DOP853 at rtol = atol = 1e-13, evaluated on 2001 points of its dense
output) for the Arenstorf orbit over one period; Van der Pol (mu = 1000) with the stiff
methods.
"""

import time

import numpy as np
import scipy
import scipy.integrate as si

import pdyn

MU = 0.012277471
Y0 = [0.994, 0.0, 0.0, -2.00158510637908252240537862224]
T = 17.0652165601579625588917206249


def arenstorf(t, y):
    x, z, vx, vz = y
    d1 = ((x + MU) ** 2 + z ** 2) ** 1.5
    d2 = ((x - 1 + MU) ** 2 + z ** 2) ** 1.5
    return [vx, vz,
            x + 2 * vz - (1 - MU) * (x + MU) / d1 - MU * (x - 1 + MU) / d2,
            z - 2 * vx - (1 - MU) * z / d1 - MU * z / d2]


ARENSTORF_EXPR = [
    "y2", "y3",
    "y0 + 2*y3 - (1 - mu)*(y0 + mu)/((y0 + mu)^2 + y1^2)^1.5"
    " - mu*(y0 - 1 + mu)/((y0 - 1 + mu)^2 + y1^2)^1.5",
    "y1 - 2*y2 - (1 - mu)*y1/((y0 + mu)^2 + y1^2)^1.5 - mu*y1/((y0 - 1 + mu)^2 + y1^2)^1.5",
]


def vdp_call(t, y, mu):
    return [y[1], mu * (1 - y[0] ** 2) * y[1] - y[0]]


VDP_EXPR = ["y1", "mu*(1 - y0^2)*y1 - y0"]


def best(f, k=5):
    times = []
    r = None
    for _ in range(k):
        t0 = time.perf_counter()
        r = f()
        times.append(time.perf_counter() - t0)
    return min(times), r


def main():
    rows = []
    ref = si.solve_ivp(arenstorf, (0, T), Y0, method="DOP853", rtol=1e-13, atol=1e-13,
                       dense_output=True)
    tt = np.linspace(0, T, 2001)
    yref = ref.sol(tt)

    def dense_err(sol):
        return np.abs(sol.sol(tt) - yref)[:2].max()

    for method in ["RK45", "RK23", "DOP853", "Radau"]:
        for rtol in [1e-6, 1e-9]:
            if method == "RK23" and rtol < 1e-8:
                continue
            kw = dict(method=method, rtol=rtol, atol=rtol, dense_output=True)
            calls = [0]

            def counted(t, y):
                calls[0] += 1
                return arenstorf(t, y)
            ts, s = best(lambda: si.solve_ivp(arenstorf, (0, T), Y0, **kw), 3)
            tp, p = best(lambda: pdyn.solve_ivp(arenstorf, (0, T), Y0, **kw), 3)
            tc, c = best(lambda: pdyn.solve_ivp(ARENSTORF_EXPR, (0, T), Y0,
                                                args={"mu": MU}, **kw))
            calls[0] = 0
            pdyn.solve_ivp(counted, (0, T), Y0, **kw)
            rows.append((f"Arenstorf {method} rtol=atol={rtol:g}, dense",
                         f"{dense_err(s):.1e} ({s.nfev} nfev, {ts * 1e3:.1f} ms)",
                         f"{dense_err(p):.1e} ({p.nfev} nfev = {calls[0]} calls made, "
                         f"{tp * 1e3:.1f} ms)",
                         f"{dense_err(c):.1e} ({tc * 1e3:.3f} ms)",
                         f"{ts / tp:.1f}x", f"{ts / tc:.0f}x"))
    for method in ["Radau", "BDF", "LSODA"]:
        kw = dict(method=method, rtol=1e-6, atol=1e-9)
        ts, s = best(lambda: si.solve_ivp(vdp_call, (0, 2000), [2.0, 0.0], args=(1000.0,),
                                          **kw), 2)
        tp, p = best(lambda: pdyn.solve_ivp(vdp_call, (0, 2000), [2.0, 0.0], args=(1000.0,),
                                            **kw), 2)
        tc, c = best(lambda: pdyn.solve_ivp(VDP_EXPR, (0, 2000), [2.0, 0.0],
                                            args={"mu": 1000.0}, **kw))
        d = abs(p.y[0, -1] - s.y[0, -1])
        rows.append((f"Van der Pol mu=1000, t=0..2000, {method} rtol 1e-6",
                     f"y0(2000) {s.y[0, -1]:.6f} ({s.nfev} nfev, {ts * 1e3:.1f} ms)",
                     f"differs by {d:.1e} ({p.nfev} nfev, {tp * 1e3:.1f} ms)",
                     f"({tc * 1e3:.3f} ms)", f"{ts / tp:.1f}x", f"{ts / tc:.0f}x"))
    print(f"SciPy {scipy.__version__}, NumPy {np.__version__}\n")
    print("| case | SciPy: dense error (nfev, time) | pdyn callable | pdyn compiled "
          "| SciPy/callable | SciPy/compiled |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
