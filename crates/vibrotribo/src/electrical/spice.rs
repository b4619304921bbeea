//! ngspice netlists of the harvester circuit, for cross-checking the charge solver against a
//! real circuit simulator, and a runner for `ngspice -b`.
//!
//! The netlist follows docs/MODEL.md §2:
//!
//! - the gaps enter as `PWL` voltage sources, 1 V standing for 1 m;
//! - the transducer is a behavioural voltage source `V = V_oc − Q/C` whose charge `Q` is a
//!   state: the voltage of a 1 F integrator node fed by the sensed loop current, in nC (a
//!   capacitor written `C={expr}` would drop the `v·dC/dt` term and be wrong);
//! - every constant is written out as a number and every product parenthesised, so no brace
//!   expansion can change precedence;
//! - the initial charge is set with `.ic` and the run uses `uic`;
//! - the delivered energy is integrated by a second 1 F node, in nJ.
//!
//! How accurate is ngspice here? On the paper's chatter case (three periods after the
//! start-up, 100 kΩ) its delivered energy converges to the library's (which an independent
//! SciPy Radau run on the plain Q-form reproduces to 10 digits) only slowly with `reltol`,
//! because the integrated charge is ~10⁵ times the part of it that sets the load voltage:
//! with gear, 3.7e-3 off at reltol 1e-4 and 2.3e-4 at 1e-6; with the trapezoidal rule and
//! `trtol = 1`, 5e-5 at 1e-6 and 8e-6 at 1e-7. Hence the defaults of [`SpiceOptions`].
//!
//! With the rectifier the transducer floats between the diodes. With nothing but ngspice's
//! `gmin` (1e-12 S across each junction) to hold that node, ngspice fails ("timestep too
//! small, trouble with node a") erratically: at reltol below ~1e-4, with tight
//! `abstol`/`vntol`, and even on a change as small as writing a constant differently. A
//! leakage conductance across each diode (`harvester.diode_parallel_conductance`, which the
//! library models too) of 1e-10 S makes it robust at any reltol; it changes the chatter case's
//! energy by ~1.5e-4. The remaining difference between the two models is `gmin`, a leak of
//! `gmin·V_s`, 1 % of such a G_p.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use super::params::{BOLTZMANN_OVER_CHARGE, EPSILON_0, HarvesterParams, Load, LoadKind, VocModel};
use super::transducer::{ChargeMap, Transducer};
use super::waveform::PwlGaps;
use crate::error::ParamError;
use thiserror::Error;

/// Charge scale of the integrator node: 1 V stands for 1 nC.
const CHARGE_SCALE: f64 = 1e9;
/// Energy scale of the energy node: 1 V stands for 1 nJ.
const ENERGY_SCALE: f64 = 1e9;

/// ngspice's transient integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpiceMethod {
    /// Trapezoidal rule (ngspice's default).
    #[default]
    Trapezoidal,
    /// Gear (BDF) of order up to 2.
    Gear,
}

/// Settings of the ngspice run. The defaults were found by convergence studies on the
/// paper's chatter case (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SpiceOptions {
    /// ngspice `reltol`, dimensionless. Default: 1e-6 with a resistor load, 1e-5 with the
    /// rectifier (which needs `harvester.diode_parallel_conductance > 0`, see the module
    /// docs).
    pub reltol: Option<f64>,
    /// ngspice `trtol` (how far the truncation error is trusted; lower is stricter),
    /// dimensionless. Default 1 (ngspice's own default is 7).
    pub trtol: f64,
    /// ngspice `abstol`, A. Default: ngspice's (1e-12 A).
    pub abstol: Option<f64>,
    /// ngspice `vntol`, V. Default: ngspice's (1e-6 V).
    pub vntol: Option<f64>,
    /// Largest time step (`tmax` of `.tran`), s. Default: the mean spacing of the PWL
    /// points. ngspice's own step control is not reliable on these waveforms: on 2 periods of
    /// the paper's default case (after 50 periods) with a step limit of span/50 it took 3149
    /// points and delivered 25 % too much energy; capped at the PWL spacing it agrees with
    /// vibrotribo to 3e-6.
    pub max_step: Option<f64>,
    /// Integration method. Default trapezoidal.
    pub method: SpiceMethod,
    /// The ngspice executable. Default `ngspice` (found on `PATH`).
    pub executable: PathBuf,
}

