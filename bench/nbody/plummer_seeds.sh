#!/usr/bin/env bash
# Mean initial energy (and its spread) of [nbody] Plummer spheres over 24 seeds, softening 0:
# what docs/nbody.md quotes for the sample as drawn (rescale = false: -0.264 at N = 1000) and
# rescaled to Henon units (rescale = true: -1/4 to round-off).
#   bash bench/nbody/plummer_seeds.sh 1000 false      # PDYN=path/to/pdyn to choose the binary
set -euo pipefail
N=${1:?N}; RESCALE=${2:?true|false}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
PDYN=${PDYN:-$ROOT/target/debug/pdyn}
dir=$(mktemp -d)
for seed in $(seq 1 24); do
cat > "$dir/p.toml" <<T
name = "p"
[nbody]
units = "nbody"
plummer = { n = $N, seed = $seed, rescale = $RESCALE }
integrator = "leapfrog"
gravity = "tree"
dt = 0.001
t_end = 0.001
points = 2
T
"$PDYN" run "$dir/p.toml" --out "$dir/out" >/dev/null
python3 -c "import json,sys;print(json.load(open(sys.argv[1]))['energy']['initial'])" "$dir/out/summary.json"
done | python3 -c "import sys,statistics as s;v=[float(x) for x in sys.stdin];print('N=$N rescale=$RESCALE mean E',s.mean(v),'sd',s.stdev(v))"
rm -rf "$dir"
