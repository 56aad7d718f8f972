//! The α_t decision: the stiffness a fit starts from, fitted where the record resolves it and
//! the request leaves α_t open, else held at what the sets publish.

use super::FitRequest;
use crate::progress::Progress;
use subfric_fit::{FitOptions, Param};
use subfric_model::{Model, Params};
use subfric_reading::PreparedTest;

/// The stiffness the fit starts from, into `template`, and whether α_t is fitted: a series
/// stiffness the loading slopes resolve (the machine's compliance in the slip column) is
/// fitted, from the slopes' estimate, unless the request says what to do with α_t; else, where
/// a first loading rises over several rows, from a trial (α_t free against α_t held, with the
/// request's other parameters), kept when the rise decides it; else the stiffness the sets
/// publish (`published`: each set's), with a note when they disagree. Returns the stiffness
/// fitted, if any. The trial calibrates with `options` (the request's, counting the job's runs).
pub(super) fn starting_stiffness(
    req: &FitRequest,
    options: &FitOptions,
    tests: &[PreparedTest],
    published: &[(String, Option<Params>)],
    template: &mut Model,
    progress: &dyn Progress,
) -> Option<subfric_reading::Stiffness> {
    let (alpha, why) = held_stiffness(published, template.params.alpha_t);
    if let (Some(p), None) = (alpha, &req.start) {
        template.params.alpha_t = p.alpha_t;
        template.params.alpha_n = p.alpha_n;
    }
    let alpha_given = alpha_given(req);
    let resolved = (!alpha_given)
        .then(|| decided(req, options, tests, template))
        .flatten();
    match (&resolved, why) {
        (Some(s), _) => s.set_in(template),
        (None, Some(why)) if !alpha_given => progress.note(&why),
        _ => {}
    }
    resolved
}

/// Whether the request says what to do with α_t (a start, α_t freed or fixed).
fn alpha_given(req: &FitRequest) -> bool {
    req.start.is_some()
        || req.free.contains(&Param::AlphaT)
        || req.fix.iter().any(|(p, _)| *p == Param::AlphaT)
}

/// The α_t decision on `tests` (`subfric_reading::decide_stiffness`): what the unloads and
/// reloads resolve, else the trial with the request's other parameters.
fn decided(
    req: &FitRequest,
    options: &FitOptions,
    tests: &[PreparedTest],
    template: &Model,
) -> Option<subfric_reading::Stiffness> {
    // `fit` reads no velocity step one by one: no springs.
    let readings = subfric_reading::StiffnessReadings {
        resolved: subfric_reading::resolved_stiffness(tests),
        springs: None,
    };
    subfric_reading::decide_stiffness(readings, || {
        let mut held = *template;
        for (p, v) in &req.fix {
            p.set(&mut held, *v);
        }
        subfric_fit::stiffness_by_trial(tests, &held, &req.free_not_fixed(), options)
    })
}

/// The α_t decision again on the tests with their bedding taken out (`seated`), into
/// `template`, where [`starting_stiffness`] decided nothing on the travel as recorded and the
/// request leaves α_t open: a rise that stiffens is a closure and reads no stiffness, and once
/// the closure is out of the travel the rise may show the spring behind it.
pub(super) fn seated_stiffness(
    req: &FitRequest,
    options: &FitOptions,
    seated: &[PreparedTest],
    template: &mut Model,
) -> Option<subfric_reading::Stiffness> {
    if alpha_given(req) {
        return None;
    }
    let found = decided(req, options, seated, template)?;
    found.set_in(template);
    Some(found)
}

/// The contact stiffness a fit holds (α_t and α_n, which lab data rarely determine), from the
/// published parameters of the sets `(name, published)`: a single set's, or the value every set
/// of a joint fit publishes. Returns it (`None`: the sample values) and, when it does not come
/// from a single set's publication, a note saying what is held and why.
fn held_stiffness(
    sets: &[(String, Option<Params>)],
    sample: f64,
) -> (Option<Params>, Option<String>) {
    let published: Vec<(&String, Params)> =
        sets.iter().filter_map(|(n, p)| p.map(|p| (n, p))).collect();
    let agree = published.len() == sets.len()
        && published
            .windows(2)
            .all(|w| w[0].1.alpha_t == w[1].1.alpha_t && w[0].1.alpha_n == w[1].1.alpha_n);
    match (sets.len(), agree, published.first()) {
        (1, true, Some((_, p))) => (Some(*p), None),
        (_, true, Some((_, p))) => (
            Some(*p),
            Some(format!(
                "alpha_t held at {} kN/mm³, the value every set publishes (free it with --free …,alpha_t, or set it with --fix alpha_t=…)",
                p.alpha_t
            )),
        ),
        _ if published.is_empty() => (
            None,
            Some(format!(
                "alpha_t held at {sample} kN/mm³, a typical value: {} publish{} none (free it with --free …,alpha_t, or set it with --fix alpha_t=…)",
                if sets.len() == 1 { "the set" } else { "the sets" },
                if sets.len() == 1 { "es" } else { "" }
            )),
        ),
        _ => (
            None,
            Some(format!(
                "alpha_t held at {sample} kN/mm³, a typical value: the sets do not publish one value ({}) (free it with --free …,alpha_t, or set it with --fix alpha_t=…)",
                sets.iter()
                    .map(|(n, p)| match p {
                        Some(p) => format!("{} {}", crate::visible(n), p.alpha_t),
                        None => format!("{} none", crate::visible(n)),
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        ),
    }
}
