#!/usr/bin/env python3
"""Model files of the linear structures issue 12 names next to the pendulum chain, with
symbolic parameters per element, for whole-process measurements (bench/structure_times.py):

- `building_toml(n)`: an n-storey shear building (floor masses m_i, storey stiffnesses k_i,
  unstretched storey height L) shaken at its base, d = d0 sin(omega t), as
  examples/building.toml is for n = 2;
- `spring_chain_toml(n)`: n masses m_i in a line between two walls, joined by n + 1 springs
  k_1 ... k_(n+1) of unstretched length L, the first mass displaced.

    python3 bench/structure_models.py building 10 > /tmp/building10.toml
    python3 bench/structure_models.py spring_chain 50 > /tmp/spring_chain50.toml
"""
import sys


def building_toml(n: int) -> str:
    s = f'name = "{n}-storey shear building"\ngravity = "[0, -g, 0]"\n\n[parameters]\n'
    s += "g = 9.81\nL = 3.0\nd0 = 0.05\nomega = 9.0\n"
    for i in range(1, n + 1):
        s += f"m{i} = {1.0 + 0.1 * (i % 3)}\nk{i} = {400.0 + 10.0 * i}\n"
    s += '\n[coordinates]\nd = "d0*sin(omega*t)"\n'
    for i in range(1, n + 1):
        s += f'y{i} = {{ initial = "{i}*L", rate = 0.0 }}\n'
    s += '\n[points]\nground = "[0, d, 0]"\n'
    for i in range(1, n + 1):
        s += f'\n[particles.floor{i}]\nmass = "m{i}"\nposition = "[0, y{i}, 0]"\n'
    for i in range(1, n + 1):
        below, lower = ("ground", "d") if i == 1 else (f"floor{i - 1}", f"y{i - 1}")
        s += (
            f'\n[[forces]]\nkind = "spring"\nname = "storey {i}"\n'
            f'between = ["floor{i}", "{below}"]\nk = "k{i}"\nl0 = "L"\n'
            f'length = "y{i} - {lower}"\n'
        )
    return s


def spring_chain_toml(n: int) -> str:
    s = f'name = "{n}-mass spring chain"\n\n[parameters]\nL = 1.0\n'
    for i in range(1, n + 1):
        s += f"m{i} = {1.0 + 0.25 * (i % 4)}\n"
    for i in range(1, n + 2):
        s += f"k{i} = {100.0 + 5.0 * (i % 7)}\n"
    s += "\n[coordinates]\n"
    for i in range(1, n + 1):
        start = f"{i}*L + 0.1" if i == 1 else f"{i}*L"
        s += f'x{i} = {{ initial = "{start}", rate = 0.0 }}\n'
    s += f'\n[points]\nleft_wall = "[0, 0, 0]"\nright_wall = "[{n + 1}*L, 0, 0]"\n'
    for i in range(1, n + 1):
        s += f'\n[particles.p{i}]\nmass = "m{i}"\nposition = "[x{i}, 0, 0]"\n'
    for i in range(1, n + 2):
        a = "left_wall" if i == 1 else f"p{i - 1}"
        b = "right_wall" if i == n + 1 else f"p{i}"
        xa = "0" if i == 1 else f"x{i - 1}"
        xb = f"{n + 1}*L" if i == n + 1 else f"x{i}"
        s += (
            f'\n[[forces]]\nkind = "spring"\nname = "spring {i}"\n'
            f'between = ["{b}", "{a}"]\nk = "k{i}"\nl0 = "L"\nlength = "{xb} - {xa}"\n'
        )
    return s


if __name__ == "__main__":
    kind, n = sys.argv[1], int(sys.argv[2])
    sys.stdout.write({"building": building_toml, "spring_chain": spring_chain_toml}[kind](n))