impl Default for SpiceOptions {
    fn default() -> Self {
        SpiceOptions {
            reltol: None,
            trtol: 1.0,
            abstol: None,
            vntol: None,
            max_step: None,
            method: SpiceMethod::default(),
            executable: PathBuf::from("ngspice"),
        }
    }
}

impl SpiceOptions {
    /// The `reltol` used for `load`.
    pub fn reltol_for(&self, load: LoadKind) -> f64 {
        self.reltol.unwrap_or(match load {
            LoadKind::Rectifier => 1e-5,
            _ => 1e-6,
        })
    }
}

/// Running ngspice failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SpiceError {
    /// The parameters are invalid.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// ngspice could not be started.
    #[error("cannot run `{program}` ({reason}); install ngspice (Debian: apt-get install -y ngspice)")]
    NotFound {
        /// The executable tried.
        program: String,
        /// The operating system's reason.
        reason: String,
    },
    /// Reading or writing the run's files failed.
    #[error("ngspice run files: {0}")]
    Io(String),
    /// ngspice ran but produced no complete result.
    #[error("ngspice failed ({status}): {message}")]
    Failed {
        /// Exit status.
        status: String,
        /// The relevant part of its output.
        message: String,
    },
    /// The data file could not be parsed.
    #[error("cannot parse ngspice output: {0}")]
    Parse(String),
}

/// The output of one ngspice run, in SI units, at ngspice's own time points.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SpiceRun {
    /// Time points, s.
    pub time: Vec<f64>,
    /// Charge moved between the electrodes Q, C.
    pub charge_c: Vec<f64>,
    /// Transducer terminal voltage V, V.
    pub voltage_v: Vec<f64>,
    /// Energy delivered to the load since the start, J (`∫V²/R` for the resistor,
    /// `∫V_s I_out` for the rectifier).
    pub energy_j: Vec<f64>,
    /// Storage capacitor voltage, V (rectifier only; empty otherwise).
    pub storage_voltage_v: Vec<f64>,
    /// Wall-clock time of the ngspice process, start-up included.
    pub elapsed: Duration,
}

impl SpiceRun {
    /// Linear interpolation of `series` (one of this run's vectors) at time `t`, s (clamped to
    /// the run's span).
    pub fn at(&self, series: &[f64], t: f64) -> f64 {
        let k = self.time.partition_point(|&x| x < t);
        if k == 0 {
            return series[0];
        }
        if k >= self.time.len() {
            return series[series.len() - 1];
        }
        let (t0, t1) = (self.time[k - 1], self.time[k]);
        let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
        series[k - 1] + w * (series[k] - series[k - 1])
    }
}

/// Formats a number so that ngspice reads back the same double.
fn num(x: f64) -> String {
    format!("{x:e}")
}

/// The initial charge the library uses: `initial_charge` or `C(t₀)·V_oc(t₀)`, C.
pub fn initial_charge(params: &HarvesterParams, pwl: &PwlGaps) -> f64 {
    let gaps: Vec<f64> = (0..pwl.gap_count()).map(|k| pwl.value(0, k)).collect();
    params.initial_charge.unwrap_or_else(|| {
        ChargeMap::new(&params.transducer())
            .state(&gaps)
            .equilibrium_charge
    })
}

