//! The optimal mass ratio R_mo(Ω) of a three-mass harvester (the paper's Sect. 4.3.2,
//! Fig. 16): on a grid of Ω × R_m = m₂/m₁ (m₁ and m₃ fixed) the average power of every point
//! is computed (by the sweep runners); at each Ω the best R_m of the row, refined by the
//! parabola through it and its neighbours, is the optimum; a quadratic
//! R_mo = aΩ² + bΩ + c is fitted through the optima and compared with the paper's.

/// The paper's fit of the optimal mass ratio, R_mo = aΩ² + bΩ + c: `[a, b, c]`.
pub const PAPER_MASS_RATIO_FIT: [f64; 3] = [11.43, -28.46, 18.03];

/// The paper's fit of the optimal mass ratio evaluated at Ω = `w`.
pub fn paper_mass_ratio_fit(w: f64) -> f64 {
    let [a, b, c] = PAPER_MASS_RATIO_FIT;
    a * w * w + b * w + c
}

/// The maximum of `values` on the equally spaced `grid`, refined by the parabola through the
/// best point and its neighbours (when it is interior and the parabola is concave), as
/// (abscissa, value); `None` if no value is finite.
pub fn refine_maximum(grid: &[f64], values: &[f64]) -> Option<(f64, f64)> {
    let (best, &vmax) = values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    if best == 0 || best + 1 >= values.len() || !values[best - 1].is_finite() || !values[best + 1].is_finite()
    {
        return Some((grid[best], vmax));
    }
    let (a, b, c) = (values[best - 1], vmax, values[best + 1]);
    let denom = a - 2.0 * b + c;
    if denom >= 0.0 {
        return Some((grid[best], vmax));
    }
    let h = grid[best + 1] - grid[best];
    let shift = 0.5 * (a - c) / denom;
    Some((grid[best] + shift * h, b - 0.25 * (a - c) * shift))
}

/// The optimal mass ratio at one Ω.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassRatioOptimum {
    /// Ω = ω/√(k₁/m₁).
    pub omega_ratio: f64,
    /// The optimal R_m = m₂/m₁.
    pub mass_ratio: f64,
    /// The (refined) average power there, W.
    pub average_power_w: f64,
    /// Whether the optimum is at an end of the R_m range (widen the range).
    pub at_edge: bool,
}

/// The optimal mass ratio at each Ω of `omegas`: the maximum of its row of `power` (W,
/// row-major, `ratios.len()` mass ratios per Ω) refined by [`refine_maximum`]. An Ω without
/// a finite power is left out.
pub fn mass_ratio_optima(omegas: &[f64], ratios: &[f64], power: &[f64]) -> Vec<MassRatioOptimum> {
    let (Some(&first), Some(&last)) = (ratios.first(), ratios.last()) else {
        return Vec::new();
    };
    omegas
        .iter()
        .zip(power.chunks(ratios.len()))
        .filter_map(|(&w, row)| {
            let (r, p) = refine_maximum(ratios, row)?;
            let at_edge = (r - first).abs() < 1e-12 || (r - last).abs() < 1e-12;
            Some(MassRatioOptimum {
                omega_ratio: w,
                mass_ratio: r,
                average_power_w: p,
                at_edge,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vertex_of_a_sampled_parabola_is_found_exactly() {
        // p(r) = 3 − (r − 2.3)², sampled on 1, 1.5, …, 4: vertex at 2.3, value 3.
        let grid: Vec<f64> = (0..7).map(|k| 1.0 + 0.5 * f64::from(k)).collect();
        let values: Vec<f64> = grid.iter().map(|r| 3.0 - (r - 2.3) * (r - 2.3)).collect();
        let (r, p) = refine_maximum(&grid, &values).unwrap();
        assert!((r - 2.3).abs() < 1e-12 && (p - 3.0).abs() < 1e-12, "{r} {p}");
        let o = mass_ratio_optima(&[0.7, 0.8], &grid, &[values.clone(), vec![f64::NAN; 7]].concat());
        assert_eq!(o.len(), 1);
        assert!(!o[0].at_edge);
        assert!((paper_mass_ratio_fit(1.0) - (11.43 - 28.46 + 18.03)).abs() < 1e-12);
    }
}
