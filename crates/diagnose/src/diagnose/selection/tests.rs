//! Unit tests of the selection stages, on small hand-made inputs.
use super::*;
use crate::folds::PieceKind;
use crate::score::PieceScore;
use subfric_model::Params;

pub(super) fn healing() -> Effect {
    Effect::from_name("log-healing").unwrap()
}

fn report(effect: Effect, form: &'static str, score: f64, ssr: f64) -> FormReport {
    FormReport {
        effect,
        form: form.into(),
        parameters: BTreeMap::new(),
        ssr,
        in_sample_score: score,
        converged: true,
        settled: false,
        polished: true,
        switched_off: false,
        termination: subfric_fit::Termination::CostConverged,
        chosen: false,
        model: Model::base(Params::sample()).unwrap(),
    }
}

#[test]
fn the_best_scoring_form_of_each_family_is_chosen_and_failed_fits_never() {
    let mut r = vec![
        report(Effect::from_name("rate").unwrap(), "a", 10.0, 5.0),
        report(Effect::from_name("rate").unwrap(), "b", 30.0, 4.0),
        report(healing(), "c", 50.0, f64::NAN),
        report(healing(), "d", -5.0, 9.0),
        report(Effect::from_name("rate").unwrap(), "e", 20.0, 4.5),
    ];
    let mut chosen = choose_forms(&mut r, &[0, 1, 2, 3, 4]);
    chosen.sort_unstable();
    // Rate: "b" (30 beats 10 and 20); healing: "d", since "c" failed (non-finite misfit)
    // however high its score.
    assert_eq!(chosen, vec![1, 3]);
    let marked: Vec<bool> = r.iter().map(|f| f.chosen).collect();
    assert_eq!(marked, vec![false, true, false, true, false]);
}

#[test]
fn a_form_whose_fit_did_not_converge_is_never_chosen_however_high_its_score() {
    let rate = Effect::from_name("rate").unwrap();
    let unconverged = |mut r: FormReport| {
        r.converged = false;
        r.termination = subfric_fit::Termination::MaxIterations;
        r
    };
    let mut r = vec![
        report(rate, "a", 10.0, 5.0),
        unconverged(report(rate, "b", 90.0, 1.0)),
        unconverged(report(healing(), "c", 50.0, 2.0)),
    ];
    // Rate: "a", not the unconverged "b"; healing: no form judged, so no family.
    assert_eq!(choose_forms(&mut r, &[0, 1, 2]), vec![0]);
    assert!(!r[1].chosen && !r[2].chosen);
}

#[test]
fn a_form_stopped_by_its_limit_but_settled_is_judged_by_its_score() {
    let rate = Effect::from_name("rate").unwrap();
    let settled = |mut r: FormReport| {
        r.converged = false;
        r.settled = true;
        r.termination = subfric_fit::Termination::MaxIterations;
        r
    };
    let mut r = vec![
        report(rate, "a", 10.0, 5.0),
        settled(report(rate, "b", 90.0, 1.0)),
    ];
    // Its continuation no longer lowered the misfit: "b" is judged, and its score wins.
    assert_eq!(choose_forms(&mut r, &[0, 1]), vec![1]);
}

#[test]
fn the_forms_polished_are_the_two_best_screened_of_each_family_best_first() {
    let rate = Effect::from_name("rate").unwrap();
    let r = vec![
        report(rate, "a", 10.0, 5.0),
        report(rate, "b", 30.0, 4.0),
        report(healing(), "c", 50.0, f64::NAN),
        report(healing(), "d", -5.0, 9.0),
        report(rate, "e", 20.0, 4.5),
    ];
    // Rate's "b" then "e" ("a" third); healing's "d" alone ("c" failed).
    assert_eq!(ranked_by_family(&r, 2), vec![vec![1, 4], vec![3]]);
    assert_eq!(ranked_by_family(&r, 1), vec![vec![1], vec![3]]);
}

