//! Step 3: the forward selection through its stages (both first effects followed when the first
//! is only tentative), how many of the effects taken are named, and the backward step.

use super::*;

/// An effect the selection took, with its comparison against the model before it and the
/// model holding it.
#[derive(Clone)]
pub(in crate::diagnose) struct Selected {
    pub(in crate::diagnose) form: Form,
    pub(in crate::diagnose) own: Comparison,
    /// Named on what the events read one by one show outright, its held-out pieces where
    /// they were read agreeing ([`credited_on_events`]).
    pub(in crate::diagnose) credited_on_events: bool,
    pub(in crate::diagnose) at: Current,
    /// Taken on its own evidence but explaining too little alone (see [`Decision::Tentative`]).
    pub(in crate::diagnose) tentative: bool,
}

/// What the forward selection decided: every stage, the effects named, and the final model.
pub(in crate::diagnose) struct Selection {
    pub(in crate::diagnose) stages: Vec<SelectionStage>,
    pub(in crate::diagnose) named: Vec<Selected>,
    pub(in crate::diagnose) current: Current,
    /// Effects the backward step dropped.
    pub(in crate::diagnose) dropped: Vec<DroppedEffect>,
}

/// Step 3: forward selection on held-out pieces. Each stage adds every remaining family to
/// the current model (re-ranked on top of it after the first) and takes the one the verdict
/// names or keeps tentatively; at the end the smallest set that explains the gap is named.
/// When the first step is only tentative, the two most significant candidates are both
/// followed (two effects of similar size can rank either way alone) and the path whose named
/// effects explain the gap with the most held-out evidence is kept. When the drift of the
/// measurement took the first stage, the path the selection takes without it is followed too
/// and kept where its named effects together are not outweighed by the drift
/// ([`named_over_drift`]).
pub(in crate::diagnose) fn forward_selection(
    cx: &Context,
    base: &Current,
    families: &[Family],
    lib: &[Form],
    first_stage: &[FormReport],
) -> Selection {
    let (first, kept) = selection_stage(cx, base, families, true);
    cx.trace("selection stage 1");
    cx.step(4, 1, cx.opts.thresholds.max_effects);
    let th = &cx.opts.thresholds;
    let mut path = follow(cx, base, lib, first_stage, &first, &kept);
    // The drift of the measurement is the null of the physical explanation as a whole, not of
    // each effect alone: where it outweighs every single candidate, the effects the selection
    // takes without it are followed too, and they are named together when the drift does not
    // outweigh them together (a slip softening behind a rate law traces a trend in time as
    // much as in slip, and each alone explained less than the drift).
    if first.decision == Decision::Drift {
        let physical = stage_decision(cx, first.reference_chi2, &first.candidates, None, true);
        if matches!(physical, Decision::Named(_) | Decision::Tentative(_)) {
            let mut stage = first.clone();
            stage.decision = physical;
            let alternative = follow(cx, base, lib, first_stage, &stage, &kept);
            let named = alternative.named_count(th);
            let joint = named.checked_sub(1).map(|n| &alternative.joint[n]);
            if first
                .drift
                .as_ref()
                .is_some_and(|d| named_over_drift(&d.held_out, joint))
            {
                path = alternative;
            }
        }
    }
    path.selected.truncate(path.named_count(th));
    let current = path
        .selected
        .last()
        .map_or_else(|| base.clone(), |s| s.at.clone());
    let mut selection = Selection {
        stages: path.stages,
        named: path.selected,
        current,
        dropped: Vec::new(),
    };
    backward_elimination(cx, base, &mut selection);
    selection
}

