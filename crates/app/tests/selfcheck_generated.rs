//! The fast part of `subfric selfcheck`: sets made by the independent generator of
//! `subfric-harness` (its own forward model, effects in forms from the friction literature,
//! rig and logger artifacts) are diagnosed without being told what they hold, and every verdict
//! must be right. Each diagnosis takes seconds; each set is chosen for the
//! regression it catches; the sets are drawn by seed, not picked by their verdicts (one is
//! the campaign set where a regression was found, named by its seed).

use subfric_app::selfcheck::{diagnose_generated, library_equivalents, Case};
use subfric_diagnose::{DiagnoseOptions, Effect};
use subfric_harness::generator::{
    all_classes, campaign_set, generate_seeded, Form, Generated, Layout, Options, Profile,
};

/// Fewer rows than a lab file keep the diagnoses short.
const ROWS: Options = Options::rows(0.6);

fn set(name: &str, class: &[Form], profile: Profile) -> Generated {
    generate_seeded(name, class, profile, &ROWS, 2026).expect("the set generates")
}

fn verdict(g: &Generated, opts: &DiagnoseOptions) -> Case {
    let c = diagnose_generated(g, opts).expect("the diagnosis runs");
    eprintln!(
        "{}: truth {} [{}], named {:?} ({:.1} s)\n  truth.json: {}",
        c.name, c.truth_label, c.profile, c.verdict, c.elapsed_s, g.truth.json
    );
    c
}

fn assert_right(c: &Case) {
    assert!(
        c.right(),
        "{} ({}, {}): named {:?}",
        c.name,
        c.truth_label,
        c.profile,
        c.verdict
    );
}

#[test]
fn no_effect_behind_machine_compliance_seating_toes_and_an_unload_is_none() {
    // Issue 20: the base fit swallowed rig artifacts and an effect was named where there is
    // none. Rig profile: a compliant machine, a seating toe on every test, an unload.
    let g = set("none-rig", &[], Profile::Rig);
    let arts = &g.truth.json["artifacts"];
    assert!(arts["machine_kn_mm3"].as_f64().is_some());
    assert!(!arts["seating_toes"].as_array().unwrap().is_empty());
    let c = verdict(&g, &DiagnoseOptions::default());
    assert_eq!(c.verdict, Vec::<Effect>::new(), "a false alarm: {c:?}");
}

#[test]
fn no_effect_on_a_lab_rig_whose_first_stroke_left_a_gap_that_closes_softly_is_none() {
    // Issue 20: lab profile (seating toes, a compliant machine, a rate-adaptive logger, files
    // cut from a run); the first stroke of the cyclic test ended before its seating gap had
    // closed. The rest of the gap was read where the first reload reaches 5 % of the peak,
    // before the softly closing contact had stiffened: 0.0218 mm taken out of about 0.0235,
    // and the reload's elastic rows missed by up to 2.6 kPa (45 % of the excess, base misfit
    // 1.94×): `unexplained`. Read at 15 % and 25 % of the peak: `none`. The no-effect set of
    // the generator's campaign of seed 5 (gen-01-1), where this was found.
    let c = verdict(&campaign(5, &[]), &DiagnoseOptions::default());
    assert_eq!(c.profile, "lab");
    assert_eq!(c.verdict, Vec::<Effect>::new(), "a false alarm: {c:?}");
}

#[test]
fn rate_and_state_recorded_by_a_lab_logger_is_named_rate() {
    // Ageing law; rate-adaptive sampling, a jittering clock, 0.1 µm quantised displacement.
    let g = set("rsf-logger", &[Form::RsfAgeing], Profile::Logger);
    assert_right(&verdict(&g, &DiagnoseOptions::default()));
}

#[test]
fn a_pressure_dependence_is_named_pressure() {
    let g = set("pressure-clean", &[Form::PressurePower], Profile::Clean);
    assert_right(&verdict(&g, &DiagnoseOptions::default()));
}

