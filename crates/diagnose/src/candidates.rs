//! The library of candidate effects: each a small extension of the model with one or two
//! parameters and a physical name.

use serde::{Deserialize, Serialize};
use subfric_fit::Param;

/// An effect the diagnosis can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Effect {
    /// The base model explains the data: the gap is noise.
    None,
    /// Direct rate dependence: friction rises with the log of the slip rate.
    Rate,
    /// Pressure dependence of μ_s and μ_k.
    Pressure,
    /// Slip hardening or softening with accumulated slip.
    SlipHardening,
    /// Logarithmic time healing instead of exponential recovery.
    LogHealing,
    /// Forward and backward sliding differ.
    Direction,
    /// A real gap that no candidate explains (e.g. measurement drift).
    Unexplained,
}

impl Effect {
    /// Every effect a verdict can name.
    pub const ALL: [Effect; 7] = [
        Effect::None,
        Effect::Rate,
        Effect::Pressure,
        Effect::SlipHardening,
        Effect::LogHealing,
        Effect::Direction,
        Effect::Unexplained,
    ];

    /// Name as in `diagnosis.json`.
    pub fn name(self) -> &'static str {
        match self {
            Effect::None => "none",
            Effect::Rate => "rate",
            Effect::Pressure => "pressure",
            Effect::SlipHardening => "slip-hardening",
            Effect::LogHealing => "log-healing",
            Effect::Direction => "direction",
            Effect::Unexplained => "unexplained",
        }
    }

    /// Parses a name.
    pub fn from_name(s: &str) -> Option<Effect> {
        Effect::ALL.iter().copied().find(|e| e.name() == s)
    }

    /// One-line physical description.
    pub fn describe(self) -> &'static str {
        match self {
            Effect::None => "no effect beyond the base model: the remaining gap is noise",
            Effect::Rate => "direct rate dependence: friction rises with log slip rate (a ln(1 + v/v_c))",
            Effect::Pressure => "pressure dependence: μ_s and μ_k scale as (p / 100 kPa)^(-β)",
            Effect::SlipHardening => "slip hardening/softening: friction changes by h s_h (1 − exp(−s/s_h)) with accumulated slip s",
            Effect::LogHealing => "logarithmic healing: recovery slows as ξ t_c/(t_c + θ) with contact age θ (aging law, memory slip d_c)",
            Effect::Direction => "direction dependence: backward sliding friction scaled by (1 − d)",
            Effect::Unexplained => "a real gap none of the candidates explains",
        }
    }
}

impl std::fmt::Display for Effect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A candidate extension: its extra parameters and starting values to try.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// The effect it models.
    pub effect: Effect,
    /// Extra free parameters.
    pub params: Vec<Param>,
    /// Starting values of the extra parameters (natural units), one vector per start.
    pub starts: Vec<Vec<f64>>,
    /// Values that switch the effect off (the base model).
    pub neutral: Vec<f64>,
}

/// The candidate library; `v_ref` is the typical slip rate of the data [mm/s].
pub fn library(v_ref: f64) -> Vec<Candidate> {
    vec![
        Candidate {
            effect: Effect::Rate,
            params: vec![Param::RateA, Param::RateVc],
            starts: vec![
                vec![0.01, 0.01 * v_ref],
                vec![0.01, v_ref],
                vec![-0.01, 0.1 * v_ref],
            ],
            neutral: vec![0.0, 0.1 * v_ref],
        },
        Candidate {
            effect: Effect::Pressure,
            params: vec![Param::PressureBeta],
            starts: vec![vec![0.1], vec![-0.1]],
            neutral: vec![0.0],
        },
        Candidate {
            effect: Effect::SlipHardening,
            params: vec![Param::SlipH, Param::SlipSh],
            starts: vec![vec![0.02, 2.0], vec![-0.02, 2.0], vec![0.01, 100.0], vec![-0.01, 100.0]],
            neutral: vec![0.0, 2.0],
        },
        Candidate {
            effect: Effect::LogHealing,
            params: vec![Param::HealTc, Param::HealDc],
            starts: vec![vec![1.0, 0.01], vec![30.0, 0.01], vec![30.0, 0.1], vec![1000.0, 0.001]],
            neutral: vec![1e6, 0.01],
        },
        Candidate {
            effect: Effect::Direction,
            params: vec![Param::DirectionD],
            starts: vec![vec![0.1], vec![-0.1]],
            neutral: vec![0.0],
        },
    ]
}
