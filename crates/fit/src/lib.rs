//! # subfric-fit
//!
//! Calibration of the subloading-friction model against one or many tests: a least-squares
//! problem in a transformed parameter space ([`Space`]), solved by a global stage (informed
//! first guesses read off the curves by `subfric-reading`, then differential evolution) followed by
//! Levenberg–Marquardt (or argmin's Nelder–Mead) from several distinct starts in parallel,
//! with standard errors, correlations, flat directions and profile intervals
//! ([`calibrate`]). Residuals are normalised by the noise level estimated from each test, so
//! tests at different normal stresses and controls weigh fairly and a reduced χ² of 1 means
//! "at the noise level".

pub mod adequacy;
pub mod bedding;
pub mod calibrate;
pub mod dataset;
pub mod drift;
pub mod global;
pub mod interval;
pub mod localise;
pub mod problem;
pub mod report;
pub mod sampling;
pub mod space;
pub mod stiffness;
pub mod uncertainty;

// The bounded Levenberg–Marquardt and the problem trait live in `subfric-solve` (below this
// crate and `subfric-reading`, whose velocity-step fits use them); here at their old paths.
pub use subfric_solve::{lm, residuals};

#[cfg(test)]
use subfric_solve::test_problems;

pub use bedding::{fit_bedding, seat, Bedding, Seated};
pub use calibrate::{
    best_informed_guesses, calibrate, calibrate_from, compare_with_published, with_base_of,
    CalibrationStage, Combination, FitError, FitOptions, FitReport, LocalMemo, LocalRun, Method,
    ParamReport, Status,
};
pub use dataset::{misfits, residuals_in_noise_units, TestMisfit};
pub use drift::{drift_coefficients, remove_drift, FittedDrift};
pub use interval::Interval;
pub use lm::Termination;
pub use problem::{Problem, RunCounter};
pub use residuals::{Bounded, Residuals};
pub use space::{AtBound, Coord, Param, Space};
pub use stiffness::stiffness_by_trial;
