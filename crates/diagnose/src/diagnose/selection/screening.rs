//! Step 2 of the diagnosis: every form of every family screened on the base, the best of each
//! family polished, and, at each later stage, the families refitted on top of the current model.

use super::*;

/// 2. Every form fitted to all data from its starts, scored in-sample against the base.
pub(super) fn fit_forms(cx: &Context, base: &Model, forms: &[Form]) -> Vec<(FormReport, SpecFit)> {
    forms
        .par_iter()
        .map(|f| {
            let spec = Spec::with(f);
            let starts: Vec<Model> = f
                .starts
                .iter()
                .map(|s| with_values(base, &spec, std::slice::from_ref(s)))
                .collect();
            // Screening: a few iterations rank the forms; the best of each family is then
            // polished (see `polish`).
            let fitted = cx.screen_spec(base, &spec, &starts, cx.opts.screening);
            let r = &fitted.result;
            let in_sample = in_sample_score(
                cx,
                f,
                &cx.base_residuals,
                &cx.in_sample(&r.model, &spec, &cx.tests),
            );
            cx.form_screened(forms.len());
            cx.trace(&format!(
                "screened {}: score {:.1}, ssr {:.4e}, converged {}, {:?}",
                f.name,
                in_sample.0,
                r.ssr,
                r.converged,
                parameters_of(&r.model, std::slice::from_ref(f))
            ));
            (
                FormReport {
                    effect: f.effect,
                    form: f.name.to_string(),
                    parameters: parameters_of(&r.model, std::slice::from_ref(f)),
                    ssr: r.ssr,
                    in_sample_score: in_sample.0,
                    converged: r.converged && r.ssr.is_finite(),
                    settled: false,
                    termination: r.termination.clone(),
                    polished: false,
                    switched_off: false,
                    chosen: false,
                    model: r.model,
                },
                fitted,
            )
        })
        .collect()
}

/// The best form of each family among forms `among` (largest penalised in-sample score; of
/// equal scores the one listed first), marked `chosen`. A form whose fit failed, or neither
/// converged nor settled, is not judged, however high its score: a family with no other form
/// has none.
pub(super) fn choose_forms(reports: &mut [FormReport], among: &[usize]) -> Vec<usize> {
    let mut best: BTreeMap<Effect, usize> = BTreeMap::new();
    for &i in among {
        let r = &reports[i];
        if !r.judged() {
            continue;
        }
        match best.get(&r.effect) {
            Some(&j) if reports[j].in_sample_score >= r.in_sample_score => {}
            _ => {
                best.insert(r.effect, i);
            }
        }
    }
    for &i in best.values() {
        reports[i].chosen = true;
    }
    best.into_values().collect()
}

/// How many of a family's `ranked` forms, ranked by their screened scores, are polished: every
/// one of a family that acts on whole tests, else `otherwise`. A whole-test family's forms differ
/// in how they share the misfit among the tests at different normal stresses, and the screening
/// — a few iterations on a share of the rows, unweighted — weighs the tests otherwise than the
/// polish and the score do: a power law on μ screened 48 behind the linear law and, polished,
/// scored 21 ahead of it (held-out D 23 against −24, and the pressure effect named beside a
/// log-healing instead of missed). Such a family has few forms of one parameter each.
pub(super) fn polished_of_family(
    effect: Effect,
    ranked: usize,
    otherwise: impl FnOnce() -> usize,
) -> usize {
    if effect.acts_on_whole_tests() {
        ranked
    } else {
        otherwise().min(ranked)
    }
}

/// The best forms of each family by penalised in-sample score, best first (failed fits
/// never), one list per family in the families' order: `per_family` of each, every one of a
/// family that acts on whole tests ([`polished_of_family`]).
pub(super) fn ranked_by_family(reports: &[FormReport], per_family: usize) -> Vec<Vec<usize>> {
    let mut by_family: BTreeMap<Effect, Vec<usize>> = BTreeMap::new();
    for (i, r) in reports.iter().enumerate() {
        if r.ssr.is_finite() {
            by_family.entry(r.effect).or_default().push(i);
        }
    }
    by_family
        .into_values()
        .map(|mut ranked| {
            // Stable: of equal scores the form listed first stays first.
            ranked.sort_by(|&a, &b| {
                reports[b]
                    .in_sample_score
                    .total_cmp(&reports[a].in_sample_score)
            });
            let effect = reports[ranked[0]].effect;
            ranked.truncate(polished_of_family(effect, ranked.len(), || per_family));
            ranked
        })
        .collect()
}

