#!/usr/bin/env python3
"""Whole-process times of `pdyn derive`, `pdyn run --t-end 10`, `pdyn run --method exact` and
`pdyn check` on the linear structures of bench/structure_models.py (an n-storey shear
building, an n-mass spring chain, symbolic mass and stiffness per element), best of REPEAT
runs each:

    cargo build --release -p pdyn-cli
    python3 bench/structure_times.py building:10 spring_chain:50

Prints one Markdown table row per model and the load average before and after.
"""
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from structure_models import building_toml, spring_chain_toml  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PDYN = os.environ.get("PDYN", os.path.join(ROOT, "target", "release", "pdyn"))
REPEAT = int(os.environ.get("REPEAT", "3"))
MODELS = {"building": building_toml, "spring_chain": spring_chain_toml}


def best(args):
    times = []
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        subprocess.run([PDYN, *args], capture_output=True, check=True)
        times.append(time.perf_counter() - t0)
    return min(times)


def main():
    specs = sys.argv[1:] or ["building:10", "spring_chain:50"]
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print("| model | `pdyn derive` | `pdyn run --t-end 10` | `--method exact` | `pdyn check` |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec in specs:
            kind, n = spec.split(":")
            path = os.path.join(tmp, f"{kind}{n}.toml")
            with open(path, "w") as f:
                f.write(MODELS[kind](int(n)))
            d = best(["derive", path])
            run = best(["run", path, "--t-end", "10"])
            exact = best(["run", path, "--t-end", "10", "--method", "exact"])
            check = best(["check", path, "--t-end", "10"])
            print(f"| {kind} n = {n} | {d:.3f} s | {run:.3f} s | {exact:.3f} s | {check:.3f} s |")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
