#!/usr/bin/env python3
"""CPU time (user + system of the child, from the kernel's rusage) of whole commands run
alternately, REPEAT rounds; prints the median and the minimum of each. CPU time is the
figure to read on a loaded machine (wall time waits for the other jobs).

    python3 bench/cpu_alternate.py 7 -- OLD/pdyn run NET.toml --t-end 8 -- NEW/pdyn run NET.toml --t-end 8
"""
import os
import statistics
import subprocess
import sys


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
    for _ in range(rounds):
        for i, c in enumerate(commands):
            p = subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            _, status, usage = os.wait4(p.pid, 0)
            if status != 0:
                sys.exit(f"{' '.join(c)} failed with status {status}")
            times[i].append((usage.ru_utime + usage.ru_stime) * 1000)
    print(f"load average after: {os.getloadavg()[0]:.2f}; {rounds} rounds")
    for c, t in zip(commands, times):
        print(f"{statistics.median(t):9.1f} ms median, {min(t):9.1f} ms min  {' '.join(c)}")


if __name__ == "__main__":
    main()
