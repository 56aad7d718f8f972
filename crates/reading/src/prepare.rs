//! From an experiment set on disk to the tests the objective sees: the imposed column is
//! conditioned (measurement jitter removed), each test keeps its segmentation and its initial
//! state, and long records are thinned to the rows that carry information ([`crate::thin`]).

use crate::fit_test::FitTest;
use crate::thin::{bins, scale_for_budget, thin_test};
use crate::{
    close_gap, gap_remainder, seating_toe, segment, SeatingToe, SegmentKind, SegmentOptions,
    Segmentation, StartKind,
};
use subfric_data::{ExperimentSet, TestData};
use subfric_model::{Control, Initial, Model};

/// A test ready for fitting, with the segmentation its residuals are localised by.
#[derive(Clone, Debug)]
pub struct PreparedTest {
    /// The objective's view of the test: thinned when the set is long.
    pub fit: FitTest,
    /// Every row of the record (misfit on all rows, figures); equal to `fit` when not thinned.
    pub full: FitTest,
    /// Row of the full record that each row of `fit` stands for.
    pub kept: Vec<usize>,
    /// Phases of the full record (holds, steps, reversals, cycles).
    pub segmentation: Segmentation,
    /// A seating toe excluded from the start of the record (its rows are not in `full`).
    pub toe: Option<SeatingToe>,
    /// The record's rows the test was prepared from (after a seating toe was cut), one per
    /// row of `full`.
    pub source: TestData,
}

impl PreparedTest {
    /// True when `fit` holds fewer rows than the record.
    pub fn is_thinned(&self) -> bool {
        self.fit.len() != self.full.len()
    }

    /// Kind of segment of row `i` of `fit`.
    pub fn kind_of_fit_row(&self, i: usize) -> SegmentKind {
        let r = self.kept.get(i).copied().unwrap_or(0);
        self.segmentation
            .row_kind
            .get(r)
            .copied()
            .unwrap_or(SegmentKind::SteadySliding)
    }
}

/// How tests are prepared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrepareOptions {
    /// Segmentation settings.
    pub segment: SegmentOptions,
    /// Rows the fitted tests of a set may hold together; a longer set is thinned to about this
    /// many (0: never thin).
    pub budget_rows: usize,
}

impl Default for PrepareOptions {
    fn default() -> Self {
        PrepareOptions {
            segment: SegmentOptions::default(),
            budget_rows: 6000,
        }
    }
}

/// The model's control for the data's control.
pub fn control_of(c: subfric_data::ControlColumn) -> Control {
    match c {
        subfric_data::ControlColumn::Slip => Control::Slip,
        subfric_data::ControlColumn::Shear => Control::Shear,
    }
}

/// The model's initial state for the start the segmentation decided.
fn initial_of(seg: &Segmentation) -> Initial {
    let s = &seg.start;
    match s.kind {
        StartKind::Rest => Initial::Rest,
        StartKind::Loaded => Initial::Loaded {
            shear_kpa: s.shear_kpa,
        },
        // The model takes the speed; the direction is the traction's sign.
        StartKind::Sliding => Initial::Sliding {
            shear_kpa: s.shear_kpa,
            rate_mm_s: s.rate.abs(),
        },
    }
}

/// Prepares one test with all its rows: conditions the imposed column, segments it, takes the
/// initial state.
pub fn prepare_test(test: &TestData, name: String, opts: &SegmentOptions) -> PreparedTest {
    let segmentation = segment(test, opts);
    // A seating toe is a rig artifact, not friction: its rows are left out and the test
    // starts at rest under the traction where the steep loading has begun.
    if let Some(mut toe) = seating_toe(test, &segmentation) {
        let mut trimmed = test.rows_from(toe.first_kept);
        // A slack first leg may end before the gap has closed: the rest of it closes on the
        // first reload the same way, and that travel is no motion of the interface either.
        if let Some(direction) = toe.slack_leg_direction {
            let seg = segment(&trimmed, opts);
            if let Some(gap) = gap_remainder(&trimmed, &seg, direction) {
                trimmed = close_gap(&trimmed, &gap, direction);
                let (a, b) = (toe.first_kept + gap.from_row, toe.first_kept + gap.to_row);
                let rows = if b > a + 1 {
                    format!(
                        "rows {}–{} of the record, the shear near zero, left out",
                        a + 1,
                        b - 1
                    )
                } else {
                    format!("between rows {a} and {b} of the record")
                };
                toe.reason.push_str(&format!(
                    "; the rest of the gap, {:.4} mm, closed on the first reload the same way ({rows}): the imposed travel after it is shorter by that much",
                    gap.travel_mm,
                ));
                toe.remainder = Some(gap);
            }
        }
        let mut p = prepare_untrimmed(&trimmed, name, opts);
        let loaded = Initial::Loaded {
            shear_kpa: toe.start_shear_kpa,
        };
        p.fit.initial = loaded;
        p.full.initial = loaded;
        let start = &mut p.segmentation.start;
        start.kind = StartKind::Loaded;
        start.shear_kpa = toe.start_shear_kpa;
        start.reason = format!(
            "after a seating toe, at rest under {:.2} kPa where the steep loading has begun",
            toe.start_shear_kpa
        );
        p.toe = Some(toe);
        return p;
    }
    finish(test, name, segmentation)
}