#[test]
fn every_form_of_a_family_that_acts_on_whole_tests_is_polished_whatever_its_screened_rank() {
    let pressure = Effect::from_name("pressure").unwrap();
    assert!(pressure.acts_on_whole_tests() && !healing().acts_on_whole_tests());
    let r = vec![
        report(pressure, "power law", -239.0, 8.6e5),
        report(pressure, "linear", -191.4, 8.1e5),
        report(pressure, "exponential", -191.8, 8.1e5),
        report(pressure, "failed", 0.0, f64::NAN),
        report(healing(), "a", 10.0, 5.0),
        report(healing(), "b", 30.0, 4.0),
        report(healing(), "c", 20.0, 4.5),
    ];
    // Pressure: all three that were fitted, best screened first (the failed fit never);
    // healing: its two best.
    let ranked = ranked_by_family(&r, 2);
    assert!(ranked.contains(&vec![1, 2, 0]), "{ranked:?}");
    assert!(ranked.contains(&vec![5, 6]), "{ranked:?}");
    // A later stage: every form of pressure, however far behind; of healing, those the
    // screening cannot tell from the best.
    assert_eq!(polished_of_family(pressure, 3, || 1), 3);
    assert_eq!(polished_of_family(healing(), 3, || 1), 1);
    assert_eq!(polished_of_family(healing(), 2, || 5), 2);
}

#[test]
fn a_whole_test_family_is_predicted_held_out_in_its_best_forms_and_the_tests_levels_choose() {
    // Up to three forms of pressure are predicted held out (the best in-sample and the next
    // two); any other family keeps its one form.
    let pressure = Effect::from_name("pressure").unwrap();
    let fit = || SpecFit {
        result: crate::fits::FitResult {
            model: Model::base(Params::sample()).unwrap(),
            ssr: 1.0,
            converged: true,
            termination: subfric_fit::Termination::CostConverged,
            starts: 1,
        },
        fit_tests: Vec::new(),
        settled: false,
    };
    let forms = crate::candidates::every_form();
    let of = |e: Effect| -> Vec<(Form, SpecFit)> {
        forms
            .iter()
            .filter(|f| f.effect == e)
            .map(|f| (f.clone(), fit()))
            .collect()
    };
    let names =
        |v: Vec<(Form, SpecFit)>| -> Vec<&'static str> { v.iter().map(|(f, _)| f.name).collect() };
    let pressure_forms = of(pressure);
    assert!(pressure_forms.len() > WHOLE_TEST_FORMS);
    let expected: Vec<&str> = pressure_forms[..WHOLE_TEST_FORMS - 1]
        .iter()
        .map(|(f, _)| f.name)
        .collect();
    assert_eq!(
        names(held_out_alternatives(pressure, of(pressure).into_iter())),
        expected
    );
    assert!(held_out_alternatives(healing(), of(healing()).into_iter()).is_empty());
    // The choice: the per-piece evidence plus the tests' levels against the scatter between
    // specimens. By the pieces alone the first form would win (48.5), whose levels carried
    // to the stresses held out are far off (−321).
    let evidence = [(48.5, -321.4), (23.1, 119.1), (19.8, 148.8)];
    assert_eq!(most_evidence(&evidence), Some(2));
    // Of equal totals the first (the best in-sample); one form is its own choice; none, none.
    assert_eq!(most_evidence(&[(10.0, 5.0), (5.0, 10.0)]), Some(0));
    assert_eq!(most_evidence(&[(-3.0, 0.0)]), Some(0));
    assert_eq!(most_evidence(&[]), None);
}

pub(super) fn comparison(score: f64, n_eff: f64, pieces: Vec<PieceScore>) -> Comparison {
    Comparison {
        score,
        shape_score: score,
        level_score: 0.0,
        excess_shrink: 0.5,
        relative_shrink: 0.5,
        typical_shrink: 0.1,
        reference_chi2: 4.0,
        candidate_chi2: 2.0,
        rows: 100,
        n_eff,
        parameters: 0,
        pieces,
    }
}

