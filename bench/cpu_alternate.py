#!/usr/bin/env python3
"""CPU time (user + system of the child, from the kernel's rusage) and wall time of whole
commands run alternately, REPEAT rounds; prints the median and the minimum of each. CPU time
is the figure to read on a loaded machine (wall time waits for the other jobs); wall time is
the one that shows work moved to another core (a writer thread).

    python3 bench/cpu_alternate.py 7 -- OLD/pdyn run NET.toml --t-end 8 -- NEW/pdyn run NET.toml --t-end 8
"""
import os
import statistics
import subprocess
import sys
import time


def main():
    if len(sys.argv) < 4 or sys.argv[2] != "--":
        sys.exit(__doc__)
    rounds = int(sys.argv[1])
    commands, current = [], None
    for a in sys.argv[2:]:
        if a == "--":
            current = []
            commands.append(current)
        else:
            current.append(a)
    times = [[] for _ in commands]
    walls = [[] for _ in commands]
    for _ in range(rounds):
        for i, c in enumerate(commands):
            start = time.perf_counter()
            p = subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            _, status, usage = os.wait4(p.pid, 0)
            walls[i].append((time.perf_counter() - start) * 1000)
            if status != 0:
                sys.exit(f"{' '.join(c)} failed with status {status}")
            times[i].append((usage.ru_utime + usage.ru_stime) * 1000)
    print(f"load average after: {os.getloadavg()[0]:.2f}; {rounds} rounds")
    for c, t, w in zip(commands, times, walls):
        print(
            f"CPU {statistics.median(t):9.1f} ms median, {min(t):9.1f} ms min;"
            f" wall {statistics.median(w):9.1f} ms median, {min(w):9.1f} ms min  {' '.join(c)}"
        )


if __name__ == "__main__":
    main()
