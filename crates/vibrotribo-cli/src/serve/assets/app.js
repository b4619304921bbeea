// The vibrotribo explorer: parameter fields built from the configuration schema, the run view,
// the orbit diagram, the power map and the basins, all computed by the server's API
// (POST /api/run, /api/orbit, /api/map, /api/basins) and plotted with uPlot.
"use strict";

const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
  "#17becf", "#bcbd22", "#7f7f7f"];

// The state the URL carries: the overrides, the grid views' forms, the orbit diagram's zoomed
// region and whether its continuation branches are shown.
const state = { set: {}, orbit: null, map: null, basins: null, orbitRange: null, branches: false };
let schema = null;
let lastRun = null;
const busy = new Map();

// ---- status -------------------------------------------------------------------------------

function setBusy(what, text) {
  if (text == null) busy.delete(what); else busy.set(what, text);
  const el = document.getElementById("status") || document.querySelector("[data-testid=status]");
  if (busy.size === 0) {
    el.textContent = "idle";
    el.dataset.state = "idle";
  } else {
    el.textContent = [...busy.values()].join(" · ");
    el.dataset.state = "busy";
  }
}

// ---- API ----------------------------------------------------------------------------------

// A request's sequence number: the page's clock in microseconds, increasing with each request,
// so that the server never lets a request sent earlier supersede one sent later.
let lastSeq = 0;
function nextSeq() {
  lastSeq = Math.max(lastSeq + 1, Math.floor((performance.timeOrigin + performance.now()) * 1000));
  return lastSeq;
}

async function post(path, body, signal) {
  const r = await fetch(path, {
    method: "POST", headers: { "Content-Type": "application/json" },
    body: JSON.stringify(body), signal,
  });
  if (!r.ok) {
    let message = r.statusText;
    try { message = (await r.json()).error; } catch (_) { /* not JSON */ }
    const e = new Error(message);
    e.status = r.status;
    throw e;
  }
  return r;
}

// Reads a stream of JSON lines, calling `onLine` with each.
async function readLines(response, onLine) {
  const reader = response.body.getReader();
  const decoder = new TextDecoder();
  let buffer = "";
  for (;;) {
    const { value, done } = await reader.read();
    if (done) break;
    buffer += decoder.decode(value, { stream: true });
    let nl;
    while ((nl = buffer.indexOf("\n")) >= 0) {
      const line = buffer.slice(0, nl);
      buffer = buffer.slice(nl + 1);
      if (line.trim()) onLine(JSON.parse(line));
    }
  }
}

// ---- URL state ----------------------------------------------------------------------------

function saveUrl() {
  const s = encodeURIComponent(JSON.stringify(state));
  history.replaceState(null, "", "#" + s);
}

function loadUrl() {
  if (location.hash.length < 2) return;
  try {
    const s = JSON.parse(decodeURIComponent(location.hash.slice(1)));
    Object.assign(state, s);
  } catch (_) { /* a bad link: start from the configuration */ }
}

function formValues(form) {
  const out = {};
  for (const el of form.elements) if (el.name) out[el.name] = el.value;
  return out;
}

function fillForm(form, values) {
  if (!values) return;
  for (const el of form.elements) if (el.name && values[el.name] != null) el.value = values[el.name];
}

// ---- parameters ---------------------------------------------------------------------------

function fieldOf(key) {
  return document.querySelector(`[data-testid="param-${CSS.escape(key)}"]`);
}