#[test]
fn each_extra_parameter_costs_the_log_of_the_independent_rows() {
    let c = comparison(50.0, 1000.0, vec![]);
    assert_eq!(penalised(&c, 0), 50.0);
    assert!((penalised(&c, 2) - (50.0 - 2.0 * 1000f64.ln())).abs() < 1e-12);
    // Fewer than one independent row counts as one (no reward for a negative log).
    let tiny = comparison(5.0, 0.2, vec![]);
    assert_eq!(penalised(&tiny, 3), 5.0);
}

#[test]
fn the_shrink_by_kind_of_piece_is_the_share_of_its_misfit_removed() {
    let piece = |kind, test, rows, b: f64, c: f64| PieceScore {
        kind,
        test,
        rows,
        n_eff: rows as f64,
        reference_ssr: b,
        candidate_ssr: c,
        beyond_training: false,
    };
    let c = comparison(
        40.0,
        300.0,
        vec![
            piece(PieceKind::VelocityStep, 0, 100, 400.0, 100.0),
            piece(PieceKind::VelocityStep, 1, 100, 200.0, 200.0),
            piece(PieceKind::Hold, 0, 50, 100.0, 150.0),
        ],
    );
    let k = kind_shrinks(&c);
    let steps = k
        .iter()
        .find(|s| s.kind == PieceKind::VelocityStep.name())
        .unwrap();
    assert_eq!(steps.rows, 200);
    assert!((steps.shrink - 0.5).abs() < 1e-12, "{}", steps.shrink);
    assert!((steps.reference_chi2 - 3.0).abs() < 1e-12);
    let holds = k.iter().find(|s| s.kind == PieceKind::Hold.name()).unwrap();
    assert!(
        (holds.shrink + 0.5).abs() < 1e-12,
        "worse: {}",
        holds.shrink
    );
}

#[test]
fn a_later_stage_polishes_the_best_screened_form_and_those_the_screening_cannot_tell_from_it() {
    // 2 ln(1000) = 13.8: the runner-up 8.7 behind is polished too, one 30 behind is not.
    let n = 1000.0;
    assert_eq!(polished_among(&[(-133.6, n), (-142.3, n), (-172.0, n)]), 2);
    assert_eq!(polished_among(&[(-133.6, n), (-163.6, n), (-164.0, n)]), 1);
    // Ties all the way down are all polished; an empty family polishes nothing.
    assert_eq!(polished_among(&[(5.0, n), (5.0, n), (4.0, n)]), 3);
    assert_eq!(polished_among(&[]), 0);
    // The margin grows with the effective rows: on 10 rows, 2 ln 10 = 4.6.
    assert_eq!(polished_among(&[(0.0, 10.0), (-8.7, 10.0)]), 1);
}

#[test]
fn an_effect_the_events_show_needs_most_of_their_pieces_predicted_better_not_every_one() {
    let piece = |test: usize, reference_ssr: f64, candidate_ssr: f64| crate::score::PieceScore {
        kind: crate::folds::PieceKind::InitialLoading,
        test,
        rows: 300,
        n_eff: 4.0,
        reference_ssr,
        candidate_ssr,
        beyond_training: false,
    };
    // Four tests of five predicted better; the one at the reference stress a little worse.
    let four_of_five: Vec<_> = (0..5)
        .map(|t| {
            if t == 4 {
                piece(t, 216.8, 223.7)
            } else {
                piece(t, 100.0, 60.0)
            }
        })
        .collect();
    assert!(most_predicted_better(
        &four_of_five.iter().collect::<Vec<_>>(),
        5
    ));
    // Three of five is not two thirds.
    let three_of_five: Vec<_> = (0..5)
        .map(|t| piece(t, 100.0, if t < 3 { 60.0 } else { 120.0 }))
        .collect();
    assert!(!most_predicted_better(
        &three_of_five.iter().collect::<Vec<_>>(),
        5
    ));
    // One piece read, however much better, says nothing ...
    let one = [piece(0, 100.0, 1.0)];
    assert!(!most_predicted_better(&one.iter().collect::<Vec<_>>(), 1));
    // ... one judged of three read (the middle of three holds, the others predicted beyond
    // their like) is judged on its own, better ...
    assert!(most_predicted_better(&one.iter().collect::<Vec<_>>(), 3));
    // ... or worse.
    let worse = [piece(0, 100.0, 101.0)];
    assert!(!most_predicted_better(&worse.iter().collect::<Vec<_>>(), 3));
}

