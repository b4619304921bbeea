//! `plot DIR` refused the directories of `continue`, `periodic`, `load-sweep`,
//! `optimize-mass-ratio` and `optimize` ("holds no vibrotribo results"). It now draws every
//! kind a command writes, told by the kind's manifest, with the drawing code of that command's
//! `--plot`: from a copy of a run's data files (its pictures left out), `plot` draws the same
//! pictures, byte for byte.

use std::collections::BTreeSet;
use std::path::Path;

use super::util::{config_file, stderr, tempdir, vibrotribo};

/// The pictures in `dir`.
fn pictures(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png") || n.ends_with(".svg"))
        .collect()
}

/// Runs `args` (which write `--plot` pictures into `run`), copies `run`'s data files to a
/// fresh directory, draws it with `plot`, and checks that the same pictures come out; the
/// PNGs byte for byte.
fn plot_equals_the_commands_plot(kind: &str, args: &[&str]) {
    let tmp = tempdir();
    let run = tmp.path().join("run");
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["--plot", "--out", run.to_str().unwrap()]);
    let o = vibrotribo(&all);
    assert!(o.status.success(), "{kind}: {}", stderr(&o));
    let drawn = pictures(&run);
    assert!(
        drawn.iter().any(|n| n.ends_with(".png")),
        "{kind}: --plot drew nothing"
    );
    let copy = tmp.path().join("copy");
    std::fs::create_dir(&copy).unwrap();
    for e in std::fs::read_dir(&run).unwrap() {
        let name = e.unwrap().file_name();
        if !drawn.contains(&*name.to_string_lossy()) {
            std::fs::copy(run.join(&name), copy.join(&name)).unwrap();
        }
    }
    let o = vibrotribo(&["plot", copy.to_str().unwrap()]);
    assert!(o.status.success(), "plot of a {kind} directory: {}", stderr(&o));
    assert_eq!(
        pictures(&copy),
        drawn,
        "{kind}: the pictures of plot and of --plot"
    );
    for name in drawn.iter().filter(|n| n.ends_with(".png")) {
        let (a, b) = (
            std::fs::read(run.join(name)).unwrap(),
            std::fs::read(copy.join(name)).unwrap(),
        );
        assert!(a == b, "{kind}: {name} of plot differs from that of --plot");
    }
}

#[test]
fn plot_draws_a_load_sweep() {
    plot_equals_the_commands_plot(
        "load-sweep",
        &[
            "load-sweep",
            "-q",
            "--steps",
            "5",
            "--set",
            "run.periods=12",
            "--set",
            "run.transient_periods=4",
        ],
    );
}

#[test]
fn plot_draws_a_periodic_orbit() {
    let io = config_file("impact_oscillator.toml");
    plot_equals_the_commands_plot(
        "periodic",
        &["periodic", io.to_str().unwrap(), "--mechanics-only"],
    );
    plot_equals_the_commands_plot("periodic", &["periodic", "--transient", "20"]);
}

#[test]
fn plot_draws_a_continuation_with_its_bifurcations() {
    // Ω 0.7 → 1.0 on the default chain folds at Ω ≈ 0.80: a marker drawn from continue.json.
    plot_equals_the_commands_plot(
        "continue",
        &[
            "continue",
            "--param",
            "omega_ratio",
            "--from",
            "0.7",
            "--to",
            "1.0",
            "--doublings",
            "0",
            "--mechanics-only",
        ],
    );
}

#[test]
fn plot_draws_an_optimal_mass_ratio() {
    plot_equals_the_commands_plot(
        "optimize-mass-ratio",
        &[
            "optimize-mass-ratio",
            "-q",
            "--omega-steps",
            "3",
            "--rm-steps",
            "5",
            "--transient",
            "20",
            "--recorded",
            "10",
        ],
    );
}

