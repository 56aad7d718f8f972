//! Unit tests of the diagnosis context: pieces, folds, what each piece is read at, stiffness.
use super::*;
use crate::folds::PieceKind;
use subfric_data::{ControlColumn, ExperimentMeta, ExperimentSet, Interface, TestData, TestSpec};
use subfric_model::{simulate, Control, Params, Protocol};

/// One slide–hold–slide of the paper's sample parameters at 100 kPa, `rows_per_slide`
/// rows each slide, with a small deterministic wiggle for noise.
pub(in crate::diagnose) fn shs_set(rows_per_slide: usize) -> ExperimentSet {
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
    set_of(time, slip)
}

/// A slip-controlled test at 100 kPa through the imposed `slip` at `time`, simulated with
/// the paper's sample parameters plus a small deterministic wiggle for noise.
fn set_of(time: Vec<f64>, slip: Vec<f64>) -> ExperimentSet {
    let n = time.len();
    let normal = vec![100.0; n];
    let model = Model::base(Params::sample()).unwrap();
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let shear: Vec<f64> = simulate(&model, &proto)
        .unwrap()
        .shear
        .iter()
        .enumerate()
        .map(|(i, s)| s + 0.05 * ((i * 7919 % 13) as f64 - 6.0))
        .collect();
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
            normal_kpa: normal,
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        }],
    }
}

pub(in crate::diagnose) fn quiet(_: Step) {}

#[test]
fn a_hold_is_read_at_its_duration_a_velocity_step_at_its_rate_and_a_first_loading_at_its_stress() {
    // The hold of `shs_set`: 50 rows 4 s apart after the first slide.
    let pieces = crate::folds::pieces(&crate::prepare_for_diagnosis(&shs_set(200)));
    let hold = pieces.iter().find(|p| p.kind == PieceKind::Hold).unwrap();
    let at = hold.at.expect("a hold is read at its duration").exp();
    assert!((150.0..=200.0).contains(&at), "{at}");
    // The first loading at the test's normal stress, 100 kPa.
    let first: Vec<f64> = pieces
        .iter()
        .filter(|p| p.kind == PieceKind::InitialLoading)
        .map(|p| p.at.expect("a first loading is read at its stress").exp())
        .collect();
    assert_eq!(first.len(), 1, "{pieces:?}");
    assert!((first[0] - 100.0).abs() < 1e-9, "{first:?}");
    // Slides at 0.01, 0.1 and 0.01 mm/s, 300 rows each, 1 s apart.
    let (mut time, mut slip) = (vec![0.0], vec![0.0]);
    for rate in [0.01, 0.1, 0.01] {
        for _ in 0..300 {
            time.push(time.last().unwrap() + 1.0);
            slip.push(slip.last().unwrap() + rate);
        }
    }
    let pieces = crate::folds::pieces(&crate::prepare_for_diagnosis(&set_of(time, slip)));
    let steps: Vec<f64> = pieces
        .iter()
        .filter(|p| p.kind == PieceKind::VelocityStep)
        .map(|p| p.at.expect("a step is read at its rate").exp())
        .collect();
    assert_eq!(steps.len(), 2, "{pieces:?}");
    assert!((steps[0] / 0.1 - 1.0).abs() < 0.01, "{steps:?}");
    assert!((steps[1] / 0.01 - 1.0).abs() < 0.01, "{steps:?}");
}

