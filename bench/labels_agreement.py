#!/usr/bin/env python3
"""Agreement of the default sweep's labels with long plain runs.

On random points across the paper's parameter ranges (Ω in [0.3, 1.2], R_m in [1, 7],
R_δ in [1, 1.5], restitution μ in [0.3, 0.9]; the default and the chatter chain, each from
rest), each point is computed twice with `vibrotribo sweep --steps 1 --mechanics-only`: the
default (`--settle auto`, 300 + 100 periods) and a plain run of 3000 transient periods
(`--settle fixed --transient 3000`), the independent truth. The table counts, for points
whose long run is periodic, how often the default sweep gives the same period and impacts
per period, another period, `settling`, or a non-periodic label; for points whose long run is
not periodic, how often the default sweep claims a period.

Usage: bench/labels_agreement.py BINARY [POINTS] [SEED] [--csv FILE] [--part I/N]
(BINARY: a release build of vibrotribo; POINTS default 500; SEED default 1; --part I/N runs
only the points k with k mod N = I, the same points as the whole run draws, so that N
processes side by side cover it; their tables add up.)
"""

import csv
import os
import random
import subprocess
import sys
import tempfile
from collections import Counter

CHAINS = {
    "default": [],
    "chatter": ["--set", "oscillator.masses=[0.05,0.15,0.05]", "--set", "oscillator.gaps=[0.005,0.005]"],
}


def point(binary, chain, omega, rm, rd, mu, extra):
    with tempfile.TemporaryDirectory() as out:
        cmd = [binary, "sweep", "--param", "excitation.omega_ratio", "--from", str(omega), "--to", str(omega),
               "--steps", "1", "--mechanics-only", "--threads", "1", "-q", "--out", out,
               "--set", f"mass_ratio={rm}", "--set", f"gap_ratio={rd}", "--set", f"restitution={mu}"]
        cmd += CHAINS[chain] + extra
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            return {"error": r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "failed"}
        with open(os.path.join(out, "summary.csv")) as f:
            return next(csv.DictReader(f))


def verdict(auto, long):
    if auto.get("error") or long.get("error"):
        return "failed"
    lp, ap = int(long["period"]), int(auto["period"])
    if long["motion"] == "periodic":
        if auto["motion"] == "periodic":
            same = ap == lp and abs(float(auto["impacts_per_period"]) - float(long["impacts_per_period"])) \
                <= lp * float(long["impacts_per_period"]) / 100 + 1e-9
            return "periodic: same orbit" if same else "periodic: other orbit"
        return f"periodic: default says {auto['motion']}"
    return ("not periodic: default claims a period" if auto["motion"] == "periodic"
            else f"not periodic ({long['motion']}): default says {auto['motion']}")


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    out_csv = sys.argv[sys.argv.index("--csv") + 1] if "--csv" in sys.argv else None
    if out_csv in args:
        args.remove(out_csv)
    part = sys.argv[sys.argv.index("--part") + 1] if "--part" in sys.argv else "0/1"
    if part in args:
        args.remove(part)
    part_i, part_n = (int(x) for x in part.split("/"))
    binary = args[0]
    n = int(args[1]) if len(args) > 1 else 500
    rng = random.Random(int(args[2]) if len(args) > 2 else 1)
    table = Counter()
    rows = []
    for k in range(n):
        chain = "default" if k % 2 == 0 else "chatter"
        omega, rm = rng.uniform(0.3, 1.2), rng.uniform(1.0, 7.0)
        rd, mu = rng.uniform(1.0, 1.5), rng.uniform(0.3, 0.9)
        if k % part_n != part_i:
            continue
        auto = point(binary, chain, omega, rm, rd, mu, [])
        long = point(binary, chain, omega, rm, rd, mu, ["--settle", "fixed", "--transient", "3000"])
        v = verdict(auto, long)
        table[v] += 1
        rows.append([k, chain, omega, rm, rd, mu, auto.get("motion"), auto.get("period"),
                     auto.get("label_source", ""), auto.get("coexisting_period", ""),
                     long.get("motion"), long.get("period"), v])
        print(f"{k:4d} {chain:8s} Ω={omega:.4f} R_m={rm:.3f} R_δ={rd:.4f} μ={mu:.3f}: "
              f"default {auto.get('motion')} {auto.get('period')}, long {long.get('motion')} "
              f"{long.get('period')} -> {v}", flush=True)
    if out_csv:
        with open(out_csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["k", "chain", "omega_ratio", "mass_ratio", "gap_ratio", "restitution", "default_motion",
                        "default_period", "label_source", "coexisting_period", "long_motion", "long_period",
                        "verdict"])
            w.writerows(rows)
    print(f"\n{sum(table.values())} points:")
    for v, c in sorted(table.items()):
        print(f"  {c:5d}  {v}")


if __name__ == "__main__":
    main()
