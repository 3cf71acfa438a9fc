#!/usr/bin/env bash
# Runs every peer in one go: pdyn-ode and ode_solvers (Rust, release build), SciPy solve_ivp,
# scipy.integrate.ode('dop853') (Hairer's Fortran) and REBOUND (Python).
# Needs: cargo; python3 with scipy, numpy, rebound (pip install scipy rebound).
set -euo pipefail
cd "$(dirname "$0")"
echo "problem,impl,method,tol,error,fevals,seconds"
cargo run --release -q
python3 scipy_peers.py
