#!/usr/bin/env python3
"""REBOUND's IAS15 on the figure-eight, from the initial conditions of
crates/pdyn-gravity/src/systems.rs (8 published digits; Li & Liao's 10; the 15-digit refinement).

Usage (from the repository root):

    python3 bench/nbody/figure_eight_rebound.py

On the exact orbit the middle body's acceleration vanishes at every Euler configuration
(t = k T/6); PRS23's step-size criterion then shrinks the steps with the distance to that zero
and they never pass it. pdyn's IAS15 floors the criterion (src/integrators/ias15.rs; 229 steps a
period for all three starts, tests/ias15.rs). This prints REBOUND's step count and return error
after one period, or where it stalls: each run is capped at STEP_CAP steps.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run  # noqa: E402  (re-executes this script in run.py's venv, with REBOUND)

STEP_CAP = 20000


def simo(x1, y1, vx3, vy3):
    return [((x1, y1), (-vx3 / 2, -vy3 / 2)), ((-x1, -y1), (-vx3 / 2, -vy3 / 2)),
            ((0.0, 0.0), (vx3, vy3))]


def euler(p1, p2):
    return [((-1.0, 0.0), (p1, p2)), ((1.0, 0.0), (p1, p2)), ((0.0, 0.0), (-2 * p1, -2 * p2))]


CASES = [
    ("8 digits (Simó)", simo(0.97000436, -0.24308753, -0.93240737, -0.86473146), 6.32591398),
    ("10 digits (Li & Liao 2017)", euler(0.3471168881, 0.5327249454), 6.3259139829),
    ("15 digits (refined)", euler(0.347116888118927, 0.532724945388030), 6.32591398292621),
]


def main():
    for name, bodies, period in CASES:
        sim = run.rebound.Simulation()
        sim.G = 1.0
        for (x, y), (vx, vy) in bodies:
            sim.add(m=1.0, x=x, y=y, vx=vx, vy=vy)
        sim.integrator = "ias15"
        sim.dt = 1e-3
        start = [(p.x, p.y, p.vx, p.vy) for p in sim.particles]
        while sim.t < period and sim.steps_done < STEP_CAP:
            sim.dt = min(sim.dt, period - sim.t)
            sim.steps(1)
        if sim.t < period:
            print(f"{name}: stalled at t = {sim.t!r} (T/6 = {period / 6!r}), dt = {sim.dt:.1e} "
                  f"after {sim.steps_done} steps")
            continue
        num = sum((a - b) ** 2 for p, s in zip(sim.particles, start)
                  for a, b in zip((p.x, p.y, p.vx, p.vy), s))
        den = sum(b * b for s in start for b in s)
        print(f"{name}: {sim.steps_done} steps, relative state difference after one period "
              f"{math.sqrt(num / den):.3e}")


if __name__ == "__main__":
    main()
