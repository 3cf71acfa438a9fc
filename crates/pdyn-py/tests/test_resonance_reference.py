"""The 60-digit references of crates/pdyn/tests/resonance/ come from their script: regenerated
here and compared byte for byte, so the Rust test's expected values are reproducible."""
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
DIR = ROOT / "crates" / "pdyn" / "tests" / "resonance"


def test_resonance_references_regenerate_identically(tmp_path):
    pytest.importorskip("mpmath")
    subprocess.run([sys.executable, str(DIR / "reference.py"), str(tmp_path)], check=True)
    for name in ("building.csv", "overdamped.csv"):
        assert (tmp_path / name).read_bytes() == (DIR / name).read_bytes(), name
