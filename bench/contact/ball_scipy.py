#!/usr/bin/env python3
"""The bouncing ball of examples/contact/bouncing_ball.toml with SciPy: solve_ivp (RK45 or DOP853,
rtol 1e-10, atol 1e-12) from bounce to bounce with a terminal event at the floor, the
velocity reversed and scaled by e at each restart; the bounces end in resting contact when
the remaining time of the geometric sequence falls below 1e-10 of the elapsed time (pdyn's
rule). Writes every solver point to a CSV, as pdyn run --out does. Usage: ball_scipy.py OUT.csv [METHOD (RK45, DOP853)]"""
import sys

import numpy as np
from scipy.integrate import solve_ivp

g, h, e, t_end = 9.81, 1.0, 0.5, 2.0
METHOD = sys.argv[2] if len(sys.argv) > 2 else "RK45"


def rhs(t, y):
    return [y[1], -g]


def floor(t, y):
    return y[0]


floor.terminal = True
floor.direction = -1

t, y = 0.0, np.array([h, 0.0])
ts, ys, bounces = [], [], []
while t < t_end:
    sol = solve_ivp(rhs, (t, t_end), y, rtol=1e-10, atol=1e-12, events=floor, method=METHOD)
    ts.append(sol.t)
    ys.append(sol.y.T)
    if sol.status != 1:
        break
    t = sol.t_events[0][0]
    y = sol.y_events[0][0].copy()
    bounces.append(t)
    y[0] = 0.0
    rest = False
    if len(bounces) >= 4:
        d0, d1, d2 = np.diff(bounces[-4:])
        r1, r2 = d1 / d0, d2 / d1
        if 0 < r2 < 1 and abs(r2 - r1) <= 1e-3 * r2 + 1e-9:
            remaining = d2 * r2 / (1 - r2)
            if remaining <= 1e-10 * t:
                rest = True
                t_inf = t + remaining
    if rest:
        y[1] = 0.0
        tt = np.array([t, t_end])
        ts.append(tt)
        ys.append(np.array([[0.0, 0.0], [0.0, 0.0]]))
        break
    y[1] = -e * y[1]
t_all = np.concatenate(ts)
y_all = np.vstack(ys)
np.savetxt(sys.argv[1], np.column_stack([t_all, y_all]), delimiter=",", header="t,y,y'", comments="")
print(f"scipy: {len(bounces)} bounces, rest at t = {t_inf:.12f}")
