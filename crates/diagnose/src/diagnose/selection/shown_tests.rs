//! Unit tests of what the events read one by one credit: the pieces where they were read, at
//! the level where the effect lives, between readings of their like, and the standard a
//! further effect is held to.
use super::tests::{comparison, healing};
use super::*;
use crate::folds::PieceKind;
use crate::score::PieceScore;
use subfric_model::Params;

/// A held-out piece of `kind` from test `test`, its misfits under the reference and the
/// candidate; a smooth misfit, one effective row in ten.
fn piece_score(
    kind: PieceKind,
    test: usize,
    rows: usize,
    reference_ssr: f64,
    candidate_ssr: f64,
) -> PieceScore {
    PieceScore {
        kind,
        test,
        rows,
        n_eff: rows as f64 / 10.0,
        reference_ssr,
        candidate_ssr,
        beyond_training: false,
    }
}

/// A rate-law candidate whose family the velocity steps show outright, held out over all pieces
/// (`all`) and over the five steps (`steps`, their (reference, candidate) misfits).
fn shown_rate(all: Comparison, steps: Comparison) -> CandidateScore {
    CandidateScore {
        effect: Effect::from_name("rate").unwrap(),
        spec: "slip-hardening + rate".into(),
        extra_parameters: BTreeMap::new(),
        model: Model::base(Params::sample()).unwrap(),
        held_out_shrink: all.excess_shrink,
        held_out: all,
        held_out_within: None,
        by_kind: vec![],
        own_kinds: vec![],
        shown_in: vec![OwnKindScore {
            kind: crate::candidates::OwnKind::Piece(PieceKind::VelocityStep),
            held_out: steps,
            within: None,
        }],
        between_tests: 0.0,
        between_tests_shrink: 0.0,
        without_first_loadings: 0.0,
    }
}

#[test]
fn an_effect_the_events_show_explains_enough_when_a_typical_piece_of_its_kind_loses_its_excess() {
    let th = crate::verdict::Thresholds::default();
    let step = |test, reference_ssr, candidate_ssr| {
        piece_score(
            PieceKind::VelocityStep,
            test,
            64,
            reference_ssr,
            candidate_ssr,
        )
    };
    // As on a fresh set (rate + slip softening, after slip softening): four of five steps
    // predicted better, 46 % of the steps' summed excess removed, a typical step's misfit
    // down 37 % at 6.6× the noise (44 % of its excess); over all pieces D 34, 34 % of the
    // excess, a typical piece 5 % — under the 70 % a summed share must reach.
    let pieces = vec![
        step(0, 1111.0, 317.0),
        step(0, 645.0, 1302.0),
        step(0, 615.0, 494.0),
        step(0, 1194.0, 134.0),
        step(0, 1946.0, 871.0),
    ];
    let mut steps = comparison(15.9, 30.0, pieces);
    (
        steps.excess_shrink,
        steps.typical_shrink,
        steps.reference_chi2,
    ) = (0.46, 0.37, 6.56);
    let mut all = comparison(34.2, 1500.0, vec![]);
    (all.excess_shrink, all.typical_shrink, all.reference_chi2) = (0.34, 0.05, 2.34);
    assert!(!crate::verdict::material(&steps.clone(), &th));
    let stresses = [100.0];
    assert!(confirmed_where_shown(
        &shown_rate(all.clone(), steps.clone()),
        None,
        &stresses,
        &th
    ));
    // A typical step hardly better (4 %, 5 % of its excess): the summed share alone would
    // hang on the two steps much better; not enough.
    let mut barely = steps.clone();
    barely.typical_shrink = 0.04;
    assert!(!confirmed_where_shown(
        &shown_rate(all.clone(), barely),
        None,
        &stresses,
        &th
    ));
    // The held-out misfit of all pieces together raised: not confirmed however the steps go.
    let mut raised = all.clone();
    raised.excess_shrink = -0.1;
    assert!(!confirmed_where_shown(
        &shown_rate(raised, steps.clone()),
        None,
        &stresses,
        &th
    ));
    // Two steps of five better is not most of them.
    let mut two_of_five = steps;
    for p in &mut two_of_five.pieces[2..] {
        p.candidate_ssr = 2.0 * p.reference_ssr;
    }
    assert!(!confirmed_where_shown(
        &shown_rate(all, two_of_five),
        None,
        &stresses,
        &th
    ));
}

