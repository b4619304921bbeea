#!/usr/bin/python3
"""Side-by-side of vibrotribo and Siconos 4.4 on the default and chatter cases (mechanics).

The same chain is built in Siconos: a `LagrangianDS` with diagonal mass matrix, its spring
and damper forces to the moving base (k_i (x_i - y) + c_i (x_i' - y'), y = A sin wt) in a
small C plugin compiled here, and one `LagrangianLinearTIR` per gap (d_k = delta_k + x_k -
x_{k+1} >= 0) with Newton's impact law. Two schemes are run:

* event-driven (`EventDriven` + `LsodarOSI`) at its default tolerance and at rtol = atol =
  1e-6 and 1e-9, with `setToleranceED(1e-9)` (its built-in 2.2e-12 stops long runs);
* Moreau-Jean time-stepping (`TimeStepping` + `MoreauJeanOSI(0.5)` + `LCP`) at several
  steps h = T/n.

Reference: the impacts in vibrotribo's `events.csv` of `simulate --mechanics-only` on the
same configuration. Each of our impacts in the compared window is matched with the nearest
Siconos impact on the same contact: the table gives the largest time error (in periods T)
and the largest relative error in closing speed, the impact counts, and the CPU time per
period (median of repeats; Siconos's loop only, set-up excluded; vibrotribo's whole
process over 5000 periods, run after each Siconos run so that each ratio is taken on a
pair made side by side, the table giving the median ratio). Failures are reported with
Siconos's message where it prints one, and the time they happen beside our first
accumulation point.

Run with the system Python that carries Debian's python3-siconos; bench/siconos/run.sh
installs it and builds the binary. Prints a Markdown table.
"""

import argparse
import ctypes
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

import siconos.kernel as sk

ROOT = Path(__file__).resolve().parents[2]
LIBC = ctypes.CDLL(None)

PLUGIN = r"""
#include <math.h>
static const double K[3] = {%(k)s}, C[3] = {%(c)s};
static const double A = %(a)r, W = %(w)r;
void fint(double t, unsigned int n, double *q, double *v, double *f, unsigned int nz, double *z)
{
    double y = A * sin(W * t), yd = A * W * cos(W * t);
    for (unsigned int i = 0; i < n; i++) f[i] = K[i] * (q[i] - y) + C[i] * (v[i] - yd);
}
void jq(double t, unsigned int n, double *q, double *v, double *J, unsigned int nz, double *z)
{
    for (unsigned int i = 0; i < n * n; i++) J[i] = 0.0;
    for (unsigned int i = 0; i < n; i++) J[i * n + i] = K[i];
}
void jv(double t, unsigned int n, double *q, double *v, double *J, unsigned int nz, double *z)
{
    for (unsigned int i = 0; i < n * n; i++) J[i] = 0.0;
    for (unsigned int i = 0; i < n; i++) J[i * n + i] = C[i];
}
"""


def per_mass(value, n):
    """A scalar or a list of n values, as a list."""
    return list(value) if isinstance(value, list) else [value] * n


def load_case(path):
    """The chain of a configuration file: defaults from configs/default.toml, then the file."""
    with open(ROOT / "configs" / "default.toml", "rb") as f:
        base = tomllib.load(f)
    with open(path, "rb") as f:
        over = tomllib.load(f)
    for section, table in over.items():
        base.setdefault(section, {}).update(table)
    osc, exc, run = base["oscillator"], base["excitation"], base["run"]
    m = osc["masses"]
    n = len(m)
    k = per_mass(osc["stiffness"], n)
    c = per_mass(osc["damping"], n)
    w = exc["omega_ratio"] * math.sqrt(k[0] / m[0])
    return {
        "m": m, "k": k, "c": c, "gaps": osc["gaps"], "e": osc["restitution"],
        "a": exc["amplitude"], "w": w, "T": 2 * math.pi / w,
        "q0": per_mass(run.get("initial_positions", 0.0), n),
        "v0": per_mass(run.get("initial_velocities", 0.0), n),
    }


