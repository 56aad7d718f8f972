//! # subfric-fit
//!
//! Calibration of the subloading-friction model against one or many tests: a least-squares
//! problem in a transformed parameter space ([`Space`]), solved by a global stage (informed
//! first guesses read off the curves, then differential evolution) followed by
//! Levenberg–Marquardt (or argmin's Nelder–Mead) from several distinct starts in parallel,
//! with standard errors, correlations, flat directions and profile intervals
//! ([`calibrate`]). Residuals are normalised by the noise level estimated from each test, so
//! tests at different normal stresses and controls weigh fairly and a reduced χ² of 1 means
//! "at the noise level".

pub mod calibrate;
pub mod dataset;
pub mod global;
pub mod guess;
pub mod lm;
pub mod prepare;
pub mod problem;
pub mod space;
pub mod uncertainty;

pub use calibrate::{
    calibrate, compare_with_published, FitError, FitOptions, FitReport, Method, ParamReport, Stage,
    Status,
};
pub use dataset::{misfits, typical_rate, FitTest, TestMisfit};
pub use prepare::{control_of, prepare_set, prepare_test, reference_model, PreparedTest};
pub use problem::{model_runs, Problem};
pub use space::{Coord, Param, Space};
