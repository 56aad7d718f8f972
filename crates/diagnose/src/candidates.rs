//! The library of candidate effects: each registered family (rate, healing, pressure, slip,
//! direction, ...) in the forms used in the field, each form a small extension of the model
//! with its extra parameters, first guesses read off the curves, and the values that switch it
//! off — all from the family's module in `subfric_model::terms`.

use crate::features::DataFeatures;
use crate::folds::PieceKind;
use serde::{Deserialize, Serialize};
use subfric_fit::Param;
use subfric_model::terms::{self, Shows};
use subfric_model::Extensions;

/// An effect the diagnosis can name (a family of forms).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    /// The base model explains the data: the gap is noise.
    None,
    /// A real gap that no candidate explains (e.g. measurement drift).
    Unexplained,
    /// Nothing could be held out (no kind of piece occurs twice, as in a set of one monotonic
    /// test): whether an effect is missing cannot be judged on held-out data.
    CannotJudge,
    /// A registered family (index in `subfric_model::terms::FAMILIES`): everything about it
    /// comes from its module.
    Term(u8),
}

impl Effect {
    /// Whether the variable this effect acts through varies in data with features `f`, so
    /// that it can be named there ([`subfric_model::terms::TermEvidence::varies`]); effects that
    /// are not families always can.
    pub fn varies_in(self, f: &DataFeatures) -> bool {
        match self {
            Effect::Term(i) => terms::family(i).varies(&f.scales()),
            _ => true,
        }
    }

    /// The registered family tried by default whose term follows the accumulated slip alone
    /// (slip hardening): where a residual that grows with slip or with the cycles points.
    pub fn of_accumulated_slip() -> Option<Effect> {
        Effect::registered_where(|f| f.monotone_in_slip())
    }

    /// The registered family tried by default that reads the sliding direction: where a
    /// residual that follows the direction points.
    pub fn of_sliding_direction() -> Option<Effect> {
        Effect::registered_where(|f| f.reads_direction())
    }

    /// The registered family tried by default that reads the normal stress: where a residual
    /// that follows the normal stress points.
    pub fn of_normal_stress() -> Option<Effect> {
        Effect::registered_where(|f| f.reads_normal_stress())
    }

    /// The registered family tried by default that reads the slip rate: where a residual that
    /// follows the slip rate or its recent change points.
    pub fn of_slip_rate() -> Option<Effect> {
        Effect::registered_where(|f| f.reads_slip_rate())
    }

    /// The registered family tried by default that gains friction at rest: where a residual
    /// that follows the time at rest points.
    pub fn of_time_at_rest() -> Option<Effect> {
        Effect::registered_where(|f| f.gains_at_rest())
    }

    fn registered_where(what: impl Fn(&dyn terms::TermFamily) -> bool) -> Option<Effect> {
        terms::FAMILIES
            .iter()
            .position(|f| f.tried_by_default() && what(*f))
            .map(|i| Effect::Term(i as u8))
    }

    /// Every effect a verdict can name: none, the registered families, unexplained.
    pub fn every() -> Vec<Effect> {
        let registered = (0..terms::FAMILIES.len()).map(|i| Effect::Term(i as u8));
        std::iter::once(Effect::None)
            .chain(registered)
            .chain([Effect::Unexplained])
            .collect()
    }

