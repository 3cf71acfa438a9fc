#!/usr/bin/env python3
"""SymPy's KanesMethod on the n-link planar pendulum chain (peer for `pdyn derive`).

Prints `n, seconds` for each n: the time to build the chain and form Kane's equations
(mass matrix and forcing), the same work `pdyn derive` does (without solving for q'').
Installs sympy from PyPI if it is missing.
"""
import subprocess
import sys
import time

try:
    import sympy as sm
    import sympy.physics.mechanics as me
except ImportError:  # pragma: no cover
    subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet", "sympy"])
    import sympy as sm
    import sympy.physics.mechanics as me


def derive(n):
    q = me.dynamicsymbols(f"q:{n}")
    u = me.dynamicsymbols(f"u:{n}")
    m = sm.symbols(f"m:{n}")
    l = sm.symbols(f"l:{n}")
    g, t = sm.symbols("g t")
    frame = me.ReferenceFrame("N")
    origin = me.Point("O")
    origin.set_vel(frame, 0)
    prev = origin
    particles, loads, kd = [], [], []
    for i in range(n):
        link = frame.orientnew(f"A{i}", "Axis", [q[i], frame.z])
        link.set_ang_vel(frame, u[i] * frame.z)
        p = prev.locatenew(f"P{i}", l[i] * link.x)
        p.v2pt_theory(prev, frame, link)
        particles.append(me.Particle(f"Pa{i}", p, m[i]))
        loads.append((p, m[i] * g * frame.x))
        kd.append(q[i].diff(t) - u[i])
        prev = p
    km = me.KanesMethod(frame, q_ind=q, u_ind=u, kd_eqs=kd)
    km.kanes_equations(particles, loads)
    return km.mass_matrix_full, km.forcing_full


if __name__ == "__main__":
    sizes = [int(a) for a in sys.argv[1:]] or [2, 4, 8, 16]
    print(f"sympy {sm.__version__}")
    for n in sizes:
        t0 = time.perf_counter()
        derive(n)
        print(f"{n}, {time.perf_counter() - t0:.4f}", flush=True)
