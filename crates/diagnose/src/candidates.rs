//! The library of candidate effects: each family (rate, pressure, slip, healing, direction) in
//! the forms used in the field, each form a small extension of the model with its extra
//! parameters, first guesses read off the curves, and the values that switch it off.

use crate::features::DataFeatures;
use crate::folds::PieceKind;
use serde::{Deserialize, Serialize};
use subfric_fit::Param;
use subfric_model::terms::{self, Shows};
use subfric_model::{AtRest, Extensions, Healing, HealingForm, RateEffect, RateForm};

/// An effect the diagnosis can name (a family of forms).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    /// The base model explains the data: the gap is noise.
    None,
    /// Rate dependence: direct effect, rate and state, power law, steady state only.
    Rate,
    /// Time healing at rest (log or power law) instead of exponential recovery.
    LogHealing,
    /// A real gap that no candidate explains (e.g. measurement drift).
    Unexplained,
    /// A registered family (index in `subfric_model::terms::FAMILIES`): everything about it
    /// comes from its module.
    Term(u8),
}

impl Effect {
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

    fn registered_where(what: impl Fn(&dyn terms::TermFamily) -> bool) -> Option<Effect> {
        terms::FAMILIES
            .iter()
            .position(|f| f.tried_by_default() && what(*f))
            .map(|i| Effect::Term(i as u8))
    }

    /// Every effect a verdict can name: none, the built-in families, the registered ones,
    /// unexplained.
    pub fn every() -> Vec<Effect> {
        let registered = (0..terms::FAMILIES.len()).map(|i| Effect::Term(i as u8));
        std::iter::once(Effect::None)
            .chain(Effect::BUILT_IN)
            .chain(registered)
            .chain([Effect::Unexplained])
            .collect()
    }

    /// The built-in physical families (the registered ones, slip hardening among them, are
    /// `Effect::Term`).
    pub const BUILT_IN: [Effect; 2] = [Effect::Rate, Effect::LogHealing];

