//! A diagnosis counts its model runs into the counter its caller hands it (the progress
//! display reads them there), and only its own: a calibration running beside it on another
//! thread with its own counter sees exactly its own runs.

use std::sync::Mutex;
use subfric_data::{ControlColumn, ExperimentMeta, ExperimentSet, Interface, TestData, TestSpec};
use subfric_diagnose::{diagnose_reporting, prepare_for_diagnosis, DiagnoseOptions, Step};
use subfric_fit::{calibrate, FitOptions, Param, RunCounter, Space};
use subfric_model::{simulate, Control, Model, Params, Protocol};
use subfric_reading::FitTest;

/// Slip then time of one slide–hold–slide, `rows_per_slide` rows each slide.
fn slide_hold_slide(rows_per_slide: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut time, mut slip) = (Vec::new(), Vec::new());
    let du = 2.0 / rows_per_slide as f64;
    for i in 0..=rows_per_slide {
        time.push(i as f64);
        slip.push(du * i as f64);
    }
    for i in 1..=50 {
        time.push(rows_per_slide as f64 + 4.0 * i as f64);
        slip.push(2.0);
    }
    let t0 = *time.last().unwrap();
    for i in 1..=rows_per_slide {
        time.push(t0 + i as f64);
        slip.push(2.0 + du * i as f64);
    }
    (time, slip)
}

/// The sample parameters' shear along `slip` at 100 kPa, with a small deterministic wiggle
/// for noise.
fn shear_of(time: &[f64], slip: &[f64]) -> Vec<f64> {
    let normal = vec![100.0; time.len()];
    let proto = Protocol {
        control: Control::Slip,
        time,
        imposed: slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let model = Model::base(Params::sample()).unwrap();
    simulate(&model, &proto)
        .unwrap()
        .shear
        .iter()
        .enumerate()
        .map(|(i, s)| s + 0.05 * ((i * 7919 % 13) as f64 - 6.0))
        .collect()
}

/// A set of one slide–hold–slide test.
fn shs_set() -> ExperimentSet {
    let (time, slip) = slide_hold_slide(150);
    let shear = shear_of(&time, &slip);
    let n = time.len();
    let spec = TestSpec::new("shs", "shs.csv", ControlColumn::Slip, 100.0);
    ExperimentSet {
        dir: "shs".into(),
        meta: ExperimentMeta {
            name: "shs".into(),
            title: "shs".into(),
            source: "made in the test".into(),
            provenance: None,
            interface: Interface::default(),
            tests: vec![spec.clone()],
            reference_parameters: None,
            units: None,
            extra: Default::default(),
        },
        tests: vec![TestData {
            spec,
            path: "shs.csv".into(),
            time_s: time,
            slip_mm: slip,
            shear_kpa: shear,
            normal_kpa: vec![100.0; n],
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        }],
    }
}

#[test]
fn a_diagnosis_counts_its_runs_into_its_own_counter_as_it_goes() {
    let prepared = prepare_for_diagnosis(&shs_set());
    let opts = DiagnoseOptions {
        global_evaluations: 300,
        starts: 2,
        ..DiagnoseOptions::default()
    };
    let diagnosis_runs = RunCounter::new();
    // The runs the diagnosis had counted as each step began.
    let at_steps: Mutex<Vec<(usize, usize)>> = Mutex::new(Vec::new());
    // Read under the lock, so the readings are in the order they are pushed.
    let report = |s: Step| {
        at_steps
            .lock()
            .unwrap()
            .push((s.number, diagnosis_runs.runs()));
    };
    // A calibration beside it, on another thread, with its own counter.
    let (time, slip) = slide_hold_slide(100);
    let (shear, normal) = (shear_of(&time, &slip), vec![100.0; time.len()]);
    let other = [FitTest::new(
        "other",
        Control::Slip,
        time,
        slip,
        shear,
        normal,
    )];
    let other_runs = RunCounter::new();
    let other_opts = FitOptions {
        global_evaluations: 300,
        starts: 2,
        profiles: false,
        run_counter: Some(other_runs.clone()),
        ..FitOptions::default()
    };
    let space = Space::new(Model::base(Params::sample()).unwrap(), &Param::BASE, &[]);
    let other_report = std::thread::scope(|s| {
        let fit = s.spawn(|| calibrate(&other, space, &other_opts, &|_| {}).unwrap());
        diagnose_reporting(&prepared, &opts, &report, &diagnosis_runs).expect("diagnoses");
        fit.join().unwrap()
    });
    assert_eq!(other_runs.runs(), other_report.optimizer.evaluations);
    let at_steps = at_steps.into_inner().unwrap();
    let runs: Vec<usize> = at_steps.iter().map(|&(_, r)| r).collect();
    assert!(
        runs.windows(2).all(|w| w[0] <= w[1]),
        "the count never falls: {at_steps:?}"
    );
    // The base fit is counted before the screening begins, and the later steps' fits after.
    assert!(
        at_steps.iter().any(|&(n, _)| n == Step::COUNT),
        "{at_steps:?}"
    );
    let first_screening = at_steps.iter().find(|&&(n, _)| n == 2).unwrap().1;
    assert!(first_screening > 0, "{at_steps:?}");
    assert!(diagnosis_runs.runs() > first_screening, "{at_steps:?}");
}
