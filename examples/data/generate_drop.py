#!/usr/bin/env python3
"""Regenerates examples/data/drop.csv deterministically (Python's standard library only):

    python3 examples/data/generate_drop.py

A ball filmed at 60 frames per second while it falls, tracked to 2 cm (the noise σ = 0.02 m,
normal, `random.Random(26)`); 200 frames. The filming starts after the release: the first
frame at t = 0 sees the ball at z0 = 50 m already falling at u0 = 0.8 m/s. Quadratic drag,
z'' = −g + c z'², with the truth

    g = 9.81 m/s², c = 0.05 1/m (terminal speed vt = sqrt(g/c) = 14.007 m/s),

so that, with a = atanh(u0/vt), the height is in closed form:

    z(t) = z0 − (vt²/g) [ln cosh(g t/vt + a) − ln cosh(a)].

`pdyn fit examples/data/drop.toml --data examples/data/drop.csv --free c,initial.z,rate.z`
recovers c, z0 and −u0 (examples/data/README.md).
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
G, C, Z0, U0, SIGMA, FPS, FRAMES = 9.81, 0.05, 50.0, 0.8, 0.02, 60.0, 200


def height(t):
    vt = math.sqrt(G / C)
    a = math.atanh(U0 / vt)
    return Z0 - vt * vt / G * (math.log(math.cosh(G * t / vt + a)) - math.log(math.cosh(a)))


def main():
    rng = random.Random(26)
    with open(os.path.join(HERE, "drop.csv"), "w", newline="\n") as f:
        f.write("# a filmed drop: 60 fps, tracked to 0.02 m; see generate_drop.py\n")
        f.write("t,z\n")
        for i in range(FRAMES):
            t = i / FPS
            f.write("{:.6f},{:.4f}\n".format(t, height(t) + rng.gauss(0.0, SIGMA)))


if __name__ == "__main__":
    main()
