#!/usr/bin/env python3
"""Where the instructions of a vibrotribo run go, from a callgrind profile.

    valgrind --tool=callgrind --callgrind-out-file=OUT vibrotribo simulate ...
    python3 bench/callgrind_breakdown.py OUT [events]

Reads `callgrind_annotate --inclusive=yes OUT` and prints the inclusive instruction counts
(Ir) of the parts of a run, as counts, per cent of the whole process and, given the number
of mechanical events of the run, per event. Functions inlined into their callers have no
entry of their own; the parts are chosen among functions that the release build keeps.
"""
import re
import subprocess
import sys

PARTS = [
    # (label, indent, regular expressions of function names whose inclusive counts add up)
    ("whole process", 0, None),
    ("simulation (Simulator::run_until, observers included)", 0, [r"Simulator::run_until$"]),
    ("  mechanics (run_until minus the flow observers)", 0, "MECH"),
    ("    event search (Simulator::next_event)", 0, [r"Simulator>?::next_event$"]),
    ("      of which the searches' iterations (roots::Search::advance)", 0,
     [r"roots::first_root$", r"roots::Search::advance$"]),
    ("    events: impacts, sticking, chatter (Simulator::handle)", 0, [r"Simulator::handle$"]),
    ("  charge solver (ChargeSolver::advance_flow)", 0, [r"ChargeSolver>::advance_flow$"]),
    # Undercounted where the build inlines Oscillator::taylor into it (current builds do):
    # inlined callees have no inclusive entry of their own.
    ("    Taylor expansion of the gaps (GapPolynomial::build; see the note)", 0,
     [r"GapPolynomial::build$", r"Oscillator::taylor$"]),
    ("    Radau stage solves (trial_resistor, trial_rectifier)", 0,
     [r"ChargeSolver>::trial_resistor$", r"ChargeSolver>::trial_rectifier$"]),
    ("    outputs of steps: samples, breakdown (record)", 0, [r"ChargeSolver>::record$"]),
    ("      of which the air-breakdown check (BreakdownMargin::add)", 0, [r"BreakdownMargin::add$"]),
    ("  mechanical samples (Flow::state_at)", 0, [r"Flow::state_at$"]),
    ("text formatting of outputs (core::fmt::write)", 0, [r"^core::fmt::write$"]),
]


def inclusive(path):
    out = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--auto=no", "--threshold=100", path],
        capture_output=True, text=True, check=True,
    ).stdout
    total = None
    funcs = {}
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+) \([ \d.]+%\)\s+(.*)$", line)
        if not m:
            continue
        count = int(m.group(1).replace(",", ""))
        rest = m.group(2)
        if rest.startswith("PROGRAM TOTALS"):
            total = count
            continue
        # Only entries of real (not inlined) functions carry the object file in brackets.
        if not rest.rstrip().endswith("]"):
            continue
        name = rest.rsplit(" [", 1)[0]
        name = name.split(":", 1)[1] if ":" in name.split("::", 1)[0] else name
        funcs[name] = max(funcs.get(name, 0), count)
    return total, funcs


def main():
    path = sys.argv[1]
    events = float(sys.argv[2]) if len(sys.argv) > 2 else None
    total, funcs = inclusive(path)

    def grab(patterns):
        return sum(c for n, c in funcs.items() if any(re.search(p, n) for p in patterns))

    observers = sum(
        c for n, c in funcs.items()
        if re.search(r"as vibrotribo::dynamics::observer::Observer>::flow$", n)
        and ("Recorder" in n or "Mechanics" in n)
    )
    head = "%-64s %15s %7s" % ("part", "instructions", "share")
    if events:
        head += " %10s" % "per event"
    print(head)
    for label, _, pats in PARTS:
        if pats is None:
            c = total
        elif pats == "MECH":
            c = grab([r"Simulator::run_until$"]) - observers
        else:
            c = grab(pats)
        if c == 0 and pats not in (None, "MECH"):
            continue
        row = "%-64s %15s %6.1f%%" % (label, f"{c:,}", 100.0 * c / total)
        if events:
            row += " %10.0f" % (c / events)
        print(row)


if __name__ == "__main__":
    main()
