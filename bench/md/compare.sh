#!/usr/bin/env bash
# Same-initial-state trajectory comparison pdyn-md vs LAMMPS (4,000 LJ atoms, 100 steps).
# Run from the repository root after bench/md/run.sh has made the venv:  bash bench/md/compare.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
export LD_LIBRARY_PATH="$here/.venv/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
mkdir -p "$here/run/cmp"
for steps in ${STEPS:-100}; do
  (cd "$root" && cargo run --release -q -p pdyn-md --example lammps_compare -- "$here/run/cmp" 10 "$steps")
  OMP_NUM_THREADS=1 "$here/.venv/bin/python" "$here/compare_lammps.py" "$here/run/cmp" "$steps"
done