#[test]
fn two_effects_at_once_are_both_named_in_files_cut_from_a_run() {
    // Issue 20: second effects were never credited. Slip softening or hardening and a linear
    // pressure dependence, with every artifact (velocity steps cut from a longer run).
    let g = set(
        "slip-pressure-lab",
        &[Form::SlipExp, Form::PressureLinear],
        Profile::Lab,
    );
    assert_eq!(g.truth.json["midrun"], serde_json::Value::Bool(true));
    assert_right(&verdict(&g, &DiagnoseOptions::default()));
}

/// Set `k` of the generator campaign of `seed` whose class is `class` (`subfric selfcheck
/// --write DIR --per-class 1 --seed SEED` writes it as gen-NN-1).
fn campaign(seed: u64, class: &[Form]) -> Generated {
    let index = all_classes()
        .iter()
        .position(|c| c == class)
        .expect("a class of the campaign");
    campaign_set(seed, index, 0, class, &Options::default()).expect("the set generates")
}

#[test]
fn healing_behind_a_compliant_rig_is_named_when_its_screened_fit_is_polished_on_the_base() {
    // The best healing form was screened on a share of the rows, where the base parameters
    // fitted with it do worse on all rows than the base itself; the polish ranked its starts
    // on a sample, ran from the form's template (no healing) and ended there: `unexplained`.
    // Polished also from the form's values on the base, healing is named. Seed 5's
    // log-healing set (rig profile), where this was found.
    assert_right(&verdict(
        &campaign(5, &[Form::HealLog]),
        &DiagnoseOptions::default(),
    ));
}

#[test]
fn rate_and_state_that_creeps_in_the_holds_is_named_when_the_polish_decides_its_form() {
    // Issue 20: holds relaxing by 0.13 in friction (rate and state, slip law, creep at rest;
    // slip softening beside it, lab profile). Screened on a share of the rows, the locked slip
    // law ranked above the creeping one (14.6 against -15.1); polished, the creeping one scores
    // 31.5 and the locked 14.6, but only the best screened form of a family was polished: the
    // locked form, which cannot relax the holds, failed on the held-out pieces and the verdict
    // was `unexplained`. The two best screened forms of each family are now polished and the
    // better one taken. The rate + slip softening set of the generator's campaign of seed 3
    // (gen-21-1), where this was found; the softening is not named yet (left in the issue).
    let c = verdict(
        &campaign(3, &[Form::RsfSlip, Form::SlipCapped]),
        &DiagnoseOptions::default(),
    );
    let rate = Effect::from_name("rate").unwrap();
    let softening = Effect::from_name("slip-hardening").unwrap();
    assert!(c.verdict.contains(&rate), "rate not named: {c:?}");
    assert!(
        c.verdict.iter().all(|e| *e == rate || *e == softening),
        "an effect the set does not hold: {c:?}"
    );
}

#[test]
fn rate_and_state_behind_pressure_is_named_when_a_later_stage_polishes_the_forms_screening_cannot_tell_apart(
) {
    // Issue 20: rate and state (ageing law, locked at rest) beside a pressure power law on
    // mu_k, logger profile. Pressure is taken first; on top of it the screening ranked the
    // direct effect just ahead of rate and state (-133.6 against -142.3 on 3 000 rows), only
    // the first was polished, it failed on the held-out velocity steps (-19 in D) and healing
    // was taken in its place: `pressure + log-healing + rate`. Every form within two
    // parameters' penalty of a family's best screened form is now polished at later stages:
    // `pressure + rate`. The rate + pressure set of the generator's campaign of seed 13
    // (gen-19-1), where this was found.
    assert_right(&verdict(
        &campaign(13, &[Form::RsfAgeing, Form::PressurePower]),
        &DiagnoseOptions::default(),
    ));
}

#[test]
fn healing_erased_by_slip_is_named_beside_a_direction_effect() {
    // Issue 20: on top of a direction effect the peaks after the holds were left unexplained
    // (verdict `direction`, its held-out misfit 4.6x the noise, 97 % of it after the holds),
    // because the healing forms that make such peaks (a gain of their own, erased by slip)
    // ranked low on a base without direction and were not refitted later. The holds show the
    // peaks one by one, so those forms are refitted on top of direction. The set is the healing
    // + direction set of the generator's campaign of seed 3 (`subfric selfcheck --write DIR
    // --per-class 1 --seed 3`: gen-22-1), where this was found.
    let g = campaign(3, &[Form::HealLog, Form::DirectionMu]);
    assert_right(&verdict(&g, &DiagnoseOptions::default()));
}