/// The best form of every family not yet in `current`, each fitted on top of it: an effect
/// masked by another one not yet modelled may show its best form only now. Every form is
/// screened (starts: the form's own starts and its first-stage fit with the current effects
/// added — see [`alone_plus_current`] — on the current model; the form switched off only where
/// it has neither); the best
/// of each family and those the screening cannot tell from it (see [`polished_among`]; every
/// form of a family that acts on whole tests, see [`polished_of_family`]) are polished on the
/// current model, and the best once polished is the family's form, as in the
/// first stage.
pub(super) fn rescreen(
    cx: &Context,
    current: &Current,
    lib: &[Form],
    first_stage: &[FormReport],
) -> Vec<Family> {
    let own_residuals = residuals(&cx.tests, &current.model, None);
    // (in-sample score, effective rows) of a fitted model against the current one.
    let score_of = |model: &Model, f: &Form| {
        in_sample_score(cx, f, &own_residuals, &residuals(&cx.tests, model, None))
    };
    let scored: Vec<(usize, f64, f64, SpecFit)> = lib
        .par_iter()
        .enumerate()
        .filter(|(_, f)| !current.spec.forms.iter().any(|g| g.effect == f.effect))
        .map(|(i, f)| {
            let spec = current.spec.plus(f);
            let starts = rescreen_starts(first_stage, f, current);
            let fitted = cx.screen_spec(&current.model, &spec, &starts, cx.opts.rescreening);
            let (score, n_eff) = score_of(&fitted.result.model, f);
            (i, score, n_eff, fitted)
        })
        .collect();
    let mut by_family: BTreeMap<Effect, Vec<(usize, f64, f64, SpecFit)>> = BTreeMap::new();
    for entry in scored {
        if entry.1.is_finite() {
            by_family
                .entry(lib[entry.0].effect)
                .or_default()
                .push(entry);
        }
    }
    let to_polish: Vec<(usize, SpecFit)> = by_family
        .into_iter()
        .flat_map(|(effect, mut ranked)| {
            // Stable: of equal scores the form listed first stays first.
            ranked.sort_by(|a, b| b.1.total_cmp(&a.1));
            let keep = polished_of_family(effect, ranked.len(), || {
                polished_among(&ranked.iter().map(|r| (r.1, r.2)).collect::<Vec<_>>())
            });
            ranked.truncate(keep);
            ranked.into_iter().map(|(i, _, _, fitted)| (i, fitted))
        })
        .collect();
    let polished: Vec<(usize, f64, SpecFit)> = to_polish
        .into_par_iter()
        .map(|(i, screened)| {
            let spec = current.spec.plus(&lib[i]);
            let fitted = cx.fit_spec_to_convergence(
                &current.model,
                &spec,
                &[screened.result.model],
                Effort::refit(cx.opts.candidate_iterations),
            );
            let (score, _) = score_of(&fitted.result.model, &lib[i]);
            (i, score, fitted)
        })
        .collect();
    for (i, score, fitted) in &polished {
        cx.trace(&format!(
            "rescreened on {}: {} polished, score {score:.1}, judged {}, {:?}",
            current.spec.describe(),
            lib[*i].name,
            fitted.judged(),
            parameters_of(&fitted.result.model, std::slice::from_ref(&lib[*i]))
        ));
    }
    families_of_polished(lib, polished)
}

/// The starts of form `f` screened on top of `current`: its own starts and its first-stage fit
/// with the current effects added ([`alone_plus_current`]), on the current model; the form
/// switched off only where it has neither.
///
/// Not from the form switched off beside them: that start is the current model itself, which
/// the comparison holds already, and ranked first by its misfit it was the one refined. From
/// there an amplitude at its neutral zero moves only as far as the gradient of a model with
/// none of the effect leads: a rate-and-state law polished on top of slip softening stayed at
/// a = b = 0 where the velocity steps read a 0.006, b 0.04 and its first-stage fit held
/// a 0.010 (fresh seed 33002). A form that cannot help ends near zero from its own starts too.
pub(super) fn rescreen_starts(
    first_stage: &[FormReport],
    f: &Form,
    current: &Current,
) -> Vec<Model> {
    let alone = Spec::with(f);
    let mut starts: Vec<Model> = f
        .starts
        .iter()
        .map(|v| with_values(&current.model, &alone, std::slice::from_ref(v)))
        .collect();
    starts.extend(alone_plus_current(first_stage, f, current));
    if starts.is_empty() {
        starts.push(switched_off(
            &with_values(&current.model, &alone, std::slice::from_ref(&f.neutral)),
            &alone,
        ));
    }
    starts
}

