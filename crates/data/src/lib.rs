//! # subfric-data
//!
//! Experiment data of the subloading-friction calibration: one folder per experiment set,
//! holding `experiment.json` and one CSV per test (see `DATA-FORMAT.md`).
//!
//! - [`load_set`], [`load_test`], [`write_set`]: read and write sets; every problem of every
//!   file is reported at once, naming the file, line and field ([`DataError`], [`InputProblem`]).
//! - [`import()`]: lab files in other delimiters, units and column names.
//! - [`plausibility`]: warnings about valid but unlikely data (a unit off by 10³, all zeros).
//! - [`write_atomic`]: every file this crate writes is written whole or not at all.
//!
//! What a record says (its segments, noise, artifacts, events, readings) is read by
//! `subfric-reading`, over the records this crate loads.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use subfric_data::load_set;
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

pub mod csvio;
mod error;
pub mod fsio;
mod gaps;
pub mod import;
mod jsonpos;
pub mod located;
pub mod meta;
pub mod plausible;
pub mod set;
pub mod text;
pub mod write;

pub use error::{DataError, InputProblem};
pub use fsio::{write_atomic, PathKind};
pub use import::{
    import, ColumnRef, Delimiter, ImportFormat, ImportSpec, Keep, KeepColumn, LengthUnit, RateUnit,
    StressUnit, TimeUnit,
};
pub use meta::{parse_meta, ControlColumn, ExperimentMeta, InitialSpec, Interface, TestSpec};
pub use plausible::{plausibility, Warning};
pub use set::{
    load_set, load_test, write_set, Channel, ExperimentSet, TestData, ACCEPTED_COLUMNS,
    CHANNEL_COLUMNS, EXPERIMENT_JSON,
};
pub use text::{visible, MAX_NAME_BYTES};
