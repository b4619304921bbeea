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
