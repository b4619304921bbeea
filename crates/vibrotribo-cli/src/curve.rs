//! `vibrotribo curve`: a fold, period doubling, Neimark–Sacker or grazing point of a branch
//! followed in a second parameter ([`vibrotribo::curve::curve_config`]), with the
//! codimension-two points where the curve meets another or ends.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use vibrotribo::config::Config;
use vibrotribo::curve::{ConfigCurve, CurveConfigOptions, CurveRequest, curve_config, curve_powers};
use vibrotribo::orbits::curve::{Codim2Kind, CurveEnd, CurveKind, CurveOptions};

use crate::config::ConfigArgs;
use crate::manifest::{Codim2Record, CurveManifest, Kind};
use crate::output::{CsvFile, create_dir, csv_text, multipliers_text, numbered};

/// Options of `vibrotribo curve`.
#[derive(Debug, clap::Args)]
pub struct CurveArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// The bifurcation followed: a multiplier at +1 (fold), at −1 (period_doubling), a
    /// complex pair on the unit circle (neimark_sacker), or an orbit touching a contact with
    /// zero speed (grazing).
    #[arg(long, value_parser = ["fold", "period_doubling", "neimark_sacker", "grazing"])]
    pub kind: String,
    /// The branch's parameter: any key `continue --param` accepts.
    #[arg(long)]
    pub param: String,
    /// The bifurcation of that kind nearest this value of --param is followed (searched on
    /// the branch through the orbit found there, within ± --window of it).
    #[arg(long, allow_negative_numbers = true)]
    pub near: f64,
    /// The second parameter, in which the bifurcation is followed.
    #[arg(long)]
    pub param2: String,
    /// Start of the second parameter's range: the bifurcation is located there.
    #[arg(long, allow_negative_numbers = true)]
    pub from2: f64,
    /// End of the second parameter's range.
    #[arg(long, allow_negative_numbers = true)]
    pub to2: f64,
    /// Period of the branch, in excitation periods (default: that of the orbit found after
    /// the transient at --near).
    #[arg(long)]
    pub period: Option<u32>,
    /// Half width of the search window in --param, relative to |--near|.
    #[arg(long, default_value_t = CurveConfigOptions::default().window)]
    pub window: f64,
    /// Periods simulated at --near from the configured initial state before shooting.
    #[arg(long, default_value_t = CurveConfigOptions::default().transient)]
    pub transient: u32,
    /// Most points on the curve.
    #[arg(long, default_value_t = CurveOptions::default().max_points)]
    pub max_points: usize,
    /// Mechanics only: no power along the curve.
    #[arg(long)]
    pub mechanics_only: bool,
    /// Write curve.csv, codim2.csv and curve.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Runs `vibrotribo curve`.
pub fn run(args: &CurveArgs) -> Result<()> {
    if args.period == Some(0) {
        bail!("--period must be at least 1");
    }
    if !(args.near.is_finite() && args.from2.is_finite() && args.to2.is_finite()) {
        bail!("--near, --from2 and --to2 must be finite numbers");
    }
    if args.from2 == args.to2 {
        bail!("--from2 and --to2 must differ");
    }
    let kind: CurveKind = args.kind.parse()?;
    let config = args.input.load()?;
    config.check_uncoupled("curve")?;
    config.check_periodic("continuation of bifurcation curves (`curve`)")?;
    let request = CurveRequest {
        kind,
        key: args.param.clone(),
        near: args.near,
        key2: args.param2.clone(),
        from2: args.from2,
        to2: args.to2,
        period: args.period,
    };
    let d = CurveConfigOptions::default();
    let options = CurveConfigOptions {
        transient: args.transient,
        window: args.window,
        curve: CurveOptions {
            max_points: args.max_points,
            ..d.curve
        },
    };
    let result = curve_config(&config, &request, &options)?;
    let power =
        (!args.mechanics_only).then(|| curve_powers(&config, &result.key, &result.key2, &result.curve));
    print_curve(&result);
    create_dir(&args.out)?;
    write_files(&args.out, &config, args, &result, power.as_deref())?;
    println!(
        "  wrote {0}/curve.csv, {0}/codim2.csv, {0}/curve.json",
        args.out.display()
    );
    Ok(())
}

/// Why a curve ended, in words.
pub fn end_text(end: &CurveEnd) -> String {
    match end {
        CurveEnd::RangeEnd { parameter2 } => format!("range end at {parameter2}"),
        CurveEnd::MaxPoints => "point limit reached".into(),
        CurveEnd::StepFloor {
            parameter,
            parameter2,
            reason,
        } => format!("no continuation past ({parameter}, {parameter2}): {reason}"),
        CurveEnd::SequenceChange => {
            "the orbit's event sequence changes (see the codimension-two points)".into()
        }
        CurveEnd::Degenerate {
            parameter,
            parameter2,
        } => format!(
            "the condition no longer applies past ({parameter}, {parameter2}): no critical multiplier or gap minimum left"
        ),
        other => format!("{other:?}"),
    }
}

