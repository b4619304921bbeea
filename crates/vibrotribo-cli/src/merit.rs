//! The triboelectric figures of merit of a `simulate` run in its files: the breakdown
//! boundary at the run's states (`breakdown_boundary.csv`) and the V–Q picture (`vq_cycle`:
//! the run's cycle after the transient, the CMEO cycle, the Paschen boundary). The numbers
//! come from [`vibrotribo::merit`].

use std::path::Path;

use anyhow::Result;
use vibrotribo::merit::BoundaryPoint;

use crate::output::{CsvFile, column, numbers, read_csv};
use crate::plot::{self, Figure, Series, both};

/// Writes `breakdown_boundary.csv`: per state of the run (thinned), the smallest and largest
/// charge no air gap breaks down at and the terminal voltage there.
pub fn write_boundary(dir: &Path, points: &[BoundaryPoint]) -> Result<()> {
    let mut csv = CsvFile::create(
        &dir.join("breakdown_boundary.csv"),
        &["q_low_c", "v_low_v", "q_high_c", "v_high_v"],
    )?;
    for p in points {
        csv.row([p.q_low_c, p.v_low_v, p.q_high_c, p.v_high_v])?;
    }
    csv.flush()
}

/// Draws `vq_cycle.png/.svg` of a `simulate` directory with a harvester: the run's V–Q
/// trajectory after the transient, the CMEO cycle `cmeo_cycle` (summary.json's) and the breakdown boundary;
/// nothing where the directory holds no boundary (a run without a harvester).
pub fn plot_vq(dir: &Path, cmeo_cycle: Option<&[[f64; 2]; 4]>, transient_s: f64) -> Result<()> {
    let boundary = dir.join("breakdown_boundary.csv");
    if !boundary.exists() {
        return Ok(());
    }
    let (h, rows) = read_csv(&dir.join("trajectory.csv"))?;
    let (Ok(qc), Ok(vc)) = (column(&h, "q_c"), column(&h, "v_v")) else {
        return Ok(());
    };
    let t = numbers(&rows, 0);
    let after: Vec<usize> = (0..t.len()).filter(|&j| t[j] >= transient_s).collect();
    let (all_q, all_v) = (numbers(&rows, qc), numbers(&rows, vc));
    let q: Vec<f64> = after.iter().map(|&j| all_q[j]).collect();
    let v: Vec<f64> = after.iter().map(|&j| all_v[j]).collect();
    let (bh, brows) = read_csv(&boundary)?;
    let edge = |name: &str| column(&bh, name).map(|c| numbers(&brows, c));
    let (ql, vl, qh, vh) = (
        edge("q_low_c")?,
        edge("v_low_v")?,
        edge("q_high_c")?,
        edge("v_high_v")?,
    );
    let corners: &[[f64; 2]] = cmeo_cycle.map_or(&[], |c| c.as_slice());
    let mut cq: Vec<f64> = corners.iter().map(|c| c[0]).collect();
    let mut cv: Vec<f64> = corners.iter().map(|c| c[1]).collect();
    if let (Some(&q0), Some(&v0)) = (cq.first(), cv.first()) {
        cq.push(q0);
        cv.push(v0);
    }
    let fig = Figure::new(
        "V–Q: the run after the transient, the CMEO cycle, the breakdown boundary",
        "charge Q [C]",
        "terminal voltage V [V]",
    );
    let lines = [
        Series::new("run", &q, &v),
        Series::new("CMEO cycle", &cq, &cv).dashed(),
    ];
    let points = [
        Series::new("breakdown boundary", &ql, &vl).colour(3),
        Series::unlabelled(&qh, &vh).colour(3),
    ];
    both(dir, "vq_cycle", |path| {
        plot::lines_and_points(path, &fig, &lines, &points, 2)
    })
}
