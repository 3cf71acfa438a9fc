#!/usr/bin/env python3
"""Writes `ground.csv`, the synthetic ground-acceleration record of `earthquake.toml`,
deterministically (Python's standard library only: `random.Random(2026)`, fixed decimals):

    python3 examples/data/generate_earthquake.py

A real-looking accelerogram, generated rather than downloaded: Gaussian white noise at
200 Hz passed through a Kanai-Tajimi filter (the ground's soil column as an oscillator of
frequency omega_g = 15 rad/s and damping zeta_g = 0.6, integrated exactly sample by sample
as a linear system driven by piecewise-constant noise), then a high-pass Kanai-Tajimi /
Clough-Penzien second stage (omega_f = 1.5 rad/s, zeta_f = 0.6) so that the record's
velocity and displacement do not drift, times the Jennings envelope (a quadratic rise over
2 s, strong motion until 8 s, exponential decay exp(-0.35 (t - 8)) after), scaled to a peak
ground acceleration of 0.3 g. 20 s, column `a` in m/s^2.
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
DT = 0.005
DURATION = 20.0
PGA = 0.3 * 9.81


def envelope(t):
    if t < 2.0:
        return (t / 2.0) ** 2
    if t < 8.0:
        return 1.0
    return math.exp(-0.35 * (t - 8.0))


def oscillator_step(state, force, omega, zeta, dt):
    """x'' + 2 zeta omega x' + omega^2 x = force over one step, force held constant
    (semi-implicit Euler with 20 substeps: small next to the sampling)."""
    x, v = state
    n = 20
    h = dt / n
    for _ in range(n):
        v += h * (force - 2.0 * zeta * omega * v - omega * omega * x)
        x += h * v
    return (x, v)


def main():
    rng = random.Random(2026)
    n = int(round(DURATION / DT)) + 1
    wg, zg = 15.0, 0.6
    wf, zf = 1.5, 0.6
    soil = (0.0, 0.0)
    high = (0.0, 0.0)
    raw = []
    for i in range(n):
        w = rng.gauss(0.0, 1.0)
        soil = oscillator_step(soil, w, wg, zg, DT)
        # Kanai-Tajimi: the soil's absolute acceleration -(2 zeta_g omega_g x' + omega_g^2 x)
        ag = -(2.0 * zg * wg * soil[1] + wg * wg * soil[0])
        high = oscillator_step(high, ag, wf, zf, DT)
        # Clough-Penzien: the high-pass second stage's relative acceleration
        af = -(2.0 * zf * wf * high[1] + wf * wf * high[0])
        raw.append(ag + af)
    shaped = [envelope(i * DT) * a for i, a in enumerate(raw)]
    peak = max(abs(a) for a in shaped)
    with open(os.path.join(HERE, "ground.csv"), "w", newline="\n") as f:
        f.write("# synthetic accelerogram: generate_earthquake.py (seed 2026), PGA 0.3 g\n")
        f.write("t,a\n")
        for i, a in enumerate(shaped):
            f.write("{:.3f},{:.6f}\n".format(i * DT, a * PGA / peak))


if __name__ == "__main__":
    main()