/// The families of forms polished on the current model (form index, polished in-sample score,
/// fit): each family's form is its best polished one.
fn families_of_polished(lib: &[Form], polished: Vec<(usize, f64, SpecFit)>) -> Vec<Family> {
    let mut by_family: BTreeMap<Effect, Vec<(usize, f64, SpecFit)>> = BTreeMap::new();
    for (i, score, fitted) in polished {
        by_family
            .entry(lib[i].effect)
            .or_default()
            .push((i, score, fitted));
    }
    // A judged form (converged, or settled) comes before any form whose fit neither converged
    // nor settled, even continued (its score says where the fit stopped, not what the form can
    // do); such a form is taken only where its family has no other (a rate-and-state law
    // behind slip hardening, slow to converge on steps of few rows, would otherwise leave its
    // family untried; its report says it did not converge). Of equal ranks the form polished
    // first stays first.
    by_family
        .into_values()
        .map(|mut ranked| {
            ranked.sort_by(|a, b| (b.2.judged().cmp(&a.2.judged())).then(b.1.total_cmp(&a.1)));
            let mut ranked = ranked.into_iter();
            let (i, _, fitted) = ranked.next().expect("a family has a polished form");
            let alternatives = held_out_alternatives(
                lib[i].effect,
                ranked
                    .filter(|r| r.2.judged())
                    .map(|(j, _, fit)| (lib[j].clone(), fit)),
            );
            Family {
                effect: lib[i].effect,
                form: lib[i].clone(),
                alone: fitted,
                alternatives,
            }
        })
        .collect()
}

/// Forms of a family that acts on whole tests, besides its best in-sample, that the selection
/// also predicts held out to choose the family's form: the next best in-sample ones, up to
/// [`WHOLE_TEST_FORMS`] in all (none for any other family). Its forms differ in how they carry a
/// test's level from the normal stresses fitted to the one held out, and in-sample they are
/// judged on the stresses they were fitted to: a linear law on μ_s alone scored 19 above one on
/// μ as a whole, and held out it added 130 % to the misfit it was to remove. `ranked` is best
/// first, judged forms only.
pub(super) fn held_out_alternatives(
    effect: Effect,
    ranked: impl Iterator<Item = (Form, SpecFit)>,
) -> Vec<(Form, SpecFit)> {
    if !effect.acts_on_whole_tests() {
        return Vec::new();
    }
    ranked.take(WHOLE_TEST_FORMS - 1).collect()
}

/// Forms of a family that acts on whole tests predicted held out at each stage, its best
/// in-sample included ([`held_out_alternatives`]): each costs a held-out refit per fold.
pub(super) const WHOLE_TEST_FORMS: usize = 3;

/// Form `f`'s first-stage fit (alone on the base) with the effects of `current` added at their
/// current values: a start for `f` on top of them. The current model was fitted without `f`,
/// and where `f` acts on whole tests (a pressure effect moves every test's level) the base
/// parameters bent to the first effect can hold `f`, started switched off on them, in a valley
/// far from its own: of two effects each seen alone, the pair then fits worse than the second
/// one alone did. Starting from both single-effect fits lets the pair find the better of them.
pub(super) fn alone_plus_current(
    first_stage: &[FormReport],
    f: &Form,
    current: &Current,
) -> Option<Model> {
    let alone = first_stage
        .iter()
        .find(|r| r.effect == f.effect && r.form == f.name && r.ssr.is_finite())?;
    let values: Vec<Vec<f64>> = current
        .spec
        .forms
        .iter()
        .map(|g| {
            g.params
                .iter()
                .zip(&g.neutral)
                .map(|(p, &n)| p.get(&current.model).unwrap_or(n))
                .collect()
        })
        .collect();
    Some(with_values(&alone.model, &current.spec, &values))
}