/// An ngspice netlist of the harvester `params` driven by the gaps `pwl` from its first time
/// t₀ to `t_end`, s (ngspice time 0 is t₀), writing `time, v(q), v(e), v(a,c)[, v(s)]` to `data_file` with `wrdata`.
///
/// Nodes: `a`/`c` transducer terminals, `q` charge (1 V = 1 nC), `e` energy (1 V = 1 nJ),
/// `s` storage capacitor (rectifier), `g0`, `g1` gaps (1 V = 1 m).
pub fn netlist(
    params: &HarvesterParams,
    pwl: &PwlGaps,
    t_end: f64,
    options: &SpiceOptions,
    data_file: &str,
) -> Result<String, ParamError> {
    params.validate_for_gaps(pwl.gap_count())?;
    if matches!(params.load, Load::Open | Load::Short) {
        return Err(ParamError::Conflict {
            name: "load".into(),
            message: format!(
                "\"{}\" has no circuit to simulate in ngspice",
                params.load.kind().as_str()
            ),
        });
    }
    let t0 = pwl.times()[0];
    if !t_end.is_finite() || t_end <= t0 {
        return Err(ParamError::Invalid {
            name: "spice.t_end".into(),
            value: t_end,
            reason: "must lie after the waveform's first time",
        });
    }
    let transducer = params.transducer();
    let q0 = initial_charge(params, pwl);
    let mut s = String::new();
    let w = &mut s;
    // Writing to a String cannot fail.
    let _ = writeln!(
        w,
        "* vibrotribo triboelectric harvester: {} mode, {} load",
        params.mode.as_str(),
        params.load.kind().as_str()
    );
    let _ = writeln!(
        w,
        "* S = {} m2, sigma = {} C/m2, d0 = {} m, eps0 = {} F/m",
        num(params.area),
        num(params.charge_density),
        num(params.effective_thickness()),
        num(EPSILON_0)
    );
    let contacts = transducer.contacts();
    for (node, &k) in contacts.iter().enumerate() {
        let _ = writeln!(w, "* gap of contact {k} (m), 1 V = 1 m");
        let _ = write!(w, "Vg{node} g{node} 0 PWL(");
        for j in 0..pwl.times().len() {
            let _ = write!(w, "\n+ {} {}", num(pwl.times()[j] - t0), num(pwl.value(j, k)));
        }
        let _ = writeln!(w, " )");
    }
    let inv_eps_area = 1.0 / (EPSILON_0 * params.area);
    let d0 = params.effective_thickness();
    let k_voc = params.charge_density / EPSILON_0;
    let (voc, gap_sum) = match transducer {
        Transducer::Freestanding(f) => (
            match f.voc_model {
                VocModel::Paper => format!("({}*V(g1))", num(2.0 * k_voc)),
                VocModel::Exact => format!("({}*(V(g1)-V(g0)))", num(k_voc)),
            },
            format!("({} + V(g0) + V(g1))", num(d0)),
        ),
        Transducer::ContactSeparation(_) => (
            format!("({}*V(g0))", num(k_voc)),
            format!("({} + V(g0))", num(d0)),
        ),
    };
    let _ = writeln!(w, "* transducer: V(a,c) = Voc - Q/C, Q = V(q) nC");
    let _ = writeln!(
        w,
        "Bteng a c V = {{ {voc} - ((V(q)/{})*({gap_sum}*{})) }}",
        num(CHARGE_SCALE),
        num(inv_eps_area)
    );
    let _ = writeln!(w, "Vsense a a1 0");
    let _ = writeln!(w, "Cq q 0 1");
    let _ = writeln!(w, "Bq 0 q I = {{ i(Vsense)*{} }}", num(CHARGE_SCALE));
    let _ = writeln!(w, "Ce e 0 1");
    let mut ic = format!(".ic v(q)={} v(e)=0", num(q0 * CHARGE_SCALE));
    let mut probes = String::from("v(q) v(e) v(a,c)");
    match &params.load {
        Load::Resistor { resistance } => {
            let _ = writeln!(w, "Rload a1 c {}", num(*resistance));
            let _ = writeln!(w, "Vgnd c 0 0");
            let _ = writeln!(w, "Be 0 e I = {{ (V(a1,c)*i(Vsense))*{} }}", num(ENERGY_SCALE));
        }
        Load::Rectifier(rect) => {
            let d = &rect.diode;
            let vt = d.thermal_voltage;
            let celsius = vt / BOLTZMANN_OVER_CHARGE - 273.15;
            let _ = writeln!(w, "* full-wave bridge into the storage capacitor");
            let _ = writeln!(w, "D1 a1 p dbridge");
            let _ = writeln!(w, "D2 c p dbridge");
            let _ = writeln!(w, "D3 0 a1 dbridge");
            let _ = writeln!(w, "D4 0 c dbridge");
            if d.parallel_conductance > 0.0 {
                let r = num(1.0 / d.parallel_conductance);
                let _ = writeln!(w, "* leakage across each diode");
                for (k, (p, n)) in [("a1", "p"), ("c", "p"), ("0", "a1"), ("0", "c")]
                    .iter()
                    .enumerate()
                {
                    let _ = writeln!(w, "Rleak{} {p} {n} {r}", k + 1);
                }
            }
            let _ = writeln!(w, "Vout p s 0");
            let _ = writeln!(w, "Cs s 0 {}", num(rect.storage_capacitance));
            if let Some(r) = rect.storage_load_resistance {
                let _ = writeln!(w, "Rs s 0 {}", num(r));
            }
            let _ = writeln!(
                w,
                ".model dbridge D(IS={} N={} RS={})",
                num(d.saturation_current),
                num(d.ideality),
                num(d.series_resistance)
            );
            let _ = writeln!(w, ".options temp={} tnom={}", num(celsius), num(celsius));
            let _ = writeln!(w, "Be 0 e I = {{ (V(s)*i(Vout))*{} }}", num(ENERGY_SCALE));
            let vs0 = num(rect.storage_initial_voltage);
            let _ = write!(ic, " v(s)={vs0} v(p)={vs0}");
            probes.push_str(" v(s)");
        }
        Load::Open | Load::Short => unreachable!("rejected above"),
    }
    let _ = writeln!(w, "{ic}");
    let mut opts = format!(
        ".options reltol={} trtol={}",
        num(options.reltol_for(params.load.kind())),
        num(options.trtol)
    );
    if let Some(a) = options.abstol {
        let _ = write!(opts, " abstol={}", num(a));
    }
    if let Some(v) = options.vntol {
        let _ = write!(opts, " vntol={}", num(v));
    }
    if options.method == SpiceMethod::Gear {
        opts.push_str(" method=gear");
    }
    let _ = writeln!(w, "{opts}");
    let _ = writeln!(w, ".control");
    let _ = writeln!(w, "set wr_singlescale");
    let _ = writeln!(w, "set wr_vecnames");
    let _ = writeln!(w, "option numdgt=16");
    let span = t_end - t0;
    let mean_spacing = span / (pwl.times().len().max(2) - 1) as f64;
    let tmax = options.max_step.unwrap_or(mean_spacing).min(span / 50.0);
    // ngspice always starts at 0: the waveform's first time is shifted there.
    let _ = writeln!(w, "tran {} {} 0 {} uic", num(tmax), num(span), num(tmax));
    let _ = writeln!(w, "wrdata {data_file} {probes}");
    let _ = writeln!(w, ".endc");
    let _ = writeln!(w, ".end");
    Ok(s)
}

