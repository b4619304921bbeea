#!/bin/sh
# Side-by-side speed comparison, one run: vibrotribo's engine (criterion, median) against the
# scipy solve_ivp baseline (median of 3 separate processes), both on the paper's default case
# and its chatter case. Prints periods/s for each, the ratio per simulated period, and the
# engine's events/s per core (the target: 1 000 000 in the default case).
#
# Usage: bench/compare.sh [scipy periods, default 100]
# Needs python3 with numpy and scipy (pip install numpy scipy).
set -e
P=${1:-100}
D=$(cd "$(dirname "$0")" && pwd)
ROOT=$(dirname "$D")
OUT=$(mktemp)
trap 'rm -f "$OUT"' EXIT

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
LOG=$(mktemp)
trap 'rm -f "$OUT" "$LOG"' EXIT
(cd "$ROOT" && cargo bench -q -p vibrotribo --bench engine -- --noplot "periods" >"$LOG" 2>&1) ||
  { cat "$LOG"; exit 1; }
for c in default chatter; do
  for i in 1 2 3; do
    python3 "$D/scipy_baseline.py" --case "$c" --periods "$P" --json >> "$OUT"
  done
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$OUT" "$ROOT/target/criterion" <<'PY'
import glob, json, os, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
crit = sys.argv[2]
print("%-8s %22s %22s %8s %18s" % ("case", "vibrotribo periods/s", "scipy periods/s", "ratio",
                                   "vibrotribo events/s"))
for case in ("default", "chatter"):
    runs = [r for r in rows if r["case"] == case]
    if any(r["status"] != "ok" for r in runs):
        sys.exit("scipy baseline did not finish the %s case: %s" % (case, runs))
    scipy_rate = runs[0]["periods"] / statistics.median(r["wall_s"] for r in runs)
    [est] = glob.glob(os.path.join(crit, case + "_case", "periods (*)", "new", "estimates.json"))
    periods = float(est.split("periods (")[1].split(")")[0])
    median_ns = json.load(open(est))["median"]["point_estimate"]
    vt_rate = periods / (median_ns * 1e-9)
    # Events per period of the benchmark's own run, from its events benchmark's name (the
    # events/s target is per core: the engine benchmark is single-threaded).
    names = glob.glob(os.path.join(crit, case + "_case", "events (* in * periods)"))
    ev = ""
    if names:
        n_events, n_periods = os.path.basename(names[0])[len("events ("):-len(" periods)")].split(" in ")
        ev = "%18.0f" % (vt_rate * float(n_events) / float(n_periods))
    print("%-8s %22.0f %22.1f %7.0fx %s" % (case, vt_rate, scipy_rate, vt_rate / scipy_rate, ev))
PY
