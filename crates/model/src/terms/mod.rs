//! Registered effect families: one folder each (`terms/<family>/`, its law in `mod.rs`, its
//! unit tests in `tests.rs`), listed in [`FAMILIES`].
//!
//! A registered family adds a term T(s, t) to the friction of the cone, μ_eff = … + T, where s is
//! the accumulated plastic slip [mm] and t the time since the contact started [s], scales μ,
//! μ_s, μ_k, κ or ũ by a factor of the contact's condition (its normal stress and sliding
//! direction), or gains friction at rest as a law of the contact's age (time healing: in place
//! of the recovery of Eq. 24, beside it, or as a gain of its own that slip erases). Everything
//! the rest of subfric needs to know about the family lives in its module, behind
//! [`TermFamily`], which is four traits, one per kind of caller (`family.rs`):
//!
//! - [`TermLaw`], the law, what the integrator needs: its parameters (keys, units, scales,
//!   bounds) and forms, the term and its slope in s (for the implicit return mapping) or the
//!   factor and its range, what it reads of the contact, and which values are valid;
//! - [`TermFile`], how parameter files name it (its key, aliases, the fields naming the form);
//! - [`TermGuess`], its first guesses read off the scales of a data set;
//! - [`TermEvidence`], the diagnosis's rules: where in a test it shows, whether it is tried,
//!   and what the events read one by one must show for it, say against it or show outright.
//!
//! The calibration (`subfric-fit`) frees its parameters as `Param::Term`, the diagnosis
//! (`subfric-diagnose`) fits its forms as candidates through the same engine as the base
//! model, and parameter files carry it under its key — none of them names the family.
//!
//! Adding a family: write its folder (a unit struct in `mod.rs` with one `impl` block per part,
//! [`TermLaw`], [`TermFile`] (often empty: every method has a default), [`TermGuess`] and
//! [`TermEvidence`]; [`TermFamily`] follows; its unit tests beside it), and add its line to the
//! registry (`registry!`, which declares the folder and lists the family in [`FAMILIES`]).
//! Every effect family of subfric is registered: rate, time healing, pressure, slip hardening,
//! the time trend and the direction effect. A family whose friction depends on its history
//! integrates a state: it builds its law for a form and parameters ([`StateFamily`], a
//! [`StateLaw`]: its variables, how they start, evolve at rest and while sliding, act on
//! friction and what values are valid), its registry line ends `with state`, and the contact
//! states carry its variables in generic slots ([`StateSlots`]) that neither the integrator nor
//! the C interface names — rate (θ, the rate terms a locked form holds) and time healing (the
//! contact's age, a gain of its own) do so. A family whose friction depends on the plastic
//! slip rate also gives the return mapping its law as a [`RateEffect`] (the rate family), for
//! what steady sliding at a rate gives.
//!
//! In a parameter file each family switched on is an object under its key (its name in
//! snake_case), `"ext": {"slip_hardening": {"form": "capped", "h": 0.01, "s_h": 2}}`; the
//! form may be left out (the family's first), and so may a parameter (its default). Older files
//! gave a family as `"term": {"family": "time-trend", ...}`, which is still read.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::Target;

mod family;
#[macro_use]
mod registry;
mod slots;
mod state;

registry! {
    rate::Rate with state,
    healing::TimeHealing with state,
    pressure::Pressure,
    slip_hardening::SlipHardening,
    time_trend::TimeTrend,
    direction::Direction,
    #[cfg(test)] run_in::RunIn with state,
}

pub use direction::Direction;
pub use family::{TermEvidence, TermFamily, TermFile, TermGuess, TermLaw};
pub use healing::TimeHealing;
pub use pressure::Pressure;
pub use rate::{AtRest, Rate, RateEffect, RateForm};
pub use slip_hardening::SlipHardening;
pub use slots::Terms;
pub(crate) use state::LawOp;
pub use state::{
    FamilyState, StateFamily, StateLaw, StateSlots, StateTerms, StateVar, MAX_STATE_SLOTS,
};
pub use time_trend::TimeTrend;

/// Most registered families a model may carry at once (one slot each in [`Terms`]).
pub const MAX_FAMILIES: usize = 8;

/// Most parameters a registered family may have.
pub const MAX_TERM_PARAMS: usize = 6;

