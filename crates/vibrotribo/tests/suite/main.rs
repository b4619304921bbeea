//! The library's integration tests, one binary (one link of the library instead of one per
//! file): each module is a test file of its own concern; `cargo test -p vibrotribo --test
//! suite NAME` runs the tests whose path contains NAME (e.g. `reliability`).

mod common;

mod attractors;
mod bandwidth;
mod bifmap;
mod charge_layers;
mod chirp;
mod config;
mod config_reference;
mod coupling;
mod coupling_base_motion;
mod coupling_checks;
mod coupling_events;
mod electrical_accuracy;
mod electrical_analytic;
#[cfg(feature = "spice")]
mod electrical_ngspice;
mod electrical_rectifier_switching;
mod electrical_sweep;
mod events_vs_bruteforce;
mod excitation_energy;
mod excitation_engine;
mod excitation_signals;
mod external_forces;
mod floquet_labels;
mod flow_vs_integrator;
mod issue_breakdown_depends_on_sampling;
mod issue_charge_solver_underflow;
mod issue_coupled_stick_release_loop;
mod issue_long_phases_cost_and_stop;
mod issue_resonant_microchatter;
#[cfg(feature = "spice")]
mod issue_spice_step_limit;
mod issue_touching_group_residual_velocity;
mod issue_touching_masses_event_storm;
mod labels;
mod layering;
mod lyapunov;
mod merit;
mod motion;
mod optimize;
mod orbits_branch_points;
mod orbits_branch_stability;
mod orbits_cascade_certified;
mod orbits_continuation;
mod orbits_curve;
mod orbits_doubling_switch;
mod orbits_grazing;
mod orbits_neimark_sacker;
mod orbits_non_smooth_fold;
mod orbits_runs_onto;
mod orbits_shooting;
mod properties;
mod reference_default_case;
mod reliability;
mod response;
mod sensitivity_nonsmooth;
mod sensitivity_parameters;
mod sensitivity_stm;
mod special_cases;
mod stop_inside_chatter;
mod stops;
mod stops_sensitivity;
mod sweep_parameters;
mod validation;
