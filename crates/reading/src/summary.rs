//! A readable summary of an experiment set, for `subfric check`.

use std::fmt;

use serde::Serialize;

use crate::noise::{estimate_noise, NoiseEstimate};
use crate::segment::{segment, SegmentOptions, Start, StartKind};
use subfric_data::meta::ControlColumn;
use subfric_data::set::{ExperimentSet, TestData};
use subfric_data::text::{num, visible};

/// Summary of one hold.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HoldSummary {
    /// First row of the hold.
    pub start_row: usize,
    /// One past the last row.
    pub end_row: usize,
    /// Time the hold began, s.
    pub start_time_s: f64,
    /// Duration, s.
    pub duration_s: f64,
}

/// Summary of one velocity step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepSummary {
    /// Row of the step (last row at the old rate).
    pub row: usize,
    /// Time of the step, s.
    pub time_s: f64,
    /// Imposed rate before, per s.
    pub from_rate: f64,
    /// Imposed rate after, per s.
    pub to_rate: f64,
}

/// Summary of one test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TestSummary {
    /// Test name.
    pub name: String,
    /// CSV file name.
    pub file: String,
    /// Imposed column.
    pub control: ControlColumn,
    /// Number of rows.
    pub rows: usize,
    /// First and last time, s.
    pub time_span_s: (f64, f64),
    /// Smallest and largest slip, mm.
    pub slip_range_mm: (f64, f64),
    /// Smallest and largest shear, kPa.
    pub shear_range_kpa: (f64, f64),
    /// Smallest and largest normal stress, kPa (equal when constant).
    pub normal_range_kpa: (f64, f64),
    /// True when the CSV gave friction instead of shear.
    pub friction_given: bool,
    /// Estimated noise SD of the imposed column (mm or kPa).
    pub imposed_noise_sd: f64,
    /// True when conditioning changed the imposed column.
    pub imposed_conditioned: bool,
    /// Distinct |sliding rates| found, ascending (mm/s or kPa/s).
    pub sliding_rates: Vec<f64>,
    /// Holds.
    pub holds: Vec<HoldSummary>,
    /// Velocity steps.
    pub velocity_steps: Vec<StepSummary>,
    /// Number of reversals of the imposed direction.
    pub reversals: usize,
    /// Number of cycles.
    pub cycles: u32,
    /// How the test starts, and why.
    pub start: Start,
    /// Noise of the imposed column.
    pub imposed_noise: NoiseEstimate,
    /// Noise of the measured column (shear kPa under slip control, slip mm under traction
    /// control): what the residuals of a fit are compared with.
    pub measured_noise: NoiseEstimate,
    /// The units the CSV's columns were written in, where the set declares them (`units` of
    /// experiment.json), as read and converted: e.g. "stress MPa → kPa ×1000".
    pub units_read: Vec<String>,
    /// The further channels the test carries (dilation, temperature, forces, area), each with
    /// its range and its missing samples: e.g. "normal_disp_mm 0..0.06".
    pub channels: Vec<String>,
    /// A constant-normal-stiffness test's stiffness [kPa/mm], when the test gives one.
    pub normal_stiffness_kpa_per_mm: Option<f64>,
}

/// Summary of an experiment set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetSummary {
    /// Set name.
    pub name: String,
    /// Title.
    pub title: String,
    /// Provenance text, if any.
    pub provenance: Option<String>,
    /// One entry per test.
    pub tests: Vec<TestSummary>,
}

