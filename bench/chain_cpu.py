#!/usr/bin/env python3
"""CPU time (user + system, from the kernel's rusage of the child) and wall time of
`pdyn run FILE --t-end T` on the n-link chain at the settings of
examples/pendulum_chain_3.toml (bench/chain_model.py --example), for two or more binaries
side by side, run alternately, REPEAT rounds; prints the medians as a Markdown table with
the method line of each binary's last run and the load average before and after:

    cargo build --release -p pdyn-cli
    cp target/release/pdyn /tmp/pdyn_before     # before a change
    REPEAT=7 python3 bench/chain_cpu.py /tmp/pdyn_before target/release/pdyn -- 16 100
    T_END=1e-9 python3 bench/chain_cpu.py ... -- 16   # the preparation alone

CPU time is the figure to read on a loaded machine: wall time waits for the other jobs.
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from chain_model import chain_toml  # noqa: E402

REPEAT = int(os.environ.get("REPEAT", "5"))
T_END = os.environ.get("T_END", "10")


def one_run(binary, path):
    """(CPU seconds, wall seconds, stdout) of one whole process."""
    t0 = time.perf_counter()
    p = subprocess.Popen(
        [binary, "run", path, "--t-end", T_END],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )
    out = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        sys.exit(f"{binary} run {path} failed with status {status}")
    return usage.ru_utime + usage.ru_stime, wall, out


def main():
    args = sys.argv[1:]
    if "--" not in args:
        sys.exit(__doc__)
    cut = args.index("--")
    binaries, ns = args[:cut], [int(a) for a in args[cut + 1 :]]
    print(f"load average before: {os.getloadavg()[0]:.2f}; REPEAT={REPEAT}, --t-end {T_END}")
    print("| n | binary | CPU (median) | wall (median) | method line |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in ns:
            path = os.path.join(tmp, f"chain{n}.toml")
            with open(path, "w") as f:
                f.write(chain_toml(n, example=True))
            cpu = {b: [] for b in binaries}
            wall = {b: [] for b in binaries}
            line = {}
            for _ in range(REPEAT):
                for b in binaries:
                    c, w, out = one_run(b, path)
                    cpu[b].append(c)
                    wall[b].append(w)
                    line[b] = next(
                        (l for l in out.decode().splitlines() if l.startswith("method ")),
                        "",
                    )
            for b in binaries:
                print(
                    f"| {n} | `{b}` | {statistics.median(cpu[b]) * 1000:.1f} ms "
                    f"| {statistics.median(wall[b]) * 1000:.1f} ms "
                    f"| {line[b].removeprefix('method ')} |"
                )
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