def build_plugin(case, workdir):
    """Compiles the force plugin of a case; returns the path of its shared object."""
    src = workdir / "forces.c"
    so = workdir / "forces.so"
    src.write_text(PLUGIN % {
        "k": ", ".join(repr(x) for x in case["k"]),
        "c": ", ".join(repr(x) for x in case["c"]),
        "a": case["a"], "w": case["w"],
    })
    subprocess.run(["gcc", "-O2", "-shared", "-fPIC", str(src), "-o", str(so), "-lm"], check=True)
    return str(so)


def build_system(case, plugin, t_end):
    """The Siconos dynamical system, its interactions (one per gap) and the NSDS."""
    ds = sk.LagrangianDS(np.array(case["q0"], float), np.array(case["v0"], float),
                         np.diag(case["m"]))
    ds.setComputeFIntFunction(plugin, "fint")
    ds.setComputeJacobianFIntqFunction(plugin, "jq")
    ds.setComputeJacobianFIntqDotFunction(plugin, "jv")
    nsds = sk.NonSmoothDynamicalSystem(0.0, t_end)
    nsds.insertDynamicalSystem(ds)
    inters = []
    n = len(case["m"])
    for j, gap in enumerate(case["gaps"]):
        h = np.zeros((1, n))
        h[0, j], h[0, j + 1] = 1.0, -1.0
        inter = sk.Interaction(sk.NewtonImpactNSL(case["e"]),
                               sk.LagrangianLinearTIR(h, np.array([gap])))
        nsds.link(inter, ds)
        inters.append(inter)
    return ds, inters, nsds


def run_event_driven(case, plugin, periods, tol):
    """Event-driven run: (impacts [(t, contact, closing speed)], cpu s, t reached, error)."""
    T = case["T"]
    ds, inters, nsds = build_system(case, plugin, periods * T)
    sim = sk.EventDriven(nsds, sk.TimeDiscretisation(0.0, T / 10))
    osi = sk.LsodarOSI()
    if tol is not None:
        osi.setTol(1, tol, tol)
    sim.insertIntegrator(osi)
    sim.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_IMPACT)
    sim.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_SMOOTH_ACC)
    sim.setToleranceED(1e-9)
    impacts, error, t_reached = [], None, 0.0
    start = time.process_time()
    log = tempfile.TemporaryFile()
    saved = [os.dup(1), os.dup(2)]
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(log.fileno(), 1)
    os.dup2(log.fileno(), 2)
    try:
        while sim.hasNextEvent():
            phase = "advanceToEvent"
            sim.advanceToEvent()
            ev = sim.eventsManager().nextEvent()
            t_reached = ev.getDoubleTimeOfEvent()
            if ev.getType() == 2:
                for j, inter in enumerate(inters):
                    y0, y1 = inter.y(0)[0], inter.y(1)[0]
                    if abs(y0) < 1e-9 and y1 < -1e-9:
                        impacts.append((t_reached, j + 1, -y1))
            phase = "processEvents"
            sim.processEvents()
    except Exception as exc:  # Siconos's C++ exceptions reach Python as Exception
        error = f"{phase}: " + " ".join(str(exc).split())
    finally:
        LIBC.fflush(None)
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)
    cpu = time.process_time() - start
    if error is not None:
        # Siconos prints its reason before raising a bare std::exception: keep its last lines.
        log.seek(0)
        printed = [ln.strip() for ln in log.read().decode(errors="replace").splitlines()
                   if ln.strip()]
        if printed:
            error = " / ".join(printed[-2:]) + f" ({error})"
    return impacts, cpu, min(t_reached, periods * T), error, None


