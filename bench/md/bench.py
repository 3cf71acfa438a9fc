"""pdyn-md vs LAMMPS on bench/in.lj, both codes alternated in one invocation.

usage (from the repository root; run.sh makes the venv, builds, then calls this):
  python bench/md/bench.py OUT.md STEPS... [--repeat R] [--pdyn target/release/pdyn]
  python bench/md/bench.py OUT.md --formula-only --pdyn target/release/pdyn  (no LAMMPS)

For every repetition and step count it runs, one after the other: LAMMPS serial (lj/cut),
pdyn-md 1 thread (in.lj's `every 20 check no`), LAMMPS lj/cut/omp with 1 and 2 threads,
pdyn-md 2 threads, pdyn-md 1 thread with its exact rebuild test. Alternating keeps both codes
under the same load on a shared machine. Each run reports its loop wall time and its CPU
time: LAMMPS's "Loop time" times its "% CPU use" (both from its log), pdyn-md's threads'
CPU time over the loop. On a loaded machine the CPU time measures the work; the wall time
also counts the waits for a core. With --pdyn, the pdyn CLI runs examples/md/lj_liquid.toml
(built-in kernel) and lj_formula.toml (the formula path), alternated, for the formula ratio.
"""
import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
run_dir = os.path.join(here, "run")
py = sys.executable
lj_bench = os.path.join(root, "target", "release", "examples", "lj_bench")
N = 32000


def lammps(steps, threads):
    log = os.path.join(run_dir, f"log.lj.{steps}.{threads}")
    env = dict(os.environ, OMP_NUM_THREADS="1")
    out = subprocess.run([py, os.path.join(here, "run_lammps.py"), str(steps), str(threads), log],
                         cwd=run_dir, env=env, check=True, capture_output=True, text=True).stdout
    loop, wall, temp, etot, press = out.strip().split(",")
    text = open(log).read()
    m = re.search(r"([0-9.]+)% CPU use with", text)
    cpu = float(loop) * float(m.group(1)) / 100 if m else float("nan")
    return dict(loop=float(loop), total=float(wall), cpu=cpu, T=temp, E=etot, P=press, builds="")