fn range(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

/// Rates within this factor of the slowest of their group count as one rate: the scatter of
/// a nominal rate across a test stays well under 30 %, deliberate velocity steps (×3, ×10) are
/// far larger.
const SAME_RATE_FACTOR: f64 = 1.3;

/// Groups rates that differ by less than 30 % ([`SAME_RATE_FACTOR`]) and returns one (the
/// median) per group.
fn distinct_rates(mut rates: Vec<f64>) -> Vec<f64> {
    rates.retain(|r| r.is_finite() && *r > 0.0);
    rates.sort_by(f64::total_cmp);
    let mut out = Vec::new();
    let mut group: Vec<f64> = Vec::new();
    for r in rates {
        if let Some(&first) = group.first() {
            if r > first * SAME_RATE_FACTOR {
                out.extend(crate::stats::upper_median(&mut group));
                group.clear();
            }
        }
        group.push(r);
    }
    out.extend(crate::stats::upper_median(&mut group));
    out
}

/// Summarises one test with the given segmentation options.
pub fn summarize_test(test: &TestData, opts: &SegmentOptions) -> TestSummary {
    let seg = segment(test, opts);
    let t = &test.time_s;
    let at = |i: usize| t.get(i).copied().unwrap_or(f64::NAN);
    let holds = seg
        .holds
        .iter()
        .zip(seg.hold_durations(test))
        .map(|(&(s, e), d)| HoldSummary {
            start_row: s,
            end_row: e,
            start_time_s: at(s.saturating_sub(1)),
            duration_s: d,
        })
        .collect();
    let velocity_steps = seg
        .rate_changes
        .iter()
        .zip(seg.step_rates())
        .map(|(&row, (from_rate, to_rate))| StepSummary {
            row,
            time_s: at(row),
            from_rate,
            to_rate,
        })
        .collect();
    // rates of levels long enough to be meaningful
    let rates = seg
        .levels
        .iter()
        .filter(|l| l.end - l.start >= 3)
        .map(|l| l.rate.abs())
        .collect();
    TestSummary {
        name: test.spec.name.clone(),
        file: test.spec.file.clone(),
        control: test.spec.control,
        rows: test.len(),
        time_span_s: (at(0), at(test.len().saturating_sub(1))),
        slip_range_mm: range(&test.slip_mm),
        shear_range_kpa: range(&test.shear_kpa),
        normal_range_kpa: range(&test.normal_kpa),
        friction_given: test.friction_given,
        units_read: units_read(&test.spec),
        channels: channels_carried(test),
        normal_stiffness_kpa_per_mm: test.spec.normal_stiffness_kpa_per_mm(),
        imposed_noise_sd: seg.conditioned.noise_sd,
        imposed_conditioned: seg.conditioned.changed,
        sliding_rates: distinct_rates(rates),
        holds,
        velocity_steps,
        reversals: seg.reversals.len(),
        cycles: seg.cycles(),
        start: seg.start.clone(),
        imposed_noise: seg.conditioned.noise,
        measured_noise: estimate_noise(&test.time_s, test.measured()),
    }
}

fn start_name(k: StartKind) -> &'static str {
    match k {
        StartKind::Rest => "rest",
        StartKind::Loaded => "loaded",
        StartKind::Sliding => "sliding",
    }
}

/// A noise SD with `≤` when it is only the quantisation floor.
fn noise_text(n: &NoiseEstimate, unit: &str) -> String {
    format!("{}{} {unit}", if n.floor { "≤" } else { "" }, num(n.sd))
}

/// Summarises every test of a set with the default segmentation options.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// std::fs::write(dir.path().join("experiment.json"), r#"{"name": "demo", "title": "Demo", "source": "doc",
///   "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#)?;
/// let mut csv = String::from("time_s,slip_mm,shear_kpa\n");
/// for i in 0..100 { csv.push_str(&format!("{},{},{}\n", i, 0.01 * i as f64, 30.0)); }
/// std::fs::write(dir.path().join("a.csv"), csv)?;
/// let set = subfric_data::load_set(dir.path())?;
/// let s = subfric_reading::summary(&set);
/// assert_eq!(s.tests[0].rows, 100);
/// assert!((s.tests[0].sliding_rates[0] - 0.01).abs() < 1e-12);
/// assert!(s.to_string().contains("demo"));
/// # Ok(()) }
/// ```
pub fn summary(set: &ExperimentSet) -> SetSummary {
    summary_with(set, &SegmentOptions::default())
}

/// Summarises every test of a set.
pub fn summary_with(set: &ExperimentSet, opts: &SegmentOptions) -> SetSummary {
    SetSummary {
        name: set.meta.name.clone(),
        title: set.meta.title.clone(),
        provenance: set.meta.provenance.clone(),
        tests: set.tests.iter().map(|t| summarize_test(t, opts)).collect(),
    }
}

fn pair(p: (f64, f64)) -> String {
    if p.0 == p.1 {
        num(p.0)
    } else {
        format!("{}..{}", num(p.0), num(p.1))
    }
}

