//! # subfric-data
//!
//! Experiment data of the subloading-friction calibration: one folder per experiment set,
//! holding `experiment.json` and one CSV per test (see `DATA-FORMAT.md`).
//!
//! - [`load_set`], [`load_test`], [`write_set`]: read and write sets; every problem of every
//!   file is reported at once, naming the file, line and field ([`DataError`], [`InputProblem`]).
//! - [`condition_imposed`]: the imposed column with measurement noise removed where it would
//!   create spurious reversals (isotonic fit per monotone run, flat holds).
//! - [`segment()`]: loading phases (initial loading, steady sliding, velocity steps, holds,
//!   unloading, reversals) and cycles, for fitting, plots and diagnosis.
//! - [`summary()`]: a readable table for `subfric check`.
//! - [`import()`]: lab files in other delimiters, units and column names.
//! - [`plausibility`]: warnings about valid but unlikely data (a unit off by 10³, all zeros).
//! - [`write_atomic`]: every file this crate writes is written whole or not at all.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use subfric_data::{load_set, segment, SegmentOptions};
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("experiment.json"), r#"{"name": "demo", "title": "Demo", "source": "doc",
//!   "tests": [{"name": "bad", "file": "bad.csv", "control": "slip", "normal_stress_kpa": 100}]}"#)?;
//! std::fs::write(dir.path().join("bad.csv"), "time_s,slip_mm,shear_kpa\n0,0,0\n0,0.1,abc\n")?;
//! let err = load_set(dir.path()).unwrap_err();
//! let text = err.to_string();
//! assert!(text.contains("bad.csv:3: field `shear_kpa`: `abc` is not a number"));
//! # Ok(()) }
//! ```

#![warn(missing_docs)]

pub mod artifacts;
pub mod condition;
pub mod csvio;
mod error;
pub mod events;
pub mod fsio;
mod gaps;
pub mod import;
mod jsonpos;
pub mod line;
pub mod located;
pub mod meta;
pub mod noise;
pub mod normal;
pub mod plausible;
pub mod segment;
pub mod set;
pub mod stats;
pub mod summary;
pub mod text;
pub mod write;

pub use artifacts::{
    close_gap, gap_remainder, seating_toe, without_gap_rows, GapRemainder, SeatingToe,
};
pub use condition::{condition_imposed, condition_imposed_with, Conditioned};
pub use error::{DataError, InputProblem};
pub use fsio::{write_atomic, PathKind};
pub use import::{
    import, ColumnRef, Delimiter, ImportFormat, ImportSpec, Keep, KeepColumn, LengthUnit, RateUnit,
    StressUnit, TimeUnit,
};
pub use meta::{parse_meta, ControlColumn, ExperimentMeta, InitialSpec, Interface, TestSpec};
pub use noise::{estimate_noise, NoiseEstimate};
pub use plausible::{plausibility, Warning};
pub use segment::{
    segment, RateLevel, Segment, SegmentKind, SegmentOptions, Segmentation, Start, StartKind,
};
pub use set::{
    load_set, load_test, write_set, Channel, ExperimentSet, TestData, ACCEPTED_COLUMNS,
    CHANNEL_COLUMNS, EXPERIMENT_JSON,
};
pub use summary::{
    reading_lines, summary, summary_with, HoldSummary, SetSummary, StepSummary, TestSummary,
};
pub use text::{visible, MAX_NAME_BYTES};
