#!/usr/bin/env python3
"""`pdyn modes` (sparse shift-invert Lanczos) against SciPy's `eigsh(K, k, M=M, sigma=0)`
(ARPACK, shift-invert with SuperLU) on the same matrices, whole process, for issue 33.

    python3 bench/modes/modes_vs_scipy.py target/release/pdyn [--sizes 1000,10000] [--count 10]

For each size: the chain of examples/chain_modes.toml with n masses (its family's size
changed), and the hanging net of bench/net (n x n nodes) where `--nets` lists sizes.

1. `pdyn modes MODEL --solver sparse --count K --json --matrices DIR` writes K.mtx and M.mtx
   (Matrix Market, every digit) of the linearization it solved;
2. pdyn's whole process is timed without `--matrices`: read the model, derive, linearize,
   equilibrium, factorize, Lanczos, print;
3. a Python process (timed whole: interpreter start, `import scipy`, reading the matrices,
   `eigsh`) computes the same K lowest modes;
4. both sets of frequencies are compared with each other and, for the chain, with the closed
   form w_j = 2 sqrt(k/m) sin(j pi / (2 (n + 1)));
5. with damping (the net's drag: C.mtx not zero), SciPy's side also gives the damped roots
   the way one would for classical damping, c_j = phi_j' C phi_j / phi_j' M phi_j and
   s^2 + c_j s + w_j^2 = 0, and pdyn's damped roots (its `damped_path` is printed) are
   compared with them.

Each timing is the fastest of `--repeat` runs (default 3). Prints a Markdown table.
"""
import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench" / "net"))
import net_model  # noqa: E402

SCIPY = r"""
import sys, time, json
t0 = time.perf_counter()
import numpy as np
import scipy.io, scipy.sparse.linalg as sla
K = scipy.io.mmread(sys.argv[1]).tocsc()
M = scipy.io.mmread(sys.argv[2]).tocsc()
t1 = time.perf_counter()
C = scipy.io.mmread(sys.argv[4]).tocsc() if len(sys.argv) > 4 else None
w2, phi = sla.eigsh(K, k=int(sys.argv[3]), M=M, sigma=0, which="LM")
damped = []
if C is not None and C.nnz and abs(C).max() > 0:
    c = np.einsum("ij,ij->j", phi, C @ phi) / np.einsum("ij,ij->j", phi, M @ phi)
    for cj, wj2 in zip(c, w2):
        r = np.roots([1.0, cj, wj2])
        damped += [[z.real, abs(z.imag)] for z in r if z.imag >= 0] if r.imag.any() else [[z.real, 0.0] for z in r]
    damped.sort(key=lambda z: (abs(complex(*z)), z[0]))
    damped = damped[: int(sys.argv[3])]
t2 = time.perf_counter()
print(json.dumps({"omega": sorted(np.sqrt(w2).tolist()), "damped": damped, "read": t1 - t0, "eigsh": t2 - t1}))
"""


def timed(cmd):
    t0 = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True)
    t = time.perf_counter() - t0
    if out.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: {out.stderr}")
    return t, out.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("pdyn")
    ap.add_argument("--python", default=sys.executable)
    ap.add_argument("--sizes", default="1000,10000")
    ap.add_argument("--nets", default="20")
    ap.add_argument("--count", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    chain = (ROOT / "examples" / "chain_modes.toml").read_text()
    cases = [(f"chain, n = {n}", chain.replace("n = 30", f"n = {n}", 1), n) for n in map(int, args.sizes.split(",")) if n]
    cases += [(f"hanging net {n}×{n} ({n * n - 2} particles)", net_model.family(n), None) for n in map(int, args.nets.split(",")) if n]
    print(f"| model | coordinates | pdyn modes (whole process) | SciPy eigsh (whole process) | of which eigsh | SciPy / pdyn | max rel. difference | max rel. error vs closed form (pdyn / SciPy) |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, text, n in cases:
            model = Path(tmp) / "model.toml"
            model.write_text(text)
            cmd = [args.pdyn, "modes", str(model), "--solver", "sparse", "--count", str(args.count), "--json"]
            subprocess.run(cmd + ["--matrices", tmp], check=True, capture_output=True)
            runs = [timed(cmd) for _ in range(args.repeat)]
            t_pdyn = min(r[0] for r in runs)
            out = json.loads(runs[0][1])
            w_pdyn = [m["omega"] for m in out["modes"]]
            srun = [timed([args.python, "-c", SCIPY, f"{tmp}/K.mtx", f"{tmp}/M.mtx", str(args.count), f"{tmp}/C.mtx"]) for _ in range(args.repeat)]
            t_scipy = min(r[0] for r in srun)
            s = json.loads(srun[0][1])
            eig = min(json.loads(r[1])["eigsh"] for r in srun)
            w_scipy = s["omega"]
            diff = max(abs(a - b) / b for a, b in zip(w_pdyn, w_scipy))
            if s["damped"]:
                d_pdyn = [complex(*d["eigenvalue"]) for d in out.get("damped_modes", [])]
                d_scipy = [complex(*z) for z in s["damped"]]
                dd = max(abs(a - b) / abs(b) for a, b in zip(d_pdyn, d_scipy)) if d_pdyn else float("nan")
                print(f"<!-- {name}: damped roots by {out.get('damped_path')}, {len(d_pdyn)} vs SciPy's {len(d_scipy)}, max rel. difference {dd:.1e} -->", flush=True)
            if n is not None:
                exact = [20 * math.sin(j * math.pi / (2 * (n + 1))) for j in range(1, args.count + 1)]
                e_p = max(abs(a - b) / b for a, b in zip(w_pdyn, exact))
                e_s = max(abs(a - b) / b for a, b in zip(w_scipy, exact))
                err = f"{e_p:.1e} / {e_s:.1e}"
            else:
                err = "–"
            print(f"| {name} | {out['coordinate_count']} | {t_pdyn:.3f} s | {t_scipy:.3f} s | {eig:.3f} s | {t_scipy / t_pdyn:.1f}× | {diff:.1e} | {err} |", flush=True)


if __name__ == "__main__":
    main()
