//! The parts of an effect family, one trait each, so that each says what one kind of caller
//! needs: the law the integrator runs ([`TermLaw`]), the parameter files' format
//! ([`TermFile`]), the first guesses ([`TermGuess`]) and the diagnosis's rules
//! ([`TermEvidence`]). [`TermFamily`] is all four; the registry lists families as
//! `&dyn TermFamily`, and a caller holding one calls any part's methods on it.

use super::{
    DataScales, EventReadings, FormGuess, RateEffect, Shows, TermForm, TermParam, MAX_TERM_PARAMS,
};
use crate::Target;

/// An effect family, registered in [`FAMILIES`](super::FAMILIES) (see the module
/// documentation): its law ([`TermLaw`]), how parameter files name it ([`TermFile`]), its first
/// guesses ([`TermGuess`]) and the diagnosis's rules for it ([`TermEvidence`]). A family's
/// folder implements each part in its own `impl` block; this trait follows.
pub trait TermFamily: TermLaw + TermFile + TermGuess + TermEvidence {}

impl<T: TermLaw + TermFile + TermGuess + TermEvidence> TermFamily for T {}

/// The law of an effect family: what the integrator (1-D, 3-D, the C interface) needs to know
/// of it — its name, parameters and forms, the term T(s, t) it adds and its slope in s, the
/// factor it puts on μ, μ_s, μ_k, κ or ũ and its range, what it reads of the contact (normal
/// stress, sliding direction, slip rate), whether it gains friction at rest, and which
/// parameter values are valid. A family with a state also implements
/// [`StateFamily`](super::StateFamily).
pub trait TermLaw: Sync + std::fmt::Debug {
    /// Name in verdicts (kebab-case, e.g. `time-trend`); in snake_case it is the family's key
    /// in parameter files ([`TermFile::key`]).
    fn name(&self) -> &'static str;
    /// One-line physical description.
    fn describe(&self) -> &'static str;
    /// Every parameter of the family.
    fn params(&self) -> &'static [TermParam];
    /// The forms; the first is the one a parameter set on its own switches on.
    fn forms(&self) -> &'static [TermForm];
    /// Whether every form's T depends on the accumulated slip alone, vanishes at s = 0 and is
    /// monotone in s (in the direction of its slope at s = 0). A record that starts mid-run is
    /// then placed at the slip whose T gives the friction the record shows.
    fn monotone_in_slip(&self) -> bool {
        false
    }
    /// T and ∂T/∂s of form `form` with the family's parameters `p` (indexed as
    /// [`TermLaw::params`]) at accumulated plastic slip `s` [mm] and time `t` [s]; zero for
    /// a family that only scales ([`TermLaw::adds_term`] false).
    fn term(&self, _form: usize, _p: &[f64; MAX_TERM_PARAMS], _s: f64, _t: f64) -> (f64, f64) {
        (0.0, 0.0)
    }
    /// Whether the family adds a term T (every form); false for one that only scales.
    fn adds_term(&self) -> bool {
        true
    }
    /// Whether the family reads the normal stress (the 3-D contact's tangent in p then takes
    /// its factor's change with p into account).
    fn reads_normal_stress(&self) -> bool {
        false
    }
    /// What form `form` scales: μ as a whole ([`Target::Friction`]), μ_s, μ_k, κ or ũ, or μ_s
    /// and μ_k each by its own size ([`Target::Bounds`]); none for a family of terms.
    fn targets(&self, _form: usize) -> &'static [Target] {
        &[]
    }
    /// The factor form `form` puts on `target` (one of μ as a whole, μ_s, μ_k, κ, ũ) of a
    /// contact at normal stress `normal_kpa` sliding in a direction whose cosine with the
    /// forward axis is `cos_forward` (±1 in 1-D); 1 where it does not act.
    fn factor_on(
        &self,
        _form: usize,
        _p: &[f64; MAX_TERM_PARAMS],
        _target: Target,
        _normal_kpa: f64,
        _cos_forward: f64,
    ) -> f64 {
        1.0
    }
    /// The least and greatest factor of [`TermLaw::factor_on`] on `target` over every
    /// condition (infinite where unbounded).
    fn range_on(&self, _form: usize, _p: &[f64; MAX_TERM_PARAMS], _target: Target) -> (f64, f64) {
        (1.0, 1.0)
    }
    /// Whether the family reads the sliding direction (a 3-D contact then needs its forward
    /// axis).
    fn reads_direction(&self) -> bool {
        false
    }
    /// (key, value, expected) of every invalid parameter of form `form`: by default each
    /// parameter the form uses, against [`TermParam::valid`].
    fn issues(
        &self,
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
    ) -> Vec<(&'static str, f64, &'static str)> {
        let params = self.params();
        self.forms()[form]
            .params
            .iter()
            .map(|&i| (&params[i], p[i]))
            .filter(|(q, v)| !q.valid(*v))
            .map(|(q, v)| (q.key, v, q.expected))
            .collect()
    }
    /// Whether the family gains friction at rest as a law of the contact's age (the time since
    /// it last slid): time healing. At most one such family is on in a model.
    fn gains_at_rest(&self) -> bool {
        false
    }
    /// Whether form `form`'s gain at rest replaces the exponential recovery ξ(μ_s − μ) of
    /// Eq. (24) (which then acts neither at rest nor while sliding).
    fn replaces_recovery(&self, _form: usize) -> bool {
        false
    }
    /// Whether the family makes friction depend on the plastic slip rate (the return mapping
    /// then solves for it). At most one such family is on in a model.
    fn reads_slip_rate(&self) -> bool {
        false
    }
    /// The law of form `form` as the return mapping solves it, for a family that reads the
    /// slip rate ([`TermLaw::reads_slip_rate`]).
    fn slip_rate_law(&self, _form: usize, _p: &[f64; MAX_TERM_PARAMS]) -> Option<RateEffect> {
        None
    }
}