    /// Name as in `diagnosis.json`.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Term(i) => terms::family(i).name(),
            Effect::None => "none",
            Effect::Rate => "rate",
            Effect::LogHealing => "log-healing",
            Effect::Unexplained => "unexplained",
        }
    }

    /// Parses a name (also `healing`, `drift` for a gap outside the library, and a
    /// registered family's aliases).
    pub fn from_name(s: &str) -> Option<Effect> {
        match s {
            "healing" | "time-healing" => Some(Effect::LogHealing),
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
        let shows: &[Shows] = match self {
            Effect::Rate => &[Shows::VelocitySteps, Shows::Holds],
            Effect::LogHealing => &[Shows::Holds],
            Effect::Term(i) => terms::family(i).shows(),
            Effect::None | Effect::Unexplained => &[],
        };
        shows.iter().map(|&s| OwnKind::from(s)).collect()
    }

    /// One-line physical description.
    pub fn describe(self) -> &'static str {
        match self {
            Effect::None => "no effect beyond the base model: the remaining gap is noise",
            Effect::Rate => "rate dependence: friction changes with the slip rate",
            Effect::LogHealing => "time healing: friction regains strength at rest as a law of time, not by exponential recovery",
            Effect::Unexplained => "a real gap none of the candidates explains",
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

fn ext_rate(form: RateForm, v_ref: f64, at_rest: AtRest) -> Extensions {
    Extensions {
        rate: Some(RateEffect {
            form,
            a: 0.0,
            v_c: 1e-3 * v_ref,
            b: 0.0,
            d_c: 0.01,
            n: 0.0,
            v_ref,
            at_rest,
        }),
        ..Extensions::default()
    }
}

fn ext_healing(form: HealingForm, recovery: bool, erase_mm: f64) -> Extensions {
    Extensions {
        healing: Some(Healing {
            b: 0.0,
            t_c: 10.0,
            n: 0.3,
            form,
            recovery,
            erase_mm,
        }),
        ..Extensions::default()
    }
}

/// The rate forms, with first guesses from the velocity steps of the data (their jump gives a,
/// their decay length D_c, the steady change a − b).
fn rate_forms(f: &DataFeatures) -> Vec<Form> {
    let v = f.v_ref;
    let g = &f.steps;
    let a0 = g.direct.clamp(0.002, 0.05);
    let b0 = (g.direct - g.steady).clamp(0.0, 0.05);
    let dc0 = g.decay_mm.clamp(1e-3, 1.0);
    let ss0 = g.steady.clamp(-0.03, 0.03);
    let cut = [1e-4 * v, 1e-2 * v];
    // The velocity steps fitted one by one give the best first guess when they could.
    let seeded: Vec<Vec<f64>> = f
        .seeds
        .rate_and_state
        .map(|(a, b, dc)| {
            let (a, b, dc) = (a.clamp(1e-4, 0.1), b.clamp(-0.05, 0.1), dc.clamp(1e-4, 1.0));
            vec![vec![a, b, dc, cut[0]], vec![a, b, dc, cut[1]]]
        })
        .unwrap_or_default();
    let state = |form, name, at_rest| Form {
        effect: Effect::Rate,
        name,
        template: ext_rate(form, v, at_rest),
        params: vec![Param::RateA, Param::RateB, Param::RateDc, Param::RateVc],
        starts: [
            vec![a0, b0, dc0, cut[0]],
            vec![a0, b0, dc0, cut[1]],
            vec![0.01, 0.008, 0.05, cut[0]],
            vec![0.5 * a0, 0.0, dc0, cut[1]],
        ]
        .into_iter()
        .chain(seeded.iter().cloned())
        .collect(),
        neutral: vec![0.0, 0.0, dc0, cut[1]],
        bounds: vec![(Param::RateVc, 1e-7 * v, 0.3 * v)],
    };
    let direct = |name, at_rest| Form {
        effect: Effect::Rate,
        name,
        template: ext_rate(RateForm::LogDirect, v, at_rest),
        params: vec![Param::RateA, Param::RateVc],
        starts: vec![
            vec![a0, cut[0]],
            vec![a0, cut[1]],
            vec![ss0, cut[1]],
            vec![-0.01, 0.1 * v],
        ],
        neutral: vec![0.0, cut[1]],
        bounds: vec![(Param::RateVc, 1e-7 * v, 10.0 * v)],
    };
    let power = |name, at_rest| Form {
        effect: Effect::Rate,
        name,
        template: ext_rate(RateForm::Power, v, at_rest),
        params: vec![Param::RateN, Param::RateVc],
        starts: vec![
            vec![(a0 / 0.6).min(0.1), cut[0]],
            vec![(ss0 / 0.6).clamp(-0.1, 0.1), cut[1]],
            vec![-0.02, cut[1]],
        ],
        neutral: vec![0.0, cut[1]],
        bounds: vec![(Param::RateVc, 1e-7 * v, 10.0 * v)],
    };
    let creep = AtRest::Creep;
    let locked = AtRest::Locked;
    vec![
        direct("direct effect a ln(1 + v/v_c)", creep),
        state(RateForm::StateAgeing, "rate and state, ageing law", creep),
        state(RateForm::StateSlip, "rate and state, slip law", creep),
        power("power law ((v + v_c)/v_ref)^n", creep),
        direct("direct effect, locked at rest", locked),
        state(
            RateForm::StateAgeing,
            "rate and state, ageing law, locked at rest",
            locked,
        ),
        state(
            RateForm::StateSlip,
            "rate and state, slip law, locked at rest",
            locked,
        ),
        power("power law, locked at rest", locked),
        Form {
            effect: Effect::Rate,
            name: "steady state only, mu_k + a ln(v/v_ref)",
            template: ext_rate(RateForm::SteadyState, v, creep),
            params: vec![Param::RateA, Param::RateVc],
            starts: vec![vec![ss0, cut[0]], vec![0.01, cut[0]], vec![-0.01, cut[0]]],
            neutral: vec![0.0, cut[0]],
            bounds: vec![(Param::RateVc, 1e-7 * v, 0.3 * v)],
        },
    ]
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
    let mut out = library_for(f);
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
                    ..Extensions::default()
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
/// // 16 built-in forms and every form of the registered families the diagnosis tries.
/// let registered: usize = subfric_model::terms::FAMILIES
///     .iter()
///     .map(|f| (0..f.forms().len()).filter(|&k| f.tries(k)).count())
///     .sum();
/// assert_eq!(names.len(), 16 + registered);
/// assert!(names.contains(&"rate and state, slip law"));
/// ```
pub fn all_form_names() -> Vec<&'static str> {
    let every_family = DataFeatures {
        seeds: Default::default(),
        v_ref: 0.01,
        p_ref: 100.0,
        pressure_levels: 2,
        sliding_rates: 2,
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
    };
    library_with(&every_family, &registered_family_names_owned())
        .iter()
        .map(|f| f.name)
        .collect()
}

fn registered_family_names_owned() -> Vec<String> {
    registered_family_names()
        .into_iter()
        .map(String::from)
        .collect()
}

fn library_for(f: &DataFeatures) -> Vec<Form> {
    let mut out = Vec::new();
    if f.sliding_rates > 1 || f.holds > 0 {
        out.extend(rate_forms(f));
    }
    if f.holds > 0 {
        out.extend(healing_forms(f.seeds.healing_per_decade));
    }
    out
}

/// The healing family (data with holds); `per_decade` is the gain per decade of hold time the
/// holds read one by one show, when they showed one.
fn healing_forms(per_decade: Option<f64>) -> Vec<Form> {
    // b of b ln(1 + t/t_c) from a gain per decade (ln 10 per decade).
    let b0 = per_decade.map_or(0.005, |d| (d / std::f64::consts::LN_10).clamp(1e-4, 0.1));
    vec![
        Form {
            effect: Effect::LogHealing,
            name: "log time, b ln(1 + t/t_c) at rest",
            template: ext_healing(HealingForm::Log, false, 0.0),
            params: vec![Param::HealB, Param::HealTc],
            starts: vec![vec![0.01, 1.0], vec![0.01, 30.0], vec![0.03, 10.0]],
            neutral: vec![0.0, 10.0],
            bounds: vec![],
        },
        Form {
            effect: Effect::LogHealing,
            name: "power-law time, b t^n at rest",
            template: ext_healing(HealingForm::Power, false, 0.0),
            params: vec![Param::HealB, Param::HealN],
            starts: vec![vec![0.005, 0.3], vec![0.002, 0.6], vec![0.01, 0.15]],
            neutral: vec![0.0, 0.3],
            bounds: vec![],
        },
        // The same laws added to the recovery ξ(μ_s − μ) of Eq. (24) instead of replacing it:
        // the base model is their b = 0, so they cannot fit worse than it, and a contact that
        // both recovers as it slides and ages at rest (as most granular interfaces do) is
        // described without giving either up.
        Form {
            effect: Effect::LogHealing,
            name: "log time at rest, added to the recovery xi",
            template: ext_healing(HealingForm::Log, true, 0.0),
            params: vec![Param::HealB, Param::HealTc],
            starts: vec![vec![0.005, 1.0], vec![0.005, 30.0], vec![0.02, 10.0]],
            neutral: vec![0.0, 10.0],
            bounds: vec![],
        },
        Form {
            effect: Effect::LogHealing,
            name: "power-law time at rest, added to the recovery xi",
            template: ext_healing(HealingForm::Power, true, 0.0),
            params: vec![Param::HealB, Param::HealN],
            starts: vec![vec![0.003, 0.3], vec![0.001, 0.6], vec![0.005, 0.15]],
            neutral: vec![0.0, 0.3],
            bounds: vec![],
        },
        // A gain of its own on top of μ (which keeps the recovery of Eq. 24), not capped at
        // μ_s and wiped out by slip over d_h: the peak a slide-hold-slide test shows after each
        // hold, gone within a short slip, that neither the recovery of μ nor κ can shape.
        Form {
            effect: Effect::LogHealing,
            name: "log time at rest, a gain of its own erased by slip over d_h",
            template: ext_healing(HealingForm::Log, true, 0.02),
            params: vec![Param::HealB, Param::HealTc, Param::HealDh],
            starts: vec![
                vec![b0, 1.0, 0.02],
                vec![b0, 10.0, 0.1],
                vec![0.5 * b0, 1.0, 0.005],
            ],
            neutral: vec![0.0, 10.0, 0.02],
            bounds: vec![(Param::HealDh, 1e-4, 1.0)],
        },
        Form {
            effect: Effect::LogHealing,
            name: "general time at rest, a gain of its own erased by slip over d_h",
            template: ext_healing(HealingForm::General, true, 0.02),
            params: vec![Param::HealB, Param::HealTc, Param::HealN, Param::HealDh],
            starts: vec![
                vec![b0, 1.0, 0.05, 0.02],
                vec![b0, 10.0, 0.3, 0.1],
                vec![0.5 * b0, 1.0, 0.6, 0.005],
            ],
            neutral: vec![0.0, 10.0, 0.3, 0.02],
            bounds: vec![(Param::HealN, 0.0, 1.0), (Param::HealDh, 1e-4, 1.0)],
        },
        // The general form of the family (see the pressure family's).
        Form {
            effect: Effect::LogHealing,
            name: "general time, b ((1 + t/t_c)^n - 1)/n at rest",
            template: ext_healing(HealingForm::General, false, 0.0),
            params: vec![Param::HealB, Param::HealTc, Param::HealN],
            starts: vec![
                vec![0.01, 1.0, 0.05],
                vec![0.01, 10.0, 0.3],
                vec![0.003, 1.0, 0.6],
            ],
            neutral: vec![0.0, 10.0, 0.3],
            bounds: vec![(Param::HealN, 0.0, 1.0)],
        },
    ]
}
