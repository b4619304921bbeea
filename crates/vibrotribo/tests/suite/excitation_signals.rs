//! The signal side of non-harmonic base motion, against truth from outside the
//! code: splines of a sine against the sine and the Hall–Meyer bounds, exact integration of
//! a piecewise-linear acceleration against the Fourier series of a triangle wave, chirps'
//! instantaneous frequency from the zero crossings of the built signal, random signals'
//! spectrum by an FFT of the signal, and the errors of bad records and keys.

// Index loops read as the formulas they implement (Gaussian elimination, spectral bins).
#![allow(clippy::needless_range_loop)]

use std::f64::consts::{PI, TAU};
use std::path::PathBuf;

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;
use vibrotribo::config::Config;
use vibrotribo::excitation::{
    BaseMotion, Chirp, EndCondition, ExcitationKind, ExcitationSpec, Harmonic, PiecewiseCubic, Psd, Quantity,
    RandomSpec, RecordSamples, RecordScaling, Sweep, record_displacement, spline_error_bounds,
};

// ---------------------------------------------------------------------------------------
// Helpers of the tests' own.

/// The L² projection of `f` onto the cubics over [0, L], evaluated by `q(t)`: normal
/// equations in the monomials of u = t/L, integrals by composite 3-point Gauss–Legendre on
/// `pieces` equal pieces (the tests' own quadrature, not the library's Legendre moments).
fn cubic_projection(f: &dyn Fn(f64) -> f64, length: f64, pieces: usize) -> impl Fn(f64) -> [f64; 3] {
    let x = [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()];
    let w = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let mut gram = [[0.0f64; 4]; 4];
    let mut rhs = [0.0f64; 4];
    let h = length / pieces as f64;
    for p in 0..pieces {
        for (xi, wi) in x.iter().zip(w) {
            let t = h * (p as f64 + 0.5 * (xi + 1.0));
            let u = t / length;
            let m = [1.0, u, u * u, u * u * u];
            let fw = f(t) * wi * h / 2.0;
            for i in 0..4 {
                rhs[i] += m[i] * fw;
                for j in 0..4 {
                    gram[i][j] += m[i] * m[j] * wi * h / 2.0;
                }
            }
        }
    }
    let b = solve4(gram, rhs);
    move |t: f64| {
        let u = t / length;
        [
            b[0] + u * (b[1] + u * (b[2] + u * b[3])),
            (b[1] + u * (2.0 * b[2] + 3.0 * u * b[3])) / length,
            (2.0 * b[2] + 6.0 * u * b[3]) / (length * length),
        ]
    }
}

/// Gaussian elimination with partial pivoting, 4×4.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..4 {
            let m = a[r][c] / a[c][c];
            for k in c..4 {
                a[r][k] -= m * a[c][k];
            }
            b[r] -= m * b[c];
        }
    }
    let mut x = [0.0; 4];
    for r in (0..4).rev() {
        let s: f64 = (r + 1..4).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    x
}

fn samples(times: Vec<f64>, values: Vec<f64>) -> RecordSamples {
    RecordSamples {
        path: "test".into(),
        value_column: "value".into(),
        time_offset: 0.0,
        times,
        values,
    }
}

/// A directory of the test's own (inside the target directory) for record files.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("excitation_signals")
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

// ---------------------------------------------------------------------------------------
// Splines of a sine.

