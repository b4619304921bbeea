#!/usr/bin/env python3
"""Event-driven scipy baseline for the vibro-impact oscillator of vibrotribo.

A straightforward `scipy.integrate.solve_ivp` implementation of the same model
that vibrotribo simulates in closed form, written the way a careful researcher
would write it today: integrate the smooth equations of motion with an adaptive
Runge-Kutta method, stop at terminal events (a gap closes, a stuck contact's
force falls to zero), apply the impact / stick / release rule, restart.

Model (see docs/MODEL.md section 1): N masses in a column (m1 on
top), each tied to the base y = A sin(w t) by k_i, c_i:

    m_i x_i'' + c_i (x_i' - y') + k_i (x_i - y) = 0

gaps d_j = delta_j - (x_{j+1} - x_j) >= 0.  Impacts: Newton restitution mu
between the two clusters (masses stuck together) that meet, momentum conserved;
simultaneous contacts resolved pairwise until no closed contact approaches.
Sticking: a closed contact whose rebound speed is below --v-stick (1e-5 m/s)
is made plastic and sticks if its contact force

    N_j = sum_{i in G, i <= j} m_i (a_G - a_i)

is compressive; stuck masses move as one body until N_j falls to zero.

Safety measures that a general-purpose integrator needs here (each was needed
to get the reference right or to keep the chatter case from going wrong):

* after a rebound with speed r against a closing relative acceleration a the
  first step of the restart is limited to r/(2a), so the integrator cannot
  step straight over the re-contact (gap event sees 0 -> negative and would
  otherwise either miss it or find the root at the restart time);
* a non-terminal event at every minimum of every open gap (d' = 0, rising):
  if a gap minimum is negative, a contact was stepped over inside one step;
  the crossing is located on the dense output and treated as an impact
  ("grazing repair");
* zero-length segments (an event at the restart time that does nothing) are
  detected and stepped over with a tiny hop; repeated failures abort;
* caps on events per period and on wall time: the run reports a failure
  instead of hanging.

Usage:
    python3 bench/scipy_baseline.py --case default --periods 100 --json
    python3 bench/scipy_baseline.py --case chatter --periods 100 --json
    python3 bench/scipy_baseline.py --check-reference
"""

import argparse
import csv
import json
import math
import os
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

REF_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "crates", "vibrotribo", "tests", "data", "reference")


# --------------------------------------------------------------------------
# cases
# --------------------------------------------------------------------------

def make_case(name, omega_ratio=None):
    if name == "default":  # paper Sect. 4.1, configuration (1), R_m = 2.5
        m = [0.048, 0.12, 0.048]
        delta = [0.020, 0.020]
        Omega = 0.70
    elif name == "chatter":  # paper Sect. 4.4, m1 = 50 g, R_m = 3, delta = 5 mm
        m = [0.05, 0.15, 0.05]
        delta = [0.005, 0.005]
        Omega = 0.60
    else:
        raise ValueError(name)
    if omega_ratio is not None:
        Omega = omega_ratio
    k = [120.0, 120.0, 120.0]
    c = [0.02, 0.02, 0.02]
    A = 0.08
    mu = 0.6
    w = Omega * math.sqrt(k[0] / m[0])
    return dict(name=name, m=m, k=k, c=c, delta=delta, A=A, mu=mu,
                Omega=Omega, w=w, T=2.0 * math.pi / w)


class SimFailure(RuntimeError):
    pass


# --------------------------------------------------------------------------
# the simulator
# --------------------------------------------------------------------------

