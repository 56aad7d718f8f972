//! Registered effect families: one module each, listed in [`FAMILIES`].
//!
//! A registered family adds a term T(s, t) to the friction of the cone, μ_eff = … + T, where s is
//! the accumulated plastic slip [mm] and t the time since the contact started [s]. Everything
//! the rest of subfric needs to know about the family lives in its module, behind
//! [`TermFamily`]: its parameters (keys, units, scales, bounds), its forms, the term and its
//! slope in s (for the implicit return mapping), where in a test it shows, and its first
//! guesses read off the scales of a data set. The calibration (`subfric-fit`) frees its
//! parameters as `Param::Term`, the diagnosis (`subfric-diagnose`) fits its forms as candidates
//! through the same engine as the base model, and parameter files carry it as
//! `"ext": {"term": {"family": "...", "form": "...", <parameters>}}` — none of them names the
//! family.
//!
//! Adding a family: write its module (a unit struct implementing [`TermFamily`], with its unit
//! tests), and add one line to [`FAMILIES`]. The five families of [`crate::extensions`] (rate,
//! pressure, slip hardening, healing, direction) predate this registry: they act on μ's bounds,
//! a state variable θ or the recovery at rest, which a term T(s, t) cannot express.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

mod time_trend;

pub use time_trend::TimeTrend;

/// The registered families, in the order the diagnosis tries them.
pub static FAMILIES: &[&dyn TermFamily] = &[&TimeTrend];

/// Most parameters a registered family may have.
pub const MAX_TERM_PARAMS: usize = 4;

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
}

impl TermParam {
    /// Whether `v` is a value the model accepts (finite; > 0 on a log scale).
    pub fn valid(&self, v: f64) -> bool {
        v.is_finite() && (!self.log_scale || v > 0.0)
    }
}

/// One form of a registered family.
#[derive(Clone, Copy, Debug)]
pub struct TermForm {
    /// Name in parameter files (kebab-case, e.g. `linear`).
    pub key: &'static str,
    /// The form in words, as the diagnosis lists it (e.g. "linear in time, c t").
    pub describe: &'static str,
    /// Indices into [`TermFamily::params`] of the parameters this form uses, in order.
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
}

/// Starting values and bounds of one form for one data set.
#[derive(Clone, Debug, PartialEq)]
pub struct FormGuess {
    /// First guesses, one vector (the form's parameters in order) per start.
    pub starts: Vec<Vec<f64>>,
    /// Values that switch the effect off (T ≡ 0).
    pub neutral: Vec<f64>,
    /// Bounds other than the defaults: (index into the form's parameters, lo, hi).
    pub bounds: Vec<(usize, f64, f64)>,
}

/// An effect family that adds a term T(s, t) to the friction (see the module documentation).
pub trait TermFamily: Sync + std::fmt::Debug {
    /// Name in verdicts and parameter files (kebab-case, e.g. `time-trend`).
    fn name(&self) -> &'static str;
    /// One-line physical description.
    fn describe(&self) -> &'static str;
    /// Every parameter of the family.
    fn params(&self) -> &'static [TermParam];
    /// The forms; the first is the one a parameter set on its own switches on.
    fn forms(&self) -> &'static [TermForm];
    /// Where its effect shows.
    fn shows(&self) -> &'static [Shows];
    /// Whether the diagnosis tries it unless asked not to. A family that data of the usual
    /// kinds cannot tell from an artifact (a drift of the measurement, say) is tried only when
    /// the user names it.
    fn tried_by_default(&self) -> bool;
    /// Whether data of these scales can say anything about the family.
    fn applies(&self, data: &DataScales) -> bool;
    /// First guesses and bounds of form `form` for data of these scales.
    fn guess(&self, form: usize, data: &DataScales) -> FormGuess;
    /// T and ∂T/∂s of form `form` with the family's parameters `p` (indexed as
    /// [`TermFamily::params`]) at accumulated plastic slip `s` [mm] and time `t` [s].
    fn term(&self, form: usize, p: &[f64; MAX_TERM_PARAMS], s: f64, t: f64) -> (f64, f64);
}

/// The registered family called `name`, with its index in [`FAMILIES`].
pub fn family_named(name: &str) -> Option<(u8, &'static dyn TermFamily)> {
    FAMILIES
        .iter()
        .enumerate()
        .find(|(_, f)| f.name() == name)
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
    /// Index in the family's [`TermFamily::forms`].
    pub form: u8,
    /// The family's parameters, indexed as [`TermFamily::params`] (unused ones at their
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
        let params = self.family().params();
        self.form()
            .params
            .iter()
            .map(|&i| (&params[i], self.p[i]))
            .filter(|(q, v)| !q.valid(*v))
            .map(|(q, v)| (q.key, v, q.expected))
            .collect()
    }
}

