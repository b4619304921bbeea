//! A period-doubling cascade read off a continuation, and its Feigenbaum ratios.

use super::types::{Bifurcation, BifurcationKind, Continuation};

/// The period doublings of the cascade that starts on the first branch, in order: the first
/// period doubling of the first branch whose doubled branch was followed, then the first such
/// doubling on that doubled branch, and so on. Empty if the first branch has none.
pub fn cascade(result: &Continuation) -> Vec<&Bifurcation> {
    let mut out = Vec::new();
    let mut branch = 0;
    while let Some(b) = result.branches.get(branch) {
        let Some(pd) = b
            .bifurcations
            .iter()
            .find(|f| f.kind == BifurcationKind::PeriodDoubling && f.child.is_some())
            .or_else(|| {
                b.bifurcations
                    .iter()
                    .find(|f| f.kind == BifurcationKind::PeriodDoubling)
            })
        else {
            break;
        };
        out.push(pd);
        match pd.child {
            Some(c) if c > branch => branch = c,
            _ => break,
        }
    }
    out
}

/// Feigenbaum ratios `δ_k = (p_k − p_{k−1}) / (p_{k+1} − p_k)` of successive period-doubling
/// parameters `p_0, p_1, …` (one fewer than the differences; empty below three points). They
/// tend to 4.669… along a cascade of a dissipative map with a quadratic maximum, only
/// asymptotically.
pub fn feigenbaum_ratios(parameters: &[f64]) -> Vec<f64> {
    parameters
        .windows(3)
        .map(|w| (w[1] - w[0]) / (w[2] - w[1]))
        .collect()
}
