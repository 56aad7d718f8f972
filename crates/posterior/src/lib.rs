//! # subfric-posterior
//!
//! Posterior sampling for the subloading-friction calibration (issue 23). This first part holds
//! the ensemble sampler ([`ensemble`]: Goodman & Weare's stretch move, walkers in parallel,
//! deterministic for a seed, a budget and a progress callback) and its convergence diagnostics
//! ([`convergence`]: integrated autocorrelation time, split R̂ over walker groups, effective
//! sample size, and a verdict that says how many more steps a run needs).

#![warn(missing_docs)]

pub mod convergence;
pub mod ensemble;
