#!/usr/bin/env bash
# A sweep's speed-up on 1 and 2 threads and its parallel efficiency: the chatter case's orbit
# diagram (configs/chatter.toml, Ω from 0.3 to 1.0 in STEPS values from rest, 300 transient
# and 100 recorded periods, with the harvester), run with RAYON_NUM_THREADS=1 and =2 in
# turn (1 2 1 2 …), RUNS times each (default 3). Prints every wall and CPU time, the
# medians, the speed-up (median wall on 1 thread / on 2) and the efficiency (speed-up / 2).
# On a machine shared with other work the speed-up is bounded by the cores left free: the
# script prints the load average before and after.
# Usage: bench/scaling.sh [RUNS] [STEPS]    (VIBROTRIBO_BIN: the binary to time)
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=bench/timing.sh
. bench/timing.sh
runs=${1:-3}
steps=${2:-81}
binary_and_scratch
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
one() {
    local threads=$1
    # Prints "wall cpu" in seconds.
    local TIMEFORMAT='%R %U %S'
    { time RAYON_NUM_THREADS=$threads "$bin" sweep configs/chatter.toml --param omega_ratio \
        --from 0.3 --to 1.0 --steps "$steps" --transient 300 --recorded 100 \
        --out "$out/run-$threads" --quiet >/dev/null; } 2>"$out/time"
    awk '{printf "%s %.2f\n", $1, $2 + $3}' "$out/time"
}
w1=() c1=() w2=() c2=()
for _ in $(seq 1 "$runs"); do
    read -r w c < <(one 1); w1+=("$w"); c1+=("$c")
    read -r w c < <(one 2); w2+=("$w"); c2+=("$c")
done
mw1=$(median "${w1[@]}"); mw2=$(median "${w2[@]}")
echo "1 thread:  wall ${w1[*]} s (median $mw1), cpu ${c1[*]} s (median $(median "${c1[@]}"))"
echo "2 threads: wall ${w2[*]} s (median $mw2), cpu ${c2[*]} s (median $(median "${c2[@]}"))"
awk -v a="$mw1" -v b="$mw2" 'BEGIN {printf "speed-up %.2f, efficiency %.0f %%\n", a / b, 50 * a / b}'
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
