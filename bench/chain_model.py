#!/usr/bin/env python3
"""Writes the model file of an n-link planar pendulum chain with symbolic m_i, l_i (as
examples/pendulum_chain_3.toml and crates/pdyn-mech/tests/common/chain.rs), for whole-process
measurements of `pdyn derive` / `pdyn run`:

    python3 bench/chain_model.py 100 > /tmp/chain100.toml
    python3 bench/chain_model.py 100 --example > /tmp/chain100.toml
    /usr/bin/time target/release/pdyn run /tmp/chain100.toml --t-end 10 -o /tmp/out.csv

Without `--example` every link starts at 0.1 rad and the run uses pdyn's default tolerances
(an easy chain). With `--example` the chain has the settings of
examples/pendulum_chain_3.toml: link i released at 0.3*i rad from rest, `[simulate]` with
t_end = 10, rtol = 1e-9, atol = 1e-12 (unit masses and lengths).
"""
import sys


def chain_toml(n: int, example: bool = False) -> str:
    s = 'name = "chain"\ngravity = "[0, -g, 0]"\n\n[parameters]\ng = 9.81\n'
    for i in range(1, n + 1):
        s += f"m{i} = 1.0\nl{i} = 1.0\n"
    s += "\n[coordinates]\n"
    for i in range(1, n + 1):
        # repr of the float: 0.3*3 is 0.8999999999999999, as in the example file.
        q0 = 0.3 * i if example else 0.1
        s += f"q{i} = {{ initial = {q0!r}, rate = 0.0 }}\n"
    for i in range(1, n + 1):
        pos = " + ".join(f"l{j}*[sin(q{j}), -cos(q{j}), 0]" for j in range(1, i + 1))
        s += f'\n[particles.p{i}]\nmass = "m{i}"\nposition = "{pos}"\n'
    if example:
        s += "\n[simulate]\nt_end = 10.0\nrtol = 1e-9\natol = 1e-12\n"
    return s


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--example"]
    sys.stdout.write(chain_toml(int(args[0]), example="--example" in sys.argv[1:]))