fn prepare_untrimmed(test: &TestData, name: String, opts: &SegmentOptions) -> PreparedTest {
    finish(test, name, segment(test, opts))
}

fn finish(test: &TestData, name: String, segmentation: Segmentation) -> PreparedTest {
    let control = control_of(test.spec.control);
    let mut fit = FitTest::new(
        name,
        control,
        test.time_s.clone(),
        segmentation.conditioned.values.clone(),
        test.measured().to_vec(),
        segmentation.normal.values.clone(),
    );
    fit.initial = initial_of(&segmentation);
    PreparedTest {
        full: fit.clone(),
        kept: (0..fit.len()).collect(),
        fit,
        segmentation,
        toe: None,
        source: test.clone(),
    }
}

impl PreparedTest {
    /// The test prepared again with `shift[i]` taken off the slip of row `i` of its record (a
    /// rig's closure taken out of the travel): segmented anew (a rise that looked stepped
    /// because the closure ran ahead of the interface is one loading) and thinned to as many
    /// rows as before; how it starts and any seating toe cut stay as they were decided.
    pub fn with_travel_less(&self, shift: &[f64]) -> PreparedTest {
        let mut test = self.source.clone();
        for (u, d) in test.slip_mm.iter_mut().zip(shift) {
            *u -= d;
        }
        let mut p = finish(
            &test,
            self.full.name.clone(),
            segment(&test, &SegmentOptions::default()),
        );
        p.segmentation.start = self.segmentation.start.clone();
        p.full.initial = self.full.initial;
        p.fit.initial = self.fit.initial;
        p.full.weight = self.full.weight;
        p.fit.weight = self.fit.weight;
        p.toe = self.toe.clone();
        if self.is_thinned() {
            thin_prepared(&mut p, self.fit.len());
        }
        p
    }
}

/// Thins a prepared test to at most about `budget` rows.
pub fn thin_prepared(p: &mut PreparedTest, budget: usize) {
    if p.full.len() <= budget {
        return;
    }
    let scale = scale_for_budget(&p.full, &p.segmentation, budget);
    let b = bins(&p.full, &p.segmentation, scale);
    if b.len() >= p.full.len() {
        return;
    }
    p.fit = thin_test(&p.full, &b);
    p.kept = b.representatives();
}

/// Prepares every test of a set; with `prefix`, test names become `set/test` (joint fits).
pub fn prepare_set(set: &ExperimentSet, prefix: bool) -> Vec<PreparedTest> {
    prepare_set_with(set, prefix, &PrepareOptions::default())
}

/// As [`prepare_set`], with options: a set with more rows than `budget_rows` is thinned, each
/// test to its share of the budget.
pub fn prepare_set_with(
    set: &ExperimentSet,
    prefix: bool,
    opts: &PrepareOptions,
) -> Vec<PreparedTest> {
    let mut tests: Vec<PreparedTest> = set
        .tests
        .iter()
        .map(|t| {
            let name = if prefix {
                format!("{}/{}", set.meta.name, t.spec.name)
            } else {
                t.spec.name.clone()
            };
            prepare_test(t, name, &opts.segment)
        })
        .collect();
    let total: usize = tests.iter().map(|p| p.full.len()).sum();
    if opts.budget_rows > 0 && total > opts.budget_rows {
        for p in tests.iter_mut() {
            let share = (opts.budget_rows as f64 * p.full.len() as f64 / total as f64).ceil();
            thin_prepared(p, (share as usize).max(200));
        }
    }
    tests
}

/// The published parameters of a set (`reference_parameters`), if any and readable.
pub fn reference_model(set: &ExperimentSet) -> Option<Model> {
    let v = set.meta.reference_parameters.as_ref()?;
    subfric_model::model_from_value(v).ok()
}
