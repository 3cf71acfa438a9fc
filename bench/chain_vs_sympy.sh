#!/usr/bin/env bash
# `pdyn derive` vs SymPy KanesMethod on the n-link pendulum chain, in one run.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo bench -p pdyn-mech --bench chain
python3 bench/sympy_chain.py 2 4 8 16