/// Parses a `wrdata` file written with `wr_singlescale` and `wr_vecnames`: a header of vector
/// names, then rows of numbers. Returns the names and the columns.
pub fn parse_wrdata(text: &str) -> Result<(Vec<String>, Vec<Vec<f64>>), SpiceError> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| SpiceError::Parse("empty data file".into()))?
        .split_whitespace()
        .map(str::to_string)
        .collect();
    let mut cols = vec![Vec::new(); header.len()];
    for (n, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.len() != header.len() {
            return Err(SpiceError::Parse(format!(
                "row {} has {} fields, expected {}",
                n + 1,
                fields.len(),
                header.len()
            )));
        }
        for (c, f) in fields.iter().enumerate() {
            let x: f64 = f
                .parse()
                .map_err(|_| SpiceError::Parse(format!("row {}: `{f}` is not a number", n + 1)))?;
            cols[c].push(x);
        }
    }
    Ok((header, cols))
}

/// A fresh directory for one run's files.
fn scratch_dir() -> Result<PathBuf, SpiceError> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let dir = std::env::temp_dir().join(format!("vibrotribo-spice-{}-{n}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| SpiceError::Io(format!("{}: {e}", dir.display())))?;
    Ok(dir)
}

/// Writes the netlist of `params` driven by `pwl` to `t_end`, s, runs `ngspice -b` on it in a
/// scratch directory (removed afterwards), and reads the result back in SI units.
pub fn run_ngspice(
    params: &HarvesterParams,
    pwl: &PwlGaps,
    t_end: f64,
    options: &SpiceOptions,
) -> Result<SpiceRun, SpiceError> {
    let dir = scratch_dir()?;
    let result = run_in(&dir, params, pwl, t_end, options);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn run_in(
    dir: &Path,
    params: &HarvesterParams,
    pwl: &PwlGaps,
    t_end: f64,
    options: &SpiceOptions,
) -> Result<SpiceRun, SpiceError> {
    let data = "vibrotribo-out.txt";
    let deck = netlist(params, pwl, t_end, options, data)?;
    let cir = dir.join("vibrotribo.cir");
    std::fs::write(&cir, deck).map_err(|e| SpiceError::Io(format!("{}: {e}", cir.display())))?;
    let started = Instant::now();
    let out = Command::new(&options.executable)
        .arg("-b")
        .arg("vibrotribo.cir")
        .current_dir(dir)
        .output()
        .map_err(|e| SpiceError::NotFound {
            program: options.executable.display().to_string(),
            reason: e.to_string(),
        })?;
    let elapsed = started.elapsed();
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let trouble: Vec<&str> = log
        .split(['\n', '\r'])
        .filter(|l| {
            let l = l.to_ascii_lowercase();
            l.contains("error") || l.contains("too small") || l.contains("aborted")
        })
        .collect();
    let hint = if params
        .load
        .rectifier()
        .is_some_and(|r| r.diode.parallel_conductance == 0.0)
    {
        " (with the rectifier, give ngspice a path at the floating bridge: set \
         harvester.diode_parallel_conductance, e.g. 1e-10 S)"
    } else {
        ""
    };
    let failed = |message: String| SpiceError::Failed {
        status: out.status.to_string(),
        message: format!("{message}{hint}"),
    };
    let text = std::fs::read_to_string(dir.join(data)).map_err(|_| failed(trouble.join(" | ")))?;
    let (names, cols) = parse_wrdata(&text)?;
    let col = |name: &str| -> Result<Vec<f64>, SpiceError> {
        names
            .iter()
            .position(|n| n == name)
            .map(|i| cols[i].clone())
            .ok_or_else(|| SpiceError::Parse(format!("no column `{name}` in {names:?}")))
    };
    let t0 = pwl.times()[0];
    let time: Vec<f64> = col("time")?.into_iter().map(|t| t + t0).collect();
    let reached = time.last().copied().unwrap_or(f64::NEG_INFINITY);
    if !trouble.is_empty() || reached < t_end - 1e-9 * t_end.abs().max(1.0) {
        return Err(failed(format!(
            "stopped at t = {reached} s: {}",
            trouble.join(" | ")
        )));
    }
    let scale = |v: Vec<f64>, s: f64| v.into_iter().map(|x| x / s).collect::<Vec<_>>();
    Ok(SpiceRun {
        charge_c: scale(col("v(q)")?, CHARGE_SCALE),
        energy_j: scale(col("v(e)")?, ENERGY_SCALE),
        voltage_v: col("v(a,c)")?,
        storage_voltage_v: if params.load.kind() == LoadKind::Rectifier {
            col("v(s)")?
        } else {
            Vec::new()
        },
        time,
        elapsed,
    })
}