#[test]
fn first_loadings_beyond_every_trained_stress_are_left_out_only_for_effects_within_tests() {
    use crate::folds::Piece;
    let beyond = |kind, test| Piece {
        beyond_training: true,
        ..Piece::new(test, 0, 10, kind)
    };
    let within = |kind, test| Piece::new(test, 0, 10, kind);
    // Monotonic tests at 50 and 400 kPa held out beyond the trained stresses, the one at
    // 100 kPa between them; holds of 10 and 1000 s beyond, 100 s between.
    let pieces = vec![
        beyond(PieceKind::InitialLoading, 0),
        beyond(PieceKind::InitialLoading, 1),
        within(PieceKind::InitialLoading, 2),
        beyond(PieceKind::Hold, 2),
        within(PieceKind::Hold, 2),
        beyond(PieceKind::Hold, 2),
    ];
    let kinds = |w: Option<Vec<Piece>>| -> Vec<(PieceKind, usize)> {
        w.expect("some left out, some kept")
            .iter()
            .map(|p| (p.kind, p.test))
            .collect()
    };
    // Healing is judged where it lives, between readings: the middle hold and the first
    // loading at the middle stress.
    assert_eq!(
        kinds(within_readings(&pieces, false)),
        [(PieceKind::InitialLoading, 2), (PieceKind::Hold, 2)]
    );
    // A pressure law is read across the stresses: every first loading stays, the holds
    // beyond their like do not.
    assert_eq!(
        kinds(within_readings(&pieces, true)),
        [
            (PieceKind::InitialLoading, 0),
            (PieceKind::InitialLoading, 1),
            (PieceKind::InitialLoading, 2),
            (PieceKind::Hold, 2)
        ]
    );
    // Nothing beyond: nothing to judge apart.
    let plain: Vec<Piece> = pieces.iter().map(|p| within(p.kind, p.test)).collect();
    assert!(within_readings(&plain, false).is_none());
}

#[test]
fn a_form_whose_parameters_all_sit_at_their_neutral_values_is_switched_off() {
    let lib = crate::candidates::every_form();
    let healing = lib
        .iter()
        .find(|f| f.effect == healing() && f.neutral.len() >= 2)
        .expect("a healing form with two parameters or more");
    let base = Model::base(Params::sample()).unwrap();
    let spec = Spec::with(healing);
    let off = with_values(&base, &spec, std::slice::from_ref(&healing.neutral));
    assert!(at_neutral(healing, &off));
    // The amplitude off its neutral value: switched on.
    let mut on_values = healing.neutral.clone();
    on_values[0] += 0.01;
    let on = with_values(&base, &spec, &[on_values]);
    assert!(!at_neutral(healing, &on));
}

#[test]
fn a_later_stage_starts_a_form_from_its_fit_alone_with_the_current_effects_added() {
    let lib = crate::candidates::every_form();
    let pressure = Effect::from_name("pressure").unwrap();
    let first = lib.iter().find(|f| f.effect == healing()).unwrap();
    let second = lib.iter().find(|f| f.effect == pressure).unwrap();
    // The current model: the base bent to the first effect (μ_k 0.30), the effect on.
    let mut bent = Params::sample();
    bent.mu_k = 0.30;
    let on: Vec<f64> = first.starts[0].clone();
    let current = Current {
        spec: Spec::with(first),
        model: with_values(
            &Model::base(bent).unwrap(),
            &Spec::with(first),
            std::slice::from_ref(&on),
        ),
        fit_tests: Vec::new(),
        held: Vec::new(),
    };
    // The second form's fit alone on the base: its own base parameters (μ_k 0.20) and values.
    let mut own = Params::sample();
    own.mu_k = 0.20;
    let alone_values: Vec<f64> = second.starts[0].clone();
    let mut alone = report(pressure, second.name, 10.0, 1.0);
    alone.model = with_values(
        &Model::base(own).unwrap(),
        &Spec::with(second),
        std::slice::from_ref(&alone_values),
    );
    let start = alone_plus_current(&[alone.clone()], second, &current).expect("a start");
    // Its own base and values, with the first effect at its current values.
    assert_eq!(start.params.mu_k, 0.20);
    for (p, v) in second.params.iter().zip(&alone_values) {
        assert_eq!(p.get(&start), Some(*v));
    }
    for (p, v) in first.params.iter().zip(&on) {
        assert_eq!(p.get(&start), Some(*v));
    }
    // No start where the form was not fitted alone, or its fit failed.
    assert!(alone_plus_current(&[], second, &current).is_none());
    alone.ssr = f64::NAN;
    assert!(alone_plus_current(&[alone], second, &current).is_none());
}

