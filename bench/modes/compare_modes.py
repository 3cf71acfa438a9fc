#!/usr/bin/env python3
"""How far apart two `pdyn modes --json` outputs of one model are.

    python3 bench/modes/compare_modes.py BEFORE.json AFTER.json

Prints whether the files are byte-identical and, per quantity, the largest difference:
frequencies (omega, relative), shapes (absolute, against their largest component, which
`modes::unit_largest` scales to 1), damped roots (relative to |s|). Exits 1 when the mode
counts or coordinates differ.
"""
import json
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    raw = [open(p, "rb").read() for p in sys.argv[1:]]
    a, b = (json.loads(r) for r in raw)
    print(f"byte-identical: {raw[0] == raw[1]}")
    if a["coordinates"] != b["coordinates"] or len(a["modes"]) != len(b["modes"]):
        print("different coordinates or mode counts")
        sys.exit(1)
    freq = shape = 0.0
    for ma, mb in zip(a["modes"], b["modes"]):
        wa, wb = ma["omega_squared"], mb["omega_squared"]
        freq = max(freq, abs(wa - wb) / max(abs(wa), abs(wb), 1e-300))
        sa, sb = ma["shape"], mb["shape"]
        shape = max(shape, max(abs(x - y) for x, y in zip(sa, sb)))
    print(f"modes {len(a['modes'])}: max relative difference of omega^2 {freq:.2e}, "
          f"of shapes (unit largest component) {shape:.2e}")
    da, db = a.get("damped_modes") or [], b.get("damped_modes") or []
    if da or db:
        if len(da) != len(db):
            print(f"damped modes: {len(da)} vs {len(db)}")
            sys.exit(1)
        worst = 0.0
        for x, y in zip(da, db):
            ra, rb = complex(*x["eigenvalue"]), complex(*y["eigenvalue"])
            worst = max(worst, abs(ra - rb) / max(abs(ra), abs(rb), 1e-300))
        print(f"damped modes {len(da)}: max relative difference of the roots {worst:.2e}")


if __name__ == "__main__":
    main()