#[test]
fn a_first_effect_that_raises_the_held_out_misfit_yields_to_one_the_events_show() {
    let with_excess = |excess: f64| {
        let mut c = comparison(100.0, 800.0, vec![]);
        c.excess_shrink = excess;
        shown_rate(c.clone(), c)
    };
    // Named on D while the summed held-out misfit rises by 66 %; the runner-up is shown by
    // the events and confirmed by its pieces: it is named instead, at the first stage.
    let candidates = [with_excess(-0.66), with_excess(0.51)];
    let named = Decision::Named(0);
    assert_eq!(
        read_with_the_events(&candidates, Some(1), named, true),
        Decision::Named(1)
    );
    // Nothing the events show: the first stays.
    assert_eq!(read_with_the_events(&candidates, None, named, true), named);
    // The named effect is itself the one shown, or lowers the misfit: it stays.
    assert_eq!(
        read_with_the_events(&candidates, Some(0), named, true),
        named
    );
    let lowers = [with_excess(0.2), with_excess(0.51)];
    assert_eq!(read_with_the_events(&lowers, Some(1), named, true), named);
    // At a later stage the further effect's own standard applies (`decide_further`).
    assert_eq!(
        read_with_the_events(&candidates, Some(1), named, false),
        Decision::Named(0)
    );
    // Where nothing is named, the effect shown is.
    assert_eq!(
        read_with_the_events(&candidates, Some(1), Decision::Unexplained, false),
        Decision::Named(1)
    );
    assert_eq!(
        read_with_the_events(&candidates, None, Decision::Tentative(0), true),
        Decision::Tentative(0)
    );
}

#[test]
fn a_further_effect_whose_own_pieces_are_all_claimed_is_judged_where_its_events_are_read() {
    let th = crate::verdict::Thresholds::default();
    let all = comparison(206.9, 2000.0, vec![]);
    let first_loadings = comparison(137.7, 60.0, vec![]);
    // Slip softening behind a rate law: its own kinds (every piece after a first loading) are
    // all velocity steps, claimed by the rate law; its slope is read on the first loadings.
    let mut softening = shown_rate(all.clone(), first_loadings.clone());
    softening.effect = Effect::from_name("slip-hardening").unwrap();
    softening.shown_in[0].kind = crate::candidates::OwnKind::Piece(PieceKind::InitialLoading);
    assert_eq!(own_standard(&softening, &th, false), first_loadings);
    // Own pieces left unclaimed but worse (holds and reversals the rate law moved), the first
    // loadings much better: a further effect is judged where it passes.
    let mut later = comparison(-38.9, 900.0, vec![]);
    later.excess_shrink = -0.72;
    let mut unclaimed = softening.clone();
    unclaimed.own_kinds = vec![OwnKindScore {
        kind: crate::candidates::OwnKind::AfterFirstLoading,
        held_out: later.clone(),
        within: None,
    }];
    let mut read_there = first_loadings.clone();
    read_there.excess_shrink = 0.98;
    unclaimed.shown_in[0].held_out = read_there.clone();
    assert_eq!(own_standard(&unclaimed, &th, false), read_there);
    // Where neither passes, the kind with the most evidence.
    let mut neither = read_there.clone();
    neither.score = -50.0;
    unclaimed.shown_in[0].held_out = neither;
    assert_eq!(own_standard(&unclaimed, &th, false), later);
    // A first effect without own pieces is judged on all of them.
    assert_eq!(own_standard(&softening, &th, true), all);
    // With neither own pieces nor unclaimed ones where its events are read (healing behind a
    // rate law that claims the holds): nothing to be credited on.
    softening.shown_in.clear();
    assert_eq!(
        own_standard(&softening, &th, false),
        Comparison::of_no_pieces()
    );
    // Own pieces come first.
    softening.own_kinds = vec![OwnKindScore {
        kind: crate::candidates::OwnKind::AfterFirstLoading,
        held_out: comparison(30.0, 100.0, vec![]),
        within: None,
    }];
    assert_eq!(own_standard(&softening, &th, false).score, 30.0);
}