#[test]
fn healing_is_named_beside_a_direction_effect_that_alone_fits_within_the_noise() {
    // Issue 20: with a direction effect the whole record was fitted within the noise (held-out
    // misfit 1.06x), so no further candidate was tried, though the holds alone were still
    // missed at 1.9x the noise and their peaks read one by one were clear of zero. A kind of
    // piece a remaining family acts on, still missed beyond the noise, now keeps the selection
    // going; the family must then explain that kind on its own. The set is the healing +
    // direction set of the generator's campaign of seed 7 (gen-22-1), where this was found.
    let g = campaign(7, &[Form::HealLog, Form::DirectionMu]);
    assert_right(&verdict(&g, &DiagnoseOptions::default()));
}

#[test]
fn a_vibrating_record_is_not_named_rate_against_steps_without_a_direct_effect() {
    // Issue 20: a load cell that vibrates (no effect, the gap in the recording). A locked power
    // law fitted a typical held-out piece 23 % better but removed 7 % of the excess, and was
    // named at the first stage, though none of the four velocity steps read one by one showed a
    // direct effect. The generator's campaign of seed 11 (gen-18-1), where this was found.
    let c = verdict(
        &campaign(11, &[Form::Vibration]),
        &DiagnoseOptions::default(),
    );
    assert!(
        !c.verdict.contains(&Effect::from_name("rate").unwrap()),
        "rate named against the steps: {c:?}"
    );
    assert_right(&c);
}

#[test]
fn a_drifting_load_cell_is_unexplained() {
    let g = set("drift-logger", &[Form::Drift], Profile::Logger);
    assert_right(&verdict(&g, &DiagnoseOptions::default()));
}

#[test]
fn a_creeping_load_cell_is_unexplained_not_slip_hardening() {
    // The cell's reading creeps towards a few per cent of the load with a lag of minutes: on
    // a monotonic slide at one rate it grows with time as slip hardening grows with slip. The
    // holds and the velocity steps part them (time passes in a hold without slip), and the
    // drift of the measurement — its creep shared by every test, as one cell reads them all
    // — must take the gap from the physical candidates.
    for profile in [Profile::Logger, Profile::Clean] {
        let g = set("creep", &[Form::Creep], profile);
        let c = verdict(&g, &DiagnoseOptions::default());
        assert_right(&c);
    }
}

#[test]
fn a_family_is_named_through_another_form_when_its_own_is_not_a_candidate() {
    // `selfcheck --unlisted`: healing that grows as a power of the hold time, diagnosed without
    // the library's power-law and general time forms, must still be healing (log time holds
    // it over the holds' three decades).
    let g = set("healing-unlisted", &[Form::HealPower], Profile::Clean);
    let opts = DiagnoseOptions {
        excluded_forms: library_equivalents(Form::HealPower)
            .iter()
            .map(|s| s.to_string())
            .collect(),
        ..DiagnoseOptions::default()
    };
    assert_eq!(opts.excluded_forms.len(), 4);
    assert_right(&verdict(&g, &opts));
}

/// `subfric fit` of generated set `g` with the default options, its μ_s and μ_k checked within
/// 5 % of the truth.
fn fit_recovering_mu_s_and_mu_k(g: &Generated) -> subfric_app::fit::FitOutcome {
    use subfric_app::fit::{run_fit, FitRequest};
    use subfric_app::progress::Silent;
    use subfric_fit::FitOptions;
    let tmp = tempfile::tempdir().unwrap();
    subfric_harness::generator::write_campaign(tmp.path(), std::slice::from_ref(g)).unwrap();
    let dir = tmp.path().join(&g.set.meta.name);
    let out = run_fit(&FitRequest::of_set(dir, FitOptions::default()), &Silent).unwrap();
    let params = &g.truth.json["params"];
    let fitted = &out.report.model.params;
    for (name, got) in [("mu_s", fitted.mu_s), ("mu_k", fitted.mu_k)] {
        let want = params[name].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 0.05 * want,
            "{name}: fitted {got}, truth {want}"
        );
    }
    out
}