/// The paths the forward selection follows from its first stage `first` (the models of its
/// candidates `kept`): the effect it took, and when it took one only tentatively the runner-up
/// too; the path whose named effects explain the gap with most held-out evidence.
fn follow(
    cx: &Context,
    base: &Current,
    lib: &[Form],
    first_stage: &[FormReport],
    first: &SelectionStage,
    kept: &[Current],
) -> Path {
    let th = &cx.opts.thresholds;
    let firsts: Vec<usize> = match first.decision {
        Decision::Named(i) => vec![i],
        Decision::Tentative(i) => {
            // The runner-up is tried as a first effect only where the events read one by one
            // do not speak against its family, as for a tentative effect at a later stage (a
            // rate law 7 D behind slip hardening, over four velocity steps of which none shows
            // a direct effect, was taken and named), and where its evidence is significant at
            // the level its effect lives (a pressure law removing 53 % of the held-out excess
            // with D 19.8 over the pieces, its tests' levels significant against the scatter
            // between specimens, was left behind a log-healing removing 9 % with D 34.8).
            let runner_up = (0..first.candidates.len())
                .filter(|&j| j != i)
                .filter(|&j| {
                    let c = &first.candidates[j].held_out;
                    super::stage::significant_where_it_lives(&first.candidates[j], th)
                        && c.excess_shrink > 0.0
                        && crate::events::corroborates(&cx.events, first.candidates[j].effect)
                        && super::stage::namable(cx, &first.candidates[j])
                })
                .max_by(|&a, &b| {
                    let score = |k: usize| first.candidates[k].held_out.score;
                    score(a).total_cmp(&score(b))
                });
            std::iter::once(i).chain(runner_up).collect()
        }
        _ => Vec::new(),
    };
    let paths: Vec<Path> = firsts
        .par_iter()
        .map(|&i| {
            let mut stage = first.clone();
            if let Decision::Tentative(_) = stage.decision {
                stage.decision = Decision::Tentative(i);
            }
            let mut path = Path::default();
            path.take(cx, base, stage, kept[i].clone(), i);
            path.go_on(cx, base, lib, first_stage);
            path
        })
        .collect();
    let best = (0..paths.len())
        .filter(|&k| paths[k].named_count(th) > 0)
        .max_by(|&a, &b| paths[a].evidence(th).total_cmp(&paths[b].evidence(th)));
    match best {
        Some(k) => paths.into_iter().nth(k).expect("index of a path"),
        None => paths.into_iter().next().unwrap_or_else(|| Path {
            stages: vec![first.clone()],
            ..Path::default()
        }),
    }
}

/// One path of the forward selection: its stages, the effects taken in turn, and the base
/// against each model holding the first k + 1 of them.
#[derive(Default)]
pub(super) struct Path {
    stages: Vec<SelectionStage>,
    selected: Vec<Selected>,
    joint: Vec<Comparison>,
}

impl Path {
    /// Takes candidate `i` of `stage` (its fitted model `next`).
    fn take(
        &mut self,
        cx: &Context,
        base: &Current,
        stage: SelectionStage,
        next: Current,
        i: usize,
    ) {
        let form = next
            .spec
            .forms
            .last()
            .expect("a selected spec has a form")
            .clone();
        self.joint
            .push(cx.compare(&cx.pieces, &base.held, &next.held));
        let credited = matches!(stage.decision, Decision::Named(_))
            && credited_on_events(cx, &stage.candidates[i], stage.drift.as_ref());
        self.selected.push(Selected {
            form,
            credited_on_events: credited,
            own: judged_on(
                &stage.candidates[i],
                matches!(stage.decision, Decision::Named(_)),
                &cx.opts.thresholds,
            ),
            at: next,
            tentative: matches!(stage.decision, Decision::Tentative(_)),
        });
        self.stages.push(stage);
    }

    /// The later stages, until one takes nothing or the most effects are taken.
    fn go_on(&mut self, cx: &Context, base: &Current, lib: &[Form], first_stage: &[FormReport]) {
        while self.selected.len() < cx.opts.thresholds.max_effects {
            let current = self.selected.last().map_or(base, |s| &s.at).clone();
            let families = rescreen(cx, &current, lib, first_stage);
            let (stage, kept) = selection_stage(cx, &current, &families, false);
            cx.trace(&format!("selection stage {}", self.stages.len() + 1));
            cx.step(4, self.stages.len() + 1, cx.opts.thresholds.max_effects);
            match stage.decision {
                Decision::Named(i) | Decision::Tentative(i) => {
                    let next = kept[i].clone();
                    self.take(cx, base, stage, next, i);
                }
                _ => {
                    self.stages.push(stage);
                    return;
                }
            }
        }
    }

    /// How many of the effects taken to name (see [`named_count`]).
    fn named_count(&self, th: &crate::verdict::Thresholds) -> usize {
        let own: Vec<Comparison> = self.selected.iter().map(|s| s.own.clone()).collect();
        let credited: Vec<bool> = self.selected.iter().map(|s| s.credited_on_events).collect();
        named_count(&self.joint, &own, &credited, th)
    }

    /// Held-out evidence of the named effects together over the base.
    fn evidence(&self, th: &crate::verdict::Thresholds) -> f64 {
        match self.named_count(th) {
            0 => f64::NEG_INFINITY,
            n => self.joint[n - 1].score,
        }
    }
}

