//! # subfric-reading
//!
//! What a subfric record says before any global model is fitted to it, read once for the
//! calibration (`subfric-fit`), the diagnosis (`subfric-diagnose`) and the application layer:
//!
//! - [`segment()`]: loading phases (initial loading, steady sliding, velocity steps, holds,
//!   unloading, reversals) and cycles, on the imposed column conditioned at the resolution of
//!   the data ([`condition`], [`imposed`]: the events of the imposed column; [`normal`]: the
//!   normal-stress column the model is given);
//! - [`artifacts`]: rig and logger artifacts (a seating toe, a gap closed in the record);
//! - [`noise`]: the noise of a column, white and slow;
//! - [`summary()`]: a readable table of a set for `subfric check`;
//! - [`prepare`]: each test as the calibration sees it ([`FitTest`], [`PreparedTest`]:
//!   conditioned, its seating toe left out, thinned to the rows that carry information);
//! - [`levels`], [`read_off`]: the per-test readings (peak and residual stress ratios and their
//!   trends; what a model's curve shows against what the record shows), [`guess`]: first
//!   guesses of the parameters read off the curves;
//! - [`stiffness`]: what the record says of the elastic stiffness α_t, and the one decision
//!   among those readings and a trial (`decide_stiffness`) that `fit` and the diagnosis share;
//! - [`events`]: the events read one by one, as friction labs read a record before any global
//!   model (every velocity step fitted on its own with a spring-slider and rate-and-state
//!   friction by `subfric-solve`'s Levenberg–Marquardt, every hold, every reversal), their
//!   consensus, the springs the steps resolve and the first guesses they give;
//! - [`features`]: what the record shows the diagnosis's candidates (rates, normal stresses,
//!   holds, reversals, steps, noise seen and unseen);
//! - [`stats`]: the small statistics every reading shares (medians, quantiles, the
//!   least-squares line, the autocorrelation).
//!
//! File formats, located errors and the I/O of records are `subfric-data`'s; this crate reads
//! the records that crate loads.

#![warn(missing_docs)]

pub mod artifacts;
pub mod condition;
pub mod estimate;
pub mod events;
pub mod features;
pub mod fit_test;
pub mod guess;
pub mod imposed;
pub mod levels;
pub mod noise;
pub mod normal;
pub mod prepare;
pub mod read_off;
pub mod segment;
pub mod stats;
pub mod stiffness;
pub mod summary;
pub mod thin;

pub use artifacts::{
    close_gap, gap_remainder, seating_toe, without_gap_rows, GapRemainder, SeatingToe,
};
pub use condition::{condition_imposed, condition_imposed_with, Conditioned};
pub use estimate::Estimate;
pub use fit_test::{typical_rate, FitTest};
pub use levels::{read_levels, LevelReadings, StressTrend, TestLevels};
pub use noise::{estimate_noise, NoiseEstimate};
pub use prepare::{
    control_of, prepare_set, prepare_set_with, prepare_test, reference_model, thin_prepared,
    PrepareOptions, PreparedTest,
};
pub use read_off::{read_off, ReadOff};
pub use segment::{
    segment, RateLevel, Segment, SegmentKind, SegmentOptions, Segmentation, Start, StartKind,
};
pub use stiffness::{decide_stiffness, resolved_stiffness, Stiffness, StiffnessReadings};
pub use summary::{
    reading_lines, summary, summary_with, HoldSummary, SetSummary, StepSummary, TestSummary,
};
