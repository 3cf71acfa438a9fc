"""`Model.ensemble` of the building's sweep (chapter 3.3.3): the whole call's wall time and
the peak memory it adds, in a fresh process per measurement (ru_maxrss only grows).

    target/venv-rel/bin/python bench/python/bench_ensemble.py        # RUNS=1000 REPEAT=3
    POINTS=20001 target/venv-rel/bin/python bench/python/bench_ensemble.py  # denser output

Each repeat is a new interpreter: warm-up ensemble of 4 runs (derive, compile, thread pool),
then ru_maxrss, the timed call, ru_maxrss again. Prints the best time, the smallest peak
increase, and a SHA-256 of every returned column (equal digests: the same bits).
"""
import hashlib
import json
import os
import subprocess
import sys


def one(runs):
    import resource
    import time

    import numpy as np
    import pdyn

    m = pdyn.Model.from_file("examples/building.toml")
    values = np.linspace(2, 30, runs)
    meas = {"top": ("y2 - (2*L - 3*m*g/(2*k))", "max_abs")}
    kw = {"points": int(os.environ["POINTS"])} if os.environ.get("POINTS") else {}
    m.ensemble(params={"omega": values[:4]}, measures=meas, **kw)  # warm-up
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    ens = m.ensemble(params={"omega": values}, measures=meas, **kw)
    secs = time.perf_counter() - t0
    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    h = hashlib.sha256()
    for name, col in sorted(ens.columns().items()):
        h.update(name.encode())
        h.update(np.ascontiguousarray(col).tobytes())
    print(json.dumps({"secs": secs, "peak_kib": rss1, "added_kib": rss1 - rss0,
                      "runs": len(ens), "threads": ens.threads, "digest": h.hexdigest()}))


if __name__ == "__main__":
    runs = int(os.environ.get("RUNS", "1000"))
    if len(sys.argv) > 1 and sys.argv[1] == "--one":
        one(runs)
        sys.exit(0)
    results = []
    for _ in range(int(os.environ.get("REPEAT", "3"))):
        out = subprocess.run([sys.executable, __file__, "--one"], check=True,
                             capture_output=True, text=True).stdout
        results.append(json.loads(out.strip().splitlines()[-1]))
        print(results[-1], flush=True)
    digests = {r["digest"] for r in results}
    best = min(r["secs"] for r in results)
    print(f"Model.ensemble, building, {runs} runs, points={os.environ.get('POINTS', 2001)}: best {best:.3f} s "
          f"({runs / best:.0f} runs/s, {results[0]['threads']} threads); "
          f"peak RSS {min(r['peak_kib'] for r in results) / 1024:.1f} MiB, "
          f"added by the call {min(r['added_kib'] for r in results) / 1024:.1f} MiB; "
          f"digest {results[0]['digest'][:16]} ({'same' if len(digests) == 1 else 'DIFFERENT'} "
          f"in every repeat)")