/// A sin ωt sampled at 200 points per period (10 periods): the clamped spline (exact end
/// slopes) meets the Hall–Meyer bounds for y, y', y'' against the sine; the displacement
/// bound is 5/384 (2π/200)⁴ A = 1.27e-8 A. The not-a-knot spline of the same samples (what
/// a displacement record gets) meets the same displacement bound (5/384 h⁴ max|y''''|)
/// at every point, ends included.
#[test]
fn spline_of_a_sine_at_200_points_per_period() {
    let (a, w) = (0.08, 35.0);
    let period = TAU / w;
    let h = period / 200.0;
    let times: Vec<f64> = (0..=2000).map(|k| k as f64 * h).collect();
    let values: Vec<f64> = times.iter().map(|&t| a * (w * t).sin()).collect();
    let bounds = spline_error_bounds(h, a * w.powi(4));
    assert!(bounds[0] / a < 1.3e-8 && bounds[0] / a > 1.2e-8, "{bounds:?}");
    let clamped = PiecewiseCubic::interpolate(
        &times,
        &values,
        EndCondition::Clamped {
            start_slope: a * w,
            end_slope: a * w * (w * times[2000]).cos(),
        },
    )
    .unwrap();
    let not_a_knot = PiecewiseCubic::interpolate(&times, &values, EndCondition::NotAKnot).unwrap();
    let mut worst = [[0.0f64; 3]; 2];
    for k in 0..=200_000 {
        let t = times[2000] * k as f64 / 200_000.0;
        let exact = [
            a * (w * t).sin(),
            a * w * (w * t).cos(),
            -a * w * w * (w * t).sin(),
        ];
        for (s, spline) in [&clamped, &not_a_knot].into_iter().enumerate() {
            let got = spline.evaluate(t);
            for d in 0..3 {
                worst[s][d] = worst[s][d].max((got[d] - exact[d]).abs());
            }
        }
    }
    println!("clamped: errors {:?}, bounds {bounds:?}", worst[0]);
    println!("not-a-knot: errors {:?}", worst[1]);
    for d in 0..3 {
        assert!(
            worst[0][d] <= bounds[d],
            "clamped, derivative {d}: {:?}",
            worst[0]
        );
    }
    assert!(worst[1][0] <= bounds[0], "not-a-knot: {:?}", worst[1]);
    for s in [&clamped, &not_a_knot] {
        assert!(
            s.continuity_defects().iter().all(|&d| d < 1e-12),
            "{:?}",
            s.continuity_defects()
        );
    }
}

// ---------------------------------------------------------------------------------------
// Exact integration of acceleration records.

/// A triangle wave of acceleration (vertices on samples, so the piecewise-linear record is
/// exact) plus a known linear drift d₀ + d₁ t: after integration and baseline correction the
/// displacement is y − P₃y, y the triangle wave's double integral from its Fourier series
/// (−8a₀/(π²ω²) Σ (−1)^k sin(nωt)/n⁴, n = 2k+1) and P₃ the least-squares cubic (the test's
/// own quadrature); the reported baseline is the drift plus (P₃y)''.
#[test]
fn triangle_wave_acceleration_integrates_exactly() {
    let (a0, period, periods) = (3.0, 1.0, 10);
    let w = TAU / period;
    let tri = |t: f64| {
        let s = (t / period).rem_euclid(1.0);
        a0 * if s < 0.25 {
            4.0 * s
        } else if s < 0.75 {
            2.0 - 4.0 * s
        } else {
            4.0 * s - 4.0
        }
    };
    let y_true = |t: f64| {
        let mut sum = 0.0;
        for k in 0..20_000 {
            let n = (2 * k + 1) as f64;
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            sum += sign * (n * w * t).sin() / n.powi(4);
        }
        -8.0 * a0 / (PI * PI * w * w) * sum
    };
    let (d0, d1) = (0.7, -0.05);
    let times: Vec<f64> = (0..=100 * periods).map(|k| k as f64 * 0.01).collect();
    let acc: Vec<f64> = times.iter().map(|&t| tri(t) + d0 + d1 * t).collect();
    let (s, report) = record_displacement(
        &samples(times.clone(), acc),
        Quantity::Acceleration,
        RecordScaling::Factor(1.0),
    )
    .unwrap();
    let length = times[times.len() - 1];
    let p3 = cubic_projection(&y_true, length, 4000);
    let scale = 8.0 * a0 / (PI * PI * w * w); // the displacement's amplitude
    let mut worst: f64 = 0.0;
    for k in 0..=2000 {
        let t = length * k as f64 / 2000.0;
        let expected = y_true(t) - p3(t)[0];
        worst = worst.max((s.displacement(t) - expected).abs());
        // The corrected acceleration: the triangle wave minus (P₃y)''.
        let acc_expected = tri(t) - p3(t)[2];
        assert!((s.acceleration(t) - acc_expected).abs() < 1e-9 * a0, "t = {t}");
    }
    println!("triangle: worst displacement error {worst:e} m of {scale:e} m");
    assert!(worst < 1e-9 * scale, "{worst:e}");
    let b = report.baseline.unwrap();
    assert!(
        (b.acceleration_offset - (d0 + p3(0.0)[2])).abs() < 1e-9 * a0,
        "{b:?}"
    );
    let slope_p3 = (p3(length)[2] - p3(0.0)[2]) / length;
    assert!(
        (b.acceleration_slope - (d1 + slope_p3)).abs() < 1e-9 * a0,
        "{b:?}"
    );
    assert!(s.continuity_defects().iter().all(|&d| d < 1e-12));
}

