//! # subfric-diagnose
//!
//! Diagnosis of the gap between a calibrated subloading-friction model and laboratory data:
//! **where** the residual lies (per test and per segment, against the noise estimated from the
//! data), **which** unmodelled effects explain it (every form of five candidate families,
//! refitted, compared with the base on held-out pieces of the data, named one after the other
//! by forward selection, and checked against what the residual itself follows), and **how far**
//! the gap shrinks with them. (`subfric selfcheck` checks it on sets made by an independent
//! generator, `subfric-harness`, scored in `subfric-app`.)

pub mod candidates;
pub mod confidence;
pub mod diagnose;
pub mod events;
pub mod evidence;
pub mod fits;
pub mod folds;
// The data features the candidates read are subfric-reading's; `crate::features` names them.
use subfric_reading::features;

pub mod score;
pub mod verdict;

pub use candidates::{library, Effect, Form};
pub use diagnose::{
    diagnose, diagnose_reporting, prepare_for_diagnosis, DiagnoseError, DiagnoseOptions, Diagnosis,
    NamedEffect, Step, Verdict, DIAGNOSIS_BUDGET_ROWS,
};
pub use verdict::Thresholds;
