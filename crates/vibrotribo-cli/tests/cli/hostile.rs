//! Hostile input: command lines that once panicked, aborted, ran without bound or answered
//! wrongly, and random command lines from a seeded generator (every subcommand, random
//! options, values and configurations, extreme sizes under an address-space limit, signals
//! at random moments). Every one must end with status 0, 1 or 2 (or the status of the signal
//! sent, 130 or 143), never with a panic, an abort or a hang, and an error must say why.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::util::{config_file, tempdir};

/// Address space a case may use (prlimit --as): large allocations fail here rather than
/// on the machine.
const ADDRESS_SPACE: u64 = 6 << 30;

/// How long a case may run before it is asked to stop (SIGTERM).
const RUN_BOUND: Duration = Duration::from_secs(60);

/// How long a case asked to stop may take to stop.
const STOP_BOUND: Duration = Duration::from_secs(30);

/// How a case ended.
#[derive(Debug, Default)]
struct Ending {
    status: Option<i32>,
    signal: Option<i32>,
    stderr: String,
    /// Did not stop within [`STOP_BOUND`] after SIGTERM.
    hung: bool,
    /// The signal this test sent (by the random moment or at [`RUN_BOUND`]).
    sent: Option<i32>,
}

const SIGINT: i32 = 2;
const SIGKILL: i32 = 9;
const SIGTERM: i32 = 15;

fn send(pid: u32, signal: i32) {
    let _ = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(pid.to_string())
        .status();
}

/// Runs the binary with `args` in `cwd` under the address-space limit, sending `signal`
/// after `after` if given, and SIGTERM at [`RUN_BOUND`].
fn run_case(args: &[String], cwd: &Path, signal: Option<(Duration, i32)>) -> Ending {
    use std::io::Read;
    use std::os::unix::process::ExitStatusExt;
    let bin = env!("CARGO_BIN_EXE_vibrotribo");
    let mut cmd = if Path::new("/usr/bin/prlimit").exists() {
        let mut c = Command::new("/usr/bin/prlimit");
        c.arg(format!("--as={ADDRESS_SPACE}")).arg("--").arg(bin);
        c
    } else {
        Command::new(bin)
    };
    let mut child = cmd
        .args(args)
        .current_dir(cwd)
        .env_remove("RUST_BACKTRACE")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot run vibrotribo");
    let mut err_pipe = child.stderr.take().expect("stderr piped");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err_pipe.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let mut ending = Ending::default();
    let mut asked_at: Option<Instant> = None;
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break Some(s);
        }
        let now = Instant::now();
        if let Some((after, sig)) = signal
            && ending.sent.is_none()
            && now - start >= after
        {
            send(child.id(), sig);
            ending.sent = Some(sig);
            asked_at = Some(now);
        }
        if ending.sent.is_none() && now - start >= RUN_BOUND {
            send(child.id(), SIGTERM);
            ending.sent = Some(SIGTERM);
            asked_at = Some(now);
        }
        if asked_at.is_some_and(|t| now - t >= STOP_BOUND) {
            ending.hung = true;
            let _ = child.kill();
            break child.wait().ok();
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    if let Some(s) = status {
        ending.status = s.code();
        ending.signal = s.signal();
    }
    ending.stderr = reader.join().unwrap_or_default();
    ending
}

/// What went wrong with a case, if anything.
fn fault(e: &Ending) -> Option<String> {
    if e.hung {
        return Some("did not stop within the bound after SIGTERM".into());
    }
    for text in ["panicked at", "RUST_BACKTRACE"] {
        if e.stderr.contains(text) {
            return Some(format!("panic text `{text}` in stderr"));
        }
    }
    if let Some(sig) = e.signal
        && Some(sig) != e.sent
    {
        return Some(format!("killed by signal {sig}, none of ours"));
    }
    match e.status {
        Some(0..=2) => {}
        Some(130) if e.sent == Some(SIGINT) => {}
        Some(143) if e.sent == Some(SIGTERM) => {}
        Some(c) => return Some(format!("exit status {c}")),
        None => {}
    }
    if matches!(e.status, Some(1 | 2)) && e.stderr.trim().is_empty() {
        return Some("failed with an empty stderr".into());
    }
    None
}

/// Counts of a batch of cases.
#[derive(Debug, Default)]
struct Tally {
    cases: usize,
    results: usize,
    clear_errors: usize,
    stopped: usize,
    faults: Vec<String>,
}

impl Tally {
    fn add(&mut self, args: &[String], e: &Ending) {
        self.cases += 1;
        if std::env::var_os("HOSTILE_VERBOSE").is_some() {
            let last = e.stderr.lines().last().unwrap_or("");
            eprintln!(
                "{:?} {:?} vibrotribo {}\n    {last}",
                e.status,
                e.sent,
                args.join(" ")
            );
        }
        match fault(e) {
            Some(f) => self
                .faults
                .push(format!("{f}: vibrotribo {}\n{}", args.join(" "), e.stderr)),
            None if e.sent.is_some() && e.status != Some(0) => self.stopped += 1,
            None if e.status == Some(0) => self.results += 1,
            None => self.clear_errors += 1,
        }
    }

