#!/usr/bin/env bash
# Continuation cost: the paper's default case continued in Ω from 0.7 down to 0.3 (every
# branch: through its grazings and sequence changes, onto doubled branches and both sides of
# its branch points), mechanics only and with the power; and 200-point bifurcation curves in
# two parameters (the default case's fold in (Ω, gap ratio), the impact oscillator's period
# doubling in (Ω, stop gap)). Each command RUNS times (default 3), whole process; prints the
# points, the discontinuity-induced points crossed, and the median wall and CPU seconds.
# Usage: bench/continuation.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=bench/timing.sh
. bench/timing.sh
runs=${1:-3}
cargo build --release -q -p vibrotribo-cli
bin="${CARGO_TARGET_DIR:-target}"/release/vibrotribo
out=target/bench-continuation
rm -rf "$out"
mkdir -p "$out"


# Runs "$@" RUNS times into $out/$name; prints the median wall and CPU (user + system) seconds.
timed() {
    local name=$1
    shift
    local walls=() cpus=()
    for i in $(seq 1 "$runs"); do
        rm -rf "${out:?}/$name"
        /usr/bin/time -f "%e %U %S" -o "$out/$name.time" "$@" --out "$out/$name" >/dev/null 2>&1
        read -r wall user sys <"$out/$name.time"
        walls+=("$wall")
        cpus+=("$(printf "%.2f" "$(echo "$user + $sys" | bc)")")
    done
    echo "$(median "${walls[@]}") $(median "${cpus[@]}")"
}

branch_report() {
    python3 - "$out/$1/continue.json" "$out/$1/bifurcations.csv" <<'PY'
import csv, json, sys
d = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
nonsmooth = ("grazing", "sequence_change", "sticking", "chatter")
b0 = d["branches"][0]
crossed = [r for r in rows if r["branch"] == "0" and r["kind"] in nonsmooth]
total = sum(b["points"] for b in d["branches"])
print(f"branch 0: {b0['points']} points, {len(crossed)} discontinuity-induced points crossed "
      f"({', '.join(sorted({r['kind'] for r in crossed}))}), end: {b0['end']}; "
      f"{len(d['branches'])} branches, {total} points in all")
PY
}

echo "== continue: default case, omega_ratio 0.7 -> 0.3, $runs runs"
for mode in mechanics power; do
    flag=()
    [ "$mode" = mechanics ] && flag=(--mechanics-only)
    read -r wall cpu < <(timed "branch-$mode" "$bin" continue --param omega_ratio --from 0.7 --to 0.3 -q "${flag[@]}")
    echo "$mode: $(branch_report "branch-$mode")"
    echo "$mode: median $wall s wall, $cpu s CPU"
done

echo "== curve: 200 points, $runs runs"
read -r wall cpu < <(timed curve-fold "$bin" curve --kind fold --param omega_ratio --near 0.80085 --period 1 \
    --param2 gap_ratio --from2 1.0 --to2 1.5 --max-points 200 --mechanics-only)
echo "default case, fold in (omega_ratio, gap_ratio): $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['points'], 'points,', d['end'])" "$out/curve-fold/curve.json"); median $wall s wall, $cpu s CPU"
read -r wall cpu < <(timed curve-doubling "$bin" curve configs/impact_oscillator.toml --set oscillator.damping=0.02 \
    --set oscillator.stops.upper.gap=0.001 --kind period_doubling --param omega_ratio --near 2.455 --period 1 \
    --param2 oscillator.stops.upper.gap --from2 0.001 --to2 0.01 --max-points 200 --mechanics-only)
echo "impact oscillator, doubling in (omega_ratio, gap): $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['points'], 'points,', d['end'])" "$out/curve-doubling/curve.json"); median $wall s wall, $cpu s CPU"
