#!/usr/bin/env python3
"""`pdyn run` of the hanging net against the same net built and integrated by NumPy + SciPy
(`bench/net/net_scipy.py`), whole process each, in one run (issue 33: "a NumPy/SciPy script
that builds and integrates the same net").

Both write the 201-row table as CSV with rtol 1e-6, atol 1e-9. pdyn runs its `auto` (DOP853 at
this rtol since 2026-11-28); SciPy runs each of `--scipy-methods` (default DOP853, the same
method, and RK45, SciPy's default and pdyn's pick before), one row each.
The two are first checked to be the same model: their states at t = 0.5 s must agree to
1e-5 (tolerance-level; the falling net folds and later the two runs part exponentially, as
any two integrations of it with different round-off do: 3e-6 at t = 2 s, 2e-2 at t = 4 s). Then each is timed `--repeat` times,
alternating, and the fastest kept; CPU time (user + system) from /usr/bin/time too.

    python3 -m venv /tmp/venv-bench && /tmp/venv-bench/bin/pip install numpy scipy
    cargo build --release -p pdyn-cli
    /tmp/venv-bench/bin/python bench/net/net_vs_scipy.py target/release/pdyn --sizes 10,20 --t-end 8
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import net_model  # noqa: E402


def timed(cmd):
    out = subprocess.run(["/usr/bin/time", "-f", "%e %U %S %M", *cmd], capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}:\n{out.stderr}")
    wall, user, system, kb = out.stderr.strip().splitlines()[-1].split()
    return float(wall), float(user) + float(system), int(kb) / 1024


def final_pdyn(pdyn, model, t_end):
    out = subprocess.run([pdyn, "run", str(model), "--t-end", str(t_end), "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)["final"]


def final_scipy(n, t_end, tmp, method):
    path = Path(tmp) / "final.json"
    subprocess.run([sys.executable, str(HERE / "net_scipy.py"), str(n), "--t-end", str(t_end), "--method", method, "--final-json", str(path)], check=True, capture_output=True)
    return json.loads(path.read_text())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("pdyn")
    ap.add_argument("--sizes", default="10,20")
    ap.add_argument("--t-end", default="8")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--scipy-methods", default="DOP853,RK45")
    args = ap.parse_args()
    print("| particles | states | SciPy method | pdyn wall | pdyn CPU | pdyn memory | SciPy wall | SciPy CPU | SciPy memory | SciPy / pdyn (wall) | SciPy / pdyn (CPU) | max difference at t = 0.5 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    methods = args.scipy_methods.split(",")
    with tempfile.TemporaryDirectory() as tmp:
        for n in map(int, args.sizes.split(",")):
            model = Path(tmp) / f"net{n}.toml"
            model.write_text(net_model.family(n))
            p = final_pdyn(args.pdyn, model, 0.5)
            diffs = {}
            for method in methods:
                s = final_scipy(n, 0.5, tmp, method)
                diffs[method] = max(abs(p[k] - s[k]) for k in s)
                if diffs[method] > 1e-5:
                    raise SystemExit(f"n = {n}, {method}: the two nets differ by {diffs[method]:.3g} at t = 0.5")
            best = {}
            for _ in range(args.repeat):
                runs = {"pdyn": [args.pdyn, "run", str(model), "--t-end", args.t_end, "--out", f"{tmp}/p{n}"]}
                for method in methods:
                    runs[method] = [sys.executable, str(HERE / "net_scipy.py"), str(n), "--t-end", args.t_end, "--method", method, "--out", f"{tmp}/s{n}.csv"]
                for side, cmd in runs.items():
                    r = timed(cmd)
                    if side not in best or r[0] < best[side][0]:
                        best[side] = r
            pw, pc, pm = best["pdyn"]
            particles = n * n - 2
            for method in methods:
                sw, sc, sm = best[method]
                print(f"| {particles} | {6 * particles} | {method} | {pw:.2f} s | {pc:.2f} s | {pm:.0f} MB | {sw:.2f} s | {sc:.2f} s | {sm:.0f} MB | {sw / pw:.1f}× | {sc / pc:.1f}× | {diffs[method]:.1e} |")

if __name__ == "__main__":
    main()