/// A family's best form with its fit alone on the base (on the current model at a later
/// stage), and, for a family that acts on whole tests, its next best forms with theirs, among
/// which the held-out pieces choose ([`held_out_alternatives`]).
#[derive(Clone)]
pub(in crate::diagnose) struct Family {
    pub(in crate::diagnose) effect: Effect,
    pub(in crate::diagnose) form: Form,
    pub(in crate::diagnose) alone: SpecFit,
    pub(in crate::diagnose) alternatives: Vec<(Form, SpecFit)>,
}

/// Step 2: every form fitted to all data and screened; the best [`POLISHED_PER_FAMILY`] forms of
/// each family (every form of a family that acts on whole tests) polished on the base
/// (reweighted when model error dominates) and the best of them by its polished in-sample score
/// taken as the family's form (a whole-test family keeps its next best for the held-out pieces
/// to choose among, see [`held_out_alternatives`]). Returns every form's
/// report, the polished ones updated with their polished fits, and the families.
pub(in crate::diagnose) fn screen_and_polish(
    cx: &Context,
    base: &Model,
    lib: &[Form],
) -> (Vec<FormReport>, Vec<Family>) {
    let (mut forms, fits): (Vec<FormReport>, Vec<SpecFit>) =
        fit_forms(cx, base, lib).into_iter().unzip();
    let mut to_polish: Vec<usize> = ranked_by_family(&forms, POLISHED_PER_FAMILY)
        .into_iter()
        .flatten()
        .collect();
    // And the forms the events read one by one single out (every rate-and-state form when the
    // velocity steps agree on rate and state): a few screening iterations leave such a form
    // unconverged and ranked by where it stopped, behind two variants of a direct effect that
    // converge at once, and it would never be polished on the base.
    let singled_out = crate::diagnose::singled_out(lib, &cx.events);
    for &i in &singled_out {
        if forms[i].ssr.is_finite() && !to_polish.contains(&i) {
            to_polish.push(i);
        }
    }
    cx.trace("every form screened");
    cx.step(3, 0, 0);
    let polished: Vec<SpecFit> = to_polish
        .par_iter()
        .map(|&i| {
            let spec = Spec::with(&lib[i]);
            // From the screened fit, and from its form's values on the base: the screening
            // rows are a share of the data, and the base parameters fitted to them with the
            // form can fit all rows worse than the base does.
            let screened = fits[i].result.model;
            let mut on_base = subfric_fit::with_base_of(&screened, base);
            on_base.params.alpha_t = base.params.alpha_t;
            on_base.params.alpha_n = base.params.alpha_n;
            let mut starts = vec![screened, on_base];
            // A form the events single out also starts from its own first guesses on the
            // base, among them what the events read (a, b and D_c of the velocity steps
            // fitted one by one): twenty screening iterations may have left it in another
            // valley.
            if singled_out.contains(&i) {
                starts.extend(
                    lib[i]
                        .starts
                        .iter()
                        .map(|v| with_values(base, &spec, std::slice::from_ref(v))),
                );
            }
            cx.fit_spec_to_convergence(base, &spec, &starts, cx.opts.polish)
        })
        .collect();
    for (fit, &i) in polished.iter().zip(&to_polish) {
        let r = &fit.result;
        let own = cx.in_sample(&r.model, &Spec::with(&lib[i]), &fit.fit_tests);
        let (score, _) = in_sample_score(cx, &lib[i], &cx.base_residuals, &own);
        let report = &mut forms[i];
        report.parameters = parameters_of(&r.model, std::slice::from_ref(&lib[i]));
        report.ssr = r.ssr;
        report.in_sample_score = score;
        report.converged = r.converged && r.ssr.is_finite();
        report.settled = fit.settled;
        report.polished = true;
        report.switched_off = at_neutral(&lib[i], &r.model);
        report.termination = r.termination.clone();
        report.model = r.model;
    }
    // A form's screened score ranks it only roughly (a few iterations on a share of the rows):
    // the family's form is the best of its forms once polished.
    let chosen = choose_forms(&mut forms, &to_polish);
    let families = families_of_chosen(&forms, lib, &to_polish, polished, &chosen);
    cx.trace("best forms polished");
    (forms, families)
}