def run_moreau_jean(case, plugin, periods, n_per_period):
    """Moreau-Jean run at h = T/n: impacts, cpu s, t reached, error, positions at t = kT."""
    T = case["T"]
    h = T / n_per_period
    ds, inters, nsds = build_system(case, plugin, periods * T)
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, h))
    sim.insertIntegrator(sk.MoreauJeanOSI(0.5))
    sim.insertNonSmoothProblem(sk.LCP())
    impacts, error = [], None
    strobe = [np.array(case["q0"], float)]
    prev_v = [inter.y(1)[0] for inter in inters]
    prev_l = [0.0 for _ in inters]
    step = 0
    start = time.process_time()
    try:
        while sim.hasNextEvent():
            sim.computeOneStep()
            step += 1
            t = step * h
            for j, inter in enumerate(inters):
                lam = inter.lambda_(1)[0]
                if lam > 0.0 and prev_l[j] <= 0.0 and prev_v[j] < 0.0:
                    impacts.append((t, j + 1, -prev_v[j]))
                prev_l[j] = lam
                prev_v[j] = inter.y(1)[0]
            if step % n_per_period == 0:
                strobe.append(np.array(ds.q(), float))
            sim.nextStep()
    except Exception as exc:
        error = " ".join(str(exc).split())
    cpu = time.process_time() - start
    return impacts, cpu, step * h, error, np.array(strobe)