#[test]
fn the_context_cuts_pieces_that_tile_the_rows_and_folds_that_hold_each_out_once() {
    let prepared = crate::prepare_for_diagnosis(&shs_set(200));
    let opts = DiagnoseOptions::default();
    let (cx, template) = Context::new(&prepared, None, &opts, &quiet, &RunCounter::new());
    // No stiffness: the five base parameters are free and α_t stays the template's.
    assert_eq!(cx.base_free, Param::BASE.to_vec());
    assert_eq!(template.params.alpha_t, opts.template.params.alpha_t);
    // The pieces tile the fitted rows in order, and the hold is one of them.
    let mut next = 0;
    for p in &cx.pieces {
        assert_eq!((p.test, p.start), (0, next), "{:?}", cx.pieces);
        assert!(p.end > p.start);
        next = p.end;
    }
    assert_eq!(next, cx.tests[0].len());
    assert!(cx.pieces.iter().any(|p| p.kind == PieceKind::Hold));
    // Every held-out piece is held out by exactly one fold, and fold_index says which.
    let index = fold_index(&cx);
    for (k, _) in cx.pieces.iter().enumerate() {
        let holding: Vec<usize> = (0..cx.folds.len())
            .filter(|&f| cx.folds[f].held.contains(&k))
            .collect();
        assert!(holding.len() <= 1, "piece {k} in folds {holding:?}");
        if let [f] = holding[..] {
            assert_eq!(index[k], f);
        }
    }
    // Each fitted row weighs the rows of the record it stands for.
    let represented: f64 = cx.weights.iter().flatten().sum();
    assert!((represented - prepared[0].full.len() as f64).abs() < 1e-6);
}

#[test]
fn a_stiffness_the_data_resolve_frees_alpha_t_from_its_value() {
    let prepared = crate::prepare_for_diagnosis(&shs_set(200));
    let opts = DiagnoseOptions::default();
    let s = Stiffness {
        alpha_t: 123.0,
        events: 2,
        evidence: "made in the test".into(),
    };
    let (cx, template) = Context::new(&prepared, Some(&s), &opts, &quiet, &RunCounter::new());
    assert_eq!(cx.base_free.last(), Some(&Param::AlphaT));
    assert_eq!(
        (template.params.alpha_t, template.params.alpha_n),
        (123.0, 123.0)
    );
}

#[test]
fn the_base_says_each_way_it_is_fitted_unlike_the_fit_command_and_no_other() {
    let reasons = |rows_per_slide: usize, opts: &DiagnoseOptions, reweight: bool, steps: bool| {
        let prepared = crate::prepare_for_diagnosis(&shs_set(rows_per_slide));
        let (mut cx, _) = Context::new(&prepared, None, opts, &quiet, &RunCounter::new());
        cx.reweight = reweight;
        let rows = prepared[0].full.len();
        let fitted = cx.tests[0].len();
        (unlike_fit(&cx, rows, fitted, steps, 26.7), rows, fitted)
    };
    let fit_like = DiagnoseOptions {
        global_evaluations: subfric_fit::FitOptions::default().global_evaluations,
        starts: subfric_fit::FitOptions::default().starts,
        ..DiagnoseOptions::default()
    };
    // A short record, the fit's search, plain weights, α_t not from steps: nothing differs.
    let (none, rows, fitted) = reasons(200, &fit_like, false, false);
    assert_eq!(rows, fitted);
    assert!(none.is_empty(), "{none:?}");
    // The diagnosis's own, shorter search is said with both budgets.
    let (search, ..) = reasons(200, &DiagnoseOptions::default(), false, false);
    assert_eq!(search.len(), 1, "{search:?}");
    assert!(search[0].contains("1000 model runs and 4 local starts (`fit`: 3000 and 8)"));
    // A record longer than the diagnosis's budget but not the fit's: binned, and said with
    // the rows; weights per piece and α_t from the steps each said once.
    let (all, rows, fitted) = reasons(2000, &fit_like, true, true);
    assert!(
        rows > crate::DIAGNOSIS_BUDGET_ROWS && fitted < rows,
        "{rows} {fitted}"
    );
    assert_eq!(all.len(), 3, "{all:?}");
    assert!(all[0].contains(&format!("{fitted} rows binned from the record's {rows}")));
    assert!(all[1].contains("one variance per piece") && all[1].contains("26.7×"));
    assert!(all[2].starts_with("α_t is the spring the velocity steps needed"));
}

