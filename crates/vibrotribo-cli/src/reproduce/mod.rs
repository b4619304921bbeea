//! `vibrotribo reproduce [--quick] --out DIR`: the paper's study (Sect. 4, Figs. 5–25)
//! recomputed with the exact simulator, and `DIR/REPORT.md` comparing each stated finding
//! with what vibrotribo finds. Nothing here is tuned to match: every verdict is computed from
//! the numbers of this run.
//!
//! One file per group of figures (`configurations`, `spacing`, `mass_ratio`, `chatter`,
//! `orbits`, `dynamics`, `extras`, `vibration`, `coupling`, `design`, `bifmaps`), on shared runs (`runs`), figure helpers (`draw`), the branches drawn over orbit diagrams (`overlay`) and context (`context`);
//! `report` writes REPORT.md.

mod bifmaps;
mod chatter;
mod command;
mod configurations;
mod context;
mod coupling;
mod design;
mod draw;
mod dynamics;
mod extras;
mod mass_ratio;
mod orbits;
mod overlay;
mod report;
mod runs;
mod spacing;
#[cfg(test)]
mod tests;
mod vibration;

pub use command::{ReproduceArgs, run};
