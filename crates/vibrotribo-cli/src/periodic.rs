//! `vibrotribo periodic`: the periodic orbit near a run, found by shooting
//! ([`vibrotribo::orbits`]), with its Floquet multipliers, its impacts and the power the
//! harvester delivers on it.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use vibrotribo::config::Config;
use vibrotribo::orbits::{
    OrbitError, PeriodicOrbit, ShootingOptions, find_periodic_orbit, periodic_orbit_from_transient,
};
use vibrotribo::study::ElectricalOutcome;
use vibrotribo::{ChainState, EventKind, Simulator, UniformSampler};

use crate::config::ConfigArgs;
use crate::manifest::{Kind, OrbitEventRecord, PeriodicManifest, config_of, read, to_value};
use crate::output::{create_dir, numbered, si, write_json};
use crate::plot::{self, Figure, Legend, Series, both};
use crate::progress::{Interrupted, Progress, orbit_cancel};

/// Options of `vibrotribo periodic`.
#[derive(Debug, clap::Args)]
pub struct PeriodicArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Period P of the orbit, in excitation periods (default: detected from 128 periods after
    /// the transient).
    #[arg(long)]
    pub period: Option<u32>,
    /// Periods simulated from the configured initial state before shooting; 0 shoots from the
    /// configured initial state itself (then the period defaults to 1).
    #[arg(long, default_value_t = 200)]
    pub transient: u32,
    /// Mechanics only: no harvester, no power.
    #[arg(long)]
    pub mechanics_only: bool,
    /// Write periodic.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the orbit's phase portraits and its multipliers (without --out: into vibrotribo-out/periodic).
    #[arg(long)]
    pub plot: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `vibrotribo periodic`.
pub fn run(args: &PeriodicArgs) -> Result<()> {
    if args.period == Some(0) {
        bail!("--period must be at least 1");
    }
    let config = args.input.load()?;
    config.check_uncoupled("periodic")?;
    config.check_periodic("periodic orbits (`periodic`)")?;
    let options = ShootingOptions {
        sim: config.sim_options().clone(),
        cancel: orbit_cancel(),
        ..ShootingOptions::default()
    };
    let chain = config.chain();
    let spinner = Progress::spinner("shooting", args.quiet);
    let orbit = if args.transient == 0 {
        find_periodic_orbit(chain, config.initial_state(), args.period.unwrap_or(1), &options)
    } else {
        periodic_orbit_from_transient(
            chain,
            config.initial_state(),
            args.transient,
            args.period,
            &options,
        )
    };
    spinner.finish();
    let orbit = match orbit {
        // No orbit to write: a periodic.json holds a converged orbit or is not written.
        Err(OrbitError::Cancelled) => {
            return Err(Interrupted {
                what: "stopped before the orbit was found; nothing written".into(),
            }
            .into());
        }
        other => other?,
    };
    // A single mass (against a stop) has no gap between masses to harvest from.
    let power = if args.mechanics_only {
        None
    } else {
        vibrotribo::branch::orbit_power(&config, &orbit)?
    };
    print_orbit(&orbit, power.as_ref());
    if let Some(dir) = &args.out {
        create_dir(dir)?;
        write_json(
            &dir.join("periodic.json"),
            &to_value(&manifest(&config, &orbit, power.as_ref())?)?,
        )?;
        if args.plot {
            plot_periodic(dir)?;
        }
        println!("  wrote {}/periodic.json", dir.display());
    }
    Ok(())
}

fn print_orbit(orbit: &PeriodicOrbit, power: Option<&ElectricalOutcome>) {
    let n = orbit.params.len();
    println!(
        "vibrotribo periodic: period-{} orbit at Ω = {:.6} ({} masses), residual {:.1e} after {} Newton iterations",
        orbit.period,
        orbit.params.omega_ratio(),
        n,
        orbit.residual,
        orbit.residuals.len().saturating_sub(1)
    );
    println!(
        "  state at t ≡ 0 (mod T): x = {:?} m, v = {:?} m/s",
        orbit.state.positions, orbit.state.velocities
    );
    let unstable = orbit.unstable_dimension();
    println!(
        "  {}: largest |multiplier| {:.6}{}",
        if orbit.stable { "stable" } else { "unstable" },
        orbit.spectral_radius(),
        if unstable > 0 {
            format!(", {unstable} multiplier(s) outside the unit circle")
        } else {
            String::new()
        }
    );
    let ms: Vec<String> = orbit
        .multipliers
        .iter()
        .map(|m| {
            if m.im == 0.0 {
                format!("{:.6}", m.re)
            } else {
                format!("{:.6}{:+.6}i", m.re, m.im)
            }
        })
        .collect();
    println!("  Floquet multipliers: {}", ms.join(", "));
    let per = orbit.impacts_per_period();
    let contacts: Vec<String> = per
        .iter()
        .enumerate()
        .filter(|&(k, _)| k + 1 < orbit.params.len() || orbit.params.is_stop(k))
        .map(|(k, c)| format!("{}: {c}", orbit.params.contact_name(k)))
        .collect();
    println!(
        "  impacts per excitation period: {} ({}){}",
        per.iter().sum::<f64>(),
        contacts.join(", "),
        if orbit.sticks() { "; sticks" } else { "" }
    );
    if let Some((k, v)) = orbit.min_closing_speed() {
        println!("  slowest impact: {v:.6} m/s at {}", orbit.params.contact_name(k));
    }
    if let Some(p) = power.and_then(|p| p.power.as_ref()) {
        println!(
            "  harvester on the orbit: average power {}, {} per excitation period",
            si(p.average_power_w, "W"),
            si(p.energy_per_period_j, "J")
        );
    }
}

fn manifest(
    config: &Config,
    orbit: &PeriodicOrbit,
    power: Option<&ElectricalOutcome>,
) -> Result<PeriodicManifest> {
    let mut state = orbit.state.positions.clone();
    state.extend(&orbit.state.velocities);
    let per = orbit.impacts_per_period();
    let events = orbit
        .events
        .iter()
        .map(|e| OrbitEventRecord {
            time_s: e.time,
            kind: e.kind.as_str().to_string(),
            contact: e.contact + 1,
            rel_velocity_m_s: e.velocity_before,
            rel_velocity_after_m_s: e.velocity_after,
        })
        .collect();
    let p = power.and_then(|p| p.power.as_ref());
    Ok(PeriodicManifest {
        command: Kind::Periodic,
        period: orbit.period,
        state,
        state_names: numbered("x", orbit.params.len(), "_m")
            .into_iter()
            .chain(numbered("v", orbit.params.len(), "_m_s"))
            .collect(),
        multipliers: orbit.multipliers.iter().map(|m| [m.re, m.im]).collect(),
        multiplier_moduli: orbit.multipliers.iter().map(|m| m.norm()).collect(),
        stable: orbit.stable,
        unstable_dimension: orbit.unstable_dimension(),
        impacts_per_period: per.iter().sum::<f64>(),
        impacts_per_period_by_contact: per,
        impacts_per_orbit: orbit
            .events
            .iter()
            .filter(|e| e.kind == EventKind::Impact)
            .count(),
        min_closing_speed_m_s: orbit.min_closing_speed().map(|m| m.1),
        min_closing_speed_contact: orbit.min_closing_speed().map(|m| m.0 + 1),
        sticks: orbit.sticks(),
        average_power_w: p.map(|p| p.average_power_w),
        energy_per_period_j: p.map(|p| p.energy_per_period_j),
        residual: orbit.residual,
        residual_history: orbit.residuals.clone(),
        events,
        excitation_period_s: orbit.params.period(),
        omega_ratio: orbit.params.omega_ratio(),
        parameters: orbit.params.clone(),
        settings: crate::manifest::settings_of(config)?,
    })
}

/// Phase portraits of every mass over one period of the orbit (section point marked) and the
/// multipliers in the complex plane with the unit circle.
pub fn plot_periodic(dir: &Path) -> Result<()> {
    let orbit: PeriodicManifest = read(&dir.join("periodic.json"))?;
    let config = config_of(&orbit.settings)?;
    let n = orbit.parameters.len();
    if orbit.state.len() != 2 * n {
        bail!(
            "periodic.json: the state has {} entries, expected {} (positions and velocities)",
            orbit.state.len(),
            2 * n
        );
    }
    let (positions, velocities) = orbit.state.split_at(n);
    let samples = 400 * orbit.period as usize;
    let duration = f64::from(orbit.period) * orbit.parameters.period();
    let mut sampler = UniformSampler::new(n, 0.0, duration / samples as f64);
    let start = ChainState {
        positions: positions.to_vec(),
        velocities: velocities.to_vec(),
    };
    let mut sim = Simulator::new(&orbit.parameters, &start, config.sim_options().clone())?;
    sim.run_until(duration, &mut sampler)?;
    for i in 0..n {
        let x: Vec<f64> = sampler.positions.iter().skip(i).step_by(n).copied().collect();
        let v: Vec<f64> = sampler.velocities.iter().skip(i).step_by(n).copied().collect();
        let (x0, v0) = ([positions[i]], [velocities[i]]);
        let mut fig = Figure::new(
            format!(
                "Period-{} orbit: mass {} (section t ≡ 0 mod T marked)",
                orbit.period,
                i + 1
            ),
            format!("x{} [m]", i + 1),
            format!("v{} [m/s]", i + 1),
        );
        fig.legend = Legend::Hidden;
        both(dir, &format!("orbit_phase_x{}", i + 1), |path| {
            plot::phase_portrait(
                path,
                &fig,
                &[Series::unlabelled(&x, &v)],
                Some(Series::unlabelled(&x0, &v0)),
            )
        })?;
    }
    let circle: Vec<(f64, f64)> = (0..=360)
        .map(|k| {
            let a = f64::from(k).to_radians();
            (a.cos(), a.sin())
        })
        .collect();
    let (cx, cy): (Vec<f64>, Vec<f64>) = circle.into_iter().unzip();
    let re: Vec<f64> = orbit.multipliers.iter().map(|m| m[0]).collect();
    let im: Vec<f64> = orbit.multipliers.iter().map(|m| m[1]).collect();
    let r = orbit.multiplier_moduli.first().map_or(0.0, |r| *r).max(1.0) * 1.1;
    let mut fig = Figure::new("Floquet multipliers", "Re λ", "Im λ");
    fig.size = (800, 800);
    fig.x_range = Some((-r, r));
    fig.y_range = Some((-r, r));
    both(dir, "orbit_multipliers", |path| {
        plot::lines_and_points(
            path,
            &fig,
            &[Series::new("unit circle", &cx, &cy).dashed().colour(7)],
            &[Series::new("multipliers", &re, &im).colour(3)],
            9,
        )
    })
}
