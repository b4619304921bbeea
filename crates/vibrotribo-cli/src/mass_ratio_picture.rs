//! The pictures of `optimize-mass-ratio`: the optimal mass ratio against Ω with its fit and
//! the paper's, drawn by the command's `--plot` and by `plot DIR` from the same files.

use std::path::Path;

use anyhow::{Result, bail};
use vibrotribo::analysis::{QuadraticFit, fit_quadratic};
use vibrotribo::study::paper_mass_ratio_fit as paper_fit;
use vibrotribo::sweep::grid;

use crate::manifest::{FitManifest, read};
use crate::output::{column, numbers, read_csv};
use crate::plot::{self, Figure, Series};

/// Draws the optima of an `optimize-mass-ratio` directory with their fit and the paper's
/// (`optimal_mass_ratio.png`/`.svg`), over the Ω range of `power_grid.csv`.
pub fn plot_optimize_mass_ratio(dir: &Path) -> Result<()> {
    let m: FitManifest = read(&dir.join("fit.json"))?;
    let (h, rows) = read_csv(&dir.join("power_grid.csv"))?;
    let omegas = numbers(&rows, column(&h, "omega_ratio")?);
    let (Some(&w_from), Some(&w_to)) = (omegas.first(), omegas.last()) else {
        bail!("{}: power_grid.csv holds no point", dir.display());
    };
    // The fit of the optima, as the command made it (the file holds its coefficients only).
    let fit = fit_quadratic(&m.omega_ratio, &m.optimal_mass_ratio).ok();
    crate::plot::both(dir, "optimal_mass_ratio", |path| {
        plot_optimal_mass_ratio(
            path,
            &m.omega_ratio,
            &m.optimal_mass_ratio,
            fit.as_ref(),
            (w_from, w_to),
        )
    })
}

/// Draws the optima (`ws`, `rs`), the paper's fit and `fit` over `[w_from, w_to]` to `path`.
pub fn plot_optimal_mass_ratio(
    path: &std::path::Path,
    ws: &[f64],
    rs: &[f64],
    fit: Option<&QuadraticFit>,
    (w_from, w_to): (f64, f64),
) -> Result<()> {
    let fine = grid(w_from, w_to, 100);
    let paper: Vec<f64> = fine.iter().map(|&w| paper_fit(w)).collect();
    let ours: Vec<f64> = fine
        .iter()
        .map(|&w| fit.map_or(f64::NAN, |f| f.eval(w)))
        .collect();
    let fig = Figure::new("Optimal mass ratio R_mo(Ω)", "Ω = ω/Ω1", "R_mo = m2/m1");
    plot::phase_portrait(
        path,
        &fig,
        &[
            Series::new("paper's fit", &fine, &paper),
            Series::new("fit to vibrotribo's optima", &fine, &ours),
        ],
        Some(Series::new("vibrotribo optima", ws, rs)),
    )
}
