#!/usr/bin/env python3
"""Writes the model file of an n-link planar pendulum chain with symbolic m_i, l_i (as
examples/pendulum_chain_3.toml and crates/pdyn-mech/tests/common/chain.rs), for whole-process
measurements of `pdyn derive` / `pdyn run`:

    python3 bench/chain_model.py 100 > /tmp/chain100.toml
    /usr/bin/time target/release/pdyn run /tmp/chain100.toml --t-end 10 -o /tmp/out.csv
"""
import sys


def chain_toml(n: int) -> str:
    s = 'name = "chain"\ngravity = "[0, -g, 0]"\n\n[parameters]\ng = 9.81\n'
    for i in range(1, n + 1):
        s += f"m{i} = 1.0\nl{i} = 1.0\n"
    s += "\n[coordinates]\n"
    for i in range(1, n + 1):
        s += f"q{i} = {{ initial = 0.1, rate = 0.0 }}\n"
    for i in range(1, n + 1):
        pos = " + ".join(f"l{j}*[sin(q{j}), -cos(q{j}), 0]" for j in range(1, i + 1))
        s += f'\n[particles.p{i}]\nmass = "m{i}"\nposition = "{pos}"\n'
    return s


if __name__ == "__main__":
    sys.stdout.write(chain_toml(int(sys.argv[1])))