#[test]
fn plot_draws_the_other_kinds() {
    plot_equals_the_commands_plot(
        "chirp",
        &["chirp", "-q", "--from", "0.6", "--to", "0.9", "--duration", "2"],
    );
    plot_equals_the_commands_plot(
        "lyapunov",
        &[
            "lyapunov",
            "-q",
            "--periods",
            "20",
            "--transient",
            "10",
            "--batches",
            "4",
        ],
    );
    plot_equals_the_commands_plot(
        "attractors",
        &[
            "attractors",
            "-q",
            "--param",
            "omega_ratio",
            "--from",
            "0.7",
            "--to",
            "0.8",
            "--steps",
            "2",
            "--samples",
            "3",
            "--transient",
            "20",
            "--recorded",
            "10",
        ],
    );
}

/// `optimize` draws its convergence without `--plot`; `plot` draws the same from its files.
#[test]
fn plot_draws_an_optimisation() {
    let tmp = tempdir();
    let run = tmp.path().join("run");
    let o = vibrotribo(&[
        "optimize",
        "-q",
        "--vary",
        "mass_ratio=1.5..3",
        "--particles",
        "3",
        "--swarm-iterations",
        "1",
        "--local-iterations",
        "2",
        "--set",
        "run.periods=10",
        "--set",
        "run.transient_periods=4",
        "--out",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = std::fs::read(run.join("convergence.png")).unwrap();
    std::fs::remove_file(run.join("convergence.png")).unwrap();
    let o = vibrotribo(&["plot", run.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(run.join("convergence.png")).unwrap() == before);
}

#[cfg(unix)]
/// `optimize-mass-ratio` stopped by Ctrl-C said "nothing was written" beside a written
/// `power_grid.csv`; it names the file and what it holds.
#[test]
fn interrupted_optimal_mass_ratio_names_the_grid_it_kept() {
    let tmp = tempdir();
    let out = tmp.path().join("rmo");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args([
            "optimize-mass-ratio",
            "-q",
            "--omega-steps",
            "40",
            "--rm-steps",
            "100",
            "--out",
        ])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("cannot run vibrotribo");
    // Stop it once the grid file holds a row.
    let grid = out.join("power_grid.csv");
    let rows = || {
        std::fs::read_to_string(&grid)
            .map(|t| t.lines().count())
            .unwrap_or(0)
    };
    while rows() < 2 {
        if child.try_wait().expect("waits").is_some() {
            panic!("the run ended before it was stopped");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    let o = child.wait_with_output().expect("waits");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(!err.contains("nothing was written"), "{err}");
    assert!(err.contains("power_grid.csv holds the"), "{err}");
    assert!(rows() >= 2);
}

/// `curve` has no `--plot`: `plot DIR` draws its directory, told by `curve.json`'s command,
/// the curve of every row of `curve.csv` in the plane of its two keys.
#[test]
fn plot_draws_a_bifurcation_curve() {
    let tmp = tempdir();
    let dir = tmp.path().join("curve");
    let io = config_file("impact_oscillator.toml");
    let o = vibrotribo(&[
        "curve",
        io.to_str().unwrap(),
        "--kind",
        "period_doubling",
        "--param",
        "omega_ratio",
        "--near",
        "2.45",
        "--param2",
        "oscillator.stops.upper.gap",
        "--from2",
        "0.001",
        "--to2",
        "0.0012",
        "--max-points",
        "5",
        "--mechanics-only",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "curve: {}", stderr(&o));
    let o = vibrotribo(&["plot", dir.to_str().unwrap()]);
    assert!(o.status.success(), "plot of a curve directory: {}", stderr(&o));
    assert_eq!(
        pictures(&dir),
        BTreeSet::from(["curve.png".to_string(), "curve.svg".to_string()])
    );
    let rows = std::fs::read_to_string(dir.join("curve.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    let svg = std::fs::read_to_string(dir.join("curve.svg")).unwrap();
    assert!(
        svg.contains(&format!("period doubling curve of period 1: {rows} points")),
        "the picture names another curve than curve.csv's {rows} points"
    );
}
