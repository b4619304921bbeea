//! How the points of a study settled before their recorded windows, as the manifests of the
//! command line's jobs record it and Python's results state it.

use serde::{Deserialize, Serialize};

use crate::study::{PointOptions, SettleMode};

/// How each point settled before its recorded window.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SettleRecord {
    /// `auto` or `fixed`.
    #[serde(default)]
    pub settle: String,
    /// `auto`: most periods run before the recorded window.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_cap_periods: Option<u64>,
    /// `auto`: periods between two checks of the motion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_block_periods: Option<u64>,
    /// `auto`: whether a geometric approach is finished by Newton shooting.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_newton: Option<bool>,
}

impl SettleRecord {
    /// The settling of `options`.
    pub fn of(options: &PointOptions) -> Self {
        let auto = match &options.settle {
            SettleMode::Auto(a) => Some(a),
            SettleMode::Fixed => None,
        };
        SettleRecord {
            settle: options.settle.as_str().to_string(),
            settle_cap_periods: auto.map(|a| a.cap_periods),
            settle_block_periods: auto.map(|a| a.block),
            settle_newton: auto.map(|a| a.shoot),
        }
    }
}