def ours(binary, config, periods, workdir):
    """vibrotribo's impacts, positions at t = kT and its first accumulation point, if any."""
    out = workdir / "ours"
    subprocess.run([binary, "simulate", str(config), "--mechanics-only",
                    "--set", f"run.periods={periods}", "--set", "run.samples_per_period=1",
                    "--set", "run.transient_periods=0", "--out", str(out), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    impacts, first_chatter = [], None
    with open(out / "events.csv") as f:
        head = f.readline().strip().split(",")
        it, ik, ic, iv = (head.index(x) for x in ("time_s", "kind", "contact", "rel_velocity_m_s"))
        for line in f:
            row = line.split(",")
            if row[ik] == "impact":
                impacts.append((float(row[it]), int(row[ic]), float(row[iv])))
            elif row[ik] == "chatter" and first_chatter is None:
                first_chatter = float(row[it])
    traj = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    strobe = traj[:, 1:4]
    return impacts, strobe, first_chatter


def our_cost(binary, config, workdir, periods=5000):
    """vibrotribo's CPU seconds per period: one whole `simulate` process over `periods`."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([binary, "simulate", str(config), "--mechanics-only",
                    "--set", f"run.periods={periods}", "--set", "run.samples_per_period=1",
                    "--set", "run.transient_periods=0", "--out", str(workdir / "long"),
                    "--quiet"], check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime) / periods


def compare(ref, got, t_end, T):
    """Largest impact-time error (T) and relative closing-speed error over our impacts < t_end.

    Only impacts faster than 1 % of the fastest are compared: inside a chatter sequence the
    bounces shrink geometrically and the schemes resolve different numbers of them (ours
    jumps to the accumulation point), so the tiny ones have no partner to compare with.
    """
    dt_max, dv_max, matched = 0.0, 0.0, 0
    by_contact = {}
    for t, c, v in got:
        by_contact.setdefault(c, []).append((t, v))
    v_floor = 0.01 * max((r[2] for r in ref), default=0.0)
    window = [r for r in ref if r[0] < t_end - 1e-9 and r[2] > v_floor]
    for t, c, v in window:
        cands = by_contact.get(c)
        if not cands:
            return float("inf"), float("inf"), len(window)
        ts, vs = min(cands, key=lambda s: abs(s[0] - t))
        dt_max = max(dt_max, abs(ts - t) / T)
        dv_max = max(dv_max, abs(vs - v) / v)
        matched += 1
    return dt_max, dv_max, matched


def fmt(x):
    return "—" if x is None else ("∞" if x == float("inf") else f"{x:.1e}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--bin", default=str(ROOT / "target" / "release" / "vibrotribo"))
    p.add_argument("--periods", type=int, default=200, help="periods of the event-driven runs")
    p.add_argument("--repeats", type=int, default=3, help="repeats for the CPU medians")
    p.add_argument("--steps", default="1000:200,10000:20,100000:2",
                   help="Moreau-Jean runs as n:periods (h = T/n), comma-separated")
    args = p.parse_args()
    mj_runs = [tuple(int(x) for x in s.split(":")) for s in args.steps.split(",")]
    rows = []
    load_start = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name, cfg in (("default", ROOT / "configs" / "default.toml"),
                          ("chatter", ROOT / "configs" / "chatter.toml")):
            case = load_case(cfg)
            T = case["T"]
            work = tmp / name
            work.mkdir()
            plugin = build_plugin(case, work)
            ref, ref_strobe, first_chatter = ours(args.bin, cfg, args.periods, work)
            our_row = len(rows)
            our_cpus = []
            schemes = [("event-driven (LsodarOSI)", f"tol {lab}", run_event_driven,
                        args.periods, tol)
                       for lab, tol in (("default", None), ("1e-6", 1e-6), ("1e-9", 1e-9))]
            schemes += [("Moreau–Jean (θ = 0.5)", f"h = T/{n}", run_moreau_jean, per, n)
                        for n, per in mj_runs]
            for scheme, setting, fn, periods, arg in schemes:
                # Each repeat runs ours beside Siconos; the ratio is taken pair by pair.
                cpus, ratios, result = [], [], None
                for _ in range(args.repeats):
                    result = fn(case, plugin, periods, arg)
                    ours_pp = our_cost(args.bin, cfg, work)
                    our_cpus.append(ours_pp)
                    pp = result[1] / max(result[2] / T, 1e-9)
                    cpus.append(pp)
                    ratios.append(pp / ours_pp)
                imp, _, t_reached, error, strobe = result
                cpu_pp = statistics.median(cpus)
                dt, dv, n_ref = compare(ref, imp, t_reached, T)
                note = ""
                if error:
                    note = f"fails at t = {t_reached / T:.6f} T"
                    if first_chatter is not None:
                        note += f" (our first accumulation point: {first_chatter / T:.6f} T)"
                    note += f": “{error[:160]}”"
                if strobe is not None and len(strobe) > 1:
                    k = min(len(strobe), len(ref_strobe))
                    dev = np.max(np.abs(strobe[:k] - ref_strobe[:k])) / case["gaps"][0]
                    half = slice(k // 2, k)
                    mean_dev = np.max(np.abs(strobe[half].mean(axis=0)
                                             - ref_strobe[half].mean(axis=0))) / case["gaps"][0]
                    note += ("; " if note else "") + (
                        f"positions at t = kT within {dev:.1e} δ₁, their mean over the "
                        f"second half within {mean_dev:.1e} δ₁")
                rows.append((name, scheme, setting, f"{t_reached / T:.4g}",
                             f"{len(imp)} / {n_ref}", fmt(dt), fmt(dv),
                             f"{cpu_pp * 1e6:.0f} µs", f"{statistics.median(ratios):.0f}×",
                             note))
                print(rows[-1], file=sys.stderr, flush=True)
            rows.insert(our_row, (name, "vibrotribo (closed form, certified events)", "—",
                                  f"{args.periods}", f"{len(ref)}", "reference", "reference",
                                  f"{statistics.median(our_cpus) * 1e6:.1f} µs", "1×",
                                  "whole process, 5000 periods"))
    print("| case | scheme | setting | periods run | impacts: Siconos / ours compared "
          "| impact time error (T) "
          "| closing speed error (rel.) | CPU / period | vs vibrotribo | notes |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print(f"\nCPU per period: medians of {args.repeats} repeats; 'vs vibrotribo': the median "
          "of the ratios of runs made side by side (ours after each Siconos run). "
          f"Load average: {load_start:.2f} at the start, {os.getloadavg()[0]:.2f} at the end.")


if __name__ == "__main__":
    main()