    /// Name as in `diagnosis.json`.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Term(i) => terms::family(i).name(),
            Effect::None => "none",
            Effect::Unexplained => "unexplained",
            Effect::CannotJudge => "cannot-judge",
        }
    }

    /// Parses a name (also `drift` for a gap outside the library, and a registered family's
    /// aliases such as `healing`).
    pub fn from_name(s: &str) -> Option<Effect> {
        match s {
            "drift" => Some(Effect::Unexplained),
            _ => Effect::every()
                .into_iter()
                .find(|e| e.name() == s)
                .or_else(|| terms::family_named(s).map(|(i, _)| Effect::Term(i))),
        }
    }

    /// The kinds of held-out piece this family acts on, where an effect of the family must
    /// show to be credited when the other pieces do not improve (see
    /// [`crate::verdict::decide_further`]).
    pub fn own_kinds(self) -> Vec<OwnKind> {
        self.kinds(|f| f.shows())
    }

    /// Whether the family acts on whole tests — on the tests away from the reference normal
    /// stress (pressure) — so that its evidence lives in the tests' levels, each test a
    /// specimen ([`crate::score::between_tests`]).
    pub fn acts_on_whole_tests(self) -> bool {
        self.own_kinds().contains(&OwnKind::AwayFromReferenceStress)
    }

    /// The kinds of held-out piece where the events that show this family outright were read
    /// ([`subfric_model::terms::TermEvidence::shown_in`]).
    pub fn shown_kinds(self) -> Vec<OwnKind> {
        self.kinds(|f| f.shown_in())
    }

    /// The kinds of held-out piece that `pick` says of the family (none for the effects that
    /// are no family).
    fn kinds(self, pick: fn(&dyn terms::TermFamily) -> &'static [Shows]) -> Vec<OwnKind> {
        let shows: &[Shows] = match self {
            Effect::Term(i) => pick(terms::family(i)),
            Effect::None | Effect::Unexplained | Effect::CannotJudge => &[],
        };
        shows.iter().map(|&s| OwnKind::from(s)).collect()
    }

    /// One-line physical description.
    pub fn describe(self) -> &'static str {
        match self {
            Effect::None => "no effect beyond the base model: the remaining gap is noise",
            Effect::Unexplained => "a real gap none of the candidates explains",
            Effect::CannotJudge => "cannot judge: nothing could be held out of these data",
            Effect::Term(i) => terms::family(i).describe(),
        }
    }
}

// In reports an effect is its name; a registered family's name is read back to its index.
impl Serialize for Effect {
    fn serialize<S: serde::Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        ser.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Effect {
    fn deserialize<D: serde::Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        let name = String::deserialize(de)?;
        Effect::every()
            .into_iter()
            .chain([Effect::CannotJudge])
            .find(|e| e.name() == name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown effect `{name}`")))
    }
}

impl std::fmt::Display for Effect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Two normal stresses closer than this in ln(p) count as one level (a few per cent apart).
const PRESSURE_LEVEL_LOG_GAP: f64 = 0.05;

/// A kind of held-out piece a family acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OwnKind {
    /// Pieces of one kind (velocity steps, holds, reversals).
    Piece(PieceKind),
    /// Every piece but the first loadings: friction after slip.
    AfterFirstLoading,
    /// The pieces of tests away from the set's reference normal stress.
    AwayFromReferenceStress,
}

impl From<Shows> for OwnKind {
    fn from(s: Shows) -> OwnKind {
        match s {
            Shows::VelocitySteps => OwnKind::Piece(PieceKind::VelocityStep),
            Shows::Holds => OwnKind::Piece(PieceKind::Hold),
            Shows::Reversals => OwnKind::Piece(PieceKind::Reversal),
            Shows::AfterFirstLoading => OwnKind::AfterFirstLoading,
            Shows::AwayFromReferenceStress => OwnKind::AwayFromReferenceStress,
            Shows::FirstLoadings => OwnKind::Piece(PieceKind::InitialLoading),
        }
    }
}

impl OwnKind {
    /// Whether a piece of kind `kind` from a test at normal stress `stress` is of this kind,
    /// with `p_ref` the set's reference normal stress.
    pub fn holds(self, kind: PieceKind, stress: f64, p_ref: f64) -> bool {
        match self {
            OwnKind::Piece(k) => k == kind,
            OwnKind::AfterFirstLoading => kind != PieceKind::InitialLoading,
            OwnKind::AwayFromReferenceStress => {
                (stress / p_ref).ln().abs() > PRESSURE_LEVEL_LOG_GAP
            }
        }
    }

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            OwnKind::Piece(k) => k.name(),
            OwnKind::AfterFirstLoading => "after the first loading",
            OwnKind::AwayFromReferenceStress => "away from the reference normal stress",
        }
    }
}

