#!/bin/sh
# The 2000× target for orbit diagrams, side by side in one run: the chatter case's orbit diagram over
# Ω ∈ [0.3, 1.0], 200 values, each 300 transient + 100 recorded periods from rest (400 periods),
# by `vibrotribo sweep` with the 100 kΩ harvester's power on 2 threads, against the scipy
# baseline (mechanics only, one process) run on every STRIDE-th value of the same grid for
# 400 periods, its time scaled up to the 200 values.
#
# Usage: bench/orbit_diagram.sh [STRIDE, default 10] [vibrotribo binary, default the release build]
# Needs python3 with numpy and scipy (pip install numpy scipy).
set -e
STRIDE=${1:-10}
D=$(cd "$(dirname "$0")" && pwd)
ROOT=$(dirname "$D")
BIN=${2:-}
if [ -z "$BIN" ]; then
  (cd "$ROOT" && cargo build --release -q -p vibrotribo-cli)
  BIN="$ROOT/target/release/vibrotribo"
fi
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$STRIDE" "$BIN" "$ROOT" "$D/scipy_baseline.py" <<'PY'
import json, os, subprocess, sys, tempfile, time
stride, binary, root, baseline = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
if stride < 1:
    sys.exit("STRIDE must be a positive integer")
lo, hi, steps, periods = 0.3, 1.0, 200, 400
with tempfile.TemporaryDirectory() as out:
    cmd = [binary, "sweep", os.path.join(root, "configs", "chatter.toml"), "--param", "omega_ratio",
           "--from", str(lo), "--to", str(hi), "--steps", str(steps), "--settle", "fixed",
           "--transient", "300", "--recorded", "100", "--threads", "2", "-q",
           "--out", os.path.join(out, "sweep")]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    vt = time.perf_counter() - t0
walls, bad = [], []
sample = list(range(stride // 2, steps, stride))
for i in sample:
    omega = lo + (hi - lo) * i / (steps - 1)
    r = subprocess.run([sys.executable, baseline, "--case", "chatter", "--omega-ratio", repr(omega),
                        "--periods", str(periods), "--json"], capture_output=True, text=True)
    row = json.loads(r.stdout.strip().splitlines()[-1])
    walls.append(row["wall_s"] if row["wall_s"] is not None else float("nan"))
    if row["status"] != "ok":
        bad.append("%.4f: %s" % (omega, row["status"]))
    print("scipy Ω = %.4f: %s, %.2f s" % (omega, row["status"], walls[-1]), flush=True)
ok = [w for w in walls if w == w]
scipy_total = sum(ok) / len(ok) * steps
print("vibrotribo sweep, 200 × 400 periods with power, 2 threads: %.2f s wall" % vt)
print("scipy, %d of the 200 values × 400 periods, mechanics only: %.1f s; scaled to 200: %.0f s"
      % (len(sample), sum(ok), scipy_total))
print("ratio: %.0f×" % (scipy_total / vt))
if bad:
    print("scipy runs not ok (their times are included; an invalid run's masses passed through "
          "each other): " + "; ".join(bad))
PY
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