/// A sine of acceleration sampled every 0.1 ms with a linear drift: the corrected
/// displacement is A sin ωt − P₃[A sin ωt] within the bound of integrating the
/// piecewise-linear interpolant (|e_raw| ≤ L²/2 · h²/8 · max|a''|) times the bound
/// 1 + Σₖ √(2k+1) of the cubic projection in the maximum norm.
#[test]
fn sampled_sine_acceleration_with_drift() {
    let (amp, w, length, h): (f64, f64, f64, f64) = (0.01, TAU, 2.0, 1e-4);
    let n = (length / h).round() as usize;
    let times: Vec<f64> = (0..=n).map(|k| k as f64 * h).collect();
    let acc: Vec<f64> = times
        .iter()
        .map(|&t| -amp * w * w * (w * t).sin() + 0.3 - 0.2 * t)
        .collect();
    let (s, _) = record_displacement(
        &samples(times, acc),
        Quantity::Acceleration,
        RecordScaling::Factor(1.0),
    )
    .unwrap();
    let y = |t: f64| amp * (w * t).sin();
    let p3 = cubic_projection(&y, length, 2000);
    let raw_bound = length * length / 2.0 * h * h / 8.0 * amp * w.powi(4);
    let lebesgue: f64 = 1.0 + (0..4).map(|k| ((2 * k + 1) as f64).sqrt()).sum::<f64>();
    let mut worst: f64 = 0.0;
    for k in 0..=4000 {
        let t = length * k as f64 / 4000.0;
        worst = worst.max((s.displacement(t) - (y(t) - p3(t)[0])).abs());
    }
    println!(
        "sampled sine: error {worst:e} m, bound {:e} m",
        lebesgue * raw_bound
    );
    assert!(worst <= lebesgue * raw_bound, "{worst:e}");
}

// ---------------------------------------------------------------------------------------
// Chirps.

