#!/usr/bin/env bash
# What the harvester and two-way coupling cost, whole process, as paired CPU-time ratios
# (user + system of each run, runs alternated A B A B … so that a machine whose speed drifts
# moves both alike; each ratio is the median of the ratios of the pairs).
#
#   1. The default case with its 100 kΩ harvester, 30 000 periods at one sample a period,
#      written to a scratch directory: BIN against BASE (if given: the speed-up BASE/BIN), and
#      against BIN --mechanics-only (what the harvester adds).
#   2. Two-way coupling against one-way, both with the exact V_oc, default outputs, on the
#      default and the chatter case, over 100 periods and over LONG periods.
#
# Usage: bench/harvester.sh [RUNS] [LONG]   (default 7 runs of each command, LONG 1000)
#   VIBROTRIBO_BIN  the binary to time (default: build and use target/release/vibrotribo)
#   BASE_BIN        a second binary to compare with in part 1 (optional), e.g. one built from
#                   an older commit in a worktree of its own
#   ONLY            "harvester" or "coupling" to run one part
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=bench/timing.sh
. bench/timing.sh
runs=${1:-7}
long=${2:-1000}
binary_and_scratch
base=${BASE_BIN:-}
only=${ONLY:-}


# pair LABEL "A command" "B command": RUNS alternated pairs after one warm-up each; prints
# the medians of A and B and the median of the pairs' ratios A/B.
pair() {
    local label=$1 a=$2 b=$3 ta tb
    local as=() bs=() rs=()
    # shellcheck disable=SC2086
    cpu $a >/dev/null; cpu $b >/dev/null
    for _ in $(seq 1 "$runs"); do
        # shellcheck disable=SC2086
        ta=$(cpu $a); tb=$(cpu $b)
        as+=("$ta"); bs+=("$tb")
        rs+=("$(awk -v x="$ta" -v y="$tb" 'BEGIN {printf "%.4f", x / y}')")
    done
    printf '%-58s A %6.3f s  B %6.3f s  A/B %.3f  (pairs %s)\n' "$label" \
        "$(median "${as[@]}")" "$(median "${bs[@]}")" "$(median "${rs[@]}")" "$(printf '%s ' "${rs[@]}" | sed 's/ $//')"
}

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg); $runs pairs per line, CPU seconds (median)"
run=(simulate -q --set run.periods=30000 --set run.samples_per_period=1 --force)
if [ "$only" != coupling ]; then
    echo "1. default case, 100 kΩ, 30 000 periods, one sample a period, files written"
    if [ -n "$base" ]; then
        # An older binary may have no --force (it wrote over its own files without it).
        pair "A = $bin, B = $base" "$bin ${run[*]} --out $out/a" "$base ${run[*]/--force/} --out $out/b"
    fi
    pair "A = with the harvester, B = --mechanics-only" \
        "$bin ${run[*]} --out $out/a" "$bin ${run[*]} --mechanics-only --out $out/m"
fi
if [ "$only" != harvester ]; then
    echo "2. two-way (A) against one-way (B) coupling, exact V_oc, default outputs"
    exact=(-q --set harvester.voc_model=exact --force)
    for periods in 100 "$long"; do
        for case in default chatter; do
            config=""
            [ "$case" = chatter ] && config=configs/chatter.toml
            p=(--set "run.periods=$periods")
            pair "$case case, $periods periods" \
                "$bin simulate $config ${exact[*]} ${p[*]} --set harvester.coupling=two_way --out $out/t" \
                "$bin simulate $config ${exact[*]} ${p[*]} --out $out/o"
        done
    done
fi
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
