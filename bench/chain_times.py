#!/usr/bin/env python3
"""Whole-process times of `pdyn derive`, the preparation of a run (`pdyn run --t-end 0.001`)
and `pdyn run --t-end 10` on the n-link pendulum chain (bench/chain_model.py), best of
REPEAT runs each, with the size of `pdyn derive`'s output and its longest line:

    cargo build --release -p pdyn-cli
    python3 bench/chain_times.py 2 3 4 8 16 32 64 100
    python3 bench/chain_times.py --example 3 16 100

Prints one Markdown table row per n and the load average before and after. With `--example`
the chain has the settings of examples/pendulum_chain_3.toml (link i released at 0.3*i rad,
rtol 1e-9, atol 1e-12; `bench/chain_model.py --example`), and only `pdyn run --t-end 10` is
timed, with its method line (method, steps, f-evaluations).
"""
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from chain_model import chain_toml  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PDYN = os.environ.get("PDYN", os.path.join(ROOT, "target", "release", "pdyn"))
REPEAT = int(os.environ.get("REPEAT", "3"))


def best(args):
    times = []
    out = b""
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        r = subprocess.run([PDYN, *args], capture_output=True, check=True)
        times.append(time.perf_counter() - t0)
        out = r.stdout
    return min(times), out


def example(ns):
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print("| n | `pdyn run --t-end 10` | method, steps, f-evaluations |")
    print("|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in ns:
            path = os.path.join(tmp, f"chain{n}.toml")
            with open(path, "w") as f:
                f.write(chain_toml(n, example=True))
            run, out = best(["run", path, "--t-end", "10"])
            line = next(
                (l for l in out.decode().splitlines() if l.startswith("method ")), ""
            )
            print(f"| {n} | {run * 1000:.1f} ms | {line.removeprefix('method ')} |")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


def main():
    if "--example" in sys.argv[1:]:
        example([int(a) for a in sys.argv[1:] if a != "--example"] or [3, 16, 100])
        return
    ns = [int(a) for a in sys.argv[1:]] or [2, 4, 8, 16, 32, 64, 100]
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print("| n | `pdyn derive` | output (longest line) | preparation | `pdyn run --t-end 10` |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in ns:
            path = os.path.join(tmp, f"chain{n}.toml")
            with open(path, "w") as f:
                f.write(chain_toml(n))
            d, text = best(["derive", path])
            longest = max((len(line) for line in text.decode().splitlines()), default=0)
            prep, _ = best(["run", path, "--t-end", "0.001"])
            run, _ = best(["run", path, "--t-end", "10"])
            print(
                f"| {n} | {d:.3f} s | {len(text) / 1000:.0f} KB ({longest}) "
                f"| {prep:.3f} s | {run:.3f} s |"
            )
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
