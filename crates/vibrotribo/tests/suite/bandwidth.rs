//! The half-power bandwidth of a frequency response against closed forms: a Lorentzian's
//! half-power points, and the envelope of up and down sweeps of a hysteretic response.

use vibrotribo::analysis::half_power_bandwidth;

/// A Lorentzian `1/((Ω − 1)² + γ²)` has its half-power points at `1 ± γ` exactly.
#[test]
fn lorentzian_half_power_band() {
    let g = 0.05;
    let samples: Vec<(f64, f64)> = (0..=2000)
        .map(|i| {
            let w = 0.5 + i as f64 / 2000.0;
            (w, 1.0 / ((w - 1.0).powi(2) + g * g))
        })
        .collect();
    let b = half_power_bandwidth(&[&samples]).unwrap();
    assert!((b.peak_frequency - 1.0).abs() < 1e-12);
    // Linear interpolation on a 5e-4 grid: second-order error.
    assert!((b.lower.unwrap() - (1.0 - g)).abs() < 1e-5, "{b:?}");
    assert!((b.upper.unwrap() - (1.0 + g)).abs() < 1e-5, "{b:?}");
    assert!((b.width().unwrap() - 2.0 * g).abs() < 2e-5);
}

/// Up and down sweeps of a hardening response: the envelope takes the upper branch where
/// both exist, and the band runs to where the upper branch ends.
#[test]
fn envelope_of_hysteresis() {
    let up: Vec<(f64, f64)> = (0..=10)
        .map(|i| (i as f64, if i <= 7 { i as f64 } else { 1.0 }))
        .collect();
    let down: Vec<(f64, f64)> = (0..=10)
        .map(|i| (i as f64, if i >= 5 { 1.0 } else { i as f64 }))
        .collect();
    let b = half_power_bandwidth(&[&up, &down]).unwrap();
    assert_eq!(b.peak_frequency, 7.0);
    assert_eq!(b.peak_power, 7.0);
    // Half power 3.5: between 3 and 4 on the rising side, between 7 and 8 on the drop.
    assert!((b.lower.unwrap() - 3.5).abs() < 1e-12);
    assert!((b.upper.unwrap() - (7.0 + 3.5 / 6.0)).abs() < 1e-12);
    assert!(half_power_bandwidth(&[]).is_err());
    assert!(half_power_bandwidth(&[&[(f64::NAN, 1.0)]]).is_err());
}

/// Branches sampled on different frequencies: each counts between its own samples (linear
/// interpolation), so a lower branch sampled in between does not make the envelope dip.
#[test]
fn envelope_of_branches_on_different_grids() {
    // The upper branch, a tent 0..2 peaking at 1 with power 10, sampled at 0, 1, 2; a lower
    // one at power 1 sampled at 0.25, 0.5, …, 1.75.
    let upper = [(0.0, 0.0), (1.0, 10.0), (2.0, 0.0)];
    let lower: Vec<(f64, f64)> = (1..8).map(|i| (0.25 * i as f64, 1.0)).collect();
    let env = vibrotribo::analysis::envelope(&[&upper, &lower]).unwrap();
    for &(f, p) in &env {
        let tent = 10.0 * (1.0 - (f - 1.0).abs());
        // The lower branch only counts within its own span.
        let floor = if (0.25..=1.75).contains(&f) { 1.0 } else { 0.0 };
        let want = tent.max(floor);
        assert!((p - want).abs() < 1e-12, "at {f}: {p}, expected {want}");
    }
    let b = half_power_bandwidth(&[&upper, &lower]).unwrap();
    // Half power 5 on the tent's sides, at 0.5 and 1.5 exactly.
    assert!(
        (b.lower.unwrap() - 0.5).abs() < 1e-12 && (b.upper.unwrap() - 1.5).abs() < 1e-12,
        "{b:?}"
    );
    // A branch that folds back (frequencies not monotone) counts on both legs; a NaN breaks it.
    let folded = [(0.0, 1.0), (2.0, 3.0), (1.0, 5.0), (f64::NAN, f64::NAN)];
    assert!(
        vibrotribo::analysis::envelope(&[&folded]).is_err(),
        "a NaN frequency is an error"
    );
    let folded = [(0.0, 1.0), (2.0, 3.0), (1.0, 5.0), (1.5, f64::NAN), (0.5, 7.0)];
    let env = vibrotribo::analysis::envelope(&[&folded]).unwrap();
    let at = |f: f64| env.iter().find(|e| e.0 == f).unwrap().1;
    assert_eq!(at(1.0), 5.0);
    assert_eq!(at(0.5), 7.0, "its own sample, not joined to the broken neighbour");
    assert!((at(2.0) - 3.0).abs() < 1e-12);
}