def pdyn_md(steps, threads, every):
    out = subprocess.run([lj_bench, "20", str(steps), str(threads), str(every)], check=True,
                         capture_output=True, text=True).stdout.strip().split(",")
    n, st, th, setup, loop, rate, prate, builds, temp, epa, press, cpu = out
    return dict(loop=float(loop), total=float(setup) + float(loop), cpu=float(cpu),
                pairs=float(prate) / threads, T=temp, E=f"{float(epa):.5f}", P=press,
                builds=builds)


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def pdyn_cli(exe, model, threads):
    c0 = child_cpu()
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    # n = 20: the in.lj size (32,000 atoms) for both models, whatever their defaults.
    out = subprocess.run([exe, "run", os.path.join(root, "examples", "md", model), "--json",
                          "--set", "n=20"],
                         check=True, capture_output=True, text=True, env=env).stdout
    s = json.loads(out)
    return dict(loop=s["loop_seconds"], cpu=child_cpu() - c0, E=s["final"]["total"] / s["atoms"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("steps", nargs="*", type=int)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--pdyn", default=None)
    ap.add_argument("--formula-repeat", type=int, default=3)
    ap.add_argument("--formula-only", action="store_true",
                    help="only the formula-vs-built-in comparison (needs --pdyn; no LAMMPS)")
    a = ap.parse_args()
    if a.formula_only:
        a.steps = []
    elif not a.steps:
        ap.error("give STEPS, or --formula-only")
    load0 = open("/proc/loadavg").read().split()[:3]
    uptime0 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    configs = [
        ("LAMMPS lj/cut (serial)", 1, lambda s: lammps(s, 0)),
        ("pdyn-md, every 20 check no", 1, lambda s: pdyn_md(s, 1, 20)),
        ("LAMMPS lj/cut/omp", 1, lambda s: lammps(s, 1)),
        ("LAMMPS lj/cut/omp", 2, lambda s: lammps(s, 2)),
        ("pdyn-md, every 20 check no", 2, lambda s: pdyn_md(s, 2, 20)),
        ("pdyn-md, exact check every step", 1, lambda s: pdyn_md(s, 1, 1)),
    ]
    results = {}  # (config index, steps) -> list of runs
    for rep in range(a.repeat):
        for steps in a.steps:
            for k, (label, cores, f) in enumerate(configs):
                r = f(steps)
                results.setdefault((k, steps), []).append(r)
                print(f"rep {rep} steps {steps} {label} x{cores}: loop {r['loop']:.3f} s, "
                      f"cpu {r['cpu']:.3f} s", file=sys.stderr, flush=True)
    formula = []
    if a.pdyn:
        for rep in range(a.formula_repeat):
            b = pdyn_cli(a.pdyn, "lj_liquid.toml", 1)
            f = pdyn_cli(a.pdyn, "lj_formula.toml", 1)
            formula.append((b, f))
            print(f"formula rep {rep}: built-in {b['loop']:.3f} s (cpu {b['cpu']:.3f}), "
                  f"formula {f['loop']:.3f} s (cpu {f['cpu']:.3f})", file=sys.stderr, flush=True)
    load1 = open("/proc/loadavg").read().split()[:3]
    uptime1 = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()

    med = lambda xs: statistics.median(xs)
    rows = []
    for steps in a.steps:
        for k, (label, cores, _) in enumerate(configs):
            rs = results[(k, steps)]
            loop, cpu, tot = med([r["loop"] for r in rs]), med([r["cpu"] for r in rs]), med([r["total"] for r in rs])
            last = rs[-1]
            pairs = f"{med([r['pairs'] for r in rs]):.3g}" if "pairs" in last else ""
            rows.append(f"| {label} | {cores} | {steps} | {loop:.3f} | {cpu:.3f} | {tot:.3f} | "
                        f"{N * steps / loop:.3g} | {N * steps / cpu:.3g} | {last['builds']} | {pairs} | "
                        f"{last['T']} | {last['E']} | {last['P']} |")
    ratio_rows = []
    for steps in a.steps:
        for rep in range(a.repeat):
            g = lambda k: results[(k, steps)][rep]
            p1, p2, px = g(1), g(4), g(5)
            ls, lo1, lo2 = g(0), g(2), g(3)
            ratio_rows.append(
                f"| {steps} | {rep + 1} | {ls['loop'] / p1['loop']:.2f} | {ls['cpu'] / p1['cpu']:.2f} | "
                f"{lo1['loop'] / p1['loop']:.2f} | {lo1['cpu'] / p1['cpu']:.2f} | "
                f"{ls['loop'] / px['loop']:.2f} | {ls['cpu'] / px['cpu']:.2f} | "
                f"{lo2['loop'] / p2['loop']:.2f} |")
    f_rows = []
    for k, (b, f) in enumerate(formula):
        f_rows.append(f"| {k + 1} | {b['loop']:.3f} | {f['loop']:.3f} | {f['loop'] / b['loop']:.2f} | "
                      f"{b['cpu']:.3f} | {f['cpu']:.3f} | {f['cpu'] / b['cpu']:.2f} | "
                      f"{abs(f['E'] - b['E']) / abs(b['E']):.1e} |")
    if formula:
        best = lambda key, i: min(pair[i][key] for pair in formula)
        steps_atoms = 100 * N  # both models: 100 steps of 32,000 atoms
        f_rows.append(
            f"| min | {best('loop', 0):.3f} | {best('loop', 1):.3f} | "
            f"{best('loop', 1) / best('loop', 0):.2f} | {best('cpu', 0):.3f} | {best('cpu', 1):.3f} | "
            f"{best('cpu', 1) / best('cpu', 0):.2f} | |\n\nAtom-steps/s from the minima: built-in "
            f"{steps_atoms / best('loop', 0):.3g} (loop wall), {steps_atoms / best('cpu', 0):.3g} "
            f"(process CPU); formula {steps_atoms / best('loop', 1):.3g} (loop wall), "
            f"{steps_atoms / best('cpu', 1):.3g} (process CPU).")
    with open(a.out, "w") as fh:
        if a.formula_only:
            fh.write(f"`uptime` before: `{uptime0}`; after: `{uptime1}`.\n\n")
            fh.write(FORMULA_HEAD + "\n".join(f_rows) + "\n")
            print(f"wrote {a.out}", file=sys.stderr)
            return
        fh.write(TEMPLATE_HEAD.format(load0=" ".join(load0), load1=" ".join(load1),
                                      uptime0=uptime0, uptime1=uptime1,
                                      steps=" ".join(map(str, a.steps)), repeat=a.repeat))
        fh.write("\n".join(rows) + "\n\n")
        fh.write(RATIO_HEAD + "\n".join(ratio_rows) + "\n\n")
        if f_rows:
            fh.write(FORMULA_HEAD + "\n".join(f_rows) + "\n\n")
    print(f"wrote {a.out}", file=sys.stderr)


TEMPLATE_HEAD = """Both codes alternated in one invocation (steps: {steps}; repetitions: {repeat}).
`uptime` before: `{uptime0}`; after: `{uptime1}`.

| code | threads | steps | loop s | loop CPU s | total s | atom-steps/s (wall) | atom-steps/s (CPU) | builds | pairs/s/thread | T | E/N | P |
|---|---|---|---|---|---|---|---|---|---|---|---|---|
"""

RATIO_HEAD = """Throughput of pdyn-md relative to LAMMPS, run by run (LAMMPS time / pdyn-md time: > 1 means
pdyn-md is faster). "wall" compares loop times, "CPU" the CPU time each loop used (robust to the
load of other jobs).

| steps | run | 1 core vs lj/cut serial, wall | CPU | vs lj/cut/omp 1 thread, wall | CPU | pdyn-md exact check vs lj/cut serial, wall | CPU | 2 threads vs lj/cut/omp 2 threads, wall |
|---|---|---|---|---|---|---|---|---|
"""

FORMULA_HEAD = """Formula path vs built-in kernel (`pdyn run examples/md/lj_liquid.toml --json --set n=20`
vs `lj_formula.toml --json --set n=20`, 32,000 atoms, 100 steps, exact rebuild test, `RAYON_NUM_THREADS=1`,
alternated; CPU time of the whole process including set-up and JIT compilation):

| run | built-in loop s | formula loop s | ratio (wall) | built-in CPU s | formula CPU s | ratio (CPU) | |ΔE/N| relative |
|---|---|---|---|---|---|---|---|
"""

if __name__ == "__main__":
    main()
