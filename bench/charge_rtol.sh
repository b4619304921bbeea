#!/usr/bin/env bash
# What the charge solver's tolerance (`electrical.rtol`) buys, on the default case with its
# resistor load (or the loads given). For each rtol:
#
#   - the solver's accepted and rejected steps per excitation period (`electrical_solver` in
#     summary.json, over the whole run, transient included);
#   - the whole process's CPU time (user + system), 30 000 periods at one sample a period,
#     files written: the median of RUNS runs, the rtols alternated run by run so that a
#     machine whose speed drifts moves them alike; and its ratio to the first rtol's (and,
#     alternated with them, the same run --mechanics-only);
#   - the accuracy against a reference run at rtol 1e-12 (200 periods): the relative error of
#     the average power after the transient and the largest relative error of one period's
#     energy.
#
# Usage: bench/charge_rtol.sh [RUNS] [RTOL ...]   (default 3 runs; rtols 1e-5 1e-4 1e-3 1e-2)
#   VIBROTRIBO_BIN  the binary to time (default: build and use target/release/vibrotribo)
#   LOADS           load resistances to measure, Ω (default "1e5", the paper's 100 kΩ)
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=bench/timing.sh
. bench/timing.sh
runs=${1:-3}
shift || true
rtols=("$@")
[ ${#rtols[@]} -eq 0 ] && rtols=(1e-5 1e-4 1e-3 1e-2)
loads=${LOADS:-1e5}
binary_and_scratch


# The figures of one rtol's runs: steps and rejected steps per period (long run), the power
# and per-period energy errors against the reference (short run).
figures() {
    python3 - "$1" "$2" "$3" <<'EOF'
import json, re, sys
long, short, ref = (json.load(open(p)) for p in sys.argv[1:4])
stats = dict(re.findall(r"(\w+): (\d+)", long["electrical_solver"]))
n = long["periods"]
power = short["average_power_w"] / ref["average_power_w"] - 1
energy = max(abs(e / r - 1) for e, r in zip(short["energy_in_each_period_j"], ref["energy_in_each_period_j"]))
print(f"{int(stats['steps']) / n:.1f} {int(stats['rejected']) / n:.1f} {power:+.1e} {energy:.1e}")
EOF
}

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg); $runs runs per rtol, CPU seconds (median)"
for load in $loads; do
    set_load=(--set "harvester.load_resistance=$load")
    echo
    echo "load $load Ω (default case, 30 000 periods at one sample a period; errors over 200 periods)"
    "$bin" simulate -q --force "${set_load[@]}" --set electrical.rtol=1e-12 --set run.periods=200 \
        --set run.samples_per_period=1 --out "$out/ref" >/dev/null
    declare -A times=()
    "$bin" simulate -q --force "${set_load[@]}" --set run.periods=300 --out "$out/warm" >/dev/null
    for _ in $(seq 1 "$runs"); do
        for r in "${rtols[@]}"; do
            t=$(cpu "$bin" simulate -q --force "${set_load[@]}" --set "electrical.rtol=$r" \
                --set run.periods=30000 --set run.samples_per_period=1 --out "$out/long-$r")
            times[$r]="${times[$r]:-} $t"
        done
        t=$(cpu "$bin" simulate -q --force "${set_load[@]}" --mechanics-only \
            --set run.periods=30000 --set run.samples_per_period=1 --out "$out/long-mech")
        times[mech]="${times[mech]:-} $t"
    done
    printf '| rtol | steps / period | rejected / period | CPU, median | speed-up vs rtol %s | power error | worst period energy error |\n' "${rtols[0]}"
    printf '|---|---|---|---|---|---|---|\n'
    base=""
    for r in "${rtols[@]}"; do
        "$bin" simulate -q --force "${set_load[@]}" --set "electrical.rtol=$r" --set run.periods=200 \
            --set run.samples_per_period=1 --out "$out/short-$r" >/dev/null
        # shellcheck disable=SC2086
        m=$(median ${times[$r]})
        [ -z "$base" ] && base=$m
        read -r steps rejected power energy < <(figures "$out/long-$r/summary.json" \
            "$out/short-$r/summary.json" "$out/ref/summary.json")
        printf '| %s | %s | %s | %.3f s | %.2f× | %s | %s |\n' "$r" "$steps" "$rejected" "$m" \
            "$(awk -v a="$base" -v b="$m" 'BEGIN {print a / b}')" "$power" "$energy"
    done
    # shellcheck disable=SC2086
    echo "the same run --mechanics-only: $(median ${times[mech]}) s (CPU, median)"
    unset times
done
echo
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
