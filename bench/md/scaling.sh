#!/usr/bin/env bash
# pdyn-md scaling with N on the in.lj system (fcc ρ* = 0.8442, T* = 1.44, LJ 2.5σ, skin 0.3σ,
# rebuild every 20 steps): time per atom-step (wall and CPU of the loop, 1 thread) and peak
# memory per atom, from 864 to 1,000,188 atoms. Prints a Markdown table.
#   bash bench/md/scaling.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release -q -p pdyn-md --example lj_bench
bin=target/release/examples/lj_bench
echo "\`uptime\`: $(uptime)"
echo
echo "| atoms | steps | loop s | µs per atom-step (wall) | µs per atom-step (CPU) | peak RSS | bytes per atom |"
echo "|---|---|---|---|---|---|---|"
for spec in "6 200" "10 100" "16 50" "25 20" "40 10" "63 5"; do
    set -- $spec
    out=$( { /usr/bin/time -f "%M" "$bin" "$1" "$2" 1 20; } 2>&1 )
    csv=$(echo "$out" | grep ',' | tail -1)
    rss_kb=$(echo "$out" | grep -v ',' | tail -1)
    IFS=, read -r n steps threads setup loop rate pairs builds t e p cpu <<<"$csv"
    python3 - "$n" "$steps" "$loop" "$cpu" "$rss_kb" <<'PY'
import sys
n, steps, loop, cpu, rss = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
per = n * steps
print(f"| {n:,} | {steps} | {loop:.3f} | {loop / per * 1e6:.3f} | {cpu / per * 1e6:.3f} | {rss / 1024:.1f} MiB | {rss * 1024 / n:.0f} |")
PY
done