    fn check(&self) {
        eprintln!(
            "hostile input: {} cases, {} results, {} clear errors, {} stopped by a signal, {} panics/aborts/hangs",
            self.cases,
            self.results,
            self.clear_errors,
            self.stopped,
            self.faults.len()
        );
        assert!(self.faults.is_empty(), "{}", self.faults.join("\n---\n"));
    }
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

fn io() -> String {
    config_file("impact_oscillator.toml").display().to_string()
}

/// The command lines of the defects found by hand, each of which must end cleanly.
fn known_cases(out: &Path) -> Vec<Vec<String>> {
    let io = io();
    let d = |name: &str| out.join(name).display().to_string();
    let short = ["--set", "run.periods=6", "--set", "run.transient_periods=2"];
    let mut cases: Vec<Vec<&str>> = vec![
        vec!["simulate", &io, "--set", "mass_ratio=3"],
        vec!["simulate", "--set", "oscillator.masses=[1e300,0.1,0.1]"],
        vec!["simulate", "--set", "oscillator.damping=1e9"],
        vec!["simulate", "--set", "excitation.harmonics[0].amplitude=1"],
        vec!["simulate", "--set", "oscillator.stiffness=1e300"],
        vec!["load-sweep", "--vq-points", "1000000000", "--steps", "2"],
        vec!["load-sweep", "--steps", "100000000000"],
        vec![
            "map",
            "--x",
            "omega_ratio",
            "--x-from",
            "0.7",
            "--x-to",
            "0.8",
            "--x-steps",
            "2",
            "--y",
            "omega_ratio",
            "--y-from",
            "0.7",
            "--y-to",
            "0.8",
            "--y-steps",
            "2",
        ],
        vec![
            "map",
            "--x",
            "omega_ratio",
            "--x-from",
            "0.7",
            "--x-to",
            "0.8",
            "--x-steps",
            "2",
            "--y",
            "frequency_hz",
            "--y-from",
            "0.7",
            "--y-to",
            "0.8",
            "--y-steps",
            "2",
        ],
        vec![
            "optimize-mass-ratio",
            "--omega-steps",
            "2",
            "--rm-steps",
            "2",
            "--transient",
            "5",
            "--recorded",
            "5",
            "--settle",
            "fixed",
            "--set",
            "oscillator.masses=[1e300,0.1,0.1]",
        ],
        vec!["export-spice", "/nonexistent/run"],
        vec!["plot", "/nonexistent/dir"],
        vec!["merge", "--out", "/nonexistent/merged", "/nonexistent/a"],
    ];
    for c in &mut cases {
        if c[0] == "simulate" || c[0] == "load-sweep" {
            c.extend_from_slice(&short);
        }
    }
    let mut cases: Vec<Vec<String>> = cases.into_iter().map(|c| strings(&c)).collect();
    cases.push(strings(&["simulate", &io, "--out", &d("io"), "--plot", "-q"]));
    cases.push(strings(&[
        "load-sweep",
        "--steps",
        "2",
        "--vq-points",
        "1000000000",
        "--out",
        &d("ls"),
        "--set",
        "run.periods=6",
    ]));
    cases
}

/// `--set` arguments of a chain of `n` equal masses (the default case's m1, its spring and
/// damper) with gaps of 2 cm, at rest.
fn chain(n: usize) -> Vec<String> {
    let list = |x: &str, len: usize| format!("[{}]", vec![x; len].join(","));
    [
        format!("oscillator.masses={}", list("0.048", n)),
        "oscillator.stiffness=120.0".into(),
        "oscillator.damping=0.02".into(),
        format!("oscillator.gaps={}", list("0.02", n - 1)),
        format!("run.initial_positions={}", list("0.0", n)),
        format!("run.initial_velocities={}", list("0.0", n)),
    ]
    .into_iter()
    .flat_map(|s| ["--set".to_string(), s])
    .collect()
}

/// `--set` arguments of a flat random excitation over 0.001–5000 Hz for 20 s: 100 000
/// harmonics, some 10¹⁰ evaluations to build.
fn wide_random() -> Vec<String> {
    [
        "excitation.kind=\"random\"",
        "excitation.rms_acceleration=1.0",
        "excitation.f_low_hz=0.001",
        "excitation.f_high_hz=5000",
        "excitation.duration_s=20",
    ]
    .into_iter()
    .flat_map(|s| ["--set".to_string(), s.to_string()])
    .collect()
}

/// Long phases asked to stop by SIGTERM two seconds in (a large random excitation's build,
/// a chain of 2000 masses), and the same sizes without `--allow-large` (refused or skipped
/// with the reason): each must end cleanly, the signalled ones within the stop bound.
fn signalled_cases() -> Vec<(Vec<String>, bool)> {
    let short = strings(&["--set", "run.periods=8", "--set", "run.transient_periods=4"]);
    let case = |head: &[&str], tail: &[Vec<String>], signal: bool| {
        let mut c = strings(head);
        for t in tail {
            c.extend(t.iter().cloned());
        }
        (c, signal)
    };
    vec![
        case(&["simulate", "-q"], &[wide_random(), short.clone()], false),
        case(
            &["simulate", "-q", "--allow-large"],
            &[wide_random(), short.clone()],
            true,
        ),
        case(
            &[
                "lyapunov",
                "-q",
                "--allow-large",
                "--periods",
                "5",
                "--transient",
                "2",
            ],
            &[wide_random(), short.clone()],
            true,
        ),
        case(&["simulate", "-q"], &[chain(2000), short.clone()], true),
        case(&["simulate", "-q"], &[chain(2000), short.clone()], false),
    ]
}

/// A small seeded generator (xorshift64*), so that a failing case can be run again.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[self.below(xs.len())]
    }

    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
}

