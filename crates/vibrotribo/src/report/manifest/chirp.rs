//! `chirp.json`, the manifest of `vibrotribo chirp`: the chirp's settings
//! ([`ChirpSettingsRecord`], which Python's `chirp` states too), per direction the run and its
//! jump, and the hysteresis.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::Kind;
use crate::config::Config;
use crate::report::BaseMotionSummary;
use crate::study::ChirpOptions;

/// The settings of a chirp: its range, duration, law and amplitude, its start, sampling and
/// how a jump is found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChirpSettingsRecord {
    /// Ω at the start of the up chirp (dimensionless).
    pub from: f64,
    /// Ω at its end (dimensionless).
    pub to: f64,
    /// Duration of each direction, s.
    pub duration_s: f64,
    /// `linear` or `logarithmic`.
    pub sweep: String,
    /// Base amplitude, m.
    pub amplitude_m: Option<f64>,
    /// Mechanics only (no harvester).
    pub mechanics_only: bool,
    /// `settled` or `initial_state`.
    pub start: String,
    /// Samples per excitation cycle.
    pub samples_per_cycle: u64,
    /// Natural frequency √(k1/m1)/2π, Hz.
    pub natural_frequency_hz: f64,
    /// dΩ/dt, 1/s.
    pub sweep_rate_omega_per_s: f64,
    /// Cycles on each side of a jump.
    pub jump_window_cycles: usize,
    /// How a jump is found, in words.
    pub jump_criterion: String,
}

/// How a chirp's jump is found, in words.
const JUMP_CRITERION: &str = "the cycle boundary where the median amplitude of the jump_window cycles after it differs most from that of the jump_window cycles before it, for any mass, relative to that mass's largest amplitude in the chirp; omega_ratio at that boundary";

impl ChirpSettingsRecord {
    /// The settings of the chirps of `options` on `config`, their base amplitude
    /// `amplitude_m` (m; `None`: no chirp ran).
    pub fn of(config: &Config, options: &ChirpOptions, amplitude_m: Option<f64>) -> Self {
        let chain = config.chain();
        ChirpSettingsRecord {
            from: options.from,
            to: options.to,
            duration_s: options.duration_s,
            sweep: options.sweep.as_str().to_string(),
            amplitude_m,
            mechanics_only: options.mechanics_only,
            start: if options.settled_start {
                "settled"
            } else {
                "initial_state"
            }
            .to_string(),
            samples_per_cycle: options.samples_per_cycle,
            natural_frequency_hz: chain.omega() / chain.omega_ratio() / std::f64::consts::TAU,
            sweep_rate_omega_per_s: (options.to - options.from) / options.duration_s,
            jump_window_cycles: options.jump_window,
            jump_criterion: JUMP_CRITERION.to_string(),
        }
    }
}

/// The jump of one chirp direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JumpRecord {
    /// Ω at the jump.
    pub omega_ratio: f64,
    /// Excitation frequency at the jump, Hz.
    pub frequency_hz: f64,
    /// The cycle at the jump.
    pub cycle: u64,
    /// The mass whose amplitude jumps most (1-based).
    pub mass: usize,
    /// The jump's size, m.
    pub size_m: f64,
    /// The jump relative to that mass's largest amplitude.
    pub relative: f64,
}

/// One direction of a chirp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChirpRunRecord {
    /// Frequency at the start, Hz.
    pub f_start_hz: f64,
    /// Frequency the end would have had, Hz.
    pub f_end_hz_requested: f64,
    /// Duration run, s.
    pub run_duration_s: f64,
    /// Excitation periods run.
    pub periods: u64,
    /// Cycles measured.
    pub cycles: usize,
    /// Impacts over the run.
    pub impacts: u64,
    /// Whether it ran to its end.
    pub complete: bool,
    /// Why it stopped early.
    pub failure: Option<String>,
    /// Its jump, if any.
    pub jump: Option<JumpRecord>,
    /// Its base motion, when it is not the chain's own harmonic.
    pub base_motion: Option<BaseMotionSummary>,
}

/// The hysteresis of a chirp: the up and down jumps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HysteresisRecord {
    /// Ω of the up jump.
    pub up_jump_omega_ratio: f64,
    /// Ω of the down jump.
    pub down_jump_omega_ratio: f64,
    /// Their difference.
    pub width: f64,
}

/// `chirp.json`: the settings, per direction the run and its jump, the hysteresis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChirpManifest {
    /// Always [`Kind::Chirp`].
    pub command: Kind,
    /// The chirp's settings (`from` … `jump_criterion`).
    #[serde(flatten)]
    pub chirp: ChirpSettingsRecord,
    /// The up chirp.
    pub up: Option<ChirpRunRecord>,
    /// The down chirp.
    pub down: Option<ChirpRunRecord>,
    /// Both jumps, when both were found.
    pub hysteresis: Option<HysteresisRecord>,
    /// Whether both directions ran to their end.
    pub complete: bool,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The program's version.
    pub vibrotribo_version: String,
}

#[cfg(test)]
mod tests {
    use super::super::round_trips;
    use super::*;

    #[test]
    fn chirp_manifest_round_trips_byte_for_byte() {
        round_trips::<ChirpManifest>(
            r#"{"command":"chirp","from":2.3,"to":2.6,"duration_s":2.0,"sweep":"linear","amplitude_m":0.01,"mechanics_only":false,"start":"settled","samples_per_cycle":200,"natural_frequency_hz":7.7969680123367615,"sweep_rate_omega_per_s":0.15000000000000013,"jump_window_cycles":5,"jump_criterion":"the cycle boundary where the median amplitude of the jump_window cycles after it differs most from that of the jump_window cycles before it, for any mass, relative to that mass's largest amplitude in the chirp; omega_ratio at that boundary","up":{"f_start_hz":17.93302642837455,"f_end_hz_requested":20.272116832075582,"run_duration_s":2.000777735052508,"periods":39,"cycles":38,"impacts":38,"complete":true,"failure":null,"jump":{"omega_ratio":2.341448798185491,"frequency_hz":18.256201381976624,"cycle":5,"mass":1,"size_m":-0.000786467814282342,"relative":0.04832352312363258},"base_motion":{"kind":"chirp","run_as":"exact per-interval cubic forces k_i y + c_i y' of the spline","spline_intervals":"15320","duration_s":"2.000777735052508e0","knot_spacing_s":"1.3059906886765717e-4","spline_error_bound_m":"9.99934915351887e-12","spline_velocity_error_bound_m_s":"2.45008770496561e-7"}},"down":{"f_start_hz":20.272116832075582,"f_end_hz_requested":17.93302642837455,"run_duration_s":2.000777735052508,"periods":39,"cycles":38,"impacts":38,"complete":true,"failure":null,"jump":{"omega_ratio":2.343133728181077,"frequency_hz":18.26933872725524,"cycle":33,"mass":1,"size_m":0.0005788544347253843,"relative":0.03631401105581164},"base_motion":{"kind":"chirp","run_as":"exact per-interval cubic forces k_i y + c_i y' of the spline","spline_intervals":"15320","duration_s":"2.000777735052508e0","knot_spacing_s":"1.3059906886765717e-4","spline_error_bound_m":"9.997557130923704e-12","spline_velocity_error_bound_m_s":"2.4496486151348593e-7"}},"hysteresis":{"up_jump_omega_ratio":2.341448798185491,"down_jump_omega_ratio":2.343133728181077,"width":-0.0016849299955863373},"complete":true,"wall_time_s":1.5,"settings":{},"vibrotribo_version":"0.1.0"}"#,
        );
    }
}
