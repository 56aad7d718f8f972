//! The library of candidate effects: each a small extension of the model with one or two
//! parameters and a physical name.

use serde::{Deserialize, Serialize};
use subfric_fit::Param;
use subfric_model::{Extensions, Healing, HealingForm, SlipForm, SlipHardening};

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
            Effect::LogHealing => "logarithmic healing: at rest friction regains b ln(1 + t/t_c), and none while sliding",
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
    /// Which form of the effect (several forms may stand for one effect).
    pub variant: &'static str,
    /// The extension switched on with its shape (parameters are then set from `params`).
    pub template: Extensions,
    /// Extra free parameters.
    pub params: Vec<Param>,
    /// Starting values of the extra parameters (natural units), one vector per start.
    pub starts: Vec<Vec<f64>>,
    /// Values that switch the effect off (the base model).
    pub neutral: Vec<f64>,
}

/// The candidate library; `v_ref` is the typical slip rate of the data [mm/s].
pub fn library(v_ref: f64) -> Vec<Candidate> {
    let hardening = |capped: bool| Extensions {
        slip_hardening: Some(SlipHardening {
            h: 0.0,
            s_h: 2.0,
            form: if capped {
                SlipForm::Capped
            } else {
                SlipForm::Exponential
            },
        }),
        ..Extensions::default()
    };
    vec![
        Candidate {
            effect: Effect::Rate,
            variant: "a ln(1 + v/v_c)",
            template: Extensions::default(),
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
            variant: "(p/100 kPa)^-beta",
            template: Extensions::default(),
            params: vec![Param::PressureBeta],
            starts: vec![vec![0.1], vec![-0.1]],
            neutral: vec![0.0],
        },
        Candidate {
            effect: Effect::SlipHardening,
            variant: "h s_h (1 - exp(-s/s_h))",
            template: hardening(false),
            params: vec![Param::SlipH, Param::SlipSh],
            starts: vec![
                vec![0.02, 2.0],
                vec![-0.02, 2.0],
                vec![0.01, 100.0],
                vec![-0.01, 100.0],
            ],
            neutral: vec![0.0, 2.0],
        },
        Candidate {
            effect: Effect::SlipHardening,
            variant: "h min(s, s_h)",
            template: hardening(true),
            params: vec![Param::SlipH, Param::SlipSh],
            starts: vec![
                vec![0.01, 5.0],
                vec![-0.01, 5.0],
                vec![0.01, 15.0],
                vec![-0.01, 15.0],
            ],
            neutral: vec![0.0, 5.0],
        },
        Candidate {
            effect: Effect::LogHealing,
            variant: "b ln(1 + t/t_c) at rest",
            template: Extensions {
                healing: Some(Healing {
                    b: 0.0,
                    t_c: 10.0,
                    n: 0.5,
                    form: HealingForm::Log,
                }),
                ..Extensions::default()
            },
            params: vec![Param::HealB, Param::HealTc],
            starts: vec![vec![0.01, 1.0], vec![0.01, 30.0], vec![0.03, 10.0]],
            neutral: vec![0.0, 10.0],
        },
        Candidate {
            effect: Effect::Direction,
            variant: "backward x (1 - d)",
            template: Extensions::default(),
            params: vec![Param::DirectionD],
            starts: vec![vec![0.1], vec![-0.1]],
            neutral: vec![0.0],
        },
    ]
}