#[test]
fn a_later_stage_starts_a_form_off_zero_never_from_the_current_model_with_it_switched_off() {
    let lib = crate::candidates::every_form();
    let rate = lib
        .iter()
        .find(|f| f.effect == Effect::from_name("rate").unwrap() && f.params.len() == 4)
        .expect("a rate-and-state form");
    let current = Current {
        spec: Spec::base(),
        model: Model::base(Params::sample()).unwrap(),
        fit_tests: Vec::new(),
        held: Vec::new(),
    };
    let switched_off = switched_off(
        &with_values(
            &current.model,
            &Spec::with(rate),
            std::slice::from_ref(&rate.neutral),
        ),
        &Spec::with(rate),
    );
    // Its own starts and its fit alone with the current effects: none is the form switched
    // off, each moves the friction (a ≠ 0).
    let mut alone = report(rate.effect, rate.name, 10.0, 1.0);
    alone.model = with_values(
        &current.model,
        &Spec::with(rate),
        std::slice::from_ref(&rate.starts[0]),
    );
    let starts = rescreen_starts(&[alone], rate, &current);
    assert_eq!(starts.len(), rate.starts.len() + 1);
    assert!(starts.iter().all(|s| *s != switched_off));
    assert!(starts
        .iter()
        .all(|s| rate.params[0].get(s).is_some_and(|a| a != 0.0)));
    // A form with no start of its own and no fit alone starts switched off: there is nothing
    // else to start from.
    let mut bare = rate.clone();
    bare.starts.clear();
    assert_eq!(rescreen_starts(&[], &bare, &current), vec![switched_off]);
}

#[test]
fn an_effect_shown_is_weighed_where_it_lives_when_shapes_elsewhere_outvote_it() {
    let th = crate::verdict::Thresholds::default();
    let candidate = |overall: f64, shown: Option<f64>| CandidateScore {
        effect: Effect::from_name("slip-hardening").unwrap(),
        spec: "base + slip-hardening".into(),
        extra_parameters: BTreeMap::new(),
        model: Model::base(Params::sample()).unwrap(),
        held_out: comparison(overall, 800.0, vec![]),
        held_out_within: None,
        held_out_shrink: 0.5,
        by_kind: vec![],
        own_kinds: vec![],
        shown_in: shown
            .map(|d| OwnKindScore {
                kind: crate::candidates::OwnKind::Piece(PieceKind::InitialLoading),
                held_out: comparison(d, 30.0, vec![]),
                within: None,
            })
            .into_iter()
            .collect(),
        between_tests: 0.0,
        between_tests_shrink: 0.0,
        without_first_loadings: 0.0,
    };
    // Over all pieces in favour: it gains.
    assert!(gains_where_it_lives(&candidate(5.0, Some(1.0)), &th));
    // Against over all pieces (the shapes of many short pieces a hair worse), but significant
    // on the first loadings where the events read it: it gains where it lives.
    assert!(gains_where_it_lives(
        &candidate(-17.0, Some(th.min_score + 15.0)),
        &th
    ));
    // Against over all pieces and short of significance where it lives: no.
    assert!(!gains_where_it_lives(
        &candidate(-17.0, Some(th.min_score - 1.0)),
        &th
    ));
    // A family with no pieces where the events are read has only the whole to go by.
    assert!(!gains_where_it_lives(&candidate(-17.0, None), &th));

    // Significant where it lives: over all pieces; or in favour there and significant where
    // the events show it, or at the level of whole tests.
    let m = th.min_score;
    assert!(significant_where_it_lives(&candidate(m, None), &th));
    assert!(!significant_where_it_lives(&candidate(m - 0.2, None), &th));
    assert!(!significant_where_it_lives(
        &candidate(m - 0.2, Some(m - 1.0)),
        &th
    ));
    assert!(significant_where_it_lives(
        &candidate(m - 0.2, Some(m + 1.0)),
        &th
    ));
    let mut levels = candidate(m - 0.2, Some(1.0));
    assert!(!significant_where_it_lives(&levels, &th));
    levels.between_tests = m + 130.0;
    assert!(significant_where_it_lives(&levels, &th));
    // Against over all pieces, it is not, however much the tests' levels favour it.
    levels.held_out = comparison(-5.0, 800.0, vec![]);
    assert!(!significant_where_it_lives(&levels, &th));
}

