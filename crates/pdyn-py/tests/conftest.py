import os
import pathlib
import threading
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture
def examples():
    return ROOT / "examples"


@pytest.fixture
def pdyn_bin():
    """The pdyn binary (PDYN_BIN, or target/debug/pdyn when built), or skip."""
    p = os.environ.get("PDYN_BIN") or str(ROOT / "target" / "debug" / "pdyn")
    if not os.path.exists(p):
        pytest.skip("the pdyn binary is not built (cargo build -p pdyn-cli)")
    return p


@pytest.fixture
def gil_probe():
    """`probe(call, runs)` runs `call(runs)` while a Python thread ticks every millisecond,
    doubling `runs` until the call lasts 0.2 s (on a fast idle machine as on a loaded one), and
    returns `(result, runs, seconds, ticks during the call)`. Had the call held the GIL, the
    ticker could not have ticked."""

    def once(call, runs):
        ticks = []
        stop = threading.Event()

        def ticker():
            while not stop.is_set():
                ticks.append(time.perf_counter())
                time.sleep(0.001)

        th = threading.Thread(target=ticker)
        th.start()
        t0 = time.perf_counter()
        result = call(runs)
        t1 = time.perf_counter()
        stop.set()
        th.join()
        return result, t1 - t0, len([t for t in ticks if t0 < t < t1])

    def probe(call, runs):
        limit = runs * 2**8
        result, seconds, ticks = once(call, runs)
        while seconds < 0.2 and runs < limit:
            runs *= 2
            result, seconds, ticks = once(call, runs)
        return result, runs, seconds, ticks

    return probe