#[test]
fn a_fit_through_a_compliant_rig_with_seating_toes_recovers_mu_s_and_mu_k_and_says_so() {
    // Issue 20: through a compliant rig (α of a few 10⁻³ kN/mm³ in series) and with a seating
    // toe on every test, μ_s and μ_k must come back within 5 %, and the fit must say what it
    // excluded and that it fitted the series stiffness.
    let g = set("none-rig", &[], Profile::Rig);
    let out = fit_recovering_mu_s_and_mu_k(&g);
    let toes = out
        .artifacts
        .iter()
        .filter(|a| a.kind == "seating-toe")
        .count();
    let expected = g.truth.json["artifacts"]["seating_toes"]
        .as_array()
        .unwrap()
        .len();
    assert_eq!(toes, expected, "{:?}", out.artifacts);
    assert!(
        out.artifacts.iter().any(|a| a.kind == "compliance"),
        "{:?}",
        out.artifacts
    );
    // The report sets μ_s and μ_k beside the peak and the residual the record shows, read
    // past the toes, and the fit keeps both.
    let read: Vec<&str> = out.read_off.iter().map(|r| r.param).collect();
    assert_eq!(read, ["mu_s", "mu_k"], "{:?}", out.read_off);
    for r in &out.read_off {
        assert!(!r.departs, "{}", r.sentence());
        assert!(!r.readings.is_empty(), "{r:?}");
    }
}

#[test]
fn the_polished_form_of_each_generated_family_converges() {
    // Issue 20: candidate forms ended "NOT converged" (83 of 138 on seven sets) and the
    // family's best was picked among failed fits. Screening stops early on purpose; the form
    // polished for each family must end by a convergence test, not the iteration limit, on
    // sets that hold that family (a rate-and-state slip law, a pressure exponential, a capped
    // slip hardening, a power-law healing, a direction effect on μ_k: one set per family, all
    // generated by the independent forward model).
    for (name, form, effect) in [
        (
            "rsf-slip-clean",
            Form::RsfSlip,
            Effect::from_name("rate").unwrap(),
        ),
        (
            "pressure-exp-lab",
            Form::PressureExp,
            Effect::from_name("pressure").unwrap(),
        ),
        (
            "slip-capped-clean",
            Form::SlipCapped,
            Effect::from_name("slip-hardening").unwrap(),
        ),
        (
            "heal-power-clean",
            Form::HealPower,
            Effect::from_name("log-healing").unwrap(),
        ),
        (
            "direction-muk-clean",
            Form::DirectionMuK,
            Effect::from_name("direction").unwrap(),
        ),
    ] {
        let profile = if name.ends_with("lab") {
            Profile::Lab
        } else {
            Profile::Clean
        };
        let g = set(name, &[form], profile);
        let prepared = subfric_diagnose::prepare_for_diagnosis(&g.set);
        let d = subfric_diagnose::diagnose(&prepared, &DiagnoseOptions::default())
            .expect("the diagnosis runs");
        let chosen: Vec<_> = d.forms.iter().filter(|f| f.chosen).collect();
        assert!(!chosen.is_empty(), "{name}: no form polished");
        let own = chosen
            .iter()
            .find(|f| f.effect == effect)
            .unwrap_or_else(|| panic!("{name}: no polished form of {effect:?}"));
        assert!(
            own.converged,
            "{name}: the polished {} stopped by {:?}",
            own.form, own.termination
        );
        // A family the verdict names must beat the base in sample. (The healing family need
        // not be named on a power-law healing set: the rate-and-state ageing law heals in log
        // time too, and its forms, which replace the recovery ξ, score below the base there.)
        if d.verdict.effects.iter().any(|e| e.effect == effect) {
            assert!(
                own.in_sample_score > 0.0,
                "{name}: {} scores {} in sample",
                own.form,
                own.in_sample_score
            );
        }
    }
}