#[test]
fn a_rate_law_is_namable_only_where_it_changes_friction_over_the_rates_slid_at() {
    let rate = Effect::from_name("rate").unwrap();
    let mut f = crate::candidates::every_form_features();
    f.sliding_rate_range = Some((0.01, 0.02));
    f.friction_noise_sd = 1.7e-3;
    let with = |law: subfric_model::RateEffect| {
        let base = Model::base(Params::sample()).unwrap();
        Model::new(base.params, base.ext.with_rate(law)).unwrap()
    };
    // A direct effect of 0.005 per e-fold moves friction by 0.0035 between 0.01 and 0.02 mm/s,
    // twice a reading's noise: it shows as a dependence on the rate.
    let shown = with(subfric_model::RateEffect::log_direct(0.005, 1e-6));
    assert!(stage::acts_over_sliding_rates(&f, rate, &shown));
    // A slope of -3e-4 with its cut-off at 2e-9 mm/s moves it by 2e-4: what it fits lies below
    // the rates slid at.
    let stop_only = with(subfric_model::RateEffect::log_direct(-3e-4, 2e-9));
    assert!(!stage::acts_over_sliding_rates(&f, rate, &stop_only));
    // The same law seen over two decades of rates (0.001 to 0.1 mm/s) still moves friction by
    // 1.4e-3, under the noise; over velocity steps of 0.01 to 10 mm/s it is 2.1e-3, over it.
    f.sliding_rate_range = Some((0.001, 0.1));
    assert!(!stage::acts_over_sliding_rates(&f, rate, &stop_only));
    f.sliding_rate_range = Some((0.01, 10.0));
    assert!(stage::acts_over_sliding_rates(&f, rate, &stop_only));
    // Under traction control the interface chooses its rates: nothing is imposed to check.
    f.sliding_rate_range = Some((0.01, 0.02));
    f.traction_tests = 1;
    assert!(stage::acts_over_sliding_rates(&f, rate, &stop_only));
    // Other families are not laws of the rate.
    f.traction_tests = 0;
    assert!(stage::acts_over_sliding_rates(&f, healing(), &stop_only));
}

#[test]
fn a_further_effect_with_no_pieces_of_its_own_is_not_credited_however_much_it_gains() {
    let th = crate::verdict::Thresholds::default();
    let rate = Effect::from_name("rate").unwrap();
    // A rate law behind a direction effect, on a record with no velocity step and no hold:
    // D 169 and most of the excess removed, all of it on the reversals.
    let mut all = comparison(169.0, 2000.0, vec![]);
    all.excess_shrink = 0.82;
    all.reference_chi2 = 2.3;
    let judged = |own: Comparison| {
        crate::verdict::decide_further(2.3, &[(rate, all.clone())], &[own], &[true], &th)
    };
    // Judged on all pieces for want of its own, it would be named ...
    assert_eq!(judged(all.clone()), Decision::Named(0));
    // ... judged on the pieces of its own kinds, of which there are none, it is not.
    assert!(!matches!(
        judged(Comparison::of_no_pieces()),
        Decision::Named(_) | Decision::Tentative(_)
    ));
}