// In a parameter file: {"family": "time-trend", "form": "linear", "c": 1e-5} — the form's
// parameters by name. Only the form's parameters are written, so a parameter of another form
// read from a file is not written back and the reader refuses it as unknown.
impl Serialize for TermEffect {
    fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let params = self.family().params();
        let form = self.form();
        let mut map = ser.serialize_map(Some(2 + form.params.len()))?;
        map.serialize_entry("family", self.family().name())?;
        map.serialize_entry("form", form.key)?;
        for &i in form.params {
            map.serialize_entry(params[i].name, &self.p[i])?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for TermEffect {
    fn deserialize<D: Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        let map = serde_json::Map::<String, serde_json::Value>::deserialize(de)?;
        let name = map
            .get("family")
            .and_then(|v| v.as_str())
            .ok_or_else(|| D::Error::custom("missing field `family` (a registered family)"))?;
        let registered = || {
            FAMILIES
                .iter()
                .map(|f| f.name())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (index, fam) = family_named(name).ok_or_else(|| {
            D::Error::custom(format!(
                "unknown family `{name}` (expected one of: {})",
                registered()
            ))
        })?;
        let form = match map.get("form") {
            None => 0,
            Some(v) => {
                let key = v.as_str().unwrap_or_default();
                fam.forms()
                    .iter()
                    .position(|f| f.key == key)
                    .ok_or_else(|| {
                        D::Error::custom(format!(
                            "unknown form {v} of `{name}` (expected one of: {})",
                            fam.forms()
                                .iter()
                                .map(|f| f.key)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ))
                    })?
            }
        };
        let mut e = TermEffect::new(index, form as u8);
        for (i, q) in fam.params().iter().enumerate() {
            if let Some(v) = map.get(q.name) {
                e.p[i] = v.as_f64().ok_or_else(|| {
                    D::Error::custom(format!("`{}` is {v} (expected a number)", q.key))
                })?;
            }
        }
        Ok(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_family_is_consistent() {
        let mut names = Vec::new();
        for (index, fam) in FAMILIES.iter().enumerate() {
            assert!(!names.contains(&fam.name()), "{} twice", fam.name());
            names.push(fam.name());
            assert!(fam.params().len() <= MAX_TERM_PARAMS, "{}", fam.name());
            assert!(!fam.forms().is_empty() && !fam.shows().is_empty());
            for q in fam.params() {
                let (lo, hi) = q.bounds;
                assert!(lo < hi && q.valid(lo) && q.valid(hi), "{}", q.key);
                assert!(q.key.ends_with(q.name), "{}", q.key);
            }
            let scales = DataScales {
                v_ref: 0.01,
                p_ref: 100.0,
                slip_span_mm: 5.0,
                duration_s: 600.0,
                holds: 1,
                reversals: 1,
                pressure_levels: 2,
                sliding_rates: 2,
            };
            for (k, form) in fam.forms().iter().enumerate() {
                let g = fam.guess(k, &scales);
                assert!(!g.starts.is_empty());
                for v in g.starts.iter().chain([&g.neutral]) {
                    assert_eq!(v.len(), form.params.len(), "{}", form.key);
                }
                // The neutral values switch the term off everywhere.
                let mut e = TermEffect::new(index as u8, k as u8);
                for (&i, &v) in form.params.iter().zip(&g.neutral) {
                    e.p[i] = v;
                }
                for (s, t) in [(0.0, 0.0), (3.0, 100.0), (10.0, 1e4)] {
                    assert_eq!(fam.term(k, &e.p, s, t).0, 0.0, "{}", form.key);
                }
            }
        }
    }

    #[test]
    fn a_term_reads_back_what_it_writes_and_refuses_an_unknown_family() {
        for (index, fam) in FAMILIES.iter().enumerate() {
            for k in 0..fam.forms().len() {
                let mut e = TermEffect::new(index as u8, k as u8);
                for (i, q) in fam.params().iter().enumerate() {
                    // A valid value away from the default, so a lost field shows.
                    e.p[i] = 0.5 * (q.bounds.0 + q.bounds.1) + 0.25 * (q.bounds.1 - q.bounds.0);
                }
                let text = serde_json::to_string(&e).unwrap();
                let back: TermEffect = serde_json::from_str(&text).unwrap();
                for &i in fam.forms()[k].params {
                    assert_eq!(back.p[i], e.p[i], "{text}");
                }
                assert_eq!((back.family, back.form), (e.family, e.form), "{text}");
            }
        }
        let err = serde_json::from_str::<TermEffect>(r#"{"family": "no-such-family"}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("unknown family `no-such-family`"), "{err}");
        assert!(serde_json::from_str::<TermEffect>(r#"{"form": "linear"}"#).is_err());
    }
}