#[test]
fn reweighting_moves_weight_off_the_piece_the_model_misses_and_keeps_the_total() {
    let prepared = crate::prepare_for_diagnosis(&shs_set(200));
    let opts = DiagnoseOptions::default();
    let (mut cx, _) = Context::new(&prepared, None, &opts, &quiet, &RunCounter::new());
    // Residuals of one noise SD everywhere but ten on the first piece.
    let missed = 0;
    let mut res: HeldOut = cx.tests.iter().map(|t| vec![1.0; t.len()]).collect();
    let first = &cx.pieces[missed];
    for r in &mut res[first.test][first.start..first.end] {
        *r = if first.start % 2 == 0 { 10.0 } else { -10.0 };
    }
    // Not reweighting: the tests as they are.
    assert!(cx.weighted_for(&res)[0].row_weight == cx.tests[0].row_weight);
    cx.reweight = true;
    let w = &cx.weighted_for(&res)[0];
    let total = |t: &FitTest| (0..t.len()).map(|i| t.weight_of(i)).sum::<f64>();
    assert!((total(w) - total(&cx.tests[0])).abs() < 1e-6 * total(w));
    let per_row = |p: &Piece| {
        (p.start..p.end)
            .map(|i| w.weight_of(i) / cx.tests[0].weight_of(i))
            .sum::<f64>()
            / (p.end - p.start) as f64
    };
    let other = &cx.pieces[1];
    // SSR 100× the noise on the missed piece: its rows weigh about a hundredth of the others'.
    let ratio = per_row(first) / per_row(other);
    assert!(ratio > 0.005 && ratio < 0.02, "{ratio}");
}

#[test]
fn model_error_dominates_only_beyond_the_threshold_of_the_noise() {
    let prepared = crate::prepare_for_diagnosis(&shs_set(200));
    let opts = DiagnoseOptions::default();
    let (mut cx, _) = Context::new(&prepared, None, &opts, &quiet, &RunCounter::new());
    let at = |cx: &mut Context, r: f64| {
        cx.base_residuals = cx.tests.iter().map(|t| vec![r; t.len()]).collect();
        model_error_dominates(cx)
    };
    let th = opts.thresholds.model_error_chi2;
    assert!(!at(&mut cx, 1.0));
    assert!(!at(&mut cx, (0.9 * th).sqrt()));
    assert!(at(&mut cx, (1.1 * th).sqrt()));
    assert_eq!(ssr_of(&vec![vec![2.0, -2.0], vec![1.0]]), 9.0);
}

#[test]
fn screening_thins_long_sets_to_their_share_and_leaves_short_ones_alone() {
    let short = crate::prepare_for_diagnosis(&shs_set(200));
    let s = screening_tests(&short);
    assert_eq!(s[0].len(), short[0].fit.len());
    let long = crate::prepare_for_diagnosis(&shs_set(1500));
    assert!(long[0].fit.len() > SCREENING_ROWS);
    let s = screening_tests(&long);
    assert!(s[0].len() <= SCREENING_ROWS + 100, "{}", s[0].len());
    assert!(s[0].len() >= SCREENING_ROWS / 2, "{}", s[0].len());
    // The thinned rows still stand for the whole record.
    let represented: f64 = (0..s[0].len()).map(|i| s[0].weight_of(i)).sum();
    assert!((represented - long[0].full.len() as f64).abs() < 1e-6 * represented);
}

#[test]
fn switching_a_form_off_sets_its_neutral_values_and_parameters_of_reads_them() {
    let features = crate::features::data_features(&crate::prepare_for_diagnosis(&shs_set(200)));
    let form = crate::candidates::library(&features)
        .into_iter()
        .find(|f| f.name.starts_with("log time"))
        .expect("a set with a hold has the log-time healing form");
    let spec = Spec {
        forms: vec![form.clone()],
        drift: false,
    };
    let on = with_values(
        &Model::base(Params::sample()).unwrap(),
        &spec,
        &[vec![0.02, 5.0]],
    );
    let read = parameters_of(&on, &spec.forms);
    assert_eq!(read.get("healing.b"), Some(&0.02));
    assert_eq!(read.get("healing.t_c"), Some(&5.0));
    let off = switched_off(&on, &spec);
    let read = parameters_of(&off, &spec.forms);
    let neutral: Vec<f64> = form.params.iter().map(|p| read[p.key()]).collect();
    assert_eq!(neutral, form.neutral);
    // The base parameters are untouched.
    assert_eq!(off.params, on.params);
}
