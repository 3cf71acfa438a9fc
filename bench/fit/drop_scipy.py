#!/usr/bin/env python3
"""The peer of `pdyn fit examples/data/drop.toml --data examples/data/drop.csv --free
c,initial.z,rate.z`: SciPy's `least_squares` (Levenberg–Marquardt, finite-difference Jacobian)
over `solve_ivp` (DOP853, rtol 1e-10, atol 1e-12, as pdyn's defaults), the same start and
stopping tolerances (1e-12). Prints the estimates as JSON."""
import json
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares


def main(path):
    d = np.loadtxt(path, delimiter=",", comments="#", skiprows=2)
    t, z = d[:, 0], d[:, 1]
    g = 9.81

    def residuals(theta):
        c, z0, v0 = theta
        sol = solve_ivp(lambda _t, y: [y[1], -g - c * abs(y[1]) * y[1]], (0.0, t[-1]),
                        [z0, v0], method="DOP853", t_eval=t, rtol=1e-10, atol=1e-12)
        return sol.y[0] - z

    t0 = time.perf_counter()
    r = least_squares(residuals, [0.02, 49.0, -0.5], method="lm", x_scale="jac",
                      ftol=1e-12, xtol=1e-12, gtol=1e-12)
    seconds = time.perf_counter() - t0
    print(json.dumps({"x": list(r.x), "cost": r.cost, "nfev": r.nfev, "status": r.status,
                      "fit_seconds": seconds}))


if __name__ == "__main__":
    main(sys.argv[1])
