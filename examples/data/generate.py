#!/usr/bin/env python3
"""Regenerates the example data of pdyn's measured-motion commands, deterministically
(Python's standard library only: `random.Random(seed)`, fixed decimals). Run from anywhere:

    python3 examples/data/generate.py

Writes, next to this script:

- track.csv  a cart tracked by a camera on the ellipse x = 4 cos(0.5 t), y = 2.5 sin(0.5 t) (m),
             10 Hz for 30 s, noise 0.01 m per coordinate. Truth: speed and a_n in closed form.
- lift.csv   a lift's vertical accelerometer at 100 Hz for 16 s: at rest for 2 s, then
             a = 0.6 sin(2π (t − 2)/10) m/s² for 10 s, then at rest; bias 0.02 m/s², noise
             0.01 m/s². Truth: it rises 100·0.6/(2π) = 9.5493 m.
- imu.csv    an accelerometer (x, y) at 100 Hz for 60 s on a vehicle moving as
             x = 30 sin(0.1 t) + 2 t, y = 20 (1 − cos(0.15 t)) (m); biases (0.05, −0.03) m/s²,
             noise 0.05 m/s².
- gps.csv    position fixes of the same vehicle at 1 Hz, noise 2 m.
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, header, rows, fmt):
    with open(os.path.join(HERE, name), "w", newline="\n") as f:
        f.write(header + "\n")
        for r in rows:
            f.write(",".join(fmt.format(v) for v in r) + "\n")


def track():
    rng = random.Random(1)
    rows = []
    for i in range(301):
        t = i / 10
        rows.append((t, 4 * math.cos(0.5 * t) + 0.01 * rng.gauss(0, 1),
                     2.5 * math.sin(0.5 * t) + 0.01 * rng.gauss(0, 1)))
    write("track.csv", "t,x,y", rows, "{:.4f}")


def lift():
    rng = random.Random(2)
    rows = []
    for i in range(1601):
        t = i / 100
        a = 0.6 * math.sin(2 * math.pi * (t - 2) / 10) if 2 <= t <= 12 else 0.0
        rows.append((t, a + 0.02 + 0.01 * rng.gauss(0, 1)))
    write("lift.csv", "t,az", rows, "{:.5f}")


def vehicle(t):
    x = 30 * math.sin(0.1 * t) + 2 * t
    y = 20 * (1 - math.cos(0.15 * t))
    ax = -30 * 0.01 * math.sin(0.1 * t)
    ay = 20 * 0.0225 * math.cos(0.15 * t)
    return x, y, ax, ay


def imu_gps():
    rng = random.Random(3)
    rows = []
    for i in range(6001):
        t = i / 100
        _, _, ax, ay = vehicle(t)
        rows.append((t, ax + 0.05 + 0.05 * rng.gauss(0, 1), ay - 0.03 + 0.05 * rng.gauss(0, 1)))
    write("imu.csv", "t,ax,ay", rows, "{:.5f}")
    rows = []
    for i in range(60):
        t = i + 0.5
        x, y, _, _ = vehicle(t)
        rows.append((t, x + 2 * rng.gauss(0, 1), y + 2 * rng.gauss(0, 1)))
    write("gps.csv", "t,x,y", rows, "{:.3f}")


if __name__ == "__main__":
    track()
    lift()
    imu_gps()
