//! Plausibility of a valid set: numbers that parse and pass validation but are unlikely for a
//! sand–metal interface test — a unit off by 10³, a measured column that is all zeros, a test
//! of a handful of rows. These are warnings, not errors: the user may know better, but a fit of
//! such data deserves a word before its numbers are believed.

use std::fmt;
use std::path::PathBuf;

use crate::meta::ControlColumn;
use crate::set::{ExperimentSet, TestData};

/// One plausibility warning, naming the file and field.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Warning {
    /// The test's CSV file.
    pub file: PathBuf,
    /// The column concerned.
    pub field: String,
    /// What looks wrong, and what was expected.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // One line, whatever the names in it hold.
        let line = format!(
            "{}: field `{}`: {}",
            self.file.display(),
            self.field,
            self.message
        );
        f.write_str(&crate::visible(&line))
    }
}

/// Largest |shear| / normal a sand–metal interface plausibly shows (dense sand on a rough
/// plate stays near 1; above 2 a unit is wrong, typically a force in N read as a stress).
pub const MAX_PLAUSIBLE_FRICTION: f64 = 2.0;
/// Smallest peak |shear| / normal of a test that slides (not all zeros).
pub const MIN_PLAUSIBLE_PEAK_FRICTION: f64 = 0.01;
/// Plausible normal stresses of a laboratory interface test [kPa].
pub const PLAUSIBLE_NORMAL_KPA: (f64, f64) = (1.0, 1.0e5);
/// Largest plausible slip magnitude [mm] (ring shear reaches a few metres).
pub const MAX_PLAUSIBLE_SLIP_MM: f64 = 1.0e4;
/// Largest plausible mean slip rate of a laboratory test [mm/s].
pub const MAX_PLAUSIBLE_RATE_MM_S: f64 = 100.0;
/// Largest plausible slip [mm] a test from rest takes to reach half its largest shear: a
/// sand–metal interface mobilises its friction within about a millimetre (a soft shear box or
/// ring within a few); a rise over more than 10 mm is a slip in µm labelled mm.
pub const MAX_PLAUSIBLE_HALF_RISE_MM: f64 = 10.0;
/// Fewest rows of a test that can show a curve.
pub const MIN_PLAUSIBLE_ROWS: usize = 10;