/// A parameter of a registered family.
#[derive(Clone, Copy, Debug)]
pub struct TermParam {
    /// Key in parameter files and on the command line, `family.name` (e.g. `time_trend.c`).
    pub key: &'static str,
    /// Name within the family's object in `ext.term` (e.g. `c`).
    pub name: &'static str,
    /// Unit for display ("" when dimensionless).
    pub unit: &'static str,
    /// Fitted on a logarithmic scale (the parameter must stay > 0); linear otherwise.
    pub log_scale: bool,
    /// Default bounds of a fit, natural units.
    pub bounds: (f64, f64),
    /// Value when a file leaves it out.
    pub default: f64,
    /// What a valid value is, in words (for the refusal of an invalid one).
    pub expected: &'static str,
    /// The open interval a valid value lies in (infinite ends: no limit but finiteness).
    pub within: (f64, f64),
    /// A reference of the data set (e.g. the reference normal stress), not a parameter a fit
    /// frees: the diagnosis sets it from [`FormGuess::references`].
    pub reference: bool,
}

/// No limit on a parameter but finiteness.
pub const ANY: (f64, f64) = (f64::NEG_INFINITY, f64::INFINITY);

impl TermParam {
    /// Whether `v` is a value the model accepts (finite, within its interval; > 0 on a log
    /// scale).
    pub fn valid(&self, v: f64) -> bool {
        v.is_finite() && (!self.log_scale || v > 0.0) && v > self.within.0 && v < self.within.1
    }
}

/// One form of a registered family.
#[derive(Clone, Copy, Debug)]
pub struct TermForm {
    /// Name in parameter files (kebab-case, e.g. `linear`).
    pub key: &'static str,
    /// The form in words, as the diagnosis lists it (e.g. "linear in time, c t").
    pub describe: &'static str,
    /// Indices into [`TermLaw::params`] of the parameters this form uses, in order.
    pub params: &'static [usize],
}

/// Where in a test an effect shows: the held-out pieces on which a family must improve the fit
/// to be credited as a further effect when the other pieces do not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shows {
    /// Velocity steps.
    VelocitySteps,
    /// Holds.
    Holds,
    /// Reversals of the sliding direction.
    Reversals,
    /// Every piece but the first loadings (after slip has accumulated).
    AfterFirstLoading,
    /// Tests away from the set's reference normal stress.
    AwayFromReferenceStress,
    /// The first loadings of the tests, through their peak and the slide past it, where the
    /// tests' levels are read.
    FirstLoadings,
}

/// The scales of a data set that a family reads its first guesses and bounds from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DataScales {
    /// Typical sliding rate [mm/s].
    pub v_ref: f64,
    /// Reference normal stress [kPa].
    pub p_ref: f64,
    /// Typical slip of a test [mm].
    pub slip_span_mm: f64,
    /// Longest test duration [s].
    pub duration_s: f64,
    /// Holds in the set.
    pub holds: usize,
    /// Reversals in the set.
    pub reversals: usize,
    /// Distinct normal stresses.
    pub pressure_levels: usize,
    /// Distinct sliding rates.
    pub sliding_rates: usize,
    /// Tests under traction control (their slip rate is not imposed: it varies as the
    /// interface creeps or runs away).
    pub traction_tests: usize,
    /// The friction gained per decade of hold time that the holds read one by one show, when
    /// they were read.
    pub healing_per_decade: Option<f64>,
    /// The velocity steps' signature read off the curves.
    pub steps: StepReading,
    /// Rate and state (a, b, D_c [mm]) from the velocity steps fitted one by one, when they
    /// could be.
    pub rate_and_state: Option<(f64, f64, f64)>,
    /// How the tests' peak and residual stress ratios change with the normal stress, read test
    /// by test.
    pub stress_trend: StressReading,
    /// The residual stress ratio's change with slip past the peak, pooled over the tests
    /// [1/mm], when it was read.
    pub slip_slope_per_mm: Option<f64>,
    /// The slip from the start of a first loading to its peak, the median over the tests
    /// whose peak was read [mm]: where the model's own rise to the peak ends.
    pub slip_to_peak_mm: Option<f64>,
}

/// The relative change of the tests' stress ratios per e-fold of normal stress,
/// d ln R / d ln p (−β of a power law), where two stresses or more were read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StressReading {
    /// Of the peak stress ratio.
    pub peak: Option<f64>,
    /// Of the residual stress ratio.
    pub residual: Option<f64>,
}

/// The velocity steps' signature, per e-fold of rate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReading {
    /// Friction jump right after a step (the direct effect a).
    pub direct: f64,
    /// Change of steady friction (a − b).
    pub steady: f64,
    /// Slip over which the excess over the new steady level decays by e [mm].
    pub decay_mm: f64,
}

