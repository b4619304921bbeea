//! The state of a reproduction: work sizes, the figures and findings collected for the
//! report, and the verdict of a finding.

use std::path::PathBuf;

use crate::job::RunArgs;

/// Work sizes of one mode.
#[derive(Debug, Clone, Copy)]
pub(super) struct Budget {
    pub(super) transient: u64,
    pub(super) recorded: u64,
    pub(super) coarse: usize,
    pub(super) fine: usize,
    pub(super) series: u64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Verdict {
    Agrees,
    Partly,
    Differs,
}

impl Verdict {
    /// All of `total` checks as the paper says: agrees; none: differs; else partly.
    pub(super) fn of(matches: usize, total: usize) -> Self {
        if matches == total {
            Verdict::Agrees
        } else if matches == 0 {
            Verdict::Differs
        } else {
            Verdict::Partly
        }
    }

    pub(super) fn text(self) -> &'static str {
        match self {
            Verdict::Agrees => "agrees",
            Verdict::Partly => "partly",
            Verdict::Differs => "**differs**",
        }
    }
}

pub(super) struct FigureEntry {
    pub(super) number: String,
    pub(super) title: String,
    pub(super) caption: String,
    pub(super) images: Vec<String>,
}

pub(super) struct Finding {
    pub(super) figures: String,
    pub(super) paper: String,
    pub(super) ours: String,
    pub(super) verdict: Verdict,
}

pub(super) struct Ctx {
    pub(super) out: PathBuf,
    pub(super) budget: Budget,
    pub(super) quick: bool,
    pub(super) quiet: bool,
    pub(super) figures: Vec<FigureEntry>,
    pub(super) findings: Vec<Finding>,
    pub(super) extras: Vec<String>,
    /// Sweep points whose charge solver failed (their mechanics is kept).
    pub(super) failures: std::sync::Mutex<Vec<String>>,
}

impl Ctx {
    pub(super) fn say(&self, what: &str) {
        if !self.quiet {
            eprintln!("reproduce: {what}");
        }
    }

    pub(super) fn figure(&mut self, number: &str, title: &str, caption: String, images: Vec<String>) {
        self.figures.push(FigureEntry {
            number: number.into(),
            title: title.into(),
            caption,
            images,
        });
    }

    pub(super) fn finding(&mut self, figures: &str, paper: &str, ours: String, verdict: Verdict) {
        self.findings.push(Finding {
            figures: figures.into(),
            paper: paper.into(),
            ours,
            verdict,
        });
    }

    pub(super) fn path(&self, name: &str) -> PathBuf {
        self.out.join(name)
    }

    pub(super) fn run_args(&self, mechanics_only: bool) -> RunArgs {
        RunArgs {
            transient: Some(self.budget.transient),
            recorded: Some(self.budget.recorded),
            mechanics_only,
            period_tolerance: vibrotribo::study::DEFAULT_PERIOD_TOLERANCE,
            floquet: false,
            // Settled before recording, so that "not periodic" is a finding, not a short
            // transient; the motions are classified.
            settle: vibrotribo::study::SettleMode::Auto(vibrotribo::study::AutoSettle::default()),
            settle_cap: vibrotribo::study::DEFAULT_SETTLE_CAP,
            threads: None,
            quiet: true,
            allow_large: false,
            force: true,
        }
    }
}