/// How parameter files name an effect family: its key in `ext`, other names, the fields that
/// name its form, and what older files wrote. Every method has a default; a family whose files
/// have always been written otherwise overrides them.
pub trait TermFile: TermLaw {
    /// Other names a user or an older file may give the family (e.g. `slip-softening`).
    fn aliases(&self) -> &'static [&'static str] {
        &[]
    }
    /// The family's key in the `ext` object of parameter files: its name in snake_case.
    fn key(&self) -> String {
        self.name().replace('-', "_")
    }
    /// The field of a parameter file that names the form (`form`, unless the family's files
    /// have always named it otherwise).
    fn form_field(&self) -> &'static str {
        "form"
    }
    /// The form an object of a parameter file names (the family's first when it names none).
    /// A family whose files name the form by more than one field reads them here.
    fn read_form(&self, obj: &serde_json::Map<String, serde_json::Value>) -> Result<usize, String> {
        let Some(v) = obj.get(self.form_field()) else {
            return Ok(0);
        };
        let key = v.as_str().unwrap_or_default();
        self.forms()
            .iter()
            .position(|f| f.key == key)
            .ok_or_else(|| {
                format!(
                    "unknown {} {v} of `{}` (expected one of: {})",
                    self.form_field(),
                    self.name(),
                    self.forms()
                        .iter()
                        .map(|f| f.key)
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })
    }
    /// The fields that name form `form` in a parameter file, as [`TermFile::read_form`]
    /// reads them.
    fn form_fields(&self, form: usize) -> Vec<(&'static str, serde_json::Value)> {
        vec![(self.form_field(), self.forms()[form].key.into())]
    }
    /// Whether older files wrote every parameter of the family whatever the form, so that one
    /// the form does not use is read and dropped whatever its value (otherwise it is accepted
    /// only at its default).
    fn older_files_wrote_every_param(&self) -> bool {
        false
    }
}

/// First guesses of an effect family's forms, read off the scales of a data set (and what the
/// events read one by one give, where they were read).
pub trait TermGuess: TermLaw {
    /// First guesses and bounds of form `form` for data of these scales.
    fn guess(&self, form: usize, data: &DataScales) -> FormGuess;
}

