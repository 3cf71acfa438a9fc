"""The n-link chain of bench/chain_model.py --example (unit masses and lengths, g = 9.81,
link i released from rest at 0.3*i rad), integrated by SciPy's DOP853 at rtol 1e-9, atol 1e-12
to t = 10: accepted and rejected steps, to compare with `pdyn run`'s method line.

    /tmp/venv-bench/bin/python bench/chain_scipy_steps.py 16
"""
import sys, numpy as np
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import rk

n = int(sys.argv[1])
g = 9.81
m = np.ones(n); l = np.ones(n)
tail = np.cumsum(m[::-1])[::-1]            # sum_{k>=i} m_k
C = tail[np.maximum.outer(np.arange(n), np.arange(n))]
L = np.outer(l, l) * C
def f(t, y):
    q, w = y[:n], y[n:]
    d = q[:, None] - q[None, :]
    M = L * np.cos(d)
    rhs = -(L * np.sin(d)) @ (w * w) - g * l * tail * np.sin(q)
    return np.concatenate([w, np.linalg.solve(M, rhs)])
attempts = [0]
# Every step attempt, accepted or rejected, is one call of rk_step.
orig_rk_step = rk.rk_step
def rk_step(*a, **k):
    attempts[0] += 1
    return orig_rk_step(*a, **k)
rk.rk_step = rk_step
y0 = np.concatenate([0.3 * np.arange(1, n + 1), np.zeros(n)])
sol = solve_ivp(f, (0, 10), y0, method="DOP853", rtol=1e-9, atol=1e-12)
acc = len(sol.t) - 1
print(f"n={n}: SciPy DOP853 nfev {sol.nfev}, attempts {attempts[0]}, accepted {acc}, rejected {attempts[0]-acc}, q1(10) = {sol.y[0,-1]:.10e}")
