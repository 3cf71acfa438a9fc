"""Whole-process timing, pdyn against LAMMPS, alternating run by run (issue 28, item 3).

usage (from the repository root, after bash bench/md/run.sh has made bench/md/.venv and
`cargo build --release -p pdyn-cli`):
    bench/md/.venv/bin/python bench/md/whole.py [--repeat 5] [--steps 300] [--pdyn target/release/pdyn]
in.melt (LAMMPS's settings, then exact checks on both sides):
    bench/md/.venv/bin/python bench/md/whole.py --steps 250 --toml bench/md/in_melt.toml \
        --lammps-input bench/md/in.melt --cases pdyn1,lmp1
    bench/md/.venv/bin/python bench/md/whole.py --steps 250 --toml bench/md/in_melt_exact.toml \
        --lammps-input bench/md/in.melt.exact --cases pdyn1,lmp1

Cases (each the command a user types, timed from fork to exit):
  pdyn 1 thread     RAYON_NUM_THREADS=1 pdyn run bench/md/in_lj.toml --out DIR
  LAMMPS serial     lmp -in in.lj -var n STEPS -log none -screen none
  pdyn 2 threads    RAYON_NUM_THREADS=2 pdyn run bench/md/in_lj.toml --out DIR
  LAMMPS 2 ranks    mpirun -np 2 lmp -in in.lj -var n STEPS -log none -screen none
Wall time and CPU time (user + system of the process and its children, from wait4) are
reported; on a machine shared with other jobs the CPU time is the steadier measure of the
work done. Medians over the repetitions.
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import time

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
venv = os.path.join(here, ".venv")

ap = argparse.ArgumentParser()
ap.add_argument("--repeat", type=int, default=5)
ap.add_argument("--steps", type=int, default=300)
ap.add_argument("--pdyn", default=os.path.join(root, "target", "release", "pdyn"))
ap.add_argument("--toml", default=os.path.join(here, "in_lj.toml"))
ap.add_argument("--lammps-input", default=os.path.join(here, "in.lj"))
ap.add_argument("--cases", default="pdyn1,lmp1,pdyn2,lmp2")
ap.add_argument("--pdyn-before", default=None,
                help="a second pdyn binary (e.g. built from the commit before a change): adds "
                     "the cases before1 and before2")
a = ap.parse_args()
a.toml, a.lammps_input, a.pdyn = (os.path.abspath(x) for x in (a.toml, a.lammps_input, a.pdyn))

env = dict(os.environ)
env["LD_LIBRARY_PATH"] = os.path.join(venv, "lib") + (
    ":" + env["LD_LIBRARY_PATH"] if env.get("LD_LIBRARY_PATH") else "")
env["OMP_NUM_THREADS"] = "1"
lmp = os.path.join(venv, "bin", "lmp")
mpirun = os.path.join(venv, "bin", "mpirun")
out = tempfile.mkdtemp(prefix="pdyn-md-whole-")
lmp_args = ["-in", os.path.basename(a.lammps_input), "-var", "n", str(a.steps),
            "-log", "none", "-screen", "none"]
pdyn_args = [a.pdyn, "run", a.toml, "--set", f"steps={a.steps}", "--out", out]
cases = {
    "pdyn1": ("pdyn, 1 thread", pdyn_args, {"RAYON_NUM_THREADS": "1"}),
    "lmp1": ("LAMMPS serial", [lmp] + lmp_args, {}),
    "pdyn2": ("pdyn, 2 threads", pdyn_args, {"RAYON_NUM_THREADS": "2"}),
    "lmp2": ("LAMMPS, 2 MPI ranks", [mpirun, "-np", "2", lmp] + lmp_args, {}),
}
if a.pdyn_before:
    before = [a.pdyn_before] + pdyn_args[1:]
    cases["before1"] = ("pdyn before, 1 thread", before, {"RAYON_NUM_THREADS": "1"})
    cases["before2"] = ("pdyn before, 2 threads", before, {"RAYON_NUM_THREADS": "2"})
chosen = [c for c in a.cases.split(",") if c]


def timed(cmd, extra):
    e = dict(env)
    e.update(extra)
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, env=e, cwd=os.path.dirname(a.lammps_input),
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    err = p.stderr.read().decode(errors="replace")
    p.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{cmd} failed: {err}")
    return wall, ru.ru_utime + ru.ru_stime


res = {c: [] for c in chosen}
print(f"`uptime` before: {os.popen('uptime').read().strip()}")
for r in range(a.repeat):
    for c in chosen:
        res[c].append(timed(cases[c][1], cases[c][2]))
print(f"`uptime` after: {os.popen('uptime').read().strip()}")
print()
print(f"{os.path.basename(a.toml)} against {os.path.basename(a.lammps_input)}, {a.steps} steps, "
      f"{a.repeat} alternating repetitions, medians")
print()
print("| case | wall s (median) | CPU s (median) | wall s, all runs |")
print("|---|---|---|---|")
med = {}
for c in chosen:
    w = statistics.median(x[0] for x in res[c])
    cpu = statistics.median(x[1] for x in res[c])
    med[c] = (w, cpu)
    runs = " ".join(f"{x[0]:.2f}" for x in res[c])
    print(f"| {cases[c][0]} | {w:.3f} | {cpu:.3f} | {runs} |")
print()
for p, l in (("pdyn1", "lmp1"), ("pdyn2", "lmp2")):
    if p in med and l in med:
        print(f"- {cases[l][0]} / {cases[p][0]}: wall {med[l][0] / med[p][0]:.2f}×, "
              f"CPU {med[l][1] / med[p][1]:.2f}×")