class Simulator:
    def __init__(self, case, method="DOP853", rtol=1e-10, atol=1e-12,
                 max_step=None, v_stick=1e-5, max_events_per_period=20000,
                 max_wall=600.0, pen_tol=1e-12, gap_tol=1e-11,
                 record_impacts=False, guards=True):
        self.p = case
        self.n = len(case["m"])
        self.m = [float(v) for v in case["m"]]
        self.k = [float(v) for v in case["k"]]
        self.c = [float(v) for v in case["c"]]
        self.delta = [float(v) for v in case["delta"]]
        self.A, self.w, self.mu, self.T = case["A"], case["w"], case["mu"], case["T"]
        self.method, self.rtol, self.atol = method, rtol, atol
        self.max_step = max_step if max_step else np.inf
        self.v_stick = v_stick
        self.max_epp = max_events_per_period
        self.max_wall = max_wall
        self.pen_tol = pen_tol      # a gap minimum below -pen_tol is a missed contact
        self.gap_tol = gap_tol      # gaps below this count as closed at an impact
        self.record = record_impacts
        self.guards = guards        # first-step limit after rebounds + repair of missed contacts
                                    # (gap minima are monitored either way)
        self.impacts = []           # (t, contact 1-based, closing speed)
        self.strobe = []            # (n, x) at t = nT
        self.stuck = [False] * (self.n - 1)
        self.counts = dict(impacts=0, sticks=0, releases=0, grazing_repairs=0,
                           hops=0, segments=0, nfev=0, steps=0)
        self.max_penetration = 0.0  # most negative gap seen (m), as a positive number

    # ---- clusters --------------------------------------------------------
    def groups(self):
        g, cur = [], [0]
        for j in range(self.n - 1):
            if self.stuck[j]:
                cur.append(j + 1)
            else:
                g.append(cur)
                cur = [j + 1]
        g.append(cur)
        return g

    def free_forces(self, t, y):
        n = self.n
        yb = self.A * math.sin(self.w * t)
        vb = self.A * self.w * math.cos(self.w * t)
        return [-(self.c[i] * (y[n + i] - vb) + self.k[i] * (y[i] - yb)) for i in range(n)]

    def accelerations(self, t, y, groups):
        f = self.free_forces(t, y)
        acc = [0.0] * self.n
        for g in groups:
            if len(g) == 1:
                i = g[0]
                acc[i] = f[i] / self.m[i]
            else:
                aG = sum(f[i] for i in g) / sum(self.m[i] for i in g)
                for i in g:
                    acc[i] = aG
        return acc

    def contact_force(self, t, y, j, groups=None):
        """Compressive force at stuck contact j (between mass j and j+1)."""
        if groups is None:
            groups = self.groups()
        g = next(g for g in groups if j in g)
        f = self.free_forces(t, y)
        aG = sum(f[i] for i in g) / sum(self.m[i] for i in g)
        return sum(self.m[i] * aG - f[i] for i in g if i <= j)

    # ---- one smooth segment ---------------------------------------------
    def make_rhs(self, groups):
        n, m, k, c = self.n, self.m, self.k, self.c
        A, w = self.A, self.w
        singles = [(g[0], m[g[0]]) for g in groups if len(g) == 1]
        multis = [(g, sum(m[i] for i in g)) for g in groups if len(g) > 1]

        def rhs(t, y):
            yb = A * math.sin(w * t)
            vb = A * w * math.cos(w * t)
            out = [0.0] * (2 * n)
            for i in range(n):
                out[i] = y[n + i]
            for i, mi in singles:
                out[n + i] = -(c[i] * (y[n + i] - vb) + k[i] * (y[i] - yb)) / mi
            for g, M in multis:
                F = 0.0
                for i in g:
                    F -= c[i] * (y[n + i] - vb) + k[i] * (y[i] - yb)
                aG = F / M
                for i in g:
                    out[n + i] = aG
            return out
        return rhs

    def make_events(self):
        n = self.n
        ev, kinds = [], []
        groups = self.groups()
        for j in range(n - 1):
            if not self.stuck[j]:
                dj = self.delta[j]
                def close(t, y, j=j, dj=dj):
                    return dj - (y[j + 1] - y[j])
                close.terminal = True
                close.direction = -1
                ev.append(close)
                kinds.append(("close", j))

                def gmin(t, y, j=j):  # d_j' ; rising through zero = gap minimum
                    return y[n + j] - y[n + j + 1]
                gmin.terminal = False
                gmin.direction = 1
                ev.append(gmin)
                kinds.append(("min", j))
            else:
                def release(t, y, j=j, groups=groups):
                    return self.contact_force(t, y, j, groups)
                release.terminal = True
                release.direction = -1
                ev.append(release)
                kinds.append(("release", j))
        return ev, kinds

    def gap(self, y, j):
        return self.delta[j] - (y[j + 1] - y[j])

    # ---- impacts and sticking -------------------------------------------
    def cluster_of(self, i, upward):
        """Masses stuck to mass i on its upper (upward=True) or lower side."""
        g = [i]
        if upward:
            while i > 0 and self.stuck[i - 1]:
                i -= 1
                g.append(i)
        else:
            while i < self.n - 1 and self.stuck[i]:
                i += 1
                g.append(i)
        return g

    def resolve_impacts(self, t, y, hit):
        """Pairwise Newton impacts until no closed contact approaches.

        hit: contact that closed (event) -- always treated as closed.
        Returns number of Newton impacts applied.
        """
        n = self.n
        v = y[n:]
        closed = [j for j in range(n - 1)
                  if not self.stuck[j] and (j == hit or self.gap(y, j) <= self.gap_tol)]
        applied = 0
        for _ in range(100000):
            best, bu = None, 0.0
            for j in closed:
                u = v[j + 1] - v[j]
                if u > bu:
                    best, bu = j, u
            if best is None:
                break
            j = best
            P = self.cluster_of(j, True)
            Q = self.cluster_of(j + 1, False)
            Mp = sum(self.m[i] for i in P)
            Mq = sum(self.m[i] for i in Q)
            Vp = sum(self.m[i] * v[i] for i in P) / Mp
            Vq = sum(self.m[i] * v[i] for i in Q) / Mq
            mu = self.mu
            Vp2 = ((Mp - mu * Mq) * Vp + Mq * (1 + mu) * Vq) / (Mp + Mq)
            Vq2 = (Mp * (1 + mu) * Vp + (Mq - mu * Mp) * Vq) / (Mp + Mq)
            for i in P:
                v[i] = Vp2
            for i in Q:
                v[i] = Vq2
            applied += 1
            self.counts["impacts"] += 1
            if self.record:
                self.impacts.append((t, j + 1, bu))
        else:
            raise SimFailure("simultaneous-impact resolution did not converge at t=%.9g" % t)
        # sticking: closed contacts left with (near-)zero relative velocity
        for j in closed:
            if self.stuck[j]:
                continue
            if abs(v[j + 1] - v[j]) < self.v_stick:
                P = self.cluster_of(j, True)
                Q = self.cluster_of(j + 1, False)
                M = sum(self.m[i] for i in P + Q)
                V = sum(self.m[i] * v[i] for i in P + Q) / M
                for i in P + Q:
                    v[i] = V
                self.stuck[j] = True
                # snap the gap shut (moves the lower cluster by <= gap_tol)
                shift = self.gap(y, j)
                if shift != 0.0:
                    for i in Q:
                        y[i] += shift
                if self.contact_force(t, y, j) > 0.0:
                    self.counts["sticks"] += 1
                else:
                    self.stuck[j] = False   # tensile: contact opens at zero speed
        return applied

    def check_releases(self, t, y):
        """Release stuck contacts whose force is not compressive (iteratively)."""
        released = 0
        while True:
            groups = self.groups()
            worst, wN = None, 0.0
            for j in range(self.n - 1):
                if self.stuck[j]:
                    N = self.contact_force(t, y, j, groups)
                    if N <= wN:
                        worst, wN = j, N
            if worst is None:
                return released
            self.stuck[worst] = False
            released += 1
            self.counts["releases"] += 1

    def safe_first_step(self, t, y):
        """Limit the first step after a rebound so it cannot skip the re-contact."""
        n = self.n
        acc = self.accelerations(t, y, self.groups())
        h = None
        for j in range(n - 1):
            if self.stuck[j] or self.gap(y, j) > 1e-9:
                continue
            r = y[n + j] - y[n + j + 1]        # d_j' > 0: opening speed
            a = acc[j] - acc[j + 1]            # d_j''
            if r > 0.0 and a < 0.0:
                hj = 0.5 * r / (-a)
                h = hj if h is None else min(h, hj)
        return h

    # ---- main loop -------------------------------------------------------
    def run(self, periods):
        n, T = self.n, self.T
        t = 0.0
        y = np.zeros(2 * n)                  # at rest at x = 0
        t_end = periods * T
        self.strobe = [(0, list(y[:n]))]
        next_strobe = 1
        ev_in_period = {}
        first_step = None
        zero_len = 0
        self.cpu_s = None
        cpu0 = time.process_time()
        wall0 = time.perf_counter()
        while t < t_end * (1 - 1e-15):
            if time.perf_counter() - wall0 > self.max_wall:
                raise SimFailure("wall-time cap %.3g s exceeded at t=%.6g (period %d)"
                                 % (self.max_wall, t, int(t / T)))
            # segments end at period boundaries (strobe, and wall-clock checks)
            seg_end = min(t_end, next_strobe * T)
            if seg_end - t < 1e-14:
                seg_end = min(t_end, (next_strobe + 1) * T)
            rhs = self.make_rhs(self.groups())
            events, kinds = self.make_events()
            opts = dict(method=self.method, rtol=self.rtol, atol=self.atol,
                        max_step=self.max_step, events=events, dense_output=True)
            if first_step is not None:
                opts["first_step"] = min(first_step, seg_end - t)
            sol = solve_ivp(rhs, (t, seg_end), y, **opts)
            self.counts["segments"] += 1
            self.counts["nfev"] += sol.nfev
            self.counts["steps"] += len(sol.t) - 1
            if sol.status < 0:
                raise SimFailure("solve_ivp failed at t=%.9g: %s" % (t, sol.message))
            t_stop = sol.t[-1]
            y_stop = sol.y[:, -1].copy()
            term = None
            if sol.status == 1:
                for e, (kind, j) in enumerate(kinds):
                    if kind != "min" and len(sol.t_events[e]):
                        term = (kind, j)
            # ---- self-check: did any open gap dip below zero inside a step?
            miss = None
            for e, (kind, j) in enumerate(kinds):
                if kind != "min":
                    continue
                for tm, ym in zip(sol.t_events[e], sol.y_events[e]):
                    dm = self.gap(ym, j)
                    if dm < 0.0:
                        self.max_penetration = max(self.max_penetration, -dm)
                    if self.guards and dm < -self.pen_tol and tm < t_stop:
                        # locate the crossing inside the step containing tm
                        idx = np.searchsorted(sol.t, tm) - 1
                        ta = sol.t[max(idx, 0)]
                        fa = self.gap(sol.sol(ta), j)
                        if fa < 0.0:
                            raise SimFailure("gap %d negative (%.3g m) at step start t=%.9g: a "
                                             "contact was missed (rebounds below the floating-point "
                                             "resolution of the gap? raise --v-stick)"
                                             % (j + 1, fa, ta))
                        tc = brentq(lambda s: self.gap(sol.sol(s), j), ta, tm,
                                    xtol=4e-16 * max(1.0, abs(tm)), rtol=4 * np.finfo(float).eps)
                        if miss is None or tc < miss[0]:
                            miss = (tc, j)
                        break
            if miss is not None:
                tc, j = miss
                t_stop = tc
                y_stop = np.array(sol.sol(tc))
                term = ("close", j)
                self.counts["grazing_repairs"] += 1
            for j in range(n - 1):
                if not self.stuck[j]:
                    d = self.gap(y_stop, j)
                    if d < 0.0:
                        self.max_penetration = max(self.max_penetration, -d)
            # ---- strobe
            if term is None:
                if abs(t_stop - next_strobe * T) < 1e-12 * max(1.0, t_stop):
                    self.strobe.append((next_strobe, list(y_stop[:n])))
                    next_strobe += 1
                t, y = t_stop, y_stop
                first_step = None
                zero_len = 0
                continue
            # ---- event handling
            pidx = int(t_stop / T)
            ev_in_period[pidx] = ev_in_period.get(pidx, 0) + 1
            if ev_in_period[pidx] > self.max_epp:
                raise SimFailure("more than %d events in period %d (t=%.9g): chatter not resolved"
                                 % (self.max_epp, pidx, t_stop))
            kind, j = term
            acted = False
            if kind == "close":
                applied = self.resolve_impacts(t_stop, y_stop, j)
                acted = applied > 0 or self.stuck[j]
            elif kind == "release":
                self.stuck[j] = False
                self.counts["releases"] += 1
                acted = True
            self.check_releases(t_stop, y_stop)
            if t_stop - t <= 1e-13 * max(1.0, t) and not acted:
                zero_len += 1
            else:
                zero_len = 0
            if zero_len >= 2:
                # an event at the restart time that changes nothing: hop over it
                self.counts["hops"] += 1
                hop = min(1e-9 * T, seg_end - t_stop)
                s2 = solve_ivp(self.make_rhs(self.groups()), (t_stop, t_stop + hop), y_stop,
                               method=self.method, rtol=self.rtol, atol=self.atol)
                y_stop = s2.y[:, -1].copy()
                t_stop = s2.t[-1]
                if zero_len > 10:
                    raise SimFailure("stuck at t=%.12g on event %s" % (t_stop, term))
            t, y = t_stop, y_stop
            first_step = self.safe_first_step(t, y) if self.guards else None
        wall = time.perf_counter() - wall0
        self.cpu_s = time.process_time() - cpu0
        return wall


