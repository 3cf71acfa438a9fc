#!/usr/bin/env python3
"""The hanging net of issue 33 built and integrated with NumPy + SciPy, as an engineer would
write it without pdyn: node and spring index arrays, a vectorised right-hand side, and
`scipy.integrate.solve_ivp(method="DOP853")` (Dormand–Prince 8(5,3), the method `pdyn run`'s
`auto` picks at this model's rtol since 2026-11-28; `--method RK45` for Dormand–Prince 5(4),
the one it picked before) with the model's tolerances (rtol 1e-6, atol 1e-9) and its output
times (201 points), the table written as CSV.

The same physics as `examples/hanging_net.toml` (`bench/net/net_model.py family N`): an n x n
net of point masses m, structural springs k (rest length a) and diagonal springs kd (rest
length sqrt(2) a), gravity g along -z, linear drag -c v, the corners (0,0) and (n-1,0)
pinned, released flat at rest.

    python3 bench/net/net_scipy.py 20 --t-end 8 --out /tmp/scipy_net20.csv
    python3 bench/net/net_scipy.py 20 --t-end 8 --final-json /tmp/final.json

`--final-json` writes the final state as a map named like pdyn's columns (`x[i,j]`,
`x[i,j]'`, ...), so `bench/net/net_vs_scipy.py` can compare the two runs.
"""
import argparse
import json
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

M, K, KD, A, C, G = 0.05, 400.0, 100.0, 0.1, 0.02, 9.81


def build(n: int):
    """Free nodes, pinned nodes and springs as index arrays."""
    nodes = [(i, j) for i in range(n) for j in range(n)]
    pinned = {(0, 0), (n - 1, 0)}
    free = [p for p in nodes if p not in pinned]
    # Every node gets a slot; the pinned ones sit after the free ones.
    order = free + sorted(pinned)
    slot = {p: s for s, p in enumerate(order)}
    rest = np.array([[i * A, j * A, 0.0] for (i, j) in order])
    pairs, ks, l0s = [], [], []
    for i in range(n):
        for j in range(n):
            if i + 1 < n:
                pairs.append((slot[(i, j)], slot[(i + 1, j)])); ks.append(K); l0s.append(A)
            if j + 1 < n:
                pairs.append((slot[(i, j)], slot[(i, j + 1)])); ks.append(K); l0s.append(A)
            if i + 1 < n and j + 1 < n:
                d = math.sqrt(2.0) * A
                pairs.append((slot[(i, j)], slot[(i + 1, j + 1)])); ks.append(KD); l0s.append(d)
                pairs.append((slot[(i + 1, j)], slot[(i, j + 1)])); ks.append(KD); l0s.append(d)
    pairs = np.array(pairs)
    return free, rest, pairs[:, 0], pairs[:, 1], np.array(ks), np.array(l0s)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("n", type=int)
    ap.add_argument("--t-end", type=float, default=8.0)
    ap.add_argument("--points", type=int, default=201)
    ap.add_argument("--method", default="DOP853", help="solve_ivp's method (DOP853 or RK45)")
    ap.add_argument("--out", help="write the table (t and every state) as CSV here")
    ap.add_argument("--final-json", help="write the final state, named as pdyn names it")
    args = ap.parse_args()
    start = time.perf_counter()

    free, rest, ia, ib, ks, l0s = build(args.n)
    nf = len(free)
    positions = rest.copy()  # pinned rows stay at rest
    gravity = np.array([0.0, 0.0, -G])

    def fun(_t, y):
        positions[:nf] = y[: 3 * nf].reshape(nf, 3)
        v = y[3 * nf :].reshape(nf, 3)
        d = positions[ib] - positions[ia]
        length = np.sqrt(np.einsum("ij,ij->i", d, d))
        f = (ks * (length - l0s) / length)[:, None] * d  # force on end a
        force = np.zeros_like(positions)
        np.add.at(force, ia, f)
        np.add.at(force, ib, -f)
        acc = force[:nf] / M + gravity - (C / M) * v
        return np.concatenate([y[3 * nf :], acc.ravel()])

    y0 = np.concatenate([rest[:nf].ravel(), np.zeros(3 * nf)])
    t_eval = np.linspace(0.0, args.t_end, args.points)
    sol = solve_ivp(fun, (0.0, args.t_end), y0, method=args.method, rtol=1e-6, atol=1e-9, t_eval=t_eval)
    if not sol.success:
        raise SystemExit(sol.message)
    if args.out:
        np.savetxt(args.out, np.column_stack([sol.t, sol.y.T]), delimiter=",", fmt="%.17g")
    if args.final_json:
        final = {}
        for s, (i, j) in enumerate(free):
            for axis, name in enumerate("xyz"):
                final[f"{name}[{i},{j}]"] = sol.y[3 * s + axis, -1]
                final[f"{name}[{i},{j}]'"] = sol.y[3 * nf + 3 * s + axis, -1]
        with open(args.final_json, "w") as f:
            json.dump(final, f)
    print(json.dumps({"nfev": int(sol.nfev), "steps": int(sol.t.size), "seconds_in_script": time.perf_counter() - start}))


if __name__ == "__main__":
    main()