/// The families of the forms `chosen` among those polished on the base (`to_polish`, their fits
/// `polished` in the same order), each with the next best judged forms of its family where
/// the held-out pieces choose among them ([`held_out_alternatives`]).
fn families_of_chosen(
    forms: &[FormReport],
    lib: &[Form],
    to_polish: &[usize],
    polished: Vec<SpecFit>,
    chosen: &[usize],
) -> Vec<Family> {
    let mut polished: BTreeMap<usize, SpecFit> = to_polish.iter().copied().zip(polished).collect();
    chosen
        .iter()
        .map(|&i| {
            let mut others: Vec<usize> = to_polish
                .iter()
                .copied()
                .filter(|&j| j != i && forms[j].effect == forms[i].effect && forms[j].judged())
                .collect();
            // Best in-sample first; of equal scores the one polished first.
            others.sort_by(|&a, &b| {
                forms[b]
                    .in_sample_score
                    .total_cmp(&forms[a].in_sample_score)
            });
            let alternatives = held_out_alternatives(
                forms[i].effect,
                others.into_iter().map(|j| {
                    let fit = polished[&j].clone();
                    (lib[j].clone(), fit)
                }),
            );
            Family {
                effect: forms[i].effect,
                form: lib[i].clone(),
                alone: polished.remove(&i).expect("chosen among the polished"),
                alternatives,
            }
        })
        .collect()
}

/// Whether every parameter of `form` in `model` sits at the value that switches the effect
/// off (to a millionth): a polish that ends there found the data want none of the effect on
/// its reference — an amplitude held at its bound of zero leaves the other parameters where
/// they started.
pub(in crate::diagnose) fn at_neutral(form: &Form, model: &Model) -> bool {
    form.params.iter().zip(&form.neutral).all(|(p, &n)| {
        p.get(model)
            .is_some_and(|v| (v - n).abs() <= 1e-6 * n.abs().max(1e-12))
    })
}

/// How many of a family's forms, ranked by screened (score, effective rows) best first, a later
/// stage polishes: the best, and every further form the screening cannot tell from it — within
/// two parameters' penalty, 2 ln n_eff. A few screening iterations leave a rate-and-state form,
/// slow to converge, just behind a direct effect that converges at once (9 points on 3 000
/// rows; once polished, the rate-and-state form explains the velocity steps and the direct
/// effect does not). Forms clearly behind are not polished: each costs a full refit per stage.
pub(super) fn polished_among(ranked: &[(f64, f64)]) -> usize {
    let Some(&(best, _)) = ranked.first() else {
        return 0;
    };
    1 + ranked[1..]
        .iter()
        .take_while(|(score, n_eff)| *score >= best - 2.0 * n_eff.max(1.0).ln())
        .count()
}

/// Forms of each family polished before the family's form is chosen: the screening ranks
/// close forms unreliably (on a record with creep in its holds the locked and the creeping
/// slip law swap places once polished).
pub(super) const POLISHED_PER_FAMILY: usize = 2;

/// The in-sample score of form `f` whose fit leaves residuals `own` where the model it extends
/// leaves `reference`, with the effective rows it rests on: the evidence over the pieces less
/// its parameters' price ([`penalised`]) and, for a family that acts on whole tests, the
/// evidence at the level of the tests against the scatter between specimens
/// ([`crate::score::between_tests`]). The forms of a pressure law differ in how they follow
/// the tests' levels across the normal stresses (linear, power or exponential in p, on μ or
/// on μ_s or μ_k alone), and the per-piece evidence weighs a test's level as one unit with no
/// scale of its own: every pressure form of a set at 50, 100 and 400 kPa scored below zero
/// in-sample that way, the polished ones included, where what the base missed most was the
/// tests away from 100 kPa (393× the noise variance at 50 kPa, 1432× at 400).
pub(super) fn in_sample_score(
    cx: &Context,
    f: &Form,
    reference: &HeldOut,
    own: &HeldOut,
) -> (f64, f64) {
    let c = cx.compare(&cx.pieces, reference, own);
    let whole_tests = if f.effect.acts_on_whole_tests() {
        crate::score::between_tests(&cx.pieces, &cx.weights, reference, own, &cx.scatter)
    } else {
        0.0
    };
    (penalised(&c, f.params.len()) + whole_tests, c.n_eff)
}

/// In-sample evidence less ln(n_eff) per extra parameter (a BIC on the effective number of
/// observations), so that forms with more parameters do not win by fitting noise.
pub(super) fn penalised(c: &Comparison, extra_parameters: usize) -> f64 {
    crate::score::penalised(c.score, c.n_eff, extra_parameters)
}
