//! From an experiment set on disk to the tests the objective sees: the imposed column is
//! conditioned (measurement jitter removed) and each test keeps its segmentation.

use crate::dataset::FitTest;
use subfric_data::{segment, ExperimentSet, SegmentOptions, Segmentation, TestData};
use subfric_model::{Control, Model, Params};

/// A test ready for fitting, with the segmentation its residuals are localised by.
#[derive(Clone, Debug)]
pub struct PreparedTest {
    /// The objective's view of the test.
    pub fit: FitTest,
    /// Phases of the test (holds, steps, reversals, cycles).
    pub segmentation: Segmentation,
}

/// The model's control for the data's control.
pub fn control_of(c: subfric_data::Control) -> Control {
    match c {
        subfric_data::Control::Slip => Control::Slip,
        subfric_data::Control::Shear => Control::Shear,
    }
}

/// Prepares one test: conditions the imposed column and segments it.
pub fn prepare_test(test: &TestData, name: String, opts: &SegmentOptions) -> PreparedTest {
    let segmentation = segment(test, opts);
    let control = control_of(test.spec.control);
    let fit = FitTest::new(
        name,
        control,
        test.time_s.clone(),
        segmentation.conditioned.values.clone(),
        test.measured().to_vec(),
        test.normal_kpa.clone(),
    );
    PreparedTest { fit, segmentation }
}

/// Prepares every test of a set; with `prefix`, test names become `set/test` (joint fits).
pub fn prepare_set(set: &ExperimentSet, prefix: bool) -> Vec<PreparedTest> {
    let opts = SegmentOptions::default();
    set.tests
        .iter()
        .map(|t| {
            let name = if prefix {
                format!("{}/{}", set.meta.name, t.spec.name)
            } else {
                t.spec.name.clone()
            };
            prepare_test(t, name, &opts)
        })
        .collect()
}

/// The published parameters of a set (`reference_parameters`), if any and readable.
pub fn reference_model(set: &ExperimentSet) -> Option<Model> {
    let v = set.meta.reference_parameters.as_ref()?;
    let p: Params = serde_json::from_value(v.clone()).ok()?;
    Model::base(p).ok()
}