/// The diagnosis's rules for an effect family: where its effect shows, whether the diagnosis
/// tries it (and which forms), whether data of given scales can say anything of it and tell it
/// from others, and what the events read one by one say for it, against it or show outright.
pub trait TermEvidence: TermLaw {
    /// Where its effect shows.
    fn shows(&self) -> &'static [Shows];
    /// Whether the diagnosis tries it unless asked not to. A family that data of the usual
    /// kinds cannot tell from an artifact (a drift of the measurement, say) is tried only when
    /// the user names it.
    fn tried_by_default(&self) -> bool;
    /// Whether data of these scales can say anything about the family.
    fn applies(&self, data: &DataScales) -> bool;
    /// Whether the variable the family acts through varies in data of these scales, so that
    /// the family can be told from others there and named (two sliding rates or more for
    /// rate, holds for healing, reversals for direction, two normal stresses for pressure).
    /// A family that applies but whose variable does not vary (a rate-and-state law on the
    /// holds of a record slid at one rate) may be fitted and weighed as an alternative, never
    /// named. By default: wherever it applies.
    fn varies(&self, data: &DataScales) -> bool {
        self.applies(data)
    }
    /// Whether the diagnosis tries form `form` (a family may read forms from files that the
    /// diagnosis leaves to the user).
    fn tries(&self, _form: usize) -> bool {
        true
    }
    /// Whether what the events read one by one leaves room for the family (true where they
    /// say nothing of it).
    fn corroborated(&self, _events: &EventReadings) -> bool {
        true
    }
    /// Whether the events read one by one speak against the family outright (velocity steps
    /// read, and not one shows a direct effect), a stronger reading than not corroborating it:
    /// a first effect that explains only a typical piece's share of the misfit, not most of its
    /// excess, is not named against it. False where they say nothing of it.
    fn contradicted(&self, _events: &EventReadings) -> bool {
        false
    }
    /// Whether the events read one by one show the family's effect outright, as a measurement
    /// across events (for pressure: the tests' peak or residual stress ratio changing with the
    /// normal stress beyond its interval). The held-out pieces weigh such an effect coarsely —
    /// each normal stress is one piece, predicted from the others, so three stresses give three
    /// pieces and a smooth misfit few independent rows in each — and a family shown this way is
    /// named when its candidate predicts every held-out piece of its kind better and explains
    /// enough, whatever its held-out evidence D. False where they do not.
    fn shown(&self, _events: &EventReadings) -> bool {
        false
    }
    /// Whether the family's term in form `form` with parameters `p` moves what the events read
    /// one by one show moving, the way they show it (for pressure: the peak or the residual
    /// read changing with the normal stress, and the form changing μ_s or μ_k with the same
    /// sign): a family shown outright is credited on those readings only through a law that
    /// follows them. True where the family reads nothing of the kind.
    fn follows_readings(
        &self,
        _form: usize,
        _p: &[f64; MAX_TERM_PARAMS],
        _events: &EventReadings,
    ) -> bool {
        true
    }
    /// Where the events that show the family outright ([`TermEvidence::shown`]) were read: the
    /// held-out pieces a candidate shown that way must each predict better. By default where
    /// its effect shows ([`TermEvidence::shows`]).
    fn shown_in(&self) -> &'static [Shows] {
        self.shows()
    }
    /// Forms the events read one by one single out: the diagnosis refits them in later stages
    /// whatever their rank on the base (on which a form may rank low for want of another
    /// effect).
    fn singled_out(&self, _events: &EventReadings) -> Vec<usize> {
        Vec::new()
    }
}

impl dyn TermFamily {
    /// Indices into [`TermLaw::params`] of the parameters of form `form` that a fit frees
    /// (its references left out), in order: what [`FormGuess`] starts and bounds index.
    pub fn fitted(&self, form: usize) -> Vec<usize> {
        self.forms()[form]
            .params
            .iter()
            .copied()
            .filter(|&i| !self.params()[i].reference)
            .collect()
    }
}
