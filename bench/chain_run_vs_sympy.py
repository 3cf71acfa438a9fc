#!/usr/bin/env python3
"""Whole process, the n-link planar pendulum chain integrated over 10 s: `pdyn run` against
what a SymPy user runs (KanesMethod -> lambdify -> SciPy solve_ivp), in one run.

Both sides start from q_i = 0.1, q_i' = 0, use Dormand-Prince 5(4) (pdyn's default `dopri5`,
SciPy's `RK45`) at rtol = 1e-6, atol = 1e-9, and write the trajectory as CSV. Each side is
timed as a whole process (interpreter start, imports, derivation, code generation,
integration, output), as a user would see it:

    cargo build --release -p pdyn-cli
    python3 bench/chain_run_vs_sympy.py 2 4 8 16

Prints one row per n: pdyn seconds, SymPy+SciPy seconds, their ratio, both f-evaluation counts
and the largest difference of the final angles. Installs sympy, scipy and numpy from PyPI if
they are missing.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PDYN = os.environ.get("PDYN", os.path.join(ROOT, "target", "release", "pdyn"))

try:
    import numpy  # noqa: F401
    import scipy  # noqa: F401
    import sympy  # noqa: F401
except ImportError:  # pragma: no cover
    subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet",
                           "numpy", "scipy", "sympy"])

sys.path.insert(0, HERE)
from chain_model import chain_toml  # noqa: E402

# What the SymPy user's script does, run as its own process.
SYMPY_USER = r"""
import sys
sys.path.insert(0, sys.argv[3])
import numpy as np
import sympy as sm
import sympy.physics.mechanics as me
from scipy.integrate import solve_ivp
from sympy_chain import derive

n, out = int(sys.argv[1]), sys.argv[2]
mm, ff = derive(n)
q = me.dynamicsymbols(f"q:{n}")
u = me.dynamicsymbols(f"u:{n}")
m = sm.symbols(f"m:{n}")
l = sm.symbols(f"l:{n}")
g = sm.symbols("g")
args = list(q) + list(u) + list(m) + list(l) + [g]
mass = sm.lambdify(args, mm, "numpy")
forcing = sm.lambdify(args, ff, "numpy")
params = [1.0] * n + [1.0] * n + [9.81]

def rhs(t, y):
    a = list(y) + params
    return np.linalg.solve(mass(*a), np.asarray(forcing(*a), dtype=float).ravel())

sol = solve_ivp(rhs, (0.0, 10.0), [0.1] * n + [0.0] * n, method="RK45",
                rtol=1e-6, atol=1e-9)
np.savetxt(out, np.column_stack([sol.t, sol.y.T]), delimiter=",")
print(sol.nfev, *sol.y[:n, -1])
"""


def timed(cmd):
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if res.returncode != 0:
        sys.exit(f"{cmd[0]} failed:\n{res.stderr}")
    return dt, res.stdout


def main():
    sizes = [int(a) for a in sys.argv[1:]] or [2, 4, 8, 16]
    if not os.path.exists(PDYN):
        sys.exit(f"{PDYN} not found: run `cargo build --release -p pdyn-cli` first")
    with tempfile.TemporaryDirectory() as tmp:
        script = os.path.join(tmp, "sympy_user.py")
        with open(script, "w") as f:
            f.write(SYMPY_USER)
        print("| n | pdyn run | SymPy + SciPy | ratio | f-evaluations (pdyn / SciPy) "
              "| max final |Δq| |")
        print("|---|---|---|---|---|---|")
        for n in sizes:
            model = os.path.join(tmp, f"chain{n}.toml")
            with open(model, "w") as f:
                f.write(chain_toml(n))
            out = os.path.join(tmp, f"pdyn{n}")
            tp, _ = timed([PDYN, "run", model, "--t-end", "10", "--out", out, "--json"])
            with open(os.path.join(out, "summary.json")) as f:
                summary = json.load(f)
            pdyn_nfev = summary["stats"]["fevals"]
            pdyn_final = [summary["final"][f"q{i + 1}"] for i in range(n)]
            ts, text = timed([sys.executable, script, str(n),
                              os.path.join(tmp, f"sympy{n}.csv"), HERE])
            fields = text.split()
            sympy_nfev = int(fields[0])
            sympy_final = [float(x) for x in fields[1:]]
            dq = max(abs(a - b) for a, b in zip(pdyn_final, sympy_final))
            print(f"| {n} | {tp:.3f} s | {ts:.3f} s | **{ts / tp:.0f}×** "
                  f"| {pdyn_nfev} / {sympy_nfev} | {dq:.1e} |", flush=True)


if __name__ == "__main__":
    main()
