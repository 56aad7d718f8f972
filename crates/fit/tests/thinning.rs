//! Long records are fitted on bins of rows (dense in transients, thin in steady sliding): the
//! fit must stay an honest least squares over all rows — the misfit on all rows of a thinned
//! fit is within a few percent of that of a fit on every row — while the objective costs a
//! fraction of the rows.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use subfric_data::{ControlColumn, ExperimentMeta, ExperimentSet, Interface, TestData, TestSpec};
use subfric_fit::{calibrate, misfits, FitOptions, Param, Space};
use subfric_model::{
    simulate, Control, Extensions, Initial, Model, Params, Protocol, RateEffect, RateForm,
};
use subfric_reading::{prepare_set_with, typical_rate, PrepareOptions};

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// A dense velocity-step record (about 12 000 rows at 0.5 µm of slip per row) from a model the
/// base cannot match exactly (rate and state), so the fit's misfit is model error, not noise.
fn long_record() -> ExperimentSet {
    let truth = Model::new(
        Params {
            mu_s: 0.6,
            mu_k: 0.45,
            kappa: 2.0,
            xi: 0.003,
            u_tilde: 20.0,
            alpha_t: 1000.0,
            alpha_n: 1000.0,
            mu_0: None,
        },
        Extensions::default().with_rate(RateEffect {
            form: RateForm::StateAgeing,
            a: 0.012,
            b: 0.009,
            d_c: 0.03,
            v_c: 1e-6,
            n: 0.0,
            v_ref: 0.01,
            at_rest: subfric_model::AtRest::Creep,
        }),
    )
    .expect("valid model");
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (mut t, mut u) = (vec![0.0], vec![0.0]);
    let du = 0.0005;
    for (rate, dist) in [
        (0.01, 2.0),
        (0.1, 1.0),
        (0.01, 1.0),
        (0.001, 0.5),
        (0.01, 1.5),
    ] {
        let n = (dist / du) as usize;
        let (t0, u0) = (*t.last().unwrap(), *u.last().unwrap());
        for j in 1..=n {
            t.push(t0 + j as f64 * du / rate);
            u.push(u0 + j as f64 * du);
        }
    }
    let n = t.len();
    let normal = vec![100.0; n];
    let shear = simulate(
        &truth,
        &Protocol {
            control: Control::Slip,
            time: &t,
            imposed: &u,
            normal: &normal,
            initial_slip: 0.0,
            initial: Initial::Rest,
        },
    )
    .expect("simulates")
    .shear;
    let measured: Vec<f64> = shear.iter().map(|s| s + 0.2 * gauss(&mut rng)).collect();
    let spec = TestSpec::new("steps", "steps.csv", ControlColumn::Slip, 100.0);
    ExperimentSet {
        dir: "long".into(),
        meta: ExperimentMeta {
            name: "long".into(),
            title: "long".into(),
            source: "generated in the test".into(),
            provenance: None,
            interface: Interface::default(),
            tests: vec![spec.clone()],
            reference_parameters: None,
            units: None,
            extra: Default::default(),
        },
        tests: vec![TestData {
            spec,
            path: "steps.csv".into(),
            time_s: t,
            slip_mm: u,
            shear_kpa: measured,
            normal_kpa: normal,
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        }],
    }
}

fn fit_on(set: &ExperimentSet, budget: usize) -> (f64, usize) {
    let prepared = prepare_set_with(
        set,
        false,
        &PrepareOptions {
            budget_rows: budget,
            ..Default::default()
        },
    );
    let tests: Vec<_> = prepared.iter().map(|p| p.fit.clone()).collect();
    let fulls: Vec<_> = prepared.iter().map(|p| p.full.clone()).collect();
    let template = Model::base(Params::sample()).unwrap();
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    let opts = FitOptions {
        global_evaluations: 600,
        starts: 2,
        profiles: false,
        ..FitOptions::default()
    };
    let report = calibrate(&tests, space, &opts, &|_| {}).expect("fit runs");
    // The misfit on every row of the record.
    let rms = misfits(&fulls, &report.model)[0].rms;
    (rms, tests[0].len())
}

#[test]
fn a_thinned_fit_misses_all_rows_by_as_much_as_a_fit_on_every_row() {
    let set = long_record();
    let rows = set.tests[0].len();
    assert!(rows > 11_000, "{rows} rows");
    let (rms_all, n_all) = fit_on(&set, 0);
    let (rms_thin, n_thin) = fit_on(&set, 1500);
    eprintln!("all-row RMS: {rms_all:.4} kPa (fit on {n_all} rows), {rms_thin:.4} kPa (fit on {n_thin} bins)");
    assert_eq!(n_all, rows);
    assert!(n_thin <= 1600, "thinned to {n_thin} rows");
    // Model error dominates (the base lacks the rate effect): well above the 0.2 kPa noise.
    assert!(rms_all > 0.3, "rms on all rows {rms_all}");
    assert!(
        (rms_thin - rms_all).abs() <= 0.03 * rms_all,
        "all-row RMS {rms_thin:.4} kPa after a fit on {n_thin} bins, {rms_all:.4} kPa after a fit on all {n_all} rows"
    );
}

#[test]
fn bins_stand_for_every_row_once() {
    let set = long_record();
    let prepared = prepare_set_with(
        &set,
        false,
        &PrepareOptions {
            budget_rows: 800,
            ..Default::default()
        },
    );
    let p = &prepared[0];
    assert!(p.is_thinned());
    let total: f64 = p.fit.row_weight.iter().sum();
    assert_eq!(total as usize, p.full.len());
    // Every event row of the record is kept as its own row: the imposed path keeps its corners.
    for &c in &p.segmentation.rate_changes {
        assert!(p.kept.contains(&c), "step row {c} not kept");
    }
    // The kept rows are in time order.
    assert!(p.fit.time.windows(2).all(|w| w[1] > w[0]));
}