/// A command line of each subcommand that runs as given (short runs), to which random
/// options and values are added.
fn base_case(command: usize, run: &str) -> Vec<&str> {
    let mut args: Vec<&str> = match command {
        0 => vec!["simulate"],
        1 => vec!["load-sweep", "--steps", "3"],
        2 => vec!["export-spice", run],
        3 => vec!["periodic"],
        4 => vec![
            "continue",
            "--param",
            "omega_ratio",
            "--from",
            "0.75",
            "--to",
            "0.8",
            "--max-points",
            "5",
        ],
        5 => vec![
            "sweep",
            "--param",
            "omega_ratio",
            "--from",
            "0.7",
            "--to",
            "0.8",
            "--steps",
            "2",
        ],
        6 => vec!["merge", "--out", "merged", run],
        7 => vec!["chirp", "--from", "0.7", "--to", "0.8", "--duration", "2"],
        8 => vec![
            "map",
            "--x",
            "omega_ratio",
            "--x-from",
            "0.7",
            "--x-to",
            "0.8",
            "--x-steps",
            "2",
            "--y",
            "mass_ratio",
            "--y-from",
            "2",
            "--y-to",
            "3",
            "--y-steps",
            "2",
        ],
        9 => vec!["optimize-mass-ratio", "--omega-steps", "2", "--rm-steps", "2"],
        10 => vec![
            "basins",
            "--x",
            "run.initial_positions[0]",
            "--x-from",
            "-0.01",
            "--x-to",
            "0.01",
            "--y",
            "run.initial_velocities[0]",
            "--y-from",
            "-0.1",
            "--y-to",
            "0.1",
            "--grid",
            "2x2",
        ],
        11 => vec![
            "attractors",
            "--param",
            "omega_ratio",
            "--from",
            "0.7",
            "--to",
            "0.8",
            "--steps",
            "2",
            "--samples",
            "2",
        ],
        12 => vec!["lyapunov", "--periods", "20", "--transient", "5"],
        13 => vec!["plot", run],
        _ => vec!["bogus"],
    };
    if matches!(command, 5 | 8 | 9 | 10 | 11) {
        args.extend_from_slice(&["--transient", "5", "--recorded", "5", "--settle", "fixed"]);
    }
    args
}

/// Options of the subcommands, each taken with a random value where it takes one.
const OPTIONS: [&str; 34] = [
    "--steps",
    "--from",
    "--to",
    "--param",
    "--transient",
    "--recorded",
    "--vq-points",
    "--dt-fraction",
    "--from-period",
    "--periods",
    "--name",
    "--x",
    "--y",
    "--x-steps",
    "--y-steps",
    "--samples",
    "--grid",
    "--jump-window",
    "--threads",
    "--shard",
    "--mass",
    "--period",
    "--max-points",
    "--duration",
    "--out",
    "--resume",
    "--force",
    "--allow-large",
    "--mechanics-only",
    "--plot",
    "-q",
    "--check",
    "--settle",
    "--omega-steps",
];

const FLAGS: [&str; 8] = [
    "--resume",
    "--force",
    "--allow-large",
    "--mechanics-only",
    "--plot",
    "-q",
    "--check",
    "--out",
];

const VALUES: [&str; 26] = [
    "0",
    "1",
    "2",
    "3",
    "-1",
    "0.5",
    "0.75",
    "1e300",
    "-1e300",
    "1e-300",
    "nan",
    "inf",
    "-inf",
    "abc",
    "",
    "1000000000",
    "1e12",
    "omega_ratio",
    "mass_ratio",
    "gap",
    "1/2",
    "0/0",
    "../../escape",
    "auto",
    "fixed",
    "excitation.amplitude",
];

