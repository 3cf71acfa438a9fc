#!/usr/bin/env python3
"""The chapter's satellite with SciPy solve_ivp (DOP853), written to CSV: the peer of
`pdyn run examples/satellite.toml --method dop853 --rtol 1e-10 --atol 1e-10 --t-end 628.3185307179587`.
Usage: satellite_scipy.py OUT.csv"""
import sys

import numpy as np
from scipy.integrate import solve_ivp

GM = 1.0


def rhs(t, w):
    x, y, vx, vy = w
    r3 = (x * x + y * y) ** 1.5
    return [vx, vy, -GM * x / r3, -GM * y / r3]


sol = solve_ivp(rhs, (0.0, 200 * np.pi), [1.0, 0.0, 0.0, 1.0], method="DOP853", rtol=1e-10, atol=1e-10)
energy = -GM / np.hypot(sol.y[0], sol.y[1]) + 0.5 * (sol.y[2] ** 2 + sol.y[3] ** 2)
table = np.column_stack([sol.t, sol.y.T, energy])
np.savetxt(sys.argv[1] if len(sys.argv) > 1 else "/dev/null", table, delimiter=",",
           header="t,x,y,x',y',energy", comments="", fmt="%.17e")
print(f"{len(sol.t)} steps, {sol.nfev} f-evaluations, energy drift {abs(energy[-1] - energy[0]) / 0.5:.2e}")
