#!/usr/bin/env bash
# Sweep throughput with --settle auto against --settle fixed on the paper's chatter diagram
# (Fig. 20 as `reproduce --quick` computes it: configs/chatter.toml, Ω from 0.3 to 1.0 in
# 201 values from rest, 300 transient and 128 recorded periods, with the harvester), on all
# cores, RUNS times each (default 3), alternating; prints each time, the medians, their
# ratio and how the auto run classified the values. Usage: bench/settle.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=bench/timing.sh
. bench/timing.sh
runs=${1:-3}
cargo build --release -q -p vibrotribo-cli
out=target/bench-settle
rm -rf "$out"
mkdir -p "$out"
sweep() {
    local mode=$1 dir=$2
    local start end
    start=$(date +%s.%N)
    "${CARGO_TARGET_DIR:-target}"/release/vibrotribo sweep configs/chatter.toml --param omega_ratio --from 0.3 --to 1.0 \
        --steps 201 --transient 300 --recorded 128 --settle "$mode" --out "$dir" --quiet >/dev/null
    end=$(date +%s.%N)
    echo "$end - $start" | bc
}
auto=()
fixed=()
for i in $(seq 1 "$runs"); do
    fixed+=("$(sweep fixed "$out/fixed-$i")")
    auto+=("$(sweep auto "$out/auto-$i")")
done
ma=$(median "${auto[@]}")
mf=$(median "${fixed[@]}")
echo "fixed: ${fixed[*]} s, median $mf s"
echo "auto:  ${auto[*]} s, median $ma s"
echo "ratio auto/fixed: $(echo "scale=3; $ma / $mf" | bc)"
for mode in fixed auto; do
    echo -n "$mode motions: "
    python3 - "$out/$mode-1/summary.csv" <<'PY'
import csv, sys
from collections import Counter
rows = list(csv.DictReader(open(sys.argv[1])))
print(dict(Counter(r["motion"] for r in rows)), "non-periodic (period 0):", sum(r["period"] == "0" for r in rows))
PY
done