function buildParams() {
  const aside = document.getElementById("params");
  aside.textContent = "";
  let section = null;
  for (const k of schema.keys) {
    const sec = k.key.split(".")[0];
    if (sec !== section) {
      section = sec;
      const h = document.createElement("h3");
      h.textContent = "[" + sec + "]";
      aside.appendChild(h);
    }
    const row = document.createElement("div");
    row.className = "param";
    const label = document.createElement("label");
    label.textContent = k.key.slice(sec.length + 1) + " ";
    const unit = document.createElement("span");
    unit.className = "unit";
    unit.textContent = k.unit === "—" ? "" : "(" + k.unit + ")";
    label.appendChild(unit);
    label.title = k.meaning + "\nallowed: " + k.allowed + "\ndefault: " + (k.default ?? k.absent);
    const input = document.createElement("input");
    input.type = "text";
    input.dataset.testid = "param-" + k.key;
    input.dataset.key = k.key;
    input.value = state.set[k.key] ?? k.value ?? "";
    input.placeholder = (k.default ?? k.absent).replace(/[`"]/g, "");
    input.title = label.title;
    if (k.given || k.key in state.set) input.classList.add("given");
    if (k.choices.length) {
      const list = document.createElement("datalist");
      list.id = "choices-" + k.key;
      for (const c of k.choices) {
        const o = document.createElement("option");
        o.value = c;
        list.appendChild(o);
      }
      row.appendChild(list);
      input.setAttribute("list", list.id);
    }
    const error = document.createElement("span");
    error.className = "error";
    error.dataset.testid = "error-" + k.key;
    input.addEventListener("change", () => applyField(input, error, k));
    input.addEventListener("keydown", (e) => { if (e.key === "Enter") applyField(input, error, k); });
    label.htmlFor = input.id = "param-" + k.key;
    row.append(label, input, error);
    aside.appendChild(row);
  }
}

// Applies a field's value: checked by the engine first (its error shown next to the field and
// nothing run), then the run view recomputed.
const fieldSeq = {};

async function applyField(input, error, k) {
  const seq = fieldSeq[k.key] = (fieldSeq[k.key] || 0) + 1;
  const text = input.value.trim();
  const original = k.value ?? "";
  const candidate = { ...state.set };
  if (text === "" || (text === original && !(k.key in state.set))) delete candidate[k.key];
  else candidate[k.key] = text;
  if (JSON.stringify(candidate) === JSON.stringify(state.set) && !error.textContent) return;
  setBusy("check", "checking");
  try {
    await post("/api/check", { set: candidate });
  } catch (e) {
    if (seq !== fieldSeq[k.key]) return;
    error.textContent = e.message;
    input.setAttribute("aria-invalid", "true");
    return;
  } finally {
    if (seq === fieldSeq[k.key]) setBusy("check", null);
  }
  // A newer value of this field was entered meanwhile: it decides.
  if (seq !== fieldSeq[k.key]) return;
  error.textContent = "";
  input.removeAttribute("aria-invalid");
  input.classList.toggle("given", k.key in candidate || k.given);
  state.set = candidate;
  saveUrl();
  scheduleRun();
  updateCommand();
}

// Sets `key` to `value` (a click in the orbit diagram) and recomputes the run.
function setParam(key, value) {
  const input = fieldOf(key);
  if (input) input.value = String(value);
  state.set = { ...state.set, [key]: String(value) };
  saveUrl();
  scheduleRun(0);
  updateCommand();
}

// Axis labels of numbers of any size (a power of 1e-5 W is not 0).
function tickValues(u, values) {
  return values.map((v) => {
    if (v == null) return "";
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-2 || a >= 1e5) ? v.toExponential(1) : String(+v.toPrecision(4));
  });
}
const AXES = [{}, { values: tickValues, size: 60 }];

// ---- run view -----------------------------------------------------------------------------

let runTimer = null;
let runAbort = null;
let runSeq = 0;
const charts = {};

function scheduleRun(delay = 80) {
  clearTimeout(runTimer);
  setBusy("run", "computing the run");
  runTimer = setTimeout(() => { runTimer = null; computeRun(); }, delay);
}

async function computeRun() {
  if (runAbort) runAbort.abort();
  const abort = runAbort = new AbortController();
  const seq = ++runSeq;
  setBusy("run", "computing the run");
  try {
    const r = await post("/api/run", { set: state.set, seq: nextSeq() }, abort.signal);
    const view = await r.json();
    if (seq !== runSeq) return;
    lastRun = view;
    showRun(view);
    document.getElementById("run-error").textContent = "";
  } catch (e) {
    if (e.name === "AbortError") return;
    // Stopped by a request the server handled after this one (an older one, abandoned by
    // this page): still the latest here, so ask again.
    if (e.status === 409) { if (seq === runSeq) scheduleRun(0); return; }
    if (seq === runSeq) document.getElementById("run-error").textContent = e.message;
  } finally {
    if (seq === runSeq && runTimer === null) setBusy("run", null);
  }
}

function lineChart(id, title, x, columns, labels, extra) {
  const el = document.getElementById(id);
  const series = [{ label: "t (s)" }];
  labels.forEach((l, i) => series.push({ label: l, stroke: COLORS[i % COLORS.length], width: 1,
    points: { show: false } }));
  const data = [x, ...columns];
  if (extra) {
    series.push(extra.series);
  }
  const opts = {
    title, width: 520, height: 220, scales: { x: { time: false } }, series, axes: AXES,
    legend: { show: true }, cursor: { drag: { x: true, y: false } },
  };
  const aligned = extra ? uPlot.join([data, extra.data]) : data;
  if (charts[id]) charts[id].destroy();
  charts[id] = new uPlot(opts, aligned, el);
}

function showRun(view) {
  const power = view.average_power_w;
  const el = document.getElementById("power-value");
  el.dataset.value = power == null ? "" : String(power);
  el.textContent = power == null ? "— (no harvester power)" : power.toPrecision(6) + " W";
  const s = view.summary;
  document.getElementById("impacts").textContent =
    `${s.impacts} after the transient (${s.impacts_per_period.toFixed(3)} per period)`;
  const m = s.motion;
  document.getElementById("motion").textContent = m == null ? "not classified"
    : m.motion + (m.motion === "periodic" ? ` (period ${m.period})` : "");
  const d = view.samples;
  const n = d.x.length;
  const impacts = { t: [], zero: [] };
  view.events.t.forEach((t, i) => {
    if (view.events.kind[i] === "impact") { impacts.t.push(t); impacts.zero.push(0); }
  });
  const ev = {
    series: { label: "impacts", stroke: "#000", fill: "#000", paths: () => null,
      points: { show: true, size: 4 } },
    data: [impacts.t, impacts.zero],
  };
  lineChart("chart-x", "positions x_i (m)", d.t, d.x, d.x.map((_, i) => `x${i + 1}`));
  lineChart("chart-gaps", "gaps d_k (m), impacts marked", d.t, d.gaps,
    d.gaps.map((_, i) => `d${i + 1}`), ev);
  lineChart("chart-voltage", "load voltage (V)", d.t, [d.voltage], ["V"]);
  lineChart("chart-power", "power into the load V·I (W)", d.t, [d.power], ["P"]);
  // Phase portrait of m1 after the transient.
  const t0 = s.transient_periods * s.excitation_period_s;
  const start = d.t.findIndex((t) => t >= t0);
  const xs = d.x[0].slice(Math.max(start, 0));
  const vs = d.v[0].slice(Math.max(start, 0));
  const el2 = document.getElementById("chart-phase");
  if (charts.phase) charts.phase.destroy();
  charts.phase = new uPlot({
    title: "phase portrait of m1 after the transient", mode: 2, width: 520, height: 220,
    scales: { x: { time: false } },
    axes: [{ label: "x1 (m)", values: tickValues }, { label: "v1 (m/s)", values: tickValues, size: 60 }],
    series: [{}, { label: "m1", stroke: COLORS[0], fill: COLORS[0], paths: uPlot.paths.points(),
      points: { show: false, size: 2, width: 0 } }],
    legend: { show: false },
  }, [null, [xs, vs]], el2);
  void n;
}

// ---- orbit diagram ------------------------------------------------------------------------

let orbitAbort = null;
let orbitChart = null;
let orbitPoints = [];
let orbitRange = null;
let orbitBranches = null;
let branchesAbort = null;

// Bifurcation kinds: legend name and colour.
const BIFURCATIONS = {
  fold: ["fold", "#ff7f0e"], branch_point: ["branch point", "#9467bd"],
  period_doubling: ["period doubling", "#2ca02c"], neimark_sacker: ["Neimark–Sacker", "#e377c2"],
  grazing: ["grazing", "#8c564b"], sticking: ["sticking", "#bcbd22"],
  sequence_change: ["sequence change", "#17becf"], other: ["other", "#7f7f7f"],
};

// The branches as uPlot series: a line per section point and run of equal stability (stable
// solid, unstable dashed), then the bifurcations, a point series per kind.
function branchSeries(mass) {
  const out = [];
  if (!orbitBranches) return out;
  let stableNamed = false, unstableNamed = false;
  for (const b of orbitBranches.branches) {
    const pts = b.points;
    for (let k = 0; k < b.period; k++) {
      let start = 0;
      while (start < pts.length) {
        const stable = pts[start].stable;
        let end = start;
        while (end + 1 < pts.length && pts[end + 1].stable === stable) end++;
        const stop = Math.min(end + 1, pts.length - 1);
        const xs = [], ys = [];
        for (let j = start; j <= stop; j++) {
          const y = (pts[j].sections[mass] || [])[k];
          if (y != null) { xs.push(pts[j].param); ys.push(y); }
        }
        const named = stable ? stableNamed : unstableNamed;
        if (stable) stableNamed = true; else unstableNamed = true;
        out.push({
          label: named ? "" : (stable ? "stable branch" : "unstable branch"),
          stroke: stable ? "#000" : "#d62728", width: 2, dash: stable ? undefined : [6, 4],
          paths: uPlot.paths.linear(), points: { show: false }, data: [xs, ys], kind: "branch",
        });
        start = end + 1;
      }
    }
  }
  const kinds = new Map();
  for (const f of orbitBranches.bifurcations) {
    const [label, color] = BIFURCATIONS[f.kind] || BIFURCATIONS.other;
    if (!kinds.has(f.kind)) kinds.set(f.kind, { label, color, xs: [], ys: [] });
    const m = kinds.get(f.kind);
    for (const y of f.sections[mass] || []) { m.xs.push(f.param); m.ys.push(y); }
  }
  for (const m of kinds.values()) {
    out.push({ label: m.label, stroke: m.color, fill: m.color, paths: uPlot.paths.points(),
      points: { show: false, size: 11, width: 0 }, data: [m.xs, m.ys], kind: "bifurcation" });
  }
  return out;
}

function motionClass(p) {
  if (p.error && !p.strobe.length) return "failed";
  const m = p.motion && p.motion.motion;
  if (m === "periodic") return "period " + p.motion.period;
  return m || (p.period ? "period " + p.period : "undetermined");
}

function orbitSeries() {
  const classes = [...new Set(orbitPoints.map(motionClass))].sort();
  const mass = Math.max(1, parseInt(document.querySelector("#orbit-form [name=mass]").value, 10) || 1);
  return classes.map((c, k) => {
    const xs = [], ys = [];
    for (const p of orbitPoints) {
      if (motionClass(p) !== c) continue;
      const n = p.masses;
      for (let j = mass - 1; j < p.strobe.length; j += n) { xs.push(p.x); ys.push(p.strobe[j]); }
    }
    return { label: c, color: COLORS[k % COLORS.length], data: [xs, ys] };
  });
}

function drawOrbit() {
  const el = document.getElementById("chart-orbit");
  const groups = orbitSeries();
  const mass = Math.max(1, parseInt(document.querySelector("#orbit-form [name=mass]").value, 10) || 1);
  const overlay = branchSeries(mass - 1);
  const series = [{}].concat(groups.map((g) => ({
    label: g.label, stroke: g.color, fill: g.color, paths: uPlot.paths.points(),
    points: { show: false, size: 3, width: 0 },
  })), overlay.map(({ data, kind, ...rest }) => rest));
  const data = [null].concat(groups.map((g) => g.data), overlay.map((o) => o.data));
  const param = state.orbit ? state.orbit.param : "";
  const range = orbitRange;
  if (orbitChart) orbitChart.destroy();
  orbitChart = new uPlot({
    mode: 2, width: 1060, height: 380,
    scales: { x: { time: false, auto: !range, range: range ? [range.x0, range.x1] : undefined },
      y: { auto: !range || range.y0 == null, range: range && range.y0 != null ? [range.y0, range.y1] : undefined } },
    axes: [{ label: param, values: tickValues }, { label: "x at t = nT (m)", values: tickValues, size: 60 }],
    series,
    cursor: { drag: { x: true, y: true, setScale: false } },
    hooks: { setSelect: [onOrbitSelect] },
  }, data, el);
  el.dataset.points = String(orbitPoints.length);
  el.dataset.branchLines = String(overlay.filter((o) => o.kind === "branch").length);
  el.dataset.bifurcations = String(overlay.filter((o) => o.kind === "bifurcation")
    .reduce((n, o) => n + o.data[0].length, 0));
  attachOrbitClick(el);
}

function onOrbitSelect(u) {
  const s = u.select;
  if (s.width < 4) return;
  const x0 = u.posToVal(s.left, "x"), x1 = u.posToVal(s.left + s.width, "x");
  const y1 = u.posToVal(s.top, "y"), y0 = u.posToVal(s.top + s.height, "y");
  u.setSelect({ left: 0, top: 0, width: 0, height: 0 }, false);
  const form = document.getElementById("orbit-form");
  form.elements.from.value = String(x0);
  form.elements.to.value = String(x1);
  orbitRange = { x0, x1, y0, y1 };
  computeOrbit(false);
  if (state.branches) computeBranches();
}

let clickBound = null;
function attachOrbitClick(el) {
  if (clickBound === el) return;
  clickBound = el;
  let down = null;
  el.addEventListener("mousedown", (e) => { down = [e.clientX, e.clientY]; });
  el.addEventListener("mouseup", (e) => {
    if (!down || !orbitChart) return;
    const moved = Math.hypot(e.clientX - down[0], e.clientY - down[1]);
    down = null;
    if (moved > 3 || orbitPoints.length === 0) return;
    const rect = orbitChart.over.getBoundingClientRect();
    const left = e.clientX - rect.left;
    if (left < 0 || left > rect.width || e.clientY < rect.top || e.clientY > rect.bottom) return;
    const v = orbitChart.posToVal(left, "x");
    let best = orbitPoints[0];
    for (const p of orbitPoints) if (Math.abs(p.x - v) < Math.abs(best.x - v)) best = p;
    setParam(state.orbit.param, best.x);
  });
}

// The continuation branches over the orbit diagram's range (POST /api/branches, what
// `vibrotribo continue` computes), drawn over its points.
async function computeBranches() {
  const f = formValues(document.getElementById("orbit-form"));
  state.branches = true;
  state.orbit = f;
  saveUrl();
  updateCommand();
  if (branchesAbort) branchesAbort.abort();
  const abort = branchesAbort = new AbortController();
  const progress = document.getElementById("branches-progress");
  progress.textContent = "continuing…";
  progress.dataset.state = "busy";
  setBusy("branches", "continuation");
  try {
    const r = await post("/api/branches", {
      set: state.set, param: f.param, from: Number(f.from), to: Number(f.to), seq: nextSeq(),
    }, abort.signal);
    const view = await r.json();
    if (abort !== branchesAbort) return;
    orbitBranches = view;
    const stable = view.rows.filter((row) => row[3] === "true").length;
    progress.textContent = `${view.branches.length} branch(es), ${view.rows.length} points `
      + `(${stable} stable), ${view.bifurcations.length} bifurcation(s)`;
    drawOrbit();
  } catch (e) {
    if (e.name !== "AbortError" && abort === branchesAbort) progress.textContent = "error: " + e.message;
  } finally {
    if (abort === branchesAbort) { setBusy("branches", null); progress.dataset.state = "idle"; }
  }
}

function hideBranches() {
  if (branchesAbort) branchesAbort.abort();
  branchesAbort = null;
  orbitBranches = null;
  state.branches = false;
  setBusy("branches", null);
  document.getElementById("branches-progress").textContent = "";
  saveUrl();
  updateCommand();
  drawOrbit();
}

async function computeOrbit(whole) {
  const form = document.getElementById("orbit-form");
  const f = formValues(form);
  if (whole) orbitRange = null;
  state.orbitRange = orbitRange;
  state.orbit = f;
  saveUrl();
  updateCommand();
  if (orbitAbort) orbitAbort.abort();
  const abort = orbitAbort = new AbortController();
  const req = {
    set: state.set,
    x: { param: f.param, from: Number(f.from), to: Number(f.to), steps: parseInt(f.steps, 10) },
    transient: f.transient === "" ? null : parseInt(f.transient, 10),
    recorded: f.recorded === "" ? null : parseInt(f.recorded, 10),
    seq: nextSeq(),
  };
  const progress = document.getElementById("orbit-progress");
  progress.textContent = "computing…";
  document.getElementById("orbit-diagram").dataset.state = "busy";
  orbitPoints = [];
  let total = 0, last = 0;
  setBusy("orbit", "orbit diagram");
  try {
    const r = await post("/api/orbit", req, abort.signal);
    let masses = 1;
    await readLines(r, (line) => {
      if (abort !== orbitAbort) return;
      if (line.kind === "start") { masses = line.masses; total = line.xs.length; }
      else if (line.kind === "point") {
        line.masses = masses;
        orbitPoints.push(line);
        progress.textContent = `${orbitPoints.length} of ${total} values`;
        setBusy("orbit", `orbit diagram ${orbitPoints.length}/${total}`);
        const now = performance.now();
        if (now - last > 150) { last = now; drawOrbit(); }
      } else if (line.kind === "end") {
        progress.textContent = `${line.done} of ${total} values in ${line.elapsed_s.toFixed(2)} s`
          + (line.complete ? "" : " (stopped)");
      }
    });
    if (abort === orbitAbort) drawOrbit();
  } catch (e) {
    if (e.name !== "AbortError") progress.textContent = "error: " + e.message;
  } finally {
    if (abort === orbitAbort) {
      setBusy("orbit", null);
      document.getElementById("orbit-diagram").dataset.state = "idle";
    }
  }
}

// ---- power map and basins: grids painted coarse to fine -----------------------------------

function heatColor(t) {
  // A perceptual ramp (dark blue → yellow) for t in [0, 1].
  const stops = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  const u = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
  const i = Math.min(Math.floor(u), stops.length - 2), f = u - i;
  const c = stops[i].map((a, k) => Math.round(a + f * (stops[i + 1][k] - a)));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

// A grid view: a uPlot chart whose draw hook paints each computed cell over the area it
// stands for until a finer point arrives (coarse points first cover 2^k cells).
function gridView(id, colorOf) {
  const view = { cells: [], xs: [], ys: [], chart: null, abort: null };
  view.draw = () => {
    const el = document.getElementById(id);
    if (view.chart) view.chart.destroy();
    const dx = view.xs.length > 1 ? (view.xs[1] - view.xs[0]) : 1;
    const dy = view.ys.length > 1 ? (view.ys[1] - view.ys[0]) : 1;
    const xr = [view.xs[0] - dx / 2, view.xs[view.xs.length - 1] + dx / 2].sort((a, b) => a - b);
    const yr = [view.ys[0] - dy / 2, view.ys[view.ys.length - 1] + dy / 2].sort((a, b) => a - b);
    view.chart = new uPlot({
      mode: 2, width: 520, height: 400,
      scales: { x: { time: false, auto: false, range: xr }, y: { auto: false, range: yr } },
      axes: [{ label: view.xKey, values: tickValues }, { label: view.yKey, values: tickValues, size: 60 }],
      series: [{}, { label: "cells", paths: () => null, points: { show: false } }],
      legend: { show: false },
      hooks: {
        draw: [(u) => {
          const ctx = u.ctx;
          ctx.save();
          ctx.beginPath();
          ctx.rect(u.bbox.left, u.bbox.top, u.bbox.width, u.bbox.height);
          ctx.clip();
          for (const c of view.cells) {
            const span = c.span;
            const x0 = u.valToPos(c.x - dx / 2, "x", true), x1 = u.valToPos(c.x - dx / 2 + span * dx, "x", true);
            const y0 = u.valToPos(c.y - dy / 2, "y", true), y1 = u.valToPos(c.y - dy / 2 + span * dy, "y", true);
            ctx.fillStyle = colorOf(c, view);
            ctx.fillRect(Math.min(x0, x1), Math.min(y0, y1), Math.abs(x1 - x0) + 1, Math.abs(y1 - y0) + 1);
          }
          ctx.restore();
        }],
      },
    }, [null, [[], []]], el);
    el.dataset.cells = String(view.cells.length);
  };
  return view;
}

function coarseness(k) {
  if (k === 0) return 30;
  let z = 0;
  while ((k & 1) === 0) { k >>= 1; z++; }
  return z;
}

async function computeGrid(view, path, formId, key, progressId, onDone) {
  const f = formValues(document.getElementById(formId));
  state[key] = f;
  saveUrl();
  updateCommand();
  if (view.abort) view.abort.abort();
  const abort = view.abort = new AbortController();
  const req = {
    set: state.set,
    x: { param: f.x, from: Number(f.x_from), to: Number(f.x_to), steps: parseInt(f.x_steps, 10) },
    y: { param: f.y, from: Number(f.y_from), to: Number(f.y_to), steps: parseInt(f.y_steps, 10) },
    transient: f.transient === "" ? null : parseInt(f.transient, 10),
    recorded: f.recorded === "" ? null : parseInt(f.recorded, 10),
    seq: nextSeq(),
  };
  const progress = document.getElementById(progressId);
  progress.textContent = "computing…";
  view.cells = [];
  view.classes = null;
  view.xKey = f.x; view.yKey = f.y;
  let total = 0, last = 0;
  setBusy(key, key);
  try {
    const r = await post(path, req, abort.signal);
    await readLines(r, (line) => {
      if (abort !== view.abort) return;
      if (line.kind === "start") {
        view.xs = line.xs; view.ys = line.ys; total = line.xs.length * line.ys.length;
      } else if (line.kind === "point") {
        const level = Math.min(coarseness(line.i), coarseness(line.j), 4);
        line.span = Math.min(1 << level, view.xs.length - line.i, view.ys.length - line.j);
        view.cells.push(line);
        progress.textContent = `${view.cells.length} of ${total} points`;
        setBusy(key, `${key} ${view.cells.length}/${total}`);
        const now = performance.now();
        if (now - last > 200) { last = now; view.draw(); }
      } else if (line.kind === "classes") {
        view.classes = line;
      } else if (line.kind === "end") {
        progress.textContent = `${line.done} of ${total} points in ${line.elapsed_s.toFixed(2)} s`
          + (line.complete ? "" : " (stopped)");
      }
    });
    if (abort === view.abort) { view.draw(); if (onDone) onDone(view); }
  } catch (e) {
    if (e.name !== "AbortError") progress.textContent = "error: " + e.message;
  } finally {
    if (abort === view.abort) setBusy(key, null);
  }
}

function mapLegend(view) {
  const ps = view.cells.map((d) => d.average_power_w).filter((p) => p != null);
  document.getElementById("map-legend").textContent = ps.length === 0 ? "no power computed"
    : `colour: average power from ${Math.min(...ps).toExponential(3)} W (dark) to ${Math.max(...ps).toExponential(3)} W (light); grey: none`;
}

const mapView = gridView("chart-map", (c, view) => {
  const ps = view.cells.map((d) => d.average_power_w).filter((p) => p != null);
  if (c.average_power_w == null || ps.length === 0) return "#ccc";
  const lo = Math.min(...ps), hi = Math.max(...ps);
  return heatColor(hi > lo ? (c.average_power_w - lo) / (hi - lo) : 0.5);
});

// While the starts run, each is shown by its fingerprint's period (grey shades); when all
// have run, the server's classification (the attractors of `vibrotribo basins`) colours them.
function provisionalColor(c) {
  if (c.error || c.period == null) return "#fff";
  return c.period === 0 ? "#777" : ["#bbb", "#999", "#ddd", "#aaa"][(c.period - 1) % 4];
}

function attractorName(a) {
  const kind = a.period === 0 ? "non-periodic" : `period ${a.period}`;
  const power = a.average_power_w == null ? "" : `, ${a.average_power_w.toPrecision(4)} W`;
  return `A${a.attractor}: ${kind}, ${a.impacts_per_period.toFixed(2)} impacts/T${power}`;
}

const basinsView = gridView("chart-basins", (c, view) => {
  if (!view.classes) return provisionalColor(c);
  const label = view.classes.labels[c.j * view.xs.length + c.i];
  return label == null ? "#fff" : COLORS[(label - 1) % COLORS.length];
});

function basinsLegend(view) {
  const el = document.getElementById("basins-legend");
  el.textContent = "";
  el.dataset.attractors = view.classes ? String(view.classes.attractors.length) : "";
  if (!view.classes) {
    el.textContent = "stopped before every start ran: not classified";
    return;
  }
  for (const a of view.classes.attractors) {
    const s = document.createElement("span");
    const i = document.createElement("i");
    i.style.background = COLORS[(a.attractor - 1) % COLORS.length];
    s.append(i, `${attractorName(a)} (basin ${(100 * a.fraction).toFixed(1)} ± ${(100 * a.fraction_se).toFixed(1)} %)`);
    el.appendChild(s);
  }
}

// ---- exports ------------------------------------------------------------------------------

function quote(text) {
  return /^[\w.,:=+\-\/\[\]]+$/.test(text) ? text : "'" + text.replace(/'/g, "'\\''") + "'";
}

function command() {
  const base = ["vibrotribo", "simulate"];
  if (schema && schema.config) base.push(quote(schema.config));
  const sets = [];
  for (const s of (schema ? schema.set : [])) sets.push("--set", quote(s));
  for (const [k, v] of Object.entries(state.set)) sets.push("--set", quote(`${k}=${v}`));
  const lines = [base.concat(sets, ["--out", "run"]).join(" ")];
  if (state.orbit) {
    const o = state.orbit;
    const sweep = ["vibrotribo", "sweep"].concat(base.slice(2), sets, ["--param", quote(o.param),
      "--from", o.from, "--to", o.to, "--steps", o.steps]);
    if (o.transient) sweep.push("--transient", o.transient);
    if (o.recorded) sweep.push("--recorded", o.recorded);
    lines.push(sweep.concat(["--out", "sweep"]).join(" "));
  }
  if (state.map) {
    const m = state.map;
    const map = ["vibrotribo", "map"].concat(base.slice(2), sets, ["--x", quote(m.x), "--x-from", m.x_from,
      "--x-to", m.x_to, "--x-steps", m.x_steps, "--y", quote(m.y), "--y-from", m.y_from, "--y-to", m.y_to,
      "--y-steps", m.y_steps]);
    if (m.transient) map.push("--transient", m.transient);
    if (m.recorded) map.push("--recorded", m.recorded);
    lines.push(map.concat(["--out", "map"]).join(" "));
  }
  if (state.basins) {
    const b = state.basins;
    const basins = ["vibrotribo", "basins"].concat(base.slice(2), sets, ["--x", quote(b.x), "--x-from",
      b.x_from, "--x-to", b.x_to, "--y", quote(b.y), "--y-from", b.y_from, "--y-to", b.y_to,
      "--grid", `${b.x_steps}x${b.y_steps}`]);
    if (b.transient) basins.push("--transient", b.transient);
    if (b.recorded) basins.push("--recorded", b.recorded);
    lines.push(basins.concat(["--out", "basins"]).join(" "));
  }
  if (state.branches && state.orbit) {
    const o = state.orbit;
    lines.push(["vibrotribo", "continue"].concat(base.slice(2), sets, ["--param", quote(o.param),
      "--from", o.from, "--to", o.to, "--out", "continue"]).join(" "));
  }
  return lines.join(" && ");
}

function updateCommand() {
  document.getElementById("export-command").value = command();
}

function download(name, type, text) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([text], { type }));
  a.download = name;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
}

async function exportToml() {
  try {
    const r = await post("/api/toml", { set: state.set });
    download("vibrotribo.toml", "application/toml", await r.text());
  } catch (e) {
    document.getElementById("run-error").textContent = e.message;
  }
}

function csvText(header, rows) {
  const cell = (v) => {
    const t = v == null ? "" : String(v);
    return /[",\n]/.test(t) ? '"' + t.replace(/"/g, '""') + '"' : t;
  };
  return [header, ...rows].map((r) => r.map(cell).join(",")).join("\n") + "\n";
}

// The run view's samples.
function runCsv() {
  if (!lastRun) return null;
  const d = lastRun.samples;
  const cols = [["time_s", d.t]];
  d.x.forEach((c, i) => cols.push([`x${i + 1}_m`, c]));
  d.v.forEach((c, i) => cols.push([`v${i + 1}_m_s`, c]));
  d.gaps.forEach((c, i) => cols.push([`d${i + 1}_m`, c]));
  cols.push(["y_m", d.base], ["v_v", d.voltage], ["p_w", d.power]);
  const rows = d.t.map((_, j) => cols.map((c) => c[1][j]));
  return csvText(cols.map((c) => c[0]), rows);
}

// The orbit diagram: one row per value and recorded period, the positions on the section.
function orbitCsv() {
  if (orbitPoints.length === 0 || !state.orbit) return null;
  const n = orbitPoints[0].masses;
  const header = [state.orbit.param, "period_index"].concat([...Array(n).keys()].map((i) => `x${i + 1}_m`),
    ["motion", "average_power_w"]);
  const rows = [];
  for (const p of [...orbitPoints].sort((a, b) => a.i - b.i)) {
    for (let k = 0; k * n < p.strobe.length; k++) {
      rows.push([p.x, k].concat(p.strobe.slice(k * n, k * n + n), [motionClass(p), p.average_power_w]));
    }
  }
  return csvText(header, rows);
}

// The continuation branches: `branch.csv` of `vibrotribo continue`, cell for cell.
function branchesCsv() {
  return orbitBranches ? csvText(orbitBranches.columns, orbitBranches.rows) : null;
}

// A grid view (map or basins): one row per point, x fastest.
function gridCsv(view, basins) {
  if (view.cells.length === 0) return null;
  const header = [view.xKey, view.yKey, "period", "impacts_per_period", "average_power_w"];
  if (basins) header.push("attractor");
  const cells = [...view.cells].sort((a, b) => a.j - b.j || a.i - b.i);
  const rows = cells.map((c) => {
    const row = [c.x, c.y, c.period, c.impacts_per_period, c.average_power_w];
    if (basins) row.push(view.classes ? view.classes.labels[c.j * view.xs.length + c.i] : null);
    return row;
  });
  return csvText(header, rows);
}

const CSV_EXPORTS = {
  run: ["run-view.csv", runCsv],
  orbit: ["orbit-diagram.csv", orbitCsv],
  branches: ["branch.csv", branchesCsv],
  map: ["map.csv", () => gridCsv(mapView, false)],
  basins: ["basins.csv", () => gridCsv(basinsView, true)],
};

function exportCsv(which) {
  const [name, make] = CSV_EXPORTS[which];
  const text = make();
  if (text == null) {
    document.getElementById("run-error").textContent = `nothing to export: compute the ${which} view first`;
    return;
  }
  download(name, "text/csv", text);
}

// ---- start --------------------------------------------------------------------------------

async function main() {
  loadUrl();
  const r = await fetch("/api/schema");
  schema = await r.json();
  document.getElementById("config-name").textContent =
    schema.config ? "configuration: " + schema.config : "the paper's default case";
  buildParams();
  fillForm(document.getElementById("orbit-form"), state.orbit);
  fillForm(document.getElementById("map-form"), state.map);
  fillForm(document.getElementById("basins-form"), state.basins);
  orbitRange = state.orbitRange;
  document.getElementById("orbit-form").addEventListener("submit", (e) => {
    e.preventDefault();
    orbitRange = null;
    computeOrbit(false);
  });
  document.getElementById("orbit-reset").addEventListener("click", () => computeOrbit(true));
  document.getElementById("map-form").addEventListener("submit", (e) => {
    e.preventDefault();
    computeGrid(mapView, "/api/map", "map-form", "map", "map-progress", mapLegend);
  });
  document.getElementById("basins-form").addEventListener("submit", (e) => {
    e.preventDefault();
    computeGrid(basinsView, "/api/basins", "basins-form", "basins", "basins-progress", basinsLegend);
  });
  document.getElementById("export-toml").addEventListener("click", exportToml);
  document.getElementById("export-csv").addEventListener("click", () => exportCsv("run"));
  for (const which of ["orbit", "branches", "map", "basins"]) {
    document.getElementById(`export-${which}-csv`).addEventListener("click", () => exportCsv(which));
  }
  document.getElementById("orbit-branches").addEventListener("click", computeBranches);
  document.getElementById("orbit-branches-hide").addEventListener("click", hideBranches);
  document.getElementById("export-command-button").addEventListener("click", () => {
    updateCommand();
    document.getElementById("export-command").select();
  });
  document.getElementById("share").addEventListener("click", () => {
    saveUrl();
    navigator.clipboard?.writeText(location.href).catch(() => {});
  });
  updateCommand();
  await computeRun();
  if (state.orbit) computeOrbit(false);
  if (state.orbit && state.branches) computeBranches();
  if (state.map) computeGrid(mapView, "/api/map", "map-form", "map", "map-progress", mapLegend);
  if (state.basins) {
    computeGrid(basinsView, "/api/basins", "basins-form", "basins", "basins-progress", basinsLegend);
  }
}

main();