#[test]
fn an_effect_on_whole_tests_is_confirmed_by_the_stress_levels_not_by_each_test() {
    let th = crate::verdict::Thresholds::default();
    let first_loading = |test, reference_ssr, candidate_ssr| {
        piece_score(
            PieceKind::InitialLoading,
            test,
            300,
            reference_ssr,
            candidate_ssr,
        )
    };
    // As on a fresh set (log-healing + pressure): tests at 50 and 400 kPa predicted 1.3× and
    // 3.6× better, the slide-hold-slide and the cyclic test, both at 100 kPa, worse.
    let pieces = vec![
        first_loading(0, 681_163.0, 523_901.0),
        first_loading(1, 2_507_277.0, 705_892.0),
        first_loading(2, 3_544.0, 6_514.0),
        first_loading(3, 6_047.0, 24_326.0),
    ];
    let stresses = [50.0, 400.0, 100.0, 101.0];
    let refs: Vec<&PieceScore> = pieces.iter().collect();
    let levels = by_stress_level(&refs, &stresses);
    assert_eq!(levels.len(), 3);
    assert_eq!(levels[1].reference_ssr, 3_544.0 + 6_047.0);
    assert_eq!(levels[1].rows, 600);
    // Test by test, two of four is not most; level by level, two of three is.
    assert!(!most_predicted_better(&refs, refs.len()));
    assert!(most_predicted_better(
        &levels.iter().collect::<Vec<_>>(),
        levels.len()
    ));
    let mut readings = comparison(40.0, 20.0, pieces);
    (
        readings.excess_shrink,
        readings.typical_shrink,
        readings.reference_chi2,
    ) = (0.61, 0.2, 500.0);
    let mut all = comparison(30.0, 1500.0, vec![]);
    all.excess_shrink = 0.6;
    let mut pressure = shown_rate(all, readings);
    pressure.effect = Effect::from_name("pressure").unwrap();
    pressure.shown_in[0].kind = crate::candidates::OwnKind::Piece(PieceKind::InitialLoading);
    assert!(confirmed_where_shown(&pressure, None, &stresses, &th));
    // A family that does not act on whole tests is still counted piece by piece.
    pressure.effect = healing();
    assert!(!confirmed_where_shown(&pressure, None, &stresses, &th));
}

