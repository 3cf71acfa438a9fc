#!/usr/bin/env python3
"""pdyn-gravity's WHFast against REBOUND's on the same initial conditions (issue 14: positions
after 1,000 years agree to 1e-8 relative).

Usage (from the repository root):

    python3 bench/nbody/agreement.py

Uses run.py's venv (REBOUND 5.2.2 from PyPI), its outer Solar System and its WHFast settings
(dt = P_Jupiter/20, corrector 17, safe_mode off). No timing, so pdyn's `bench_nbody` example is
built in the dev profile. Prints, per body, |r_pdyn − r_REBOUND| / |r_REBOUND| after 1, 10, 100
and 1000 years: none of these is a multiple of dt, so both codes end on a shortened step, which
both correct like a full one (with an uncorrected shortened step pdyn differed by 4e-7 after
1 year). The difference left is round-off, growing with the number of steps.
"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run  # noqa: E402  (re-executes this script in run.py's venv, with REBOUND)

BIN = os.path.join(run.ROOT, "target", "debug", "examples", "bench_nbody")
NAMES = ["Sun", "Jupiter", "Saturn", "Uranus", "Neptune"]


def main():
    subprocess.check_call(["cargo", "build", "-q", "-p", "pdyn-gravity", "--example",
                           "bench_nbody"], cwd=run.ROOT)
    print(f"REBOUND {run.rebound.__version__}; relative position difference, pdyn vs REBOUND WHFast")
    print("| years | " + " | ".join(NAMES) + " | max |")
    print("|---:|" + "---:|" * (len(NAMES) + 1))
    for years in (1, 10, 100, 1000):
        rel = run.position_agreement(BIN, years)
        print(f"| {years} | " + " | ".join(f"{r:.1e}" for r in rel) + f" | {max(rel):.1e} |")


if __name__ == "__main__":
    main()