/// Which size of a factor family's form scaling `on` acts on `target`: the first (μ as a
/// whole, μ_s, μ_k, κ or ũ when `on` names it, and μ_s under [`Target::Bounds`]), the second
/// (μ_k under [`Target::Bounds`]), or none.
pub fn size_on(on: Target, target: Target) -> Option<usize> {
    match (on, target) {
        (t, u) if t == u => Some(0),
        (Target::Bounds, Target::MuS) => Some(0),
        (Target::Bounds, Target::MuK) => Some(1),
        _ => None,
    }
}

/// What the events of a record read one by one say (filled by the diagnosis where it read
/// them), for a family to check that they leave room for it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventReadings {
    /// Backward weakening d = 1 − |μ backward| / μ forward over the reversals: value and its
    /// interval.
    pub backward_weakening: Option<Reading>,
    /// Friction gained per decade of hold time over the holds: value and its interval.
    pub healing_per_decade: Option<Reading>,
    /// Holds whose peak on reloading is clear of zero.
    pub holds_with_peak: usize,
    /// Whether the velocity steps fitted one by one agree on rate and state (most show a
    /// direct effect); `None` when no step was read.
    pub steps_agree_on_rate_and_state: Option<bool>,
    /// Velocity steps read one by one.
    pub steps_read: usize,
    /// Of [`EventReadings::steps_read`], the steps that show a direct effect.
    pub steps_with_direct_effect: usize,
    /// The relative change of the tests' peak stress ratio per e-fold of normal stress,
    /// d ln R / d ln p, with its interval; `None` when fewer than two stresses were read.
    pub peak_change_per_efold: Option<Reading>,
    /// The same of the residual stress ratio.
    pub residual_change_per_efold: Option<Reading>,
    /// The relative change of the stress ratio with slip past the peak, over the slip each
    /// test's first loading slid there (slope × slip / residual), pooled over the tests with
    /// its interval; `None` where no test slid far enough past its peak to read it.
    pub slip_change_relative: Option<Reading>,
}

/// A value read off a record with its interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// The value.
    pub value: f64,
    /// Lower end of its interval.
    pub lo: f64,
    /// Upper end of its interval.
    pub hi: f64,
}

impl Reading {
    /// Whether the interval leaves zero out.
    pub fn excludes_zero(&self) -> bool {
        self.lo > 0.0 || self.hi < 0.0
    }
}

/// Starting values and bounds of one form for one data set.
#[derive(Clone, Debug, PartialEq)]
pub struct FormGuess {
    /// First guesses, one vector (the form's parameters in order) per start.
    pub starts: Vec<Vec<f64>>,
    /// Values that switch the effect off (T ≡ 0).
    pub neutral: Vec<f64>,
    /// Bounds other than the defaults: (index into the form's fitted parameters, lo, hi).
    pub bounds: Vec<(usize, f64, f64)>,
    /// Values of the form's references ([`TermParam::reference`]) for these data: (index into
    /// the family's parameters, value).
    pub references: Vec<(usize, f64)>,
}

/// The registered family called `name` (or one of its aliases), with its index in
/// [`FAMILIES`].
pub fn family_named(name: &str) -> Option<(u8, &'static dyn TermFamily)> {
    FAMILIES
        .iter()
        .enumerate()
        .find(|(_, f)| f.name() == name || f.aliases().contains(&name))
        .map(|(i, f)| (i as u8, *f))
}

/// The registered family whose key in parameter files is `key`, with its index.
fn family_keyed(key: &str) -> Option<(u8, &'static dyn TermFamily)> {
    FAMILIES
        .iter()
        .enumerate()
        .find(|(_, f)| f.key() == key)
        .map(|(i, f)| (i as u8, *f))
}

/// The registered family at `index` of [`FAMILIES`].
///
/// # Panics
///
/// On an index no family has: indices come from [`family_named`] or the registry itself.
pub fn family(index: u8) -> &'static dyn TermFamily {
    FAMILIES[index as usize]
}

/// A registered family switched on in a model: which family, which form, its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermEffect {
    /// Index in [`FAMILIES`].
    pub family: u8,
    /// Index in the family's [`TermLaw::forms`].
    pub form: u8,
    /// The family's parameters, indexed as [`TermLaw::params`] (unused ones at their
    /// defaults).
    pub p: [f64; MAX_TERM_PARAMS],
}