/// A number with about 4 significant digits, with an exponent when very large or small.
fn num(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        format!("{x:.3e}")
    } else {
        let s = format!("{x:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

fn span(v: &[f64]) -> f64 {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    if lo.is_finite() {
        hi - lo
    } else {
        0.0
    }
}

/// The slip a slip-controlled test that starts at rest (its first shear below half its
/// largest) takes to reach half its largest |shear|, from its first row.
fn half_rise_slip(t: &TestData) -> Option<f64> {
    if t.spec.control != ControlColumn::Slip || t.is_empty() {
        return None;
    }
    let peak = max_abs(&t.shear_kpa);
    if peak.is_nan() || peak <= 0.0 || t.shear_kpa[0].abs() >= 0.5 * peak {
        return None;
    }
    let i = t.shear_kpa.iter().position(|s| s.abs() >= 0.5 * peak)?;
    Some((t.slip_mm[i] - t.slip_mm[0]).abs())
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The plausibility warnings of one test, after what the reader made of its file (gaps left
/// out, a coarse clock spread: [`TestData::reading_notes`]).
pub fn test_warnings(t: &TestData) -> Vec<Warning> {
    let mut out = t.reading_notes.clone();
    let shear_field = if t.friction_given {
        "friction"
    } else {
        "shear_kpa"
    };
    let mut warn = |field: &str, message: String| {
        out.push(Warning {
            file: t.path.clone(),
            field: field.to_string(),
            message,
        })
    };
    if t.len() < MIN_PLAUSIBLE_ROWS {
        warn(
            "time_s",
            format!(
                "only {} row{} (expected a curve of at least {MIN_PLAUSIBLE_ROWS} rows)",
                t.len(),
                if t.len() == 1 { "" } else { "s" }
            ),
        );
    }
    let peak_friction = t
        .shear_kpa
        .iter()
        .zip(&t.normal_kpa)
        .map(|(s, n)| (s / n).abs())
        .fold(0.0f64, f64::max);
    if t.shear_kpa.iter().all(|&s| s == 0.0) {
        warn(
            shear_field,
            "the shear is 0 on every row (expected a measured shear: is the column right?)".into(),
        );
    } else if peak_friction > MAX_PLAUSIBLE_FRICTION {
        warn(
            shear_field,
            format!(
                "the shear reaches {} times the normal stress (expected |shear|/normal below {MAX_PLAUSIBLE_FRICTION} for a sand–metal interface): is the shear a force in N (import it with --shear-unit N --area <mm²>), or in Pa rather than kPa, or the normal stress in MPa?",
                num(peak_friction)
            ),
        );
    } else if peak_friction < MIN_PLAUSIBLE_PEAK_FRICTION {
        warn(
            shear_field,
            format!(
                "the shear never exceeds {} times the normal stress (expected a peak |shear|/normal above {MIN_PLAUSIBLE_PEAK_FRICTION}): is the shear in MPa rather than kPa, or the normal stress in Pa?",
                num(peak_friction)
            ),
        );
    }
    if let Some(rise) = half_rise_slip(t).filter(|&r| r > MAX_PLAUSIBLE_HALF_RISE_MM) {
        warn(
            "slip_mm",
            format!(
                "the shear takes {} mm of slip from rest to reach half its largest value (expected well under {MAX_PLAUSIBLE_HALF_RISE_MM} mm: a sand–metal interface mobilises its friction within about a millimetre): is the slip in µm, labelled mm?",
                num(rise)
            ),
        );
    }
    let normal = max_abs(&t.normal_kpa);
    let (lo, hi) = PLAUSIBLE_NORMAL_KPA;
    if normal > hi || normal < lo {
        warn(
            "normal_kpa",
            format!(
                "the normal stress is {} kPa (expected {lo}–{hi:e} kPa for a laboratory test): is it in {}?",
                num(normal),
                if normal > hi { "Pa rather than kPa" } else { "MPa rather than kPa" }
            ),
        );
    }
    let slip = max_abs(&t.slip_mm);
    let duration = span(&t.time_s);
    let rate = if duration > 0.0 {
        span(&t.slip_mm) / duration
    } else {
        0.0
    };
    if slip > MAX_PLAUSIBLE_SLIP_MM || rate > MAX_PLAUSIBLE_RATE_MM_S {
        warn(
            "slip_mm",
            format!(
                "the slip reaches {} mm at a mean rate of {} mm/s (expected below {MAX_PLAUSIBLE_SLIP_MM:e} mm and {MAX_PLAUSIBLE_RATE_MM_S} mm/s): is the slip in µm rather than mm, or the time in ms rather than s?",
                num(slip),
                num(rate)
            ),
        );
    } else if t.spec.control == ControlColumn::Slip && t.len() > 1 && span(&t.slip_mm) == 0.0 {
        warn(
            "slip_mm",
            "the imposed slip never changes (expected a slip history under slip control)".into(),
        );
    }
    out
}

/// The plausibility warnings of every test of a set.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// std::fs::write(dir.path().join("experiment.json"), r#"{"name": "pa", "title": "t", "source": "s",
///   "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#)?;
/// let mut csv = String::from("time_s,slip_mm,shear_kpa\n");
/// // The shear written in Pa: 30 000 "kPa" at 100 kPa normal stress.
/// for i in 0..50 { csv.push_str(&format!("{i},{},{}\n", 0.01 * i as f64, 30000.0)); }
/// std::fs::write(dir.path().join("a.csv"), csv)?;
/// let set = subfric_data::load_set(dir.path())?;
/// let w = subfric_data::plausibility(&set);
/// assert_eq!(w.len(), 1);
/// assert!(w[0].to_string().contains("a.csv: field `shear_kpa`: the shear reaches 300"));
/// # Ok(()) }
/// ```
pub fn plausibility(set: &ExperimentSet) -> Vec<Warning> {
    set.tests.iter().flat_map(test_warnings).collect()
}