#[test]
fn a_first_effect_must_predict_its_own_kind_of_piece_better() {
    // A log-healing whose refits bettered the first loadings held out while the middle hold,
    // its own piece, came out no better: standing in for something else, not namable first.
    let kind = |score: f64, excess: f64, within: Option<(f64, f64)>| OwnKindScore {
        kind: crate::candidates::OwnKind::Piece(PieceKind::Hold),
        held_out: Comparison {
            excess_shrink: excess,
            ..comparison(score, 30.0, vec![])
        },
        within: within.map(|(score, excess)| Comparison {
            excess_shrink: excess,
            ..comparison(score, 10.0, vec![])
        }),
    };
    let candidate = |own_kinds: Vec<OwnKindScore>| CandidateScore {
        effect: healing(),
        spec: "base + log-healing".into(),
        extra_parameters: BTreeMap::new(),
        model: Model::base(Params::sample()).unwrap(),
        held_out: comparison(122.0, 800.0, vec![]),
        held_out_within: None,
        held_out_shrink: 0.39,
        by_kind: vec![],
        own_kinds,
        shown_in: vec![],
        between_tests: 0.0,
        between_tests_shrink: 0.0,
        without_first_loadings: 0.0,
    };
    // No piece of its own kind in the record: nothing to ask.
    assert!(own_kinds_improve(&candidate(vec![])));
    // Its holds predicted better: it may be named.
    assert!(own_kinds_improve(&candidate(vec![kind(6.0, 0.4, None)])));
    // Worse, or no better: not.
    assert!(!own_kinds_improve(&candidate(vec![kind(
        -0.3, -0.04, None
    )])));
    assert!(!own_kinds_improve(&candidate(vec![kind(0.0, 0.0, None)])));
    // Less misfit summed but less evidence (many rows a hair worse): not.
    assert!(!own_kinds_improve(&candidate(vec![kind(-4.0, 0.2, None)])));
    // More misfit summed, all of it one large step, the typical step 4× better: it may.
    let step = |reference_ssr: f64, candidate_ssr: f64| PieceScore {
        kind: PieceKind::VelocityStep,
        test: 0,
        rows: 40,
        n_eff: 20.0,
        reference_ssr,
        candidate_ssr,
        beyond_training: false,
    };
    let mut steps = kind(240.0, -0.07, None);
    steps.held_out.pieces = vec![step(400.0, 100.0), step(400.0, 100.0), step(9e4, 9.7e4)];
    assert!(own_kinds_improve(&candidate(vec![steps.clone()])));
    steps.held_out.pieces = vec![step(400.0, 1600.0), step(400.0, 1600.0), step(9e4, 6e4)];
    assert!(!own_kinds_improve(&candidate(vec![steps])));
    // Judged between readings where some holds are predicted beyond them: the middle hold
    // decides, not the longest extrapolated from the two shorter.
    assert!(own_kinds_improve(&candidate(vec![kind(
        -9.0,
        -0.5,
        Some((3.0, 0.6))
    )])));
    assert!(!own_kinds_improve(&candidate(vec![kind(
        9.0,
        0.5,
        Some((-1.0, -0.1))
    )])));
    // One kind of its own predicted better suffices (a rate law's steps, not its hold).
    assert!(own_kinds_improve(&candidate(vec![
        kind(-1.0, -0.1, None),
        kind(30.0, 0.9, None)
    ])));
}