const SETTINGS: [&str; 24] = [
    "run.periods=3",
    "run.periods=0",
    "run.periods=1e12",
    "run.transient_periods=1",
    "run.samples_per_period=1",
    "run.samples_per_period=100000000000",
    "oscillator.masses=[1e300,0.1,0.1]",
    "oscillator.masses=[1e-300,0.1,0.1]",
    "oscillator.masses=[]",
    "oscillator.damping=1e9",
    "oscillator.damping=-1",
    "oscillator.stiffness=1e300",
    "oscillator.gaps=[0,0]",
    "excitation.omega_ratio=0",
    "excitation.omega_ratio=1e9",
    "excitation.amplitude=nan",
    "excitation.harmonics[0].amplitude=1",
    "harvester.coupling=\"two_way\"",
    "harvester.storage_initial_voltage=1e9",
    "harvester.load=\"rectifier\"",
    "mass_ratio=3",
    "gap_ratio=0",
    "foo=1",
    "excitation.kind=\"random\"",
];

/// A random command line: a subcommand's runnable base, perhaps a configuration, random
/// options and values and `--set` overrides. `run` is a finished `simulate` run, `dir` a
/// scratch directory for its output.
fn random_case(rng: &mut Rng, run: &str, dir: &Path) -> Vec<String> {
    let mut args = strings(&base_case(rng.below(15), run));
    let reads_a_run = matches!(args[0].as_str(), "export-spice" | "merge" | "plot");
    if rng.chance(40) && !reads_a_run {
        let configs = [
            "default.toml",
            "impact_oscillator.toml",
            "chatter.toml",
            "record_default.toml",
        ];
        args.push(config_file(rng.pick(&configs)).display().to_string());
    }
    // Keep most runs short, so that a case is about its input, not its length.
    if rng.chance(80) && !reads_a_run {
        args.extend(strings(&[
            "--set",
            "run.periods=8",
            "--set",
            "run.transient_periods=4",
        ]));
    }
    // Half the cases as runnable as their base, the others with hostile additions.
    if rng.chance(50) {
        return args;
    }
    for _ in 0..rng.below(3) {
        let option = rng.pick(&OPTIONS);
        args.push(option.to_string());
        if option == "--out" {
            args.push(dir.join("out").display().to_string());
        } else if !FLAGS.contains(&option) {
            args.push(rng.pick(&VALUES).to_string());
        }
    }
    if !reads_a_run {
        for _ in 0..rng.below(3) {
            if rng.chance(50) {
                args.push("--set".into());
                args.push(rng.pick(&SETTINGS).to_string());
            }
        }
    }
    args
}

/// Runs `count` random cases from `seed` (and the known ones), with a signal at a random
/// moment in a quarter of them.
fn hostile(seed: u64, count: usize) {
    let scratch = tempdir();
    let mut tally = Tally::default();
    for args in known_cases(scratch.path()) {
        let e = run_case(&args, scratch.path(), None);
        tally.add(&args, &e);
    }
    for (args, signal) in signalled_cases() {
        let e = run_case(
            &args,
            scratch.path(),
            signal.then_some((Duration::from_secs(2), SIGTERM)),
        );
        tally.add(&args, &e);
    }
    // A finished run for export-spice, merge and plot to read.
    let run = scratch.path().join("run");
    let made = run_case(
        &strings(&[
            "simulate",
            "-q",
            "--out",
            run.to_str().unwrap(),
            "--set",
            "run.periods=8",
            "--set",
            "run.transient_periods=4",
        ]),
        scratch.path(),
        None,
    );
    assert_eq!(made.status, Some(0), "{}", made.stderr);
    let run = run.display().to_string();
    let mut rng = Rng(seed);
    for i in 0..count {
        let dir: PathBuf = scratch.path().join(format!("case{i}"));
        std::fs::create_dir_all(&dir).unwrap();
        let args = random_case(&mut rng, &run, &dir);
        let signal = rng.chance(25).then(|| {
            let sig = [SIGINT, SIGTERM, SIGKILL][rng.below(3)];
            (Duration::from_millis(rng.below(1500) as u64), sig)
        });
        let e = run_case(&args, &dir, signal);
        tally.add(&args, &e);
    }
    tally.check();
}

#[test]
fn hostile_command_lines_end_cleanly() {
    hostile(0x5eed_0001, 12);
}

/// The full run (`cargo test -p vibrotribo-cli --test cli hostile -- --ignored`).
#[test]
#[ignore = "minutes: the full hostile-input run"]
fn hostile_command_lines_end_cleanly_full() {
    hostile(0x5eed_0002, 400);
}
