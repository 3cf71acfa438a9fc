"""SciPy peers for pdyn-ode: solve_ivp (RK45, DOP853, Radau) and scipy.integrate.ode('dop853')
(Hairer's Fortran), plus REBOUND's leapfrog and WHFast on the long Kepler run.
Output: the same CSV lines as the Rust peers (problem,impl,method,tol,error,fevals,seconds)."""
import math
import time

import numpy as np
from scipy.integrate import ode, solve_ivp

MU = 0.012277471
AREN_Y0 = np.array([0.994, 0.0, 0.0, -2.00158510637908252240537862224])
AREN_T = 17.0652165601579625588917206249
PLEI_Y0 = np.array([3, 3, -1, -3, 2, -2, 2, 3, -3, 2, 0, 0, -4, 4,
                    0, 0, 0, 0, 0, 1.75, -1.5, 0, 0, 0, -1.25, 1, 0, 0], dtype=float)
PLEI_Y3 = np.array([
    0.3706139143970502, 3.237284092057233, -3.222559032418324, 0.6597091455775310,
    0.3425581707156584, 1.562172101400631, -0.7003092922212495, -3.943437585517392,
    -3.271380973972550, 5.225081843456543, -2.590612434977470, 1.198213693392275,
    -0.2429682344935824, 1.091449240428980, 3.417003806314313, 1.354584501625501,
    -2.590065597810775, 2.025053734714242, -1.155815100160448, -0.8072988170223021,
    0.5952396354208710, -3.741244961234010, 0.3773459685750630, 0.9386858869551073,
    0.3667922227200571, -0.3474046353808490, 2.344915448180937, -1.947020434263292])
ROBER_REF = np.array([0.2083340149701255e-7, 0.8333360770334713e-13, 0.9999999791665050])


def arenstorf(t, y):
    mup = 1.0 - MU
    d1 = ((y[0] + MU) ** 2 + y[1] ** 2) ** 1.5
    d2 = ((y[0] - mup) ** 2 + y[1] ** 2) ** 1.5
    return [y[2], y[3],
            y[0] + 2 * y[3] - mup * (y[0] + MU) / d1 - MU * (y[0] - mup) / d2,
            y[1] - 2 * y[2] - mup * y[1] / d1 - MU * y[1] / d2]


M = np.arange(1, 8, dtype=float)


def pleiades(t, s):
    x, y, v = s[:7], s[7:14], s[14:]
    dx = x[None, :] - x[:, None]
    dy = y[None, :] - y[:, None]
    r3 = (dx * dx + dy * dy) ** 1.5
    np.fill_diagonal(r3, np.inf)
    ax = (M[None, :] * dx / r3).sum(axis=1)
    ay = (M[None, :] * dy / r3).sum(axis=1)
    return np.concatenate([v, ax, ay])


def robertson(t, y):
    a = -0.04 * y[0] + 1e4 * y[1] * y[2]
    c = 3e7 * y[1] * y[1]
    return [a, -a - c, c]


def rober_jac(t, y):
    return [[-0.04, 1e4 * y[2], 1e4 * y[1]],
            [0.04, -1e4 * y[2] - 6e7 * y[1], -1e4 * y[1]],
            [0.0, 6e7 * y[1], 0.0]]


def timed(fn, min_time=0.3):
    t = time.perf_counter()
    r = fn()
    once = max(time.perf_counter() - t, 1e-7)
    reps = int(min(max(min_time / once, 3), 200))
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        r = fn()
        ts.append(time.perf_counter() - t)
    ts.sort()
    return ts[0], r  # minimum: the most robust statistic on a shared machine


def fortran_dop853(f, y0, t1, tol):
    count = [0]

    def g(t, y):
        count[0] += 1
        return f(t, y)

    def run():
        count[0] = 0
        r = ode(g).set_integrator('dop853', rtol=tol, atol=tol, nsteps=10**7)
        r.set_initial_value(y0, 0.0)
        return r.integrate(t1)
    return run, count


def main():
    tols = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
    for name, f, y0, t1, ref in [("arenstorf", arenstorf, AREN_Y0, AREN_T, AREN_Y0),
                                 ("pleiades", pleiades, PLEI_Y0, 3.0, PLEI_Y3)]:
        for tol in tols:
            for meth in ["RK45", "DOP853"]:
                s, sol = timed(lambda: solve_ivp(f, (0, t1), y0, method=meth, rtol=tol, atol=tol))
                err = np.max(np.abs(sol.y[:, -1] - ref))
                print(f"{name},scipy_solve_ivp,{meth.lower()},{tol:e},{err:e},{sol.nfev},{s:e}")
            run, count = fortran_dop853(f, y0, t1, tol)
            s, y = timed(run)
            err = np.max(np.abs(y - ref))
            print(f"{name},scipy_ode_fortran,dop853,{tol:e},{err:e},{count[0]},{s:e}")
    for tol in [1e-4, 1e-6, 1e-8, 1e-10]:
        for meth in ["Radau", "BDF", "LSODA"]:
            s, sol = timed(lambda: solve_ivp(robertson, (0, 1e11), [1.0, 0.0, 0.0], method=meth,
                                             rtol=tol, atol=tol * 1e-6, jac=rober_jac),
                           min_time=0.1)
            err = np.max(np.abs((sol.y[:, -1] - ROBER_REF) / ROBER_REF))
            print(f"robertson,scipy_solve_ivp,{meth.lower()},{tol:e},{err:e},{sol.nfev},{s:e}")
    try:
        import rebound
    except ImportError:
        print("# rebound not installed: pip install rebound")
        return
    e = 0.6
    steps = 10_000_000
    dt = 2 * math.pi / 100
    for integ in ["leapfrog", "whfast"]:
        sim = rebound.Simulation()
        sim.G = 1.0
        sim.add(m=1.0)
        sim.add(m=1e-12, a=1.0, e=e, f=0.0)  # test-particle-like, starts at pericentre
        sim.integrator = integ
        sim.dt = dt
        sim.move_to_com()
        e0 = sim.energy()
        t = time.perf_counter()
        sim.integrate(steps * dt, exact_finish_time=0)
        s = time.perf_counter() - t
        err = abs((sim.energy() - e0) / e0)  # relative energy error
        print(f"kepler,rebound,{integ},{steps},{err:e},{steps},{s:e}")


if __name__ == "__main__":
    main()