/// Columns of the summary table, one row per test.
const TABLE_HEADER: [&str; 15] = [
    "test",
    "control",
    "rows",
    "time s",
    "slip mm",
    "shear kPa",
    "normal kPa",
    "start",
    "imposed noise",
    "measured noise",
    "rates",
    "holds",
    "steps",
    "revs",
    "cycles",
];

/// The cells of a test's row of the table ([`TABLE_HEADER`]).
fn table_row(t: &TestSummary) -> [String; 15] {
    let (unit, measured_unit) = if t.control == ControlColumn::Slip {
        ("mm", "kPa")
    } else {
        ("kPa", "mm")
    };
    [
        visible(&t.name),
        t.control.to_string(),
        t.rows.to_string(),
        pair(t.time_span_s),
        pair(t.slip_range_mm),
        pair(t.shear_range_kpa),
        pair(t.normal_range_kpa),
        format!(
            "{}{}",
            start_name(t.start.kind),
            if t.start.from_spec { "" } else { "†" }
        ),
        format!(
            "{}{}",
            noise_text(&t.imposed_noise, unit),
            if t.imposed_conditioned { "*" } else { "" }
        ),
        noise_text(&t.measured_noise, measured_unit),
        rates_text(&t.sliding_rates, unit),
        t.holds.len().to_string(),
        t.velocity_steps.len().to_string(),
        t.reversals.to_string(),
        t.cycles.to_string(),
    ]
}

/// The imposed rates of a test with their unit: mm/s under slip control, kPa/s under
/// traction control (`unit`: the imposed column's).
fn rates_text(rates: &[f64], unit: &str) -> String {
    if rates.is_empty() {
        return String::new();
    }
    format!(
        "{} {unit}/s",
        rates.iter().map(|r| num(*r)).collect::<Vec<_>>().join(",")
    )
}

/// The table: header, rule and rows, each column as wide as its widest cell.
fn write_table(f: &mut fmt::Formatter<'_>, rows: &[[String; 15]]) -> fmt::Result {
    let mut widths: Vec<usize> = TABLE_HEADER.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (w, c) in widths.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |f: &mut fmt::Formatter<'_>, cells: &[String]| -> fmt::Result {
        let mut s = String::from(" ");
        for (c, w) in cells.iter().zip(&widths) {
            s.push_str(&format!(" {c:<w$}"));
        }
        writeln!(f, "{}", s.trim_end())
    };
    line(f, &TABLE_HEADER.map(str::to_string))?;
    line(
        f,
        &widths.iter().map(|w| "-".repeat(*w)).collect::<Vec<_>>(),
    )?;
    for r in rows {
        line(f, r)?;
    }
    Ok(())
}

/// The declared units of a test's columns and the factor each was converted by.
fn units_read(spec: &subfric_data::TestSpec) -> Vec<String> {
    spec.units
        .as_ref()
        .map(|u| u.conversions())
        .unwrap_or_default()
}

/// What was made of a test's columns beyond the format's own, as `fit` and `diagnose` note it
/// (`check` writes the same lines under its table): the units they were read in, the further
/// channels carried, and a constant-normal-stiffness test's stiffness.
pub fn reading_lines(test: &subfric_data::TestData) -> Vec<String> {
    reading_sentences(
        &units_read(&test.spec),
        &channels_carried(test),
        test.spec.normal_stiffness_kpa_per_mm(),
    )
}

/// The sentences of [`reading_lines`] from their parts (a test's, or its summary's).
fn reading_sentences(units: &[String], channels: &[String], stiffness: Option<f64>) -> Vec<String> {
    let mut out = Vec::new();
    if !units.is_empty() {
        out.push(format!(
            "columns read in the set's units: {}",
            units.join(", ")
        ));
    }
    if !channels.is_empty() {
        out.push(format!(
            "further channels carried, not used by the model: {}",
            channels.join(", ")
        ));
    }
    out.extend(stiffness.map(|k| {
        format!(
            "constant normal stiffness {} kPa/mm (metadata): the model is driven by the normal stress each row carries",
            num(k)
        )
    }));
    out
}

