# Whole-process A/B of two pdyn binaries on a few examples (medians of 5 alternating runs):
#   python3 bench/libm_ab.py OLD_BINARY NEW_BINARY
# Used for the libm change (docs/benchmarks.md, "One libm for every target").
import subprocess, time, statistics, sys
cases = [
  ["run","examples/pendulum_chain_3.toml","--t-end","10"],
  ["run","examples/satellite.toml"],
  ["run","examples/projectile_drag.toml","--rtol","1e-9"],
  ["run","examples/md/lj_formula.toml","--set","n=5"],
  ["run","examples/nbody/outer_solar_system.toml","--t-end","3652500"],
]
for c in cases:
    ts = {"old": [], "new": []}
    for r in range(5):
        for name, b in (("old",sys.argv[1]),("new",sys.argv[2])):
            t=time.perf_counter(); subprocess.run([b]+c, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL); ts[name].append(time.perf_counter()-t)
    o, n = statistics.median(ts["old"]), statistics.median(ts["new"])
    print(f"{' '.join(c[1:]):60s} glibc {o*1e3:8.1f} ms   libm {n*1e3:8.1f} ms   ratio {n/o:.2f}")
