#!/usr/bin/env python3
"""The stick-slip oscillator on a moving belt of examples/contact/belt.toml with SciPy, for
N stick-slip cycles: solve_ivp (RK45 or DOP853, rtol 1e-10, atol 1e-12) in the mode the contact is in,
restarted at each switch: stuck (x' = V) until the spring's pull k x reaches mu_s m g;
sliding (m x'' = -k x + mu_k m g, the belt faster than the mass) until the slip speed x' - V
returns to 0, where it sticks again if k x <= mu_s m g. Writes every solver point to a CSV.
Usage: belt_scipy.py OUT.csv CYCLES [METHOD (RK45, DOP853)]"""
import sys

import numpy as np
from scipy.integrate import solve_ivp

g, m, k, V, mu_s, mu_k = 9.81, 1.0, 50.0, 0.2, 0.6, 0.4
cycles = int(sys.argv[2])
METHOD = sys.argv[3] if len(sys.argv) > 3 else "RK45"


def stuck(t, y):
    return [V, 0.0]


def sliding(t, y):
    return [y[1], (-k * y[0] + mu_k * m * g) / m]


def breakaway(t, y):
    return k * y[0] - mu_s * m * g


breakaway.terminal = True
breakaway.direction = 1


def slip_stops(t, y):
    return y[1] - V


slip_stops.terminal = True
slip_stops.direction = 1

t, y, mode = 0.0, np.array([0.0, V]), "stuck"
ts, ys, switches = [], [], 0
while switches < 2 * cycles:
    f, ev = (stuck, breakaway) if mode == "stuck" else (sliding, slip_stops)
    sol = solve_ivp(f, (t, 1e9), y, rtol=1e-10, atol=1e-12, events=ev, method=METHOD)
    ts.append(sol.t)
    ys.append(sol.y.T)
    t = sol.t_events[0][0]
    y = sol.y_events[0][0].copy()
    switches += 1
    if mode == "stuck":
        mode = "sliding"
    else:
        y[1] = V
        mode = "stuck" if k * y[0] <= mu_s * m * g else "sliding"
np.savetxt(sys.argv[1], np.column_stack([np.concatenate(ts), np.vstack(ys)]), delimiter=",",
           header="t,x,x'", comments="")
print(f"scipy: {switches} switches, last at t = {t:.12f}")
