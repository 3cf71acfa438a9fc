#!/usr/bin/env bash
# Every test of the repository: the Rust workspace, then the Python package in a fresh venv.
#
#   scripts/test-all.sh            # cargo test --workspace, then pytest
#   SKIP_CARGO=1 scripts/test-all.sh   # only the Python part
#
# The venv lives in target/venv-test (ignored with target/); pip needs PyPI for maturin,
# pytest, numpy (and scipy, pandas, sympy, dask.distributed, pyarrow, which some tests use
# and skip without; nbclient, ipykernel and matplotlib run the notebooks).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

if [ -z "${SKIP_CARGO:-}" ]; then
    cargo test --workspace
fi
# The CLI-comparison tests run the binary: the one `cargo test --workspace` builds. (`cargo
# build -p pdyn-cli` would unify the dependencies' features over pdyn-cli alone and rebuild
# many of them and every pdyn crate a second time: minutes of CI.)
cargo test --workspace --no-run --quiet

venv="$root/target/venv-test"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --upgrade maturin pytest numpy scipy pandas sympy \
    "dask[distributed]" pyarrow tqdm xarray nbclient nbformat ipykernel matplotlib
# A debug build of the extension, installed into the venv.
(cd crates/pdyn-py && VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" "$venv/bin/maturin" develop --quiet)

set +e
# The package's tests; test_notebooks.py executes the notebooks of examples/notebooks in a
# kernel (nbclient) and counts the figures each shows.
PDYN_BIN="$root/target/debug/pdyn" "$venv/bin/python" -m pytest -q crates/pdyn-py/tests
code=$?
set -e
if [ "$code" -eq 5 ]; then
    echo "error: pytest collected no tests" >&2
    exit 1
fi
exit "$code"