#[test]
fn a_first_effect_the_events_contradict_gives_way_to_the_next_that_passes() {
    // A rate-and-state set (development seed 48004): a slip softening with the most evidence
    // (D 375) but 1 % of the held-out excess, the residual read flat with slip; a rate law
    // with D 132 and 88 % of the excess. The softening is set aside and the rate law named.
    let th = crate::verdict::Thresholds::default();
    let with = |score: f64, excess: f64, typical: f64| Comparison {
        excess_shrink: excess,
        relative_shrink: excess,
        typical_shrink: typical,
        reference_chi2: 37.3,
        candidate_chi2: 37.3 * (1.0 - excess),
        ..comparison(score, 1000.0, vec![])
    };
    let rate = Effect::from_name("rate").unwrap();
    let softening = Effect::from_name("slip-hardening").unwrap();
    let pairs = [
        (rate, with(132.0, 0.88, 0.26)),
        (softening, with(375.0, -0.01, 0.58)),
    ];
    let decide =
        |admissible: &[bool]| crate::verdict::decide_among(37.3, &pairs, admissible, None, &th);
    // Alone the stage names the softening, on its evidence.
    assert_eq!(decide(&[true, true]), Decision::Named(1));
    let softening_contradicted = |i: usize| i == 1;
    assert_eq!(
        named_past_contradicted(decide, softening_contradicted, &[true, true]),
        Decision::Named(0)
    );
    // The rate law not namable: nothing else would be named, the gap stays unexplained.
    assert_eq!(
        named_past_contradicted(decide, softening_contradicted, &[false, true]),
        Decision::Unexplained
    );
    // Both contradicted: unexplained.
    assert_eq!(
        named_past_contradicted(decide, |_| true, &[true, true]),
        Decision::Unexplained
    );
    // Nothing contradicted: the stage's own decision.
    assert_eq!(
        named_past_contradicted(decide, |_| false, &[true, true]),
        Decision::Named(1)
    );
}

#[test]
fn an_effect_kept_tentatively_is_counted_on_its_own_kind_even_where_it_passes_on_all_pieces() {
    // A slip hardening behind a rate law (fresh seed 49002, rate alone): 75 % of the held-out
    // excess, all of it at the holds; its own pieces at 1.08× the noise. Kept tentatively, it
    // is counted on its own pieces, where it passes nothing, and is not named.
    let th = crate::verdict::Thresholds::default();
    // A comparison removing `excess` of a held-out misfit of `chi2` × the noise, at D `score`.
    let removing = |score: f64, excess: f64, chi2: f64| Comparison {
        excess_shrink: excess,
        relative_shrink: excess,
        reference_chi2: chi2,
        candidate_chi2: 1.0 + (chi2 - 1.0) * (1.0 - excess),
        ..comparison(score, 900.0, vec![])
    };
    let all = removing(121.6, 0.75, 1.63);
    let own_pieces = removing(31.0, 0.08, 1.08);
    let hardening = CandidateScore {
        effect: Effect::from_name("slip-hardening").unwrap(),
        spec: "rate + slip-hardening".into(),
        extra_parameters: BTreeMap::new(),
        model: Model::base(Params::sample()).unwrap(),
        held_out: all.clone(),
        held_out_within: None,
        held_out_shrink: 0.75,
        by_kind: vec![],
        own_kinds: vec![OwnKindScore {
            kind: OwnKind::AfterFirstLoading,
            held_out: own_pieces.clone(),
            within: None,
        }],
        shown_in: vec![],
        between_tests: 0.0,
        between_tests_shrink: 0.0,
        without_first_loadings: 0.0,
    };
    assert!(crate::verdict::passes(&all, &th));
    use super::forward::judged_on;
    assert_eq!(judged_on(&hardening, true, &th).score, all.score);
    let tentative = judged_on(&hardening, false, &th);
    assert_eq!(tentative.score, own_pieces.score);
    // The rate law first, named on its own; the hardening counted where it was judged.
    let rate = removing(90.6, 0.77, 3.8);
    let joint = [rate.clone(), all.clone()];
    assert_eq!(
        crate::verdict::named_count(&joint, &[rate.clone(), tentative], &[true, false], &th),
        1
    );
    assert_eq!(
        crate::verdict::named_count(&joint, &[rate, all], &[true, false], &th),
        2
    );
}