/// The comparison an effect the selection took is counted on ([`named_count`]): all pieces when
/// it passes there and the stage `named` it, else the pieces of its own kind where it has one
/// (see `decide_further`). One the stage kept tentatively although it passed on all pieces
/// failed the stage's other standards (its own pieces at the noise, the events speaking against
/// it); counted on all pieces it would be named past them (a slip hardening behind a rate law,
/// its own pieces at 1.08× the noise, fresh seed 49002).
pub(super) fn judged_on(
    c: &CandidateScore,
    named: bool,
    th: &crate::verdict::Thresholds,
) -> Comparison {
    if named && crate::verdict::passes(&c.held_out, th) {
        c.held_out.clone()
    } else {
        c.best_own_kind(th).unwrap_or(&c.held_out).clone()
    }
}

/// The final model refitted without its form `i`, started from the fit with it switched off,
/// with its held-out residuals.
pub(super) fn without(cx: &Context, current: &Current, i: usize) -> Current {
    let mut spec = current.spec.clone();
    let form = spec.forms.remove(i);
    let start = switched_off(&current.model, &Spec::with(&form));
    let fitted = cx.fit_spec(
        &current.model,
        &spec,
        &[start],
        Effort::refit(cx.opts.candidate_iterations),
    );
    let held = cx.held_out(
        &current.model,
        &spec,
        &fitted.fit_tests,
        &[fitted.result.model, start],
    );
    Current {
        spec,
        model: fitted.result.model,
        fit_tests: fitted.fit_tests,
        held,
    }
}

/// Fewest named effects the backward step looks at.
pub(super) const MIN_EFFECTS_TO_PRUNE: usize = 3;

/// Backward step after the forward selection: a tentative step can take an effect that
/// only stood in for the ones after it (a slip hardening mimicking a pressure and a rate effect
/// together). Each tentative effect is removed in turn from the final model; while one adds no
/// significant held-out evidence given the others and the rest still explains the gap, the
/// weakest such effect is dropped, down to two effects. An effect named on its own evidence
/// is never dropped.
pub(super) fn backward_elimination(cx: &Context, base: &Current, selection: &mut Selection) {
    let th = &cx.opts.thresholds;
    loop {
        let current = &selection.current;
        let tentative: Vec<usize> = (0..selection.named.len())
            .filter(|&i| selection.named[i].tentative)
            .collect();
        // With two effects the forward step has shown already that the first alone does not
        // explain the gap; dropping it would rest on a refit of the second alone from the
        // pair's values, which can trade one effect for the other.
        if selection.named.len() < MIN_EFFECTS_TO_PRUNE || tentative.is_empty() {
            break;
        }
        let mut reduced: Vec<(usize, Current, Comparison)> = tentative
            .par_iter()
            .map(|&i| {
                let r = without(cx, current, i);
                let c = cx.compare(&cx.pieces, &r.held, &current.held);
                (i, r, c)
            })
            .collect();
        cx.trace("backward step");
        let still_explains =
            |r: &Current| material(&cx.compare(&cx.pieces, &base.held, &r.held), th);
        let weakest = (0..reduced.len())
            .filter(|&k| reduced[k].2.score < th.min_score && still_explains(&reduced[k].1))
            .min_by(|&a, &b| reduced[a].2.score.total_cmp(&reduced[b].2.score));
        let Some(k) = weakest else {
            break;
        };
        let (i, model_without, c) = reduced.swap_remove(k);
        let gone = selection.named.remove(i);
        selection.dropped.push(DroppedEffect {
            effect: gone.form.effect,
            form: gone.form.name.to_string(),
            score_given_the_others: c.score,
        });
        selection.current = model_without;
    }
    if selection.dropped.is_empty() {
        return;
    }
    // What each remaining effect adds to the others (to the base when it is alone).
    let current = selection.current.clone();
    let own: Vec<Comparison> = if selection.named.len() == 1 {
        vec![cx.compare(&cx.pieces, &base.held, &current.held)]
    } else {
        (0..selection.named.len())
            .into_par_iter()
            .map(|i| cx.compare(&cx.pieces, &without(cx, &current, i).held, &current.held))
            .collect()
    };
    for (s, c) in selection.named.iter_mut().zip(own) {
        s.own = c;
        s.at = current.clone();
    }
}
