#!/usr/bin/env bash
# Times a 200 × 200 basin picture of the paper's default case: x₂(0) ∈ [−20, 20] mm,
# v₂(0) ∈ [−3, 3] m/s (m1 and m3 at rest), 500 transient and 100 recorded periods per start,
# with the harvester's power, on all cores. Usage: bench/basins.sh [OUT_DIR] [extra options]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/bench-basins}
shift || true
cargo build --release -q -p vibrotribo-cli
rm -rf "$out"
/usr/bin/time -f "%e s wall, %U s user, %M KiB max" target/release/vibrotribo basins \
    --x 'run.initial_positions[1]' --x-from -0.02 --x-to 0.02 \
    --y 'run.initial_velocities[1]' --y-from -3 --y-to 3 \
    --grid 200x200 --out "$out" --plot --quiet "$@"