/// The generator's clean set with no effect, with a first-order wander of the same size as
/// its white noise and a correlation time of `tau_s` added to every test's shear, diagnosed.
fn diagnosed_under_wander(tau_s: f64) -> subfric_diagnose::Diagnosis {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let g = set("none-wander", &[], Profile::Clean);
    let mut s = g.set.clone();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for t in &mut s.tests {
        let white = subfric_reading::estimate_noise(&t.time_s, &t.shear_kpa).sd;
        let mut wander = 0.0;
        for i in 0..t.shear_kpa.len() {
            let dt = if i == 0 {
                0.0
            } else {
                t.time_s[i] - t.time_s[i - 1]
            };
            let phi = (-dt / tau_s).exp();
            let e: f64 = StandardNormal.sample(&mut rng);
            wander = phi * wander + white * (1.0 - phi * phi).sqrt() * e;
            t.shear_kpa[i] += wander;
        }
    }
    let d = subfric_diagnose::diagnose(
        &subfric_diagnose::prepare_for_diagnosis(&s),
        &DiagnoseOptions::default(),
    )
    .expect("the diagnosis runs");
    let base_chi2 = d.selection.first().map_or(0.0, |st| st.reference_chi2);
    eprintln!(
        "correlation time {tau_s} s: base {base_chi2:.2}, unseen noise {:.2}, verdict {}",
        d.data.unseen_noise, d.verdict.effect
    );
    assert!(
        base_chi2 > DiagnoseOptions::default().thresholds.gap_chi2,
        "the wander must put the misfit beyond the near-noise gap for this test to mean anything: {base_chi2}"
    );
    d
}

#[test]
fn no_effect_under_noise_that_wanders_over_seconds_is_none() {
    // A load cell's noise is partly correlated in time: the second differences that estimate
    // the noise see only its white part, and a model that fits to the noise still misses by the
    // rest. With a correlation time of 2 s the base model misses by more than the near-noise
    // gap, no candidate explains it, and the record's own steady stretches show the unseen
    // noise, so the verdict is `none`, not `unexplained`.
    let d = diagnosed_under_wander(2.0);
    assert!(d.data.unseen_noise > 1.2, "{}", d.data.unseen_noise);
    assert_eq!(d.verdict.effect, Effect::None, "{}", d.verdict.explanation);
}

#[test]
fn no_effect_under_a_wander_slower_than_the_raw_windows_is_none() {
    // A wander with a correlation time of 5 s: sixty rows of the raw record about a parabola
    // absorb too much of it (the raw measure alone, 1.40, leaves the misfit of 1.87 beyond the
    // near-noise gap: `unexplained`); the base model's residual over the longest windows each
    // test holds three of, about a line, shows more of it, and the verdict is `none`.
    let d = diagnosed_under_wander(5.0);
    assert!(d.data.unseen_noise > 1.3, "{}", d.data.unseen_noise);
    assert_eq!(d.verdict.effect, Effect::None, "{}", d.verdict.explanation);
}

#[test]
fn no_effect_under_a_wander_slower_than_any_window_of_steady_driving_is_none() {
    // A wander with a correlation time of 30 s (the generator's campaign of seed 17 wrote a
    // no-effect lab set with 29 s): even 240 rows about a line take most of it out, and the
    // verdict was `unexplained`. The residual's semivariogram within each stretch of steady
    // driving reaches its sill at lags the stretches hold, and shows it.
    let d = diagnosed_under_wander(30.0);
    assert!(d.data.unseen_noise > 1.3, "{}", d.data.unseen_noise);
    assert_eq!(d.verdict.effect, Effect::None, "{}", d.verdict.explanation);
}

#[test]
fn rate_and_state_within_the_noise_a_record_wanders_by_is_named_when_it_removes_half_the_excess() {
    // Seed 9's rate-and-state set (slip law, locked at rest; gen-03-1): the base misses the
    // held-out pieces by 1.55× the noise variance, within 1.3 times the 1.19 the record's
    // steady stretches scatter beyond their white noise. The rate law removes 69 % of the
    // excess with evidence D = 158 (the velocity steps 22× → 3×), too little to be named on
    // its own and kept tentatively; the gap within the unseen noise was then called noise:
    // `none`. Within that noise a candidate is now named as below the near-noise gap itself:
    // significant and removing half the excess.
    assert_right(&verdict(
        &campaign(9, &[Form::RsfSlip]),
        &DiagnoseOptions::default(),
    ));
}

