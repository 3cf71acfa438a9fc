#!/usr/bin/env bash
# Regenerates the plots of the README gallery into examples/gallery/ (PNG only).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build -q -p pdyn-cli
PDYN=target/debug/pdyn
out=$(mktemp -d)
run() { # name model [args...]
  local name=$1 model=$2; shift 2
  "$PDYN" run "examples/$model.toml" --out "$out/$name" --plot "$@" > /dev/null 2>&1 || true
  mkdir -p "examples/gallery/$name"
  cp "$out/$name"/*.png "examples/gallery/$name/"
}
run projectile_drag projectile_drag
run satellite_ode45 satellite_ode45
run satellite satellite
run satellite_symplectic satellite --method symplectic --dt 0.1 --t-end 1000
run building_omega9 building
run building_omega_resonance building --set omega=8.74
run suspension suspension
run rotating_rod_block rotating_rod_block
run kremlin_stone kremlin_stone
run nanoparticle nanoparticle
run pendulum_chain_3 pendulum_chain_3
"$PDYN" sweep examples/building.toml --out "$out/building_sweep" --plot > /dev/null
mkdir -p examples/gallery/building_sweep
cp "$out/building_sweep"/*.png examples/gallery/building_sweep/
rm -rf "$out"
du -sh examples/gallery
