#!/usr/bin/env python3
"""Whole-process set-up time and peak memory of `pdyn run NET.toml --t-end 0.001` on the
hanging net of issue 33 (n x n nodes, two pinned: 23, 98, 194, 398, 2,498, 9,998 particles),
as a Markdown table for docs/benchmarks.md.

    python3 bench/net/net_times.py target/release/pdyn            # the net written out
    python3 bench/net/net_times.py target/release/pdyn --family   # examples/hanging_net.toml
    python3 bench/net/net_times.py OLD_PDYN --legacy              # plain names, older pdyn
    python3 bench/net/net_times.py target/release/pdyn --family --sizes 20 --t-end 8  # a run

Each size is run `--repeat` times (default 3) and the fastest kept (times are wall clock;
with `--t-end` the CPU time, user + system, is shown too); peak memory is the resident set
size that /usr/bin/time reports. A run over `--timeout` seconds (default 600) is stopped and
reported as such.
"""
import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import net_model  # noqa: E402


def measure(pdyn: str, model: Path, t_end: str, timeout: float):
    """(wall seconds, CPU seconds, peak KB), or None when stopped at `timeout`."""
    try:
        out = subprocess.run(
            ["/usr/bin/time", "-f", "%e %U %S %M", pdyn, "run", str(model), "--t-end", t_end],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return None
    if out.returncode != 0:
        raise SystemExit(f"{model}: {out.stderr}")
    seconds, user, system, kb = out.stderr.strip().splitlines()[-1].split()
    return float(seconds), float(user) + float(system), int(kb)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("pdyn")
    ap.add_argument("--family", action="store_true")
    ap.add_argument("--legacy", action="store_true")
    ap.add_argument("--sizes", default="5,10,14,20,50,100")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--t-end", default="0.001", help="0.001: set-up alone")
    ap.add_argument("--timeout", type=float, default=600)
    args = ap.parse_args()
    kind = "family" if args.family else "legacy" if args.legacy else "explicit"
    make = getattr(net_model, kind)
    print("| particles | time | CPU | peak memory |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in map(int, args.sizes.split(",")):
            model = Path(tmp) / f"net{n}.toml"
            model.write_text(make(n))
            runs = []
            for _ in range(args.repeat):
                r = measure(args.pdyn, model, args.t_end, args.timeout)
                if r is None:
                    break
                runs.append(r)
            if not runs:
                print(f"| {n * n - 2} | stopped after {args.timeout:.0f} s | | |", flush=True)
                continue
            seconds = min(r[0] for r in runs)
            cpu = min(r[1] for r in runs)
            mb = min(r[2] for r in runs) / 1024
            print(f"| {n * n - 2} | {seconds:.2f} s | {cpu:.2f} s | {mb:.0f} MB |", flush=True)


if __name__ == "__main__":
    main()
