//! # subfric-model
//!
//! The subloading-friction model of sand–metal interfaces ("Description of sand–metal friction
//! behavior based on subloading-friction model", hyperelastic-based formulation):
//!
//! - hyperelastic contact f = Ē ū^e, Ē = α_t (I − n⊗n) + α_n n⊗n (Eq. 15);
//! - sliding normal-yield and subloading surfaces ‖f_t‖ = r μ f_n (Eqs. 21–22);
//! - friction coefficient μ̇ = −κ(μ − μ_k)‖u̇^p‖ + ξ(μ_s − μ), μ₀ = μ_s (Eq. 24);
//! - normal-yield ratio ṙ = ũ cot(πr/2)‖u̇^p‖ (Eqs. 27, 29);
//! - tangential associated flow (Eq. 34).
//!
//! This crate knows nothing of files, plots or optimisers: it integrates the model through a
//! loading history given as numbers ([`simulate`]) or as a declarative [`Scenario`], and reads
//! a model from the JSON text of a parameter file ([`model_from_json`]; reading the file is the
//! caller's business).

pub mod contact1;
pub mod contact3;
pub mod extensions;
mod integrator;
pub mod json;
pub mod params;
pub mod scenario;
pub mod simulate;
pub mod terms;

pub use contact1::{Contact1, State1};
pub use contact3::{Contact3, State3, StateError, Tangent3, Vec3};
pub use extensions::{Extensions, Target};
pub use integrator::StepError;
pub use json::{model_from_json, model_from_value, ModelJsonError};
pub use params::{ParamError, ParamIssue, Params, MAX_ALPHA};
pub use scenario::{Scenario, ScenarioError, Stage, MAX_SCENARIO_ROWS};
pub use simulate::{
    check_start, simulate, simulate_predicted_into, simulate_predicted_while, Control, Initial,
    Protocol, SimError, Trajectory, SLIP_RESOLUTION_SHARE,
};
pub use terms::{
    AtRest, RateEffect, RateForm, StateLaw, StateSlots, TermEffect, TermEvidence, TermFamily,
    TermFile, TermGuess, TermLaw, Terms, MAX_STATE_SLOTS,
};

/// A validated model: the paper's parameters plus optional extensions.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Model {
    /// Parameters of the base model.
    pub params: Params,
    /// Extensions (the base model when all are `None`).
    #[serde(default)]
    pub ext: Extensions,
}

impl Model {
    /// Validates parameters and extensions together, reporting every problem at once.
    pub fn new(params: Params, ext: Extensions) -> Result<Model, ParamError> {
        let mut issues = match params.validate() {
            Ok(()) => Vec::new(),
            Err(e) => e.0,
        };
        for (name, value, expected) in ext.issues() {
            issues.push(ParamIssue {
                name,
                value,
                expected: expected.to_string(),
            });
        }
        if issues.is_empty() {
            Ok(Model { params, ext })
        } else {
            Err(ParamError(issues))
        }
    }

    /// The base model of the paper.
    pub fn base(params: Params) -> Result<Model, ParamError> {
        Model::new(params, Extensions::default())
    }
}