#[test]
fn an_effect_the_events_show_is_confirmed_between_its_readings_not_beyond_them() {
    let th = crate::verdict::Thresholds::default();
    let hold = |reference_ssr, candidate_ssr| {
        piece_score(PieceKind::Hold, 2, 72, reference_ssr, candidate_ssr)
    };
    // As on fresh sets (pressure + log-healing, after pressure): holds of 10, 100 and 1000 s,
    // each predicted from the other two. The 100 s hold, between them, loses 97 % of its
    // misfit; the 1000 s one, predicted from the two shorter ones, comes out 4× worse, and the
    // 10 s one, near the noise, a little worse. Over all three the summed misfit rises.
    let (short, middle, long) = (
        hold(240.0, 724.0),
        hold(22717.0, 604.0),
        hold(17213.0, 69395.0),
    );
    let mut holds = comparison(9.6, 23.0, vec![short, middle.clone(), long]);
    (
        holds.excess_shrink,
        holds.typical_shrink,
        holds.reference_chi2,
    ) = (-0.76, 0.31, 44.0);
    let mut between = comparison(11.2, 2.4, vec![middle]);
    (
        between.excess_shrink,
        between.typical_shrink,
        between.reference_chi2,
    ) = (0.98, 0.96, 69.6);
    let mut all = comparison(40.0, 300.0, vec![]);
    (all.excess_shrink, all.typical_shrink, all.reference_chi2) = (-1.2, 0.05, 3.7);
    let mut all_between = all.clone();
    (all_between.excess_shrink, all_between.score) = (0.35, 45.0);
    let healing = |within: Option<Comparison>, all_within: Option<Comparison>| CandidateScore {
        effect: Effect::from_name("log-healing").unwrap(),
        spec: "pressure + log-healing".into(),
        extra_parameters: BTreeMap::new(),
        model: Model::base(Params::sample()).unwrap(),
        held_out_shrink: all.excess_shrink,
        held_out: all.clone(),
        held_out_within: all_within,
        by_kind: vec![],
        own_kinds: vec![],
        shown_in: vec![OwnKindScore {
            kind: crate::candidates::OwnKind::Piece(PieceKind::Hold),
            held_out: holds.clone(),
            within,
        }],
        between_tests: 0.0,
        between_tests_shrink: 0.0,
        without_first_loadings: 0.0,
    };
    let stresses = [50.0, 400.0, 100.0];
    // Judged on all three holds and all pieces, the extrapolated hold outvotes the others.
    assert!(!confirmed_where_shown(
        &healing(None, None),
        None,
        &stresses,
        &th
    ));
    // Judged between its readings: confirmed.
    assert!(confirmed_where_shown(
        &healing(Some(between.clone()), Some(all_between.clone())),
        None,
        &stresses,
        &th
    ));
    // The hold between the others predicted worse: not confirmed, whatever the others do.
    let mut worse = between.clone();
    worse.pieces = vec![hold(604.0, 22717.0)];
    assert!(!confirmed_where_shown(
        &healing(Some(worse), Some(all_between.clone())),
        None,
        &stresses,
        &th
    ));
    // The pieces between their readings, all kinds together, predicted worse: not confirmed.
    assert!(!confirmed_where_shown(
        &healing(Some(between), Some(all.clone())),
        None,
        &stresses,
        &th
    ));
}

#[test]
fn a_candidate_the_events_speak_against_is_not_named_unless_it_explains_most_of_its_excess() {
    let th = crate::verdict::Thresholds::default();
    let flat = |lo: f64, hi: f64| subfric_reading::Estimate {
        value: 0.5 * (lo + hi),
        lo,
        hi,
    };
    // Peak and residual stress ratios read at four stresses, both within ±1 % per e-fold:
    // no pressure effect of a size that matters.
    let trend = subfric_reading::StressTrend {
        tests: 4,
        stresses: 4,
        per_efold: flat(-0.004, 0.006),
        relative_per_efold: flat(-0.007, 0.011),
        cohesion_kpa: flat(-0.4, 0.3),
        friction_angle_deg: flat(30.1, 30.7),
    };
    let mut events = crate::events::EventAnalysis::default();
    events.levels.peak = Some(trend.clone());
    events.levels.residual = Some(trend);
    let pressure = |excess_shrink: f64| {
        let mut all = comparison(28.0, 300.0, vec![]);
        all.excess_shrink = excess_shrink;
        let mut c = shown_rate(all, comparison(0.0, 1.0, vec![]));
        c.effect = Effect::from_name("pressure").unwrap();
        c
    };
    // A pressure law that takes 6 % of the excess: against the readings, not named.
    assert!(!events_leave_room(&events, &pressure(0.06), &th));
    // One that takes most of it: the readings of the levels alone do not overrule it.
    assert!(events_leave_room(&events, &pressure(0.9), &th));
    // Readings that say nothing of pressure leave room for it.
    let silent = crate::events::EventAnalysis::default();
    assert!(events_leave_room(&silent, &pressure(0.06), &th));
    // Nor do they speak against another family.
    let mut healing_candidate = pressure(0.06);
    healing_candidate.effect = healing();
    assert!(events_leave_room(&events, &healing_candidate, &th));
}