# --------------------------------------------------------------------------
# reference check
# --------------------------------------------------------------------------

def load_reference():
    imp = []
    with open(os.path.join(REF_DIR, "default-case-impacts.csv")) as f:
        for row in csv.DictReader(f):
            imp.append((float(row["time_s"]), int(row["contact"]), float(row["rel_velocity_m_s"])))
    strobe = []
    with open(os.path.join(REF_DIR, "default-case-strobe.csv")) as f:
        for row in csv.DictReader(f):
            strobe.append((int(row["period"]), [float(row["x1_m"]), float(row["x2_m"]), float(row["x3_m"])]))
    return imp, strobe


def check_reference(args):
    case = make_case("default")
    sim = make_sim(case, args, record=True)
    wall = sim.run(40)
    ref, ref_strobe = load_reference()
    got = sim.impacts
    n_common = min(len(ref), len(got))
    first_mismatch = None
    for i in range(n_common):
        if ref[i][1] != got[i][1] or abs(ref[i][0] - got[i][0]) > 1e-6:
            first_mismatch = i
            break
    seq_match = first_mismatch is None and len(ref) == len(got)
    upto = n_common if first_mismatch is None else first_mismatch
    dts = [abs(ref[i][0] - got[i][0]) for i in range(upto)]
    dvs = [abs(ref[i][2] - got[i][2]) for i in range(upto)]
    rdv = [abs(ref[i][2] - got[i][2]) / ref[i][2] for i in range(upto)]
    sdx = [max(abs(a - b) for a, b in zip(rs[1], gs[1]))
           for rs, gs in zip(ref_strobe, sim.strobe)]
    out = dict(check="default-case reference, 40 periods",
               method=sim.method, rtol=sim.rtol, atol=sim.atol,
               max_step=None if sim.max_step == np.inf else sim.max_step,
               ref_impacts=len(ref), impacts=len(got), sequence_match=seq_match,
               first_mismatch_index=first_mismatch,
               max_abs_dt_s=max(dts) if dts else None,
               max_abs_dv_m_s=max(dvs) if dvs else None,
               max_rel_dv=max(rdv) if rdv else None,
               strobe_points=len(sdx), max_strobe_dx_m=max(sdx) if sdx else None,
               max_penetration_m=sim.max_penetration,
               wall_s=wall, **{k: v for k, v in sim.counts.items() if k != "impacts"})
    if first_mismatch is not None:
        i = first_mismatch
        out["mismatch"] = dict(ref=ref[i], got=got[i])
    print(json.dumps(out))
    ok = seq_match and max(dts) < 1e-8   # reference impact times are good to ~1e-9 s
    print("REFERENCE CHECK: %s  (%d/%d impacts, sequence %s, max |dt| = %.3g s, "
          "max |dv| = %.3g m/s, max strobe |dx| = %.3g m)"
          % ("PASS" if ok else "FAIL", len(got), len(ref),
             "matches" if seq_match else "DIFFERS at %s" % first_mismatch,
             max(dts) if dts else float("nan"), max(dvs) if dvs else float("nan"),
             max(sdx) if sdx else float("nan")), file=sys.stderr)
    return 0 if ok else 1