#[test]
fn rate_and_state_behind_slip_hardening_is_named_when_steps_too_fast_for_their_rows_count_neither_way(
) {
    // Seed 17's rate-and-state + slip hardening set (gen-21-1, lab profile: a row per 3 µm;
    // slip law with b = 0 and D_c = 2.4 µm, within a row). Two of the five velocity steps show
    // a direct effect (D 183 and 176); two are too fast for their rows (a fit moves friction
    // within a row, where a jump and an evolution look the same). Counted against rate and
    // state, they left two of five, short of two thirds: rate was not corroborated at the
    // second stage although it took the velocity steps from 273× to 61× the noise variance,
    // and the verdict was slip hardening alone. Counted neither way, two of three agree.
    assert_right(&verdict(
        &campaign(17, &[Form::RsfSlip, Form::SlipCapped]),
        &DiagnoseOptions::default(),
    ));
}

#[test]
fn a_rate_law_the_velocity_steps_speak_against_is_not_tried_as_a_runner_up_first_effect() {
    // Seed 19's slip softening set (capped, additive; logger profile, gen-11-1): at the first
    // stage slip hardening was kept tentatively (D 27, 10 % of the excess) and a steady-state
    // rate law (D 21, 9 %) tried beside it as the runner-up, although none of the four
    // velocity steps showed a direct effect. Its path ended with `rate` named, an effect the
    // set does not hold (held-out shrink −11 %). A runner-up is now tried only where the
    // events do not speak against its family.
    let c = verdict(
        &campaign(19, &[Form::SlipCapped]),
        &DiagnoseOptions::default(),
    );
    let softening = Effect::from_name("slip-hardening").unwrap();
    assert!(
        c.verdict
            .iter()
            .all(|e| *e == softening || *e == Effect::Unexplained),
        "an effect the set does not hold: {c:?}"
    );
}

/// Set 1 of `class` in the direct-shear programme of `seed`: what `subfric selfcheck --layout
/// direct-shear --seed SEED --write DIR` writes as gen-NN-1. Monotonic tests at three or four
/// normal stresses on a soft rig (10⁻⁴–10⁻³ kN/mm³ in series: the peak a few tenths of a mm
/// to a mm or two into the test), the generator's profiles in turn.
fn direct_shear(seed: u64, class: &[Form]) -> Generated {
    let index = all_classes()
        .iter()
        .position(|c| c == class)
        .expect("a class of the campaign");
    let opts = Options {
        layout: Layout::DirectShear,
        ..Options::default()
    };
    campaign_set(seed, index, 0, class, &opts).expect("the set generates")
}

#[test]
fn a_fit_of_a_direct_shear_programme_on_a_soft_rig_recovers_mu_s_mu_k_and_its_stiffness() {
    // Issue 20 (real direct-shear tests of dense sand: μ_s 1.90, μ_k 0.002). A lab
    // programme at 25, 100 and 400 kPa through a box of 178 kPa/mm, a seating toe on every
    // test (0.25–0.76 mm), an unload and hold half way through the 400 kPa test. α_t was
    // held at 1000 kN/mm³: after a toe the first loading no longer counted as one from rest,
    // and the unload's 0.2 mm window saw less than a third of its shear change (base misfit
    // 1568×, μ_s at its bound 3). Below 10⁻³ kN/mm³ α_t could not go at all.
    let g = direct_shear(7, &[]);
    let out = fit_recovering_mu_s_and_mu_k(&g);
    let fitted = &out.report.model.params;
    // The recorded displacement is the load point's: α_t is the series stiffness.
    let series = g.truth.json["artifacts"]["series_kpa_per_mm"]
        .as_f64()
        .unwrap()
        / 1e6;
    assert!(
        (fitted.alpha_t / series - 1.0).abs() <= 0.1,
        "α_t {} kN/mm³, series stiffness {series}",
        fitted.alpha_t
    );
    let toes = out
        .artifacts
        .iter()
        .filter(|a| a.kind == "seating-toe")
        .count();
    assert_eq!(toes, 3, "{:?}", out.artifacts);
    assert!(
        out.artifacts.iter().any(|a| a.kind == "compliance"),
        "{:?}",
        out.artifacts
    );
}