/// Each further channel of a test with the range of its values and its missing samples.
fn channels_carried(test: &subfric_data::TestData) -> Vec<String> {
    test.channels
        .iter()
        .map(|c| {
            let read: Vec<f64> = c.values.iter().copied().filter(|v| v.is_finite()).collect();
            let missing = c.values.len() - read.len();
            let (lo, hi) = range(&read);
            let span = if read.is_empty() {
                "no value".to_string()
            } else {
                format!("{}..{}", num(lo), num(hi))
            };
            match missing {
                0 => format!("{} {span}", c.name),
                m => format!("{} {span} ({m} missing samples)", c.name),
            }
        })
        .collect()
}

/// The lines under the table about one test: the units its columns were read in, the further
/// channels it carries, why its start was decided so, its holds and its velocity steps.
fn write_test_notes(f: &mut fmt::Formatter<'_>, t: &TestSummary) -> fmt::Result {
    let read = reading_sentences(&t.units_read, &t.channels, t.normal_stiffness_kpa_per_mm);
    for line in read {
        writeln!(f, "  {}: {line}", visible(&t.name))?;
    }
    if !t.start.from_spec && t.start.kind != StartKind::Rest {
        writeln!(f, "  {}: {}", visible(&t.name), t.start.reason)?;
    }
    if !t.holds.is_empty() {
        let hs: Vec<String> = t
            .holds
            .iter()
            .map(|h| format!("{} s at t={}", num(h.duration_s), num(h.start_time_s)))
            .collect();
        writeln!(f, "  {}: holds {}", visible(&t.name), hs.join(", "))?;
    }
    if !t.velocity_steps.is_empty() {
        let ss: Vec<String> = t
            .velocity_steps
            .iter()
            .map(|s| {
                format!(
                    "{}→{} at t={}",
                    num(s.from_rate.abs()),
                    num(s.to_rate.abs()),
                    num(s.time_s)
                )
            })
            .collect();
        let unit = if t.control == ControlColumn::Slip {
            "mm/s"
        } else {
            "kPa/s"
        };
        writeln!(
            f,
            "  {}: velocity steps ({unit}) {}",
            visible(&t.name),
            ss.join(", ")
        )?;
    }
    Ok(())
}

/// The explanations of the table's marks (†, ≤, *), each only when it appears.
fn write_footnotes(f: &mut fmt::Formatter<'_>, tests: &[TestSummary]) -> fmt::Result {
    if tests.iter().any(|t| !t.start.from_spec) {
        writeln!(
            f,
            "  † start decided from the data (set \"initial\": \"rest\" or \"sliding\" per test in experiment.json to say it)"
        )?;
    }
    if tests
        .iter()
        .any(|t| t.imposed_noise.floor || t.measured_noise.floor)
    {
        writeln!(
            f,
            "  ≤ noise at the quantisation floor q/√12: the data scatter no more than their resolution"
        )?;
    }
    if tests.iter().any(|t| t.imposed_conditioned) {
        writeln!(
            f,
            "  * noisy imposed column: conditioned (isotonic per monotone run, flat holds)"
        )?;
    }
    Ok(())
}

impl fmt::Display for SetSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}: {}", visible(&self.name), visible(&self.title))?;
        if let Some(p) = &self.provenance {
            writeln!(f, "  provenance: {}", visible(p))?;
        }
        let rows: Vec<[String; 15]> = self.tests.iter().map(table_row).collect();
        write_table(f, &rows)?;
        for t in &self.tests {
            write_test_notes(f, t)?;
        }
        write_footnotes(f, &self.tests)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_format() {
        assert_eq!(num(0.01), "0.01");
        assert_eq!(num(123.456), "123.5");
        assert_eq!(num(2.0), "2");
        assert_eq!(num(0.000012), "1.200e-5");
    }

    #[test]
    fn rates_say_their_unit() {
        assert_eq!(rates_text(&[0.001, 0.01], "mm"), "0.001,0.01 mm/s");
        assert_eq!(rates_text(&[0.8], "kPa"), "0.8 kPa/s");
        assert_eq!(rates_text(&[], "mm"), "");
    }

    #[test]
    fn rate_groups() {
        assert_eq!(
            distinct_rates(vec![0.01, 0.0101, 0.1, 0.0099, 0.001]),
            vec![0.001, 0.01, 0.1]
        );
    }
}
