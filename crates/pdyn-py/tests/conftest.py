import os
import pathlib

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
        pytest.skip("the pdyn binary is not built (cargo build -p pdyn)")
    return p