/// The instantaneous frequency of the built chirp, measured from the zero crossings of its
/// spline (f = 1/(2Δt) between neighbouring zeros, at their midpoint: exact for a linear
/// sweep, off by (ln r/D)²Δt²/24 for a logarithmic one), follows the sweep's law
/// (f₀ + (f₁ − f₀)t/D or f₀ (f₁/f₀)^{t/D}) at the first zeros, in the middle and at the last
/// zeros, up and down; and the spline is within its stated
/// bound of A sin φ(t), φ written here from the definition.
#[test]
fn chirp_frequency_at_start_middle_end() {
    for sweep in [Sweep::Linear, Sweep::Logarithmic] {
        for (f0, f1) in [(2.0, 12.0), (12.0, 2.0)] {
            let d = 20.0;
            let chirp = Chirp {
                amplitude: 0.01,
                f_start_hz: f0,
                f_end_hz: f1,
                duration: d,
                sweep,
            };
            let (s, acc) = chirp.to_spline(1e-11).unwrap();
            let law = |t: f64| match sweep {
                Sweep::Linear => f0 + (f1 - f0) * t / d,
                Sweep::Logarithmic => f0 * (f1 / f0).powf(t / d),
            };
            let phase = |t: f64| match sweep {
                Sweep::Linear => TAU * (f0 * t + (f1 - f0) * t * t / (2.0 * d)),
                Sweep::Logarithmic => {
                    let r = (f1 / f0).ln() / d;
                    TAU * f0 * ((r * t).exp() - 1.0) / r
                }
            };
            // Displacement within the bound.
            for k in 0..=50_000 {
                let t = d * k as f64 / 50_000.0;
                let e = (s.displacement(t) - 0.01 * phase(t).sin()).abs();
                assert!(e <= acc.error_bounds[0], "{sweep:?} {f0}->{f1} t={t}: {e:e}");
            }
            // Zero crossings near t.
            let zero_after = |t: f64| {
                let step = 1.0 / (40.0 * f0.max(f1));
                let mut a = t;
                while s.displacement(a).signum() == s.displacement(a + step).signum() {
                    a += step;
                }
                let mut b = a + step;
                for _ in 0..100 {
                    let m = 0.5 * (a + b);
                    if s.displacement(m).signum() == s.displacement(a).signum() {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                0.5 * (a + b)
            };
            for t in [0.01, d / 2.0, d - 0.6] {
                let z0 = zero_after(t);
                let z1 = zero_after(z0 + 1e-6);
                let measured = 1.0 / (2.0 * (z1 - z0));
                let expected = law(0.5 * (z0 + z1));
                // The midpoint rule's error: ∫f = f(m)Δt + f''(ξ)Δt³/24, f'' = f (ln r/D)².
                let rate = match sweep {
                    Sweep::Linear => 0.0,
                    Sweep::Logarithmic => ((f1 / f0).ln() / d).abs(),
                };
                let dt = z1 - z0;
                let bound = rate * rate * dt * dt / 24.0 * (rate * dt).exp() + 1e-7;
                assert!(
                    (measured / expected - 1.0).abs() < bound,
                    "{sweep:?} {f0}->{f1} t={t}: {measured} vs {expected}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Random signals.

/// The acceleration of `harmonics` at n equal samples over [0, d], and its one-sided
/// amplitude spectrum by FFT (bin k: frequency k/d).
fn spectrum(harmonics: &[Harmonic], d: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
    let acc: Vec<f64> = (0..n)
        .map(|j| {
            let t = d * j as f64 / n as f64;
            harmonics
                .iter()
                .map(|h| -h.amplitude * h.omega * h.omega * (h.omega * t + h.phase).sin())
                .sum()
        })
        .collect();
    let mut buf: Vec<Complex<f64>> = acc.iter().map(|&a| Complex::new(a, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let amp = buf
        .iter()
        .take(n / 2)
        .map(|z| 2.0 * z.norm() / n as f64)
        .collect();
    (acc, amp)
}

/// A flat PSD given by its RMS: the sampled signal's RMS is the requested one; its FFT has
/// equal lines at every grid frequency k/D of the band and nothing outside; the level
/// (line²/2 per 1/D) is rms²/(f_high − f_low) within the grid's rounding of the band. A
/// table PSD: every line is √(2 S(f_k)/D), S interpolated here from the table.
#[test]
fn random_signal_rms_band_and_psd() {
    let d = 8.0;
    let (rms, lo, hi) = (2.0, 5.0, 40.0);
    let flat = RandomSpec {
        psd: Psd::Flat {
            rms,
            f_low_hz: lo,
            f_high_hz: hi,
        },
        seed: 7,
        duration: d,
    };
    let (s, acc_bounds, harmonics) = flat.to_spline(1e-9).unwrap();
    let n = 1024;
    let (acc, amp) = spectrum(&harmonics, d, n);
    let measured_rms = (acc.iter().map(|a| a * a).sum::<f64>() / n as f64).sqrt();
    assert!((measured_rms / rms - 1.0).abs() < 1e-12, "{measured_rms}");
    let lines: Vec<usize> = (1..n / 2).filter(|&k| amp[k] > 1e-9 * rms).collect();
    assert_eq!(lines.first().copied(), Some((lo * d) as usize));
    assert_eq!(lines.last().copied(), Some((hi * d) as usize));
    assert_eq!(lines.len(), ((hi - lo) * d) as usize + 1);
    let nominal = rms * rms / (hi - lo);
    for &k in &lines {
        let level = amp[k] * amp[k] / 2.0 * d;
        assert!(
            (level / nominal - 1.0).abs() <= 1.0 / ((hi - lo) * d) + 1e-9,
            "bin {k}: {level}"
        );
    }
    // The spline's acceleration is the signal within its bound.
    for j in (0..n).step_by(7) {
        let t = d * j as f64 / n as f64;
        assert!(
            (s.acceleration(t) - acc[j]).abs() <= acc_bounds.error_bounds[2],
            "t = {t}"
        );
    }
    // A table.
    let (fs, vs) = (vec![3.0, 10.0, 30.0], vec![0.0, 0.5, 0.1]);
    let table = RandomSpec {
        psd: Psd::Table {
            frequencies_hz: fs.clone(),
            values: vs.clone(),
        },
        seed: 7,
        duration: d,
    };
    let (_, _, h) = table.to_spline(1e-9).unwrap();
    let (_, amp) = spectrum(&h, d, n);
    for k in 1..n / 2 {
        let f = k as f64 / d;
        let s_f = if f < fs[0] || f > fs[2] {
            0.0
        } else if f <= fs[1] {
            vs[0] + (vs[1] - vs[0]) * (f - fs[0]) / (fs[1] - fs[0])
        } else {
            vs[1] + (vs[2] - vs[1]) * (f - fs[1]) / (fs[2] - fs[1])
        };
        assert!((amp[k] - (2.0 * s_f / d).sqrt()).abs() < 1e-10, "bin {k}");
    }
}

/// The same seed gives the same signal bit for bit; another seed another signal.
#[test]
fn random_signal_is_reproducible() {
    let spec = |seed| RandomSpec {
        psd: Psd::Flat {
            rms: 1.0,
            f_low_hz: 1.0,
            f_high_hz: 20.0,
        },
        seed,
        duration: 5.0,
    };
    let a = spec(11).to_spline(1e-9).unwrap().0;
    let b = spec(11).to_spline(1e-9).unwrap().0;
    let c = spec(12).to_spline(1e-9).unwrap().0;
    assert_eq!(a, b);
    assert_eq!(a.knots(), c.knots());
    let differ = a
        .coefficients()
        .iter()
        .zip(c.coefficients())
        .filter(|(x, y)| (x[0] - y[0]).abs() > 1e-6 * x[0].abs().max(1e-9))
        .count();
    assert!(differ > a.intervals() / 2, "{differ}");
}

// ---------------------------------------------------------------------------------------
// Configurations.

fn config_error(text: &str) -> String {
    Config::from_toml_str(text).unwrap_err().to_string()
}

#[test]
fn the_record_default_configuration_reads_and_runs() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/record_default.toml");
    let c = Config::from_path(&path).unwrap();
    assert_eq!(c.excitation().kind(), ExcitationKind::Record);
    c.check_runnable().unwrap();
    assert!(!c.is_periodic());
    let motion = c.base_motion().unwrap();
    let BaseMotion::Spline(s) = &motion else {
        panic!("{motion:?}")
    };
    assert!((s.displacement.end() - 29.99).abs() < 1e-9);
    let report = s.record.unwrap();
    // Scaled to the stated peak: the largest |a| at the samples is 9.8 m/s² before the
    // (small) baseline correction.
    assert!((report.scale_factor * 1.0 - 9.8).abs() < 1e-9, "{report:?}");
    let b = report.baseline.unwrap();
    assert!(b.relative_size < 0.01, "{b:?}");
    assert!((report.peak_acceleration / 9.8 - 1.0).abs() < b.relative_size + 1e-12);
    // Harmonic configurations pass the checks.
    assert!(Config::default().check_runnable().is_ok());
    assert!(Config::default().check_periodic("x").is_ok());
}

#[test]
fn multisine_resolves_its_frequencies() {
    let c = Config::from_toml_str(
        "[excitation]\nkind = \"multisine\"\nomega_ratio = 0.7\nharmonics = [{amplitude = 0.05, ratio = 1}, {amplitude = 0.01, frequency_hz = 3, phase = 0.5}]\n",
    )
    .unwrap();
    let ExcitationSpec::Multisine(h) = c.excitation() else {
        panic!()
    };
    assert_eq!(h[0].omega, 0.7 * (120.0f64 / 0.048).sqrt());
    assert_eq!((h[1].omega, h[1].phase), (TAU * 3.0, 0.5));
    // Two harmonics: runnable, not periodic with T.
    c.check_runnable().unwrap();
    assert!(!c.is_periodic());
}

#[test]
fn chirp_and_random_defaults_follow_the_run() {
    let c = Config::from_toml_str(
        "[excitation]\nkind = \"chirp\"\nf_start_hz = 2\nf_end_hz = 9\nsweep = \"logarithmic\"\n[run]\nperiods = 20\ntransient_periods = 5\n",
    )
    .unwrap();
    let ExcitationSpec::Chirp { chirp, tolerance } = c.excitation() else {
        panic!()
    };
    assert!((chirp.duration - 20.0 * c.chain().period()).abs() < 1e-12);
    assert!((tolerance - 1e-9 * 0.08).abs() < 1e-20);
    let c = Config::from_toml_str(
        "[excitation]\nkind = \"random\"\nrms_acceleration = 3\nf_low_hz = 2\nf_high_hz = 30\nseed = 4\nduration_s = 40\n",
    )
    .unwrap();
    let ExcitationSpec::Random { spec, .. } = c.excitation() else {
        panic!()
    };
    assert_eq!((spec.seed, spec.duration), (4, 40.0));
}

/// Every bad input is refused with its key, its file, its line.
#[test]
fn bad_excitations_are_named() {
    let dir = scratch("bad");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let good: String = (0..=3000)
        .map(|k| format!("{},{}\n", k as f64 * 0.01, (k as f64 * 0.3).sin()))
        .collect();
    let good = write("good.csv", &format!("time_s,acceleration_m_s2\n{good}"));
    let record = |file: &str, extra: &str| {
        format!("[excitation]\nkind = \"record\"\nfile = \"{file}\"\nquantity = \"acceleration\"\n{extra}")
    };
    assert!(Config::from_toml_str(&record(&good, "")).is_ok());
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            record(&dir.join("absent.csv").display().to_string(), ""),
            vec!["excitation.file", "absent.csv"],
        ),
        (
            record(&write("header.csv", "t,a\n0,1\n1,2\n2,3\n3,4\n"), ""),
            vec!["excitation.file", "header.csv, line 1", "bad header"],
        ),
        (
            record(&write("cell.csv", "time_s,a\n0,1\n1,2\n2,x\n3,4\n"), ""),
            vec!["excitation.file", "cell.csv, line 4", "not a number"],
        ),
        (
            record(&write("nan.csv", "time_s,a\n0,1\n1,NaN\n2,3\n3,4\n"), ""),
            vec!["nan.csv, line 3", "not finite"],
        ),
        (
            record(&write("order.csv", "time_s,a\n0,1\n2,2\n1,3\n3,4\n"), ""),
            vec!["order.csv, line 4", "out of order"],
        ),
        (
            record(&write("repeat.csv", "time_s,a\n0,1\n1,2\n1,3\n3,4\n"), ""),
            vec!["repeat.csv, line 4", "repeated"],
        ),
        (
            record(&write("few.csv", "time_s,a\n0,1\n1,2\n2,3\n"), ""),
            vec!["few.csv", "3 samples, at least 4"],
        ),
        (
            record(&write("short.csv", "time_s,a\n0,1\n1,2\n2,3\n3,4\n"), ""),
            vec!["excitation.file", "lasts 3.000000 s", "run.periods = 100", "17.951958 s"],
        ),
        (record(&good, "scale = 2\npeak_acceleration = 3\n"), vec!["excitation.peak_acceleration", "not both"]),
        (record(&good, "peak_acceleration = -3\n"), vec!["excitation.peak_acceleration = -3"]),
        (
            "[excitation]\nkind = \"record\"\nfile = \"x.csv\"\n".to_string(),
            vec!["excitation.quantity"],
        ),
        (
            "[excitation]\nfile = \"x.csv\"\n".to_string(),
            vec!["excitation.file", "kind = \"record\"", "not of kind = \"harmonic\""],
        ),
        (
            "[excitation]\nkind = \"chirp\"\nf_start_hz = 2\nharmonics = []\n".to_string(),
            vec!["excitation.harmonics", "not of kind = \"chirp\""],
        ),
        (
            "[excitation]\nkind = \"chirp\"\nf_start_hz = 2\n".to_string(),
            vec!["excitation.f_end_hz"],
        ),
        (
            "[excitation]\nkind = \"chirp\"\nf_start_hz = 2\nf_end_hz = 3\nduration_s = 1\n".to_string(),
            vec!["excitation.duration_s", "shorter than the run", "run.periods = 100"],
        ),
        (
            "[excitation]\nkind = \"chirp\"\nf_start_hz = 2\nf_end_hz = 3e5\n".to_string(),
            vec!["excitation.spline_tolerance", "spline knots"],
        ),
        (
            "[excitation]\nkind = \"multisine\"\nharmonics = [{amplitude = 0.1}]\n".to_string(),
            vec!["excitation.harmonics[0].ratio", "exactly one of"],
        ),
        (
            "[excitation]\nkind = \"multisine\"\nharmonics = [{amplitude = 0.1, ratio = 1}, {amplitude = -1, ratio = 2}]\n"
                .to_string(),
            vec!["excitation.harmonics[1].amplitude = -1"],
        ),
        (
            "[excitation]\nkind = \"multisine\"\nharmonics = [{amplitude = 0.1, ratio = 1, freq = 2}]\n".to_string(),
            vec!["freq"],
        ),
        (
            "[excitation]\nkind = \"random\"\nf_low_hz = 1\n".to_string(),
            vec!["excitation.rms_acceleration"],
        ),
        (
            "[excitation]\nkind = \"random\"\nrms_acceleration = 1\nf_low_hz = 5\nf_high_hz = 2\n".to_string(),
            vec!["excitation.f_high_hz", "f_low_hz = 5"],
        ),
        (
            "[excitation]\nkind = \"random\"\npsd_frequencies_hz = [1, 3, 2]\npsd_values = [1, 1, 1]\n".to_string(),
            vec!["excitation.psd_values", "psd_frequencies_hz[2] = 2"],
        ),
        (
            "[excitation]\nkind = \"random\"\nrms_acceleration = 1\nf_low_hz = 1\nf_high_hz = 2\nseed = -1\n".to_string(),
            vec!["seed"],
        ),
        (
            "[excitation]\nkind = \"noise\"\n".to_string(),
            vec!["kind", "unknown variant `noise`"],
        ),
    ];
    for (text, expected) in cases {
        let e = config_error(&text);
        for x in expected {
            assert!(e.contains(x), "{text}\nexpected {x:?} in: {e}");
        }
    }
}

/// A relative record path is relative to the configuration file.
#[test]
fn record_paths_are_relative_to_the_configuration() {
    let dir = scratch("relative");
    std::fs::create_dir_all(dir.join("data")).unwrap();
    let body: String = (0..=400)
        .map(|k| format!("{},{}\n", k as f64 * 0.05, 0.001 * (k as f64 * 0.2).sin()))
        .collect();
    std::fs::write(dir.join("data/rec.csv"), format!("time_s,displacement_m\n{body}")).unwrap();
    std::fs::write(
        dir.join("run.toml"),
        "[excitation]\nkind = \"record\"\nfile = \"data/rec.csv\"\nquantity = \"displacement\"\n[run]\nperiods = 10\n",
    )
    .unwrap();
    let c = Config::from_path(&dir.join("run.toml")).unwrap();
    let motion = c.base_motion().unwrap();
    // The displacement spline passes through the samples.
    for k in [0usize, 17, 400] {
        let t = k as f64 * 0.05;
        let y = 0.001 * (k as f64 * 0.2).sin();
        assert!((motion.evaluate(t)[0] - y).abs() < 1e-15, "{k}");
    }
    // And it stays relative after an override.
    let c = c.with("run.periods", toml::Value::Integer(12)).unwrap();
    assert!(c.base_motion().is_ok());
}