impl TermEffect {
    /// Family `family` in its form `form` with every parameter at its default.
    pub fn new(family: u8, form: u8) -> TermEffect {
        let mut p = [0.0; MAX_TERM_PARAMS];
        for (slot, q) in p.iter_mut().zip(self::family(family).params()) {
            *slot = q.default;
        }
        TermEffect { family, form, p }
    }

    /// Family `family` (a name or alias) in its form keyed `form` with that form's
    /// parameters set to `values`, in order; `None` for an unknown family or form, or a count
    /// of values other than the form's.
    ///
    /// ```
    /// use subfric_model::TermEffect;
    /// let e = TermEffect::named("slip-hardening", "capped", &[0.01, 2.0]).unwrap();
    /// assert_eq!(e.term(3.0, 0.0).0, 0.02);
    /// assert!(TermEffect::named("slip-hardening", "capped", &[0.01]).is_none());
    /// ```
    pub fn named(family: &str, form: &str, values: &[f64]) -> Option<TermEffect> {
        let (index, fam) = family_named(family)?;
        let k = fam.forms().iter().position(|f| f.key == form)?;
        let used = fam.forms()[k].params;
        if used.len() != values.len() {
            return None;
        }
        let mut e = TermEffect::new(index, k as u8);
        for (&i, &v) in used.iter().zip(values) {
            e.p[i] = v;
        }
        Some(e)
    }

    /// The family.
    pub fn family(&self) -> &'static dyn TermFamily {
        family(self.family)
    }

    /// The form.
    pub fn form(&self) -> &'static TermForm {
        &self.family().forms()[self.form as usize]
    }

    /// T and ∂T/∂s at accumulated plastic slip `s` [mm] and time `t` [s].
    #[inline]
    pub fn term(&self, s: f64, t: f64) -> (f64, f64) {
        self.family().term(self.form as usize, &self.p, s, t)
    }

    /// (key, value, expected) of every invalid parameter of the form.
    pub fn issues(&self) -> Vec<(&'static str, f64, &'static str)> {
        self.family().issues(self.form as usize, &self.p)
    }
}

// Standalone (the `ext.term` object of older files): {"family": "time-trend", "form": "linear",
// "c": 1e-5} — the form's parameters by name. Only the form's parameters are written, so a
// parameter of another form read from a file is not written back and the reader refuses it as
// unknown.
impl Serialize for TermEffect {
    fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        self.write(ser, true)
    }
}

impl<'de> Deserialize<'de> for TermEffect {
    fn deserialize<D: Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        let map = serde_json::Map::<String, serde_json::Value>::deserialize(de)?;
        let name = map
            .get("family")
            .and_then(|v| v.as_str())
            .ok_or_else(|| D::Error::custom("missing field `family` (a registered family)"))?;
        let (index, _) = family_named(name).ok_or_else(|| {
            D::Error::custom(format!(
                "unknown family `{name}` (expected one of: {})",
                FAMILIES
                    .iter()
                    .map(|f| f.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        TermEffect::read(index, &map).map_err(D::Error::custom)
    }
}

impl TermEffect {
    /// Writes the form and its parameters by name, with the family's name first when
    /// `with_family`.
    fn write<S: Serializer>(&self, ser: S, with_family: bool) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let params = self.family().params();
        let form = self.form();
        let names = self.family().form_fields(self.form as usize);
        let fields = names.len() + with_family as usize + form.params.len();
        let mut map = ser.serialize_map(Some(fields))?;
        if with_family {
            map.serialize_entry("family", self.family().name())?;
        }
        for (field, value) in &names {
            map.serialize_entry(field, value)?;
        }
        for &i in form.params {
            map.serialize_entry(params[i].name, &self.p[i])?;
        }
        map.end()
    }

    /// Family `index` read from an object of its form (the family's first when left out) and
    /// parameters by name (their defaults when left out). Other keys are left for the caller's
    /// check of unknown keys.
    fn read(index: u8, map: &serde_json::Map<String, serde_json::Value>) -> Result<Self, String> {
        let fam = family(index);
        let form = fam.read_form(map)?;
        let mut e = TermEffect::new(index, form as u8);
        for (i, q) in fam.params().iter().enumerate() {
            if let Some(v) = map.get(q.name) {
                e.p[i] = v
                    .as_f64()
                    .ok_or_else(|| format!("`{}` is {v} (expected a number)", q.key))?;
            }
        }
        Ok(e)
    }
}

#[cfg(test)]
mod tests;