/// One form of an effect family.
#[derive(Clone, Debug)]
pub struct Form {
    /// The family.
    pub effect: Effect,
    /// The form, in words (e.g. "rate and state, ageing law").
    pub name: &'static str,
    /// The extension switched on with its shape (form, target, references); parameters are set
    /// from `params`.
    pub template: Extensions,
    /// Extra free parameters.
    pub params: Vec<Param>,
    /// Starting values of the extra parameters (natural units), one vector per start.
    pub starts: Vec<Vec<f64>>,
    /// Values that switch the effect off.
    pub neutral: Vec<f64>,
    /// Bounds of the extra parameters other than the defaults.
    pub bounds: Vec<(Param, f64, f64)>,
}

/// The candidate forms that the data can tell anything about (no pressure forms with one normal
/// stress, no direction without reversals, no healing without holds), with the registered
/// families that are tried by default.
pub fn library(f: &DataFeatures) -> Vec<Form> {
    library_with(f, &[])
}

/// [`library`] with the registered families named in `with` tried as well (by name, as
/// `diagnose --with-family` takes them).
pub fn library_with(f: &DataFeatures, with: &[String]) -> Vec<Form> {
    let mut out = Vec::new();
    for (i, fam) in terms::FAMILIES.iter().enumerate() {
        let asked = with.iter().any(|w| w == fam.name());
        if (fam.tried_by_default() || asked) && fam.applies(&f.scales()) {
            out.extend(term_forms(i as u8, f));
        }
    }
    out
}

/// The names of the registered families (what `diagnose --with-family` takes).
pub fn registered_family_names() -> Vec<&'static str> {
    terms::FAMILIES.iter().map(|f| f.name()).collect()
}

/// The forms of registered family `family` that the diagnosis tries, with its first guesses
/// and references for these data.
fn term_forms(family: u8, f: &DataFeatures) -> Vec<Form> {
    let fam = terms::family(family);
    let param = |index: usize| Param::Term {
        family,
        index: index as u8,
    };
    (0..fam.forms().len())
        .filter(|&k| fam.tries(k))
        .map(|k| {
            let g = fam.guess(k, &f.scales());
            let fitted = fam.fitted(k);
            let mut on = terms::TermEffect::new(family, k as u8);
            for &(i, v) in &g.references {
                on.p[i] = v;
            }
            Form {
                effect: Effect::Term(family),
                name: fam.forms()[k].describe,
                template: Extensions {
                    terms: terms::Terms::one(on),
                },
                params: fitted.iter().map(|&i| param(i)).collect(),
                starts: g.starts,
                neutral: g.neutral,
                bounds: g
                    .bounds
                    .iter()
                    .map(|&(i, lo, hi)| (param(fitted[i]), lo, hi))
                    .collect(),
            }
        })
        .collect()
}

/// The name of every form of the library, whatever the data show (the names
/// `diagnose --without-form` accepts).
///
/// ```
/// let names = subfric_diagnose::candidates::all_form_names();
/// // Every form of the registered families the diagnosis tries.
/// let registered: usize = subfric_model::terms::FAMILIES
///     .iter()
///     .map(|f| (0..f.forms().len()).filter(|&k| f.tries(k)).count())
///     .sum();
/// assert_eq!(names.len(), registered);
/// assert!(names.contains(&"rate and state, slip law"));
/// ```
pub fn all_form_names() -> Vec<&'static str> {
    every_form().iter().map(|f| f.name).collect()
}

/// Every form of the library, whatever the data show: every family applies, every family
/// registered is asked for.
pub(crate) fn every_form() -> Vec<Form> {
    library_with(&every_form_features(), &registered_family_names_owned())
}

/// Features of a set in which every family applies: two rates, two stresses, a hold and a
/// reversal.
pub(crate) fn every_form_features() -> DataFeatures {
    DataFeatures {
        seeds: Default::default(),
        v_ref: 0.01,
        p_ref: 100.0,
        pressure_levels: 2,
        sliding_rates: 2,
        sliding_rate_range: Some((0.01, 0.1)),
        friction_noise_sd: 1e-3,
        traction_tests: 0,
        holds: 1,
        reversals: 1,
        slip_span_mm: 1.0,
        duration_s: 100.0,
        unseen_noise: 1.0,
        steps: crate::features::StepSignature {
            direct: 0.01,
            steady: 0.0,
            decay_mm: 0.01,
            steps: 1,
        },
    }
}

fn registered_family_names_owned() -> Vec<String> {
    registered_family_names()
        .into_iter()
        .map(String::from)
        .collect()
}
