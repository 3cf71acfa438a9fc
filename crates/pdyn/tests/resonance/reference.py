#!/usr/bin/env python3
"""High-precision reference for closed forms near resonance (issue 34, item 2).

Writes building.csv and overdamped.csv beside this file: the exact solutions, derived by hand
below and evaluated with mpmath at 60 digits, so that cancelling 12 or 16 digits near a
resonance still leaves 44. pdyn's `run --method exact` is compared with them by
crates/pdyn/tests/resonance.rs. Regenerate with

    python3 crates/pdyn/tests/resonance/reference.py

(mpmath comes with sympy; `pip install mpmath`), or into another directory with an argument
(crates/pdyn-py/tests/test_resonance_reference.py regenerates them and compares). The CSV holds the forcing frequency (or
rate) exactly as the float the test passes to the model, written with repr().
"""
import csv
import os
import sys

from mpmath import mp, mpf, sqrt, sin, cos, exp

mp.dps = 60
HERE = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
TIMES = [mpf(k) / 2 for k in range(41)]  # 0, 0.5, ..., 20


def building():
    """examples/building.toml: floors of mass m, storeys of stiffness 2k, ground d0 sin(Wt).

    With u = q - q_static (q_static = [L - mg/k, 2L - 3mg/(2k)]):
        m u'' + K u = [2 k d0 sin(W t), 0],  K = [[4k, -2k], [-2k, 2k]],  u(0) = u'(0) = 0.
    K phi = w^2 m phi gives w^2 = (3 -+ sqrt(5)) k/m, phi = [1, (4k - m w^2)/(2k)]. With
    eta = modal amplitude, u = sum_r phi_r eta_r and
        eta_r'' + w_r^2 eta_r = g_r sin(W t),  g_r = (phi_r . [2 k d0, 0]) / (m phi_r . phi_r),
        eta_r(t) = g_r (sin(W t) - (W / w_r) sin(w_r t)) / (w_r^2 - W^2)   (zero initial state).
    """
    k, m, L, d0, g = mpf(100), mpf(1), mpf(10), mpf("0.1"), mpf("9.81")
    q_static = [L - m * g / k, 2 * L - 3 * m * g / (2 * k)]
    modes = []
    for s in (-1, 1):
        w = sqrt((3 + s * sqrt(5)) * k / m)
        phi = [mpf(1), (4 * k - m * w**2) / (2 * k)]
        modes.append((w, phi))
    rows = []
    for r, (wr, _) in enumerate(modes):
        omegas = [float(wr)]
        for j in (2, 4, 6, 8, 10, 12):
            for side in (-1, 1):
                omegas.append(float(wr * (1 + side * mpf(10) ** -j)))
        for om in omegas:
            W = mpf(om)  # exactly the float given to the model
            for t in TIMES:
                u = [mpf(0), mpf(0)]
                du = [mpf(0), mpf(0)]
                for w, phi in modes:
                    gr = (phi[0] * 2 * k * d0) / (m * (phi[0] ** 2 + phi[1] ** 2))
                    eta = gr * (sin(W * t) - (W / w) * sin(w * t)) / (w**2 - W**2)
                    deta = gr * (W * cos(W * t) - W * cos(w * t)) / (w**2 - W**2)
                    for i in range(2):
                        u[i] += phi[i] * eta
                        du[i] += phi[i] * deta
                rows.append([repr(om), mp.nstr(t, 5)] + [mp.nstr(v, 25) for v in
                            (q_static[0] + u[0], q_static[1] + u[1], du[0], du[1])])
    with open(os.path.join(HERE, "building.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["omega", "t", "y1", "y2", "y1'", "y2'"])
        w.writerows(rows)


def overdamped():
    """overdamped.toml: x'' + c x' + k x = F exp(mu t), m = 1, c = 5, k = 4 (roots -1, -4),
    x(0) = x0, x'(0) = v0, mu approaching the root -1 from both sides.

    x = P exp(mu t) + A exp(-t) + B exp(-4 t),  P = F / ((mu + 1)(mu + 4)),
    A + B = x0 - P,  -A - 4B = v0 - mu P.
    """
    F, x0, v0 = mpf(2), mpf("0.5"), mpf(-1)
    rows = []
    mus = [-1.0]
    for j in (2, 4, 6, 8, 10, 12):
        for side in (-1, 1):
            mus.append(float(-1 + side * mpf(10) ** -j))
    for mu_f in mus:
        mu = mpf(mu_f)
        P = F / ((mu + 1) * (mu + 4)) if mu != -1 else None
        for t in TIMES:
            if P is None:
                # At the root: x = Q t e^{-t} + A e^{-t} + B e^{-4t}, Q = F / 3.
                Q = F / 3
                # x(0) = A + B = x0; x'(0) = Q - A - 4B = v0.
                B = -(x0 + v0 - Q) / 3
                A = x0 - B
                x = Q * t * exp(-t) + A * exp(-t) + B * exp(-4 * t)
                dx = Q * (1 - t) * exp(-t) - A * exp(-t) - 4 * B * exp(-4 * t)
            else:
                B = ((x0 - P) + (v0 - mu * P)) / -3
                A = x0 - P - B
                x = P * exp(mu * t) + A * exp(-t) + B * exp(-4 * t)
                dx = mu * P * exp(mu * t) - A * exp(-t) - 4 * B * exp(-4 * t)
            rows.append([repr(mu_f), mp.nstr(t, 5), mp.nstr(x, 25), mp.nstr(dx, 25)])
    with open(os.path.join(HERE, "overdamped.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["mu", "t", "x", "x'"])
        w.writerows(rows)


if __name__ == "__main__":
    building()
    overdamped()
