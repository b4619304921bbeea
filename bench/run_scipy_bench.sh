#!/bin/sh
# Median-of-3 timing of the scipy baseline, each run a separate process.
# Usage: bench/run_scipy_bench.sh [periods] [extra flags for scipy_baseline.py]
set -e
P=${1:-100}
[ $# -gt 0 ] && shift
D=$(dirname "$0")
OUT=$(mktemp)
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for c in default chatter; do
  for i in 1 2 3; do
    python3 "$D/scipy_baseline.py" --case "$c" --periods "$P" --json "$@" >> "$OUT"
  done
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$OUT" <<'PY'
import json, statistics, sys
rs = [json.loads(l) for l in open(sys.argv[1])]
for c in ("default", "chatter"):
    r = [x for x in rs if x["case"] == c]
    w = [x["wall_s"] for x in r]
    med = statistics.median(w)
    x = r[0]
    cpu = statistics.median([x["cpu_s"] for x in r])
    print("%-8s %s periods=%g events=%d impacts=%d sticks=%d releases=%d  wall(median)=%.3f s "
          "[%s] cpu(median)=%.3f s  events/s=%.0f  periods/s=%.1f  (nfev=%d, steps=%d, restarts=%d)"
          % (c, x["status"], x["periods"], x["events"], x["impacts"], x["sticks"], x["releases"],
             med, ", ".join("%.3f" % v for v in w), cpu, x["events"] / med, x["periods"] / med,
             x["nfev"], x["steps"], x["segments"]))
PY
rm -f "$OUT"
