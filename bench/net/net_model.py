#!/usr/bin/env python3
"""The hanging net of issue 33 as a model file: an n x n net of particles in Cartesian
coordinates, structural and diagonal springs, gravity and linear drag, the two corners
P[0,0] and P[n-1,0] pinned; it starts flat (z = 0) at rest and falls.

Two spellings of the same model:
- `explicit`: every coordinate, particle and spring written out (what users generated before
  families), with the member names a family gives (`x[1,2]`, `P[1,2]`), so the two load the
  same model entry for entry;
- `family`: the same model as `examples/hanging_net.toml` writes it, with its size `n`;
- `legacy`: `explicit` with plain names (`x_1_2`, `P_1_2`), for a pdyn from before families.

    python3 bench/net/net_model.py explicit 10 > /tmp/net10.toml   # 98 particles
    python3 bench/net/net_model.py family 10 > /tmp/net10f.toml
"""
import re
import sys
from pathlib import Path

PARAMETERS = """[parameters]
m = 0.05
k = 400.0
kd = 100.0
a = 0.1
c = 0.02
g = 9.81
"""


def pinned(i: int, j: int, n: int) -> bool:
    return j == 0 and (i == 0 or i == n - 1)


def explicit(n: int) -> str:
    s = f'name = "Hanging net {n}x{n}"\ngravity = "[0, 0, -g]"\n\n' + PARAMETERS
    nodes = [(i, j) for i in range(n) for j in range(n)]
    free = [(i, j) for (i, j) in nodes if not pinned(i, j, n)]
    s += "\n[coordinates]\n"
    for axis, init in (("x", "i*a"), ("y", "j*a"), ("z", "0")):
        for i, j in free:
            value = init.replace("i", str(i)).replace("j", str(j))
            s += f'"{axis}[{i},{j}]" = {{ initial = "{value}", rate = 0 }}\n'
    s += "\n[points]\n"
    for i, j in nodes:
        if pinned(i, j, n):
            s += f'"P[{i},{j}]" = "[{i}*a, {j}*a, 0]"\n'
    for i, j in free:
        s += (
            f'\n[particles."P[{i},{j}]"]\nmass = "m"\n'
            f'position = "[x[{i},{j}], y[{i},{j}], z[{i},{j}]]"\n'
        )
    springs = [
        ("horizontal", "k", "a", lambda i, j: ((i, j), (i + 1, j)), n - 1, n),
        ("vertical", "k", "a", lambda i, j: ((i, j), (i, j + 1)), n, n - 1),
        ("diagonal", "kd", "sqrt(2)*a", lambda i, j: ((i, j), (i + 1, j + 1)), n - 1, n - 1),
        ("antidiagonal", "kd", "sqrt(2)*a", lambda i, j: ((i + 1, j), (i, j + 1)), n - 1, n - 1),
    ]
    for name, k, l0, ends, ni, nj in springs:
        for i in range(ni):
            for j in range(nj):
                (a1, b1), (a2, b2) = ends(i, j)
                s += (
                    f'\n[[forces]]\nkind = "spring"\nname = "{name}[i={i}, j={j}]"\n'
                    f'between = ["P[{a1},{b1}]", "P[{a2},{b2}]"]\nk = "{k}"\nl0 = "{l0}"\n'
                )
    for i, j in free:
        s += (
            f'\n[[forces]]\nkind = "linear_drag"\nname = "drag[i={i}, j={j}]"\n'
            f'on = "P[{i},{j}]"\nc = "c"\n'
        )
    return s


def family(n: int) -> str:
    example = Path(__file__).resolve().parents[2] / "examples" / "hanging_net.toml"
    text = example.read_text()
    return re.sub(r"^n = \d+", f"n = {n}", text, count=1, flags=re.M)


def legacy(n: int) -> str:
    return re.sub(r"\b([A-Za-z]\w*)\[(\d+),(\d+)\]", r"\1_\2_\3", explicit(n))


if __name__ == "__main__":
    kind, n = sys.argv[1], int(sys.argv[2])
    print({"explicit": explicit, "family": family, "legacy": legacy}[kind](n), end="")