def make_sim(case, args, record=False):
    return Simulator(case, method=args.method, rtol=args.rtol, atol=args.atol,
                     max_step=(args.max_step * case["T"]) if args.max_step else None,
                     v_stick=args.v_stick, max_events_per_period=args.max_events_per_period,
                     max_wall=args.max_wall, record_impacts=record or args.dump_impacts is not None,
                     guards=not args.naive)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", choices=["default", "chatter"], default="default")
    ap.add_argument("--periods", type=float, default=100)
    ap.add_argument("--omega-ratio", type=float, default=None,
                    help="excitation frequency ratio Ω = ω/√(k1/m1) instead of the case's own")
    ap.add_argument("--method", default="DOP853", choices=["DOP853", "RK45", "Radau", "LSODA"])
    ap.add_argument("--rtol", type=float, default=1e-10)
    ap.add_argument("--atol", type=float, default=1e-12)
    ap.add_argument("--max-step", type=float, default=None,
                    help="maximum step as a fraction of the excitation period (e.g. 5e-4 = T/2000)")
    ap.add_argument("--v-stick", type=float, default=1e-5,
                    help="rebound speed (m/s) below which a contact sticks (chatter cut-off)")
    ap.add_argument("--max-events-per-period", type=int, default=20000)
    ap.add_argument("--max-wall", type=float, default=600.0, help="wall-time cap (s)")
    ap.add_argument("--naive", action="store_true",
                    help="disable the first-step limit after rebounds and the repair of "
                         "contacts missed inside a step (gap minima are still monitored; "
                         "shows what the guards protect against)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="run N times (fresh simulator each); wall_s is the median")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--check-reference", action="store_true")
    ap.add_argument("--dump-impacts", metavar="CSV", default=None)
    args = ap.parse_args()
    if args.check_reference:
        sys.exit(check_reference(args))

    if args.omega_ratio is not None and not (args.omega_ratio > 0 and math.isfinite(args.omega_ratio)):
        sys.exit("--omega-ratio must be a positive number")
    case = make_case(args.case, args.omega_ratio)
    status, err, walls, cpus = "ok", None, [], []
    for _ in range(max(1, args.repeat)):
        sim = make_sim(case, args)      # fresh simulator for every run
        try:
            walls.append(sim.run(args.periods))
            cpus.append(sim.cpu_s)
        except SimFailure as e:
            status, err = "failed", str(e)
            break
    wall = float(np.median(walls)) if status == "ok" else None
    events = sim.counts["impacts"] + sim.counts["sticks"] + sim.counts["releases"]
    res = dict(tool="scipy-solve_ivp", case=args.case, omega_ratio=case["Omega"], status=status, error=err,
               method=sim.method, rtol=sim.rtol, atol=sim.atol,
               max_step=None if sim.max_step == np.inf else sim.max_step,
               periods=args.periods, events=events, impacts=sim.counts["impacts"],
               sticks=sim.counts["sticks"], releases=sim.counts["releases"],
               grazing_repairs=sim.counts["grazing_repairs"], hops=sim.counts["hops"],
               segments=sim.counts["segments"], steps=sim.counts["steps"],
               nfev=sim.counts["nfev"], max_penetration_m=sim.max_penetration,
               wall_s=wall, wall_runs_s=walls,
               cpu_s=float(np.median(cpus)) if status == "ok" else None, events_per_s=events / wall if status == "ok" else None,
               periods_per_s=args.periods / wall if status == "ok" else None,
               python=sys.version.split()[0], numpy=np.__version__, scipy=scipy.__version__)
    if sim.max_penetration > 1e-9:
        status = res["status"] = "invalid"
        err = res["error"] = "masses interpenetrated"
        res["warning"] = ("gaps went negative by up to %.3g m: contacts were missed and masses "
                          "passed through each other; results are wrong" % sim.max_penetration)
        print("WARNING: " + res["warning"], file=sys.stderr)
    if args.dump_impacts:
        with open(args.dump_impacts, "w") as f:
            f.write("time_s,contact,rel_velocity_m_s\n")
            for t, j, u in sim.impacts:
                f.write("%.12f,%d,%.9f\n" % (t, j, u))
    if args.json:
        print(json.dumps(res))
    else:
        for k, v in res.items():
            print("%-18s %s" % (k, v))
    if status != "ok":
        print("FAILURE: " + err, file=sys.stderr)
        sys.exit(2 if status == "failed" else 3)


if __name__ == "__main__":
    main()