#[test]
fn no_effect_in_a_direct_shear_programme_on_a_soft_rig_is_none() {
    // Lab profile, 25, 50 and 400 kPa: the 400 kPa test's 0.45 mm seating toe is only twice
    // the 0.2 mm its loading needs from 5 % to 25 % of the peak (it was not taken for a toe:
    // base misfit 136×), and with it excluded the base model fits every row within the
    // record's unseen noise (2.06× against 2.0) while a refit from the 25 and 50 kPa tests
    // predicts the 400 kPa test 48× off (μ_s 4 % low times a sixteenfold normal stress).
    let c = verdict(&direct_shear(3, &[]), &DiagnoseOptions::default());
    assert_eq!(c.verdict, Vec::<Effect>::new(), "a false alarm: {c:?}");
    // Seed 9's: the 400 kPa test's 0.13 mm toe is shorter than the 0.22 mm climb after it; the
    // climb's straight line reaches zero shear 0.13 mm into the test (base misfit 26.8× with
    // the toe kept, `unexplained`; 1.17× without it).
    let c = verdict(&direct_shear(9, &[]), &DiagnoseOptions::default());
    assert_eq!(c.verdict, Vec::<Effect>::new(), "a false alarm: {c:?}");
}

#[test]
fn a_pressure_dependence_in_a_direct_shear_programme_on_a_soft_rig_is_named_pressure() {
    // Rig profile, 25, 100, 200 and 400 kPa, μ_s changing exponentially with the normal
    // stress (by 0.14 over 290 kPa), through a box of 314 kPa/mm, a seating toe of 0.33–0.78
    // mm on every test, an unload and hold. With α_t held at or above 10⁻³ kN/mm³ (1000
    // kPa/mm) the base fit bent μ_s, ũ and κ to a loading three times too stiff, and a rate
    // law was named on tests that all slide at one rate.
    assert_right(&verdict(
        &direct_shear(3, &[Form::PressureExp]),
        &DiagnoseOptions::default(),
    ));
}

#[test]
fn slip_hardening_the_tests_readings_show_is_named_on_the_first_loadings_where_they_were_read() {
    // Seed 43's capped linear slip hardening (logger profile, gen-11-1): each test's stress
    // ratio keeps rising past its peak, by 5 % [3, 8] of its residual over the slide — beyond
    // what two specimens differ by — but the held-out pieces are whole first loadings and
    // reversals, and the candidate (D 79) took 49 % of the excess: kept tentatively, nothing
    // after it, `unexplained`. A family the tests' readings show outright is judged on the
    // pieces where they were read (most of them predicted better, enough of their misfit
    // explained) and named there.
    assert_right(&verdict(
        &campaign(43, &[Form::SlipCapped]),
        &DiagnoseOptions::default(),
    ));
}

#[test]
fn the_rate_and_state_forms_the_velocity_steps_single_out_are_polished_whatever_their_screened_rank(
) {
    // Twenty screening iterations leave a rate-and-state form unconverged and ranked by where
    // it stopped, behind the two variants of a direct effect, which converge at once; only the
    // two best forms of a family were polished, so where the steps agree on rate and state its
    // forms were never fitted to convergence on the base ("not judged") and the family went on
    // as a direct effect. The steps single them out: each is polished, and judged.
    let g = set("rsf-logger", &[Form::RsfAgeing], Profile::Logger);
    let d = subfric_diagnose::diagnose(
        &subfric_diagnose::prepare_for_diagnosis(&g.set),
        &DiagnoseOptions::default(),
    )
    .expect("the diagnosis runs");
    let consistent = d.events.rate.as_ref().is_some_and(|r| r.consistent);
    assert!(
        consistent,
        "the steps of a rate-and-state set must agree for this test to mean anything"
    );
    let state_forms: Vec<_> = d
        .forms
        .iter()
        .filter(|f| f.form.starts_with("rate and state"))
        .collect();
    assert_eq!(
        state_forms.len(),
        4,
        "{:?}",
        d.forms.iter().map(|f| &f.form).collect::<Vec<_>>()
    );
    for f in state_forms {
        assert!(
            f.converged || f.settled,
            "{} was not polished: {:?}",
            f.form,
            f.termination
        );
    }
}
