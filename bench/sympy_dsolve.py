#!/usr/bin/env python3
"""`pdyn dsolve` vs SymPy's `dsolve` on the same inputs, in one run.

Runs the Rust bench (`cargo bench -p pdyn-mech --bench dsolve`, release build), then SymPy's
`dsolve` on each case in a child process with a time limit, checks SymPy's answer against
pdyn's at t = 1.3 (same parameter values), and prints a table with the time ratio.
A SymPy case "fails" when it raises, returns no solution, times out, or disagrees.
Installs sympy from PyPI if it is missing.

Usage: python3 bench/sympy_dsolve.py [--timeout SECONDS] [--skip-cargo FILE]
"""
import json
import multiprocessing as mp
import os
import subprocess
import sys
import time

try:
    import sympy as sp
except ImportError:  # pragma: no cover
    subprocess.check_call([sys.executable, "-m", "pip", "install", "--quiet", "sympy"])
    import sympy as sp

PARAMS = dict(m=2.0, k=50.0, L0=0.4, g=9.81, L=0.3, mu=0.3, omega=2.0, V=1.5,
              alpha=0.7853981633974483, h=71.0, zeta=0.3, wn=3.0, x0=0.5, v0=-1.0)


def build(name):
    """(equations, functions, ics) for SymPy, same as crates/pdyn-mech/benches/dsolve.rs."""
    t = sp.Symbol("t")
    pos = dict(positive=True)
    m, k, g, mu, omega, zeta, wn = sp.symbols("m k g mu omega zeta wn", **pos)
    L0, L, V, alpha, h, x0, v0 = sp.symbols("L0 L V alpha h x0 v0")
    R = sp.Rational
    if name == "chain6":
        q = [sp.Function(f"q{i}")(t) for i in range(1, 7)]
        eqs = []
        for i in range(6):
            left = -100 * q[0] if i == 0 else -100 * (q[i] - q[i - 1])
            right = 0 if i == 5 else -100 * (q[i] - q[i + 1])
            eqs.append(sp.Eq((i + 1) * q[i].diff(t, 2), left + right))
        ics = {}
        for i in range(6):
            ics[q[i].subs(t, 0)] = R(1, 10) if i == 0 else 0
            ics[q[i].diff(t).subs(t, 0)] = 0
        return eqs, q, ics
    x = sp.Function("x")(t)
    y = sp.Function("y")(t)
    r = sp.Function("r")(t)
    d = lambda f, n=1: f.diff(t, n)
    at0 = lambda e: e.subs(t, 0)
    if name == "suspension":
        return [sp.Eq(m * d(x, 2), -k * (x - L0) - m * g)], [x], {at0(x): L, at0(d(x)): 0}
    if name == "rotating_rod":
        return [sp.Eq(d(r, 2) + 2 * mu * omega * d(r) - omega**2 * r, 0)], [r], {at0(r): 0, at0(d(r)): V}
    if name == "projectile":
        return ([sp.Eq(d(x, 2), 0), sp.Eq(d(y, 2), -g)], [x, y],
                {at0(x): 0, at0(d(x)): V * sp.cos(alpha), at0(y): h, at0(d(y)): V * sp.sin(alpha)})
    if name == "damped_symbolic":
        return [sp.Eq(d(x, 2) + 2 * zeta * wn * d(x) + wn**2 * x, 0)], [x], {at0(x): x0, at0(d(x)): v0}
    if name == "damped_under":
        return [sp.Eq(d(x, 2) + R(6, 10) * d(x) + 9 * x, 0)], [x], {at0(x): 1, at0(d(x)): 0}
    if name == "damped_critical":
        return [sp.Eq(d(x, 2) + 6 * d(x) + 9 * x, 0)], [x], {at0(x): 1, at0(d(x)): 0}
    if name == "damped_over":
        return [sp.Eq(d(x, 2) + 12 * d(x) + 9 * x, 0)], [x], {at0(x): 1, at0(d(x)): 0}
    if name == "resonance":
        return [sp.Eq(d(x, 2) + 4 * x, sp.sin(2 * t))], [x], {at0(x): 0, at0(d(x)): 0}
    if name == "building2":
        x1 = sp.Function("x1")(t)
        x2 = sp.Function("x2")(t)
        eqs = [sp.Eq(2000 * d(x1, 2), -400000 * (x1 - sp.sin(5 * t) / 100) - 300000 * (x1 - x2) - 800 * d(x1)),
               sp.Eq(1500 * d(x2, 2), -300000 * (x2 - x1))]
        return eqs, [x1, x2], {at0(x1): R(1, 50), at0(d(x1)): 0, at0(x2): 0, at0(d(x2)): R(1, 10)}
    raise KeyError(name)


def run_sympy(name, queue):
    eqs, funcs, ics = build(name)
    t0 = time.perf_counter()
    try:
        if len(funcs) == 1:
            sol = [sp.dsolve(eqs[0], funcs[0], ics=ics)]
        else:
            sol = sp.dsolve(eqs, funcs, ics=ics)
        dt = time.perf_counter() - t0
        subs = {sp.Symbol(k, positive=True): v for k, v in PARAMS.items()}
        subs.update({sp.Symbol(k): v for k, v in PARAMS.items()})
        subs[sp.Symbol("t")] = 1.3
        by_func = {s.lhs: s.rhs for s in sol}
        vals = [complex(sp.N(by_func[f].subs(subs))) for f in funcs]
        queue.put(("ok", dt, [v.real if abs(v.imag) < 1e-9 * (1 + abs(v.real)) else None for v in vals]))
    except Exception as e:  # SymPy raised: a failure to report
        queue.put(("error", time.perf_counter() - t0, f"{type(e).__name__}: {e}"[:120]))


def sympy_case(name, timeout):
    queue = mp.Queue()
    p = mp.Process(target=run_sympy, args=(name, queue))
    p.start()
    p.join(timeout)
    if p.is_alive():
        p.terminate()
        p.join()
        return ("timeout", timeout, None)
    return queue.get() if not queue.empty() else ("error", 0.0, "no result")


def main():
    args = sys.argv[1:]
    timeout = 120.0
    if "--timeout" in args:
        timeout = float(args[args.index("--timeout") + 1])
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    if "--skip-cargo" in args:
        lines = open(args[args.index("--skip-cargo") + 1]).read().splitlines()
    else:
        out = subprocess.run(["cargo", "bench", "-q", "-p", "pdyn-mech", "--bench", "dsolve"],
                             cwd=root, check=True, capture_output=True, text=True).stdout
        lines = out.splitlines()
    ours = [json.loads(l) for l in lines if l.startswith("{")]
    print(f"sympy {sp.__version__}, timeout {timeout:.0f} s per case")
    print(f"{'case':<18}{'pdyn':>12}{'sympy':>12}{'ratio':>10}  sympy status")
    for c in ours:
        status, secs, vals = sympy_case(c["case"], timeout)
        if status == "ok":
            agree = vals is not None and all(
                v is not None and abs(v - w) <= 1e-6 * (1 + abs(w)) for v, w in zip(vals, c["values"]))
            note = "ok" if agree else f"WRONG: {vals} vs pdyn {c['values']}"
        elif status == "timeout":
            note = f"no answer within {timeout:.0f} s"
        else:
            note = f"failed ({vals})"
        ratio = secs / c["seconds"]
        more = ">" if status == "timeout" else ""
        print(f"{c['case']:<18}{c['seconds']*1e3:>10.3f}ms{secs:>11.3f}s{more:>2}{ratio:>8.0f}x  {note}")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
