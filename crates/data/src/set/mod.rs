//! Experiment sets on disk: loading, validating and writing.

mod load;
mod parse;
mod validate;

pub use load::{load_set, load_test};
pub use parse::parse_test;
pub(crate) use parse::{comment_text, parse_number};
pub(crate) use validate::validate_data;

use std::path::PathBuf;

use crate::meta::{ControlColumn, ExperimentMeta, TestSpec};

/// Name of the description file inside a set's folder.
pub const EXPERIMENT_JSON: &str = "experiment.json";

/// Largest magnitude accepted in any column (s, mm, kPa): 10¹² s is 30 000 years, 10¹² mm a
/// million kilometres. Beyond it a value is no measurement, and the model's arithmetic on it
/// would overflow.
pub const MAX_MAGNITUDE: f64 = 1e12;

/// Column names accepted in a test CSV.
pub const ACCEPTED_COLUMNS: [&str; 5] =
    ["time_s", "slip_mm", "shear_kpa", "friction", "normal_kpa"];

/// Further channels an interface lab records, accepted in a test CSV and carried with the
/// test as read (written back with it, given to Python), not used by the model: the normal
/// (vertical) displacement — dilation, what constant-normal-stiffness tests are about — a
/// temperature, and the force and area a stress was computed from. A missing sample in one of
/// them is kept as a missing value, not a gap of the row.
pub const CHANNEL_COLUMNS: [&str; 5] = [
    "normal_disp_mm",
    "temperature_c",
    "shear_force_kn",
    "normal_force_kn",
    "area_mm2",
];

/// One further channel of a test ([`CHANNEL_COLUMNS`]): its name and a value per row (NaN
/// where the logger missed a sample).
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Column name, as in [`CHANNEL_COLUMNS`].
    pub name: String,
    /// One value per row of the test.
    pub values: Vec<f64>,
}

/// The data of one test, validated.
///
/// All column vectors have the same length, one entry per data row.
#[derive(Clone, Debug, PartialEq)]
pub struct TestData {
    /// The test's description from `experiment.json`.
    pub spec: TestSpec,
    /// Path of the CSV file.
    pub path: PathBuf,
    /// Time, s (strictly increasing).
    pub time_s: Vec<f64>,
    /// Slip, mm.
    pub slip_mm: Vec<f64>,
    /// Shear traction, kPa (computed as friction × normal when the CSV gave `friction`).
    pub shear_kpa: Vec<f64>,
    /// Normal stress per row, kPa (from the `normal_kpa` column, else from the spec).
    pub normal_kpa: Vec<f64>,
    /// True when the CSV had `friction` instead of `shear_kpa`.
    pub friction_given: bool,
    /// 1-based line number in the CSV of each row, for messages.
    pub line_of_row: Vec<usize>,
    /// The `#` comment lines (provenance text), without the `#` and one following space.
    pub comments: Vec<String>,
    /// What the reader made of the file as written, one note each (rows without a value
    /// left out as gaps, repeated time stamps spread over their clock tick): shown with the
    /// plausibility warnings.
    pub reading_notes: Vec<crate::Warning>,
    /// Further channels the CSV carried ([`CHANNEL_COLUMNS`]), in the order of its header.
    pub channels: Vec<Channel>,
}

impl TestData {
    /// The test from row `first` on (a leading artifact cut off); lines keep their numbers.
    pub fn rows_from(&self, first: usize) -> TestData {
        let first = first.min(self.len());
        TestData {
            spec: self.spec.clone(),
            path: self.path.clone(),
            time_s: self.time_s[first..].to_vec(),
            slip_mm: self.slip_mm[first..].to_vec(),
            shear_kpa: self.shear_kpa[first..].to_vec(),
            normal_kpa: self.normal_kpa[first..].to_vec(),
            friction_given: self.friction_given,
            line_of_row: self.line_of_row[first..].to_vec(),
            comments: self.comments.clone(),
            reading_notes: self.reading_notes.clone(),
            channels: self
                .channels
                .iter()
                .map(|c| Channel {
                    name: c.name.clone(),
                    values: c.values[first.min(c.values.len())..].to_vec(),
                })
                .collect(),
        }
    }

    /// The column the apparatus imposed: slip for slip control, shear for shear control.
    pub fn imposed(&self) -> &[f64] {
        match self.spec.control {
            ControlColumn::Slip => &self.slip_mm,
            ControlColumn::Shear => &self.shear_kpa,
        }
    }

    /// The measured column: shear for slip control, slip for shear control.
    pub fn measured(&self) -> &[f64] {
        match self.spec.control {
            ControlColumn::Slip => &self.shear_kpa,
            ControlColumn::Shear => &self.slip_mm,
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// True when the test has no rows.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// Friction ratio shear / normal per row.
    pub fn friction(&self) -> Vec<f64> {
        self.shear_kpa
            .iter()
            .zip(&self.normal_kpa)
            .map(|(s, n)| s / n)
            .collect()
    }

    /// True when the normal stress is not the same on every row or differs from the spec.
    pub fn normal_varies(&self) -> bool {
        self.normal_kpa
            .iter()
            .any(|&n| n != self.spec.normal_stress_kpa)
    }

    /// A fingerprint of the test's rows (time, slip, shear and normal stress, bit for bit):
    /// two tests with the same fingerprint hold the same data, whatever their names and files
    /// (a 64-bit SipHash: two different records share one by chance once in 10¹⁹).
    pub fn content_hash(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.len().hash(&mut h);
        for col in [
            &self.time_s,
            &self.slip_mm,
            &self.shear_kpa,
            &self.normal_kpa,
        ] {
            for x in col.iter() {
                x.to_bits().hash(&mut h);
            }
        }
        h.finish()
    }

    /// 1-based CSV line of a row (0 if unknown).
    pub fn line(&self, row: usize) -> usize {
        self.line_of_row.get(row).copied().unwrap_or(0)
    }
}

/// An experiment set: `experiment.json` and the data of all its tests.
#[derive(Clone, Debug, PartialEq)]
pub struct ExperimentSet {
    /// The folder it was loaded from (or is meant to be written to).
    pub dir: PathBuf,
    /// The description.
    pub meta: ExperimentMeta,
    /// The tests, in the order of `meta.tests`.
    pub tests: Vec<TestData>,
}

impl ExperimentSet {
    /// The test of that name.
    pub fn test(&self, name: &str) -> Option<&TestData> {
        self.tests.iter().find(|t| t.spec.name == name)
    }
}

// Writing sets lives in `write.rs`; its functions keep their paths here.
pub(crate) use crate::write::prepare_parent;
pub use crate::write::{meta_json_text, test_csv_text, write_set};