fn codim2_contact(kind: &Codim2Kind) -> Option<usize> {
    match kind {
        Codim2Kind::Grazing { contact } => Some(contact + 1),
        _ => None,
    }
}

fn print_curve(r: &ConfigCurve) {
    let c = &r.curve;
    println!(
        "vibrotribo curve: {} of period {} located at {} = {:.10} (±{:.1e}); {} points in ({}, {}); {}",
        c.kind.name(),
        c.period,
        r.key,
        r.located.parameter,
        r.located.precision,
        c.points.len(),
        r.key,
        r.key2,
        end_text(&c.end)
    );
    for p in &c.codim2 {
        println!(
            "    {} at {} = {:.10}, {} = {:.10}",
            p.kind.name(),
            r.key,
            p.point.parameter,
            r.key2,
            p.point.parameter2
        );
    }
}

fn write_files(
    dir: &Path,
    config: &Config,
    args: &CurveArgs,
    r: &ConfigCurve,
    power: Option<&[f64]>,
) -> Result<()> {
    let c = &r.curve;
    let n = config.chain().len();
    let mut cols: Vec<String> = vec![
        "point".into(),
        r.key.clone(),
        r.key2.clone(),
        "period".into(),
        "kind".into(),
        "condition".into(),
        "max_abs_multiplier".into(),
        "multipliers".into(),
    ];
    for k in 1..=2 * n {
        cols.push(format!("multiplier_{k}_re"));
        cols.push(format!("multiplier_{k}_im"));
    }
    cols.extend(numbered("x", n, "_m"));
    cols.extend(numbered("v", n, "_m_s"));
    cols.extend(numbered(
        "impacts_per_period_",
        config.chain().contact_count(),
        "",
    ));
    cols.extend(["gap_minimum_m", "average_power_w", "arclength"].map(String::from));
    let mut csv = CsvFile::create(&dir.join("curve.csv"), &cols)?;
    for (j, p) in c.points.iter().enumerate() {
        let mut row = vec![
            j.to_string(),
            p.parameter.to_string(),
            p.parameter2.to_string(),
            c.period.to_string(),
            c.kind.name().to_string(),
            p.condition.to_string(),
            p.multipliers.first().map_or(0.0, |m| m.norm()).to_string(),
            csv_text(&multipliers_text(&p.multipliers)),
        ];
        for k in 0..2 * n {
            let m = p.multipliers.get(k);
            row.push(m.map_or(String::new(), |m| m.re.to_string()));
            row.push(m.map_or(String::new(), |m| m.im.to_string()));
        }
        row.extend(p.state.positions.iter().map(f64::to_string));
        row.extend(p.state.velocities.iter().map(f64::to_string));
        row.extend(p.impacts_per_period.iter().map(f64::to_string));
        row.push(p.gap_minimum.map_or(String::new(), |g| g.to_string()));
        row.push(
            power
                .and_then(|pw| pw.get(j))
                .filter(|v| v.is_finite())
                .map_or(String::new(), |v| v.to_string()),
        );
        row.push(p.arclength.to_string());
        csv.row(row)?;
    }
    csv.flush()?;
    let mut codim = CsvFile::create(
        &dir.join("codim2.csv"),
        &[
            "kind",
            r.key.as_str(),
            r.key2.as_str(),
            "precision",
            "contact",
            "multipliers",
        ],
    )?;
    let mut records = Vec::new();
    for p in &c.codim2 {
        let contact = codim2_contact(&p.kind);
        codim.row([
            p.kind.name(),
            p.point.parameter.to_string(),
            p.point.parameter2.to_string(),
            p.precision.to_string(),
            contact.map_or(String::new(), |k| k.to_string()),
            csv_text(&multipliers_text(&p.point.multipliers)),
        ])?;
        records.push(Codim2Record {
            kind: p.kind.name(),
            param: p.point.parameter,
            param2: p.point.parameter2,
            precision: p.precision,
            contact,
            multipliers: p.point.multipliers.iter().map(|m| [m.re, m.im]).collect(),
        });
    }
    codim.flush()?;
    let manifest = CurveManifest {
        command: Kind::Curve,
        kind: c.kind.name().into(),
        param: r.key.clone(),
        near: args.near,
        param2: r.key2.clone(),
        from2: args.from2,
        to2: args.to2,
        period: c.period,
        contact: c.contact.map(|k| k + 1),
        located: r.located.parameter,
        located_precision: r.located.precision,
        points: c.points.len(),
        end: end_text(&c.end),
        codim2: records,
        window: args.window,
        transient_periods: args.transient,
        max_points: args.max_points,
        mechanics_only: args.mechanics_only,
        settings: crate::manifest::settings_of(config)?,
        vibrotribo_version: crate::manifest::version(),
    };
    crate::manifest::write(&dir.join("curve.json"), &manifest)
}
