//! # subfric-diagnose
//!
//! Diagnosis of the gap between a calibrated subloading-friction model and laboratory data:
//! **where** the residual lies (per test and per segment, against the noise estimated from the
//! data), **which** unmodelled effect explains it (a library of candidate extensions, each
//! refitted and compared with the base model on held-out data and by BIC), and **how far** the
//! gap shrinks with it. [`selfcheck`] checks the diagnosis on generated sets whose effect it is
//! not told.

pub mod candidates;
pub mod diagnose;
pub mod selfcheck;
pub mod synth;

pub use candidates::{library, Candidate, Effect};
pub use diagnose::{diagnose, DiagnoseError, DiagnoseOptions, Diagnosis, Thresholds, Verdict};
