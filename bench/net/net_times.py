#!/usr/bin/env python3
"""Whole-process set-up time and peak memory of `pdyn run NET.toml --t-end 0.001` on the
hanging net of issue 33 (n x n nodes, two pinned: 23, 98, 194, 398 particles), as a Markdown
table for docs/benchmarks.md.

    python3 bench/net/net_times.py target/release/pdyn            # the net written out
    python3 bench/net/net_times.py target/release/pdyn --family   # examples/hanging_net.toml
    python3 bench/net/net_times.py OLD_PDYN --legacy              # plain names, older pdyn

Each size is run `--repeat` times (default 3) and the fastest kept; peak memory is the
resident set size that /usr/bin/time reports.
"""
import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import net_model  # noqa: E402


def measure(pdyn: str, model: Path) -> tuple[float, int]:
    out = subprocess.run(
        ["/usr/bin/time", "-f", "%e %M", pdyn, "run", str(model), "--t-end", "0.001"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    if out.returncode != 0:
        raise SystemExit(f"{model}: {out.stderr}")
    seconds, kb = out.stderr.strip().splitlines()[-1].split()
    return float(seconds), int(kb)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("pdyn")
    ap.add_argument("--family", action="store_true")
    ap.add_argument("--legacy", action="store_true")
    ap.add_argument("--sizes", default="5,10,14,20")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    kind = "family" if args.family else "legacy" if args.legacy else "explicit"
    make = getattr(net_model, kind)
    print("| particles | set-up time | peak memory |")
    print("|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in map(int, args.sizes.split(",")):
            model = Path(tmp) / f"net{n}.toml"
            model.write_text(make(n))
            runs = [measure(args.pdyn, model) for _ in range(args.repeat)]
            seconds = min(r[0] for r in runs)
            mb = min(r[1] for r in runs) / 1024
            print(f"| {n * n - 2} | {seconds:.2f} s | {mb:.0f} MB |", flush=True)


if __name__ == "__main__":
    main()
