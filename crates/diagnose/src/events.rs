//! The events read one by one (`subfric_reading::events`: every velocity step fitted on its
//! own with a spring-slider, every hold, every reversal), here at their old path, and what
//! they say about each effect the diagnosis names: whether they speak against it, show it,
//! leave room for it, and whether a model's term follows them.

pub use subfric_reading::events::*;

/// Whether the events read one by one speak against a family outright, as its module says
/// ([`subfric_model::terms::TermEvidence::contradicted`]: velocity steps read of which none shows a
/// direct effect for rate, friction falling with hold time for healing).
pub fn contradicts(e: &EventAnalysis, effect: crate::Effect) -> bool {
    match effect {
        crate::Effect::Term(i) => subfric_model::terms::family(i).contradicted(&e.readings()),
        _ => false,
    }
}

/// Whether the events read one by one show a family's effect outright, as its module says
/// ([`subfric_model::terms::TermEvidence::shown`]: the tests' stress ratios changing with the
/// normal stress beyond their intervals, for pressure).
pub fn shows(e: &EventAnalysis, effect: crate::Effect) -> bool {
    match effect {
        crate::Effect::Term(i) => subfric_model::terms::family(i).shown(&e.readings()),
        _ => false,
    }
}

/// Whether `model`'s term of family `effect` follows what the events read one by one show, as
/// its module says ([`subfric_model::terms::TermEvidence::follows_readings`]); true for a model
/// without such a term and for anything but a registered family.
pub fn followed_by(e: &EventAnalysis, effect: crate::Effect, model: &subfric_model::Model) -> bool {
    match effect {
        crate::Effect::Term(i) => model.ext.terms.of(i).is_none_or(|t| {
            subfric_model::terms::family(i).follows_readings(t.form as usize, &t.p, &e.readings())
        }),
        _ => true,
    }
}

/// Whether the events read one by one leave room for a family, as its module says
/// ([`subfric_model::terms::TermEvidence::corroborated`]: velocity steps that mostly show a direct
/// effect for rate, a positive healing rate over the holds for healing, an asymmetry of the
/// reversals clear of zero for direction). Where no such event was read, nothing speaks against
/// the family.
pub fn corroborates(e: &EventAnalysis, effect: crate::Effect) -> bool {
    use crate::Effect;
    match effect {
        Effect::Term(i) => subfric_model::terms::family(i).corroborated(&e.readings()),
        _ => true,
    }
}
