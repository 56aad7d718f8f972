//! What a diagnosis reports: the types of `diagnosis.json`.

use crate::candidates::Effect;
use crate::evidence::ResidualEvidence;
use crate::features::DataFeatures;
use crate::score::Comparison;
use crate::verdict::{Decision, Thresholds};
use serde::Serialize;
use std::collections::BTreeMap;
use subfric_fit::localise::{GroupMisfit, Localisation};
use subfric_fit::TestMisfit;
use subfric_model::Model;
use subfric_reading::Stiffness;

/// One form fitted to all data.
#[derive(Clone, Debug, Serialize)]
pub struct FormReport {
    /// Family.
    pub effect: Effect,
    /// Form.
    pub form: String,
    /// SpecFit extra parameters.
    pub parameters: BTreeMap<String, f64>,
    /// In-sample SSR (noise units, fitted rows, with the weights it was fitted with).
    pub ssr: f64,
    /// In-sample evidence over the base, piece by piece like the held-out score, less
    /// ln(n_eff) per extra parameter (a BIC on the effective number of observations).
    pub in_sample_score: f64,
    /// The fit converged (a form that did not is reported, and only chosen if it still wins).
    pub converged: bool,
    /// Stopped by its iteration limit, but continued from there its SSR fell by less than one
    /// noise variance: judged like a converged form.
    pub settled: bool,
    /// How the best local run stopped (why not, when it did not converge).
    pub termination: subfric_fit::Termination,
    /// Polished on the base (to convergence, on all rows); a form that was not stays at its
    /// screening fit (a few iterations on a share of the rows), ranked behind its family's
    /// polished forms and never compared on held-out data.
    pub polished: bool,
    /// Polished, and every parameter of the form ended at the value that switches the effect
    /// off: on the base the fit wants none of it (an amplitude held at its bound of zero).
    pub switched_off: bool,
    /// The best form of its family (the one compared on held-out data).
    pub chosen: bool,
    /// The fitted model.
    pub model: Model,
}

impl FormReport {
    /// Its fit is finite and converged, or settled: its score says what the form can do, not
    /// where an iteration limit stopped it (the same test as `SpecFit::judged` on a fit).
    pub fn judged(&self) -> bool {
        self.ssr.is_finite() && (self.converged || self.settled)
    }
}

/// A candidate (the best form of a family, or the drift) against a reference model.
#[derive(Clone, Debug, Serialize)]
pub struct CandidateScore {
    /// Family (`unexplained` for the drift alternative).
    pub effect: Effect,
    /// The model compared, in words.
    pub spec: String,
    /// SpecFit extra parameters.
    pub extra_parameters: BTreeMap<String, f64>,
    /// The fitted model.
    pub model: Model,
    /// Held-out comparison with the reference.
    pub held_out: Comparison,
    /// The same comparison on the pieces predicted between readings of their like: those
    /// predicted beyond every training piece of their kind ([`crate::folds::Piece::beyond_training`])
    /// left out; `None` where no piece is.
    pub held_out_within: Option<Comparison>,
    /// Fraction of the held-out excess removed (= `held_out.excess_shrink`), for scripts.
    pub held_out_shrink: f64,
    /// Shrink per kind of piece: (kind, reference χ², candidate χ²).
    pub by_kind: Vec<KindShrink>,
    /// The comparison on the held-out pieces of each kind the family acts on
    /// ([`crate::Effect::own_kinds`]), on which an effect is credited when the other pieces do
    /// not improve.
    pub own_kinds: Vec<OwnKindScore>,
    /// The comparison on the held-out pieces of each kind where the events that show the
    /// family outright were read ([`crate::Effect::shown_kinds`]; the same kinds as
    /// `own_kinds` unless the family reads its effect elsewhere: slip hardening on the tests'
    /// first loadings).
    pub shown_in: Vec<OwnKindScore>,
    /// Held-out evidence at the level of whole tests on the pieces of `shown_in`, against the
    /// scatter between specimens ([`crate::score::between_tests`]).
    pub between_tests: f64,
    /// The share of the held-out tests' level misfit on the pieces of `shown_in`, against the
    /// scatter between specimens, that the candidate removes
    /// ([`crate::score::TestLevels::shrink`]).
    pub between_tests_shrink: f64,
    /// Held-out evidence D with the first loadings left out (0 where every piece is one).
    pub without_first_loadings: f64,
}

/// A candidate against the reference on the held-out pieces of one kind its family acts on.
#[derive(Clone, Debug, Serialize)]
pub struct OwnKindScore {
    /// The kind.
    pub kind: crate::candidates::OwnKind,
    /// The comparison on those pieces.
    pub held_out: Comparison,
    /// The comparison on those of them predicted between readings of their like, where some
    /// are predicted beyond them ([`crate::folds::Piece::beyond_training`]) and some not;
    /// `None` otherwise.
    pub within: Option<Comparison>,
}

impl OwnKindScore {
    /// The comparison the kind is judged on: between readings of its like where it has
    /// pieces there and beyond ([`OwnKindScore::within`]), else on all its pieces.
    pub fn judged(&self) -> &Comparison {
        self.within.as_ref().unwrap_or(&self.held_out)
    }
}

impl CandidateScore {
    /// The comparison over all pieces a candidate is judged on where the events show its
    /// family: the pieces predicted beyond every reading of their like left out
    /// ([`CandidateScore::held_out_within`]).
    pub fn judged_within(&self) -> &Comparison {
        self.held_out_within.as_ref().unwrap_or(&self.held_out)
    }
}

impl CandidateScore {
    /// The comparison on the own kind with most evidence among those that pass `th`, else on
    /// the own kind with most evidence; `None` for a family without own kinds.
    pub fn best_own_kind(&self, th: &crate::verdict::Thresholds) -> Option<&Comparison> {
        best_kind(self.own_kinds.iter(), th)
    }
}

/// Of the comparisons on `kinds`, the one with most evidence among those that pass `th`, else
/// the one with most evidence; `None` of no kinds.
pub fn best_kind<'a>(
    kinds: impl Iterator<Item = &'a OwnKindScore> + Clone,
    th: &crate::verdict::Thresholds,
) -> Option<&'a Comparison> {
    let by_score = |a: &&Comparison, b: &&Comparison| a.score.total_cmp(&b.score);
    let comparisons = kinds.map(|k| &k.held_out);
    comparisons
        .clone()
        .filter(|c| crate::verdict::passes(c, th))
        .max_by(by_score)
        .or_else(|| comparisons.max_by(by_score))
}

/// Held-out misfit of the reference and a candidate on one kind of piece.
#[derive(Clone, Debug, Serialize)]
pub struct KindShrink {
    /// Kind of piece.
    pub kind: String,
    /// Held-out rows.
    pub rows: usize,
    /// Reference RMS / noise.
    pub reference_rms_over_noise: f64,
    /// Candidate RMS / noise.
    pub candidate_rms_over_noise: f64,
    /// Reference mean square / noise variance (the square of `reference_rms_over_noise`).
    pub reference_chi2: f64,
    /// Candidate mean square / noise variance.
    pub candidate_chi2: f64,
    /// Fraction of the reference's SSR removed.
    pub shrink: f64,
}

/// One stage of the forward selection.
#[derive(Clone, Debug, Serialize)]
pub struct SelectionStage {
    /// The model every candidate is added to.
    pub reference: String,
    /// Held-out reduced χ² of the reference.
    pub reference_chi2: f64,
    /// Each family added to it.
    pub candidates: Vec<CandidateScore>,
    /// The drift alternative (first stage only).
    pub drift: Option<CandidateScore>,
    /// What was decided.
    pub decision: Decision,
}

/// An effect the forward selection took that the backward step dropped: the effects named
/// after it explain the gap without it.
#[derive(Clone, Debug, Serialize)]
pub struct DroppedEffect {
    /// Family.
    pub effect: Effect,
    /// Form.
    pub form: String,
    /// Held-out evidence D of the final model with it over the final model without it (below
    /// the verdict's `min_score`).
    pub score_given_the_others: f64,
}

/// An effect the diagnosis names.
#[derive(Clone, Debug, Serialize)]
pub struct NamedEffect {
    /// Family.
    pub effect: Effect,
    /// Best form.
    pub form: String,
    /// SpecFit parameters of the form.
    pub parameters: BTreeMap<String, f64>,
    /// Fraction of the held-out excess misfit (over the noise) of the model before it that it
    /// removes (with several effects named: of the final model without it).
    pub held_out_shrink: f64,
    /// Fraction of the held-out misfit of the model before it that it removes.
    pub relative_shrink: f64,
    /// How much the misfit of a typical held-out piece falls.
    pub typical_shrink: f64,
    /// Held-out evidence D (deviance units).
    pub score: f64,
    /// Extra checks: shrink on the tail of each test, and on each test left out.
    pub tail_shrink: Option<f64>,
    /// Shrink with each test left out in turn (an effect seen in one test cannot be learned
    /// without it).
    pub leave_one_test_out_shrink: Option<f64>,
    /// The events read one by one show the effect outright
    /// ([`subfric_model::terms::TermEvidence::shown`]: for pressure, the tests' stress ratios
    /// changing with the normal stress beyond their intervals).
    pub shown_by_events: bool,
}

/// The answer for scripts.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// The first effect named, or `none`, or `unexplained`.
    pub effect: Effect,
    /// Held-out shrink of that effect (0 for none/unexplained).
    pub held_out_shrink: f64,
    /// Every named effect, in the order named.
    pub effects: Vec<NamedEffect>,
    /// Plain-language reason.
    pub explanation: String,
    /// SpecFit extra parameters of the first effect.
    pub extra_parameters: BTreeMap<String, f64>,
    /// Held-out misfit with every named effect, reduced χ² in noise units: how far from the
    /// noise the final model still is.
    pub final_chi2: f64,
    /// Whether the residual evidence supports the first family named.
    pub evidence_supports: Option<bool>,
    /// The probability that the named effects are exactly right ([`crate::confidence`]); `None`
    /// when nothing was judged.
    pub confidence: Option<f64>,
    /// Other verdicts the data allow, likeliest first, with their probabilities and the test
    /// that would tell each from this one.
    pub alternatives: Vec<crate::confidence::Alternative>,
    /// What each stage of the selection weighed (evidence, misfit and probability of each
    /// option), from which `confidence` and `alternatives` follow.
    pub weighed: Vec<crate::confidence::StageWeighing>,
    /// The verdict the held-out evidence points to with the first loadings left out (each
    /// stage's best candidate by its evidence on the other pieces, named at D ≥ `min_score`);
    /// `None` when nothing was judged or no piece but first loadings was held out.
    pub without_first_loadings: Option<Vec<Effect>>,
}

impl Verdict {
    /// The effects the verdict names: empty for none, `[unexplained]` for a gap no candidate
    /// explains (and for cannot-judge, which names nothing either).
    pub fn named(&self) -> Vec<Effect> {
        match self.effect {
            Effect::None | Effect::CannotJudge => Vec::new(),
            Effect::Unexplained if self.effects.is_empty() => vec![Effect::Unexplained],
            _ => self.effects.iter().map(|e| e.effect).collect(),
        }
    }

    /// How the verdict stands (confident, probable, uncertain) by its confidence; `None` when
    /// nothing was judged.
    pub fn standing(&self) -> Option<crate::confidence::Standing> {
        self.confidence.map(crate::confidence::Standing::of)
    }

    /// "confident (…)" or "uncertain between …" (see [`crate::confidence::Certainty::sentence`]);
    /// `None` when nothing was judged.
    pub fn certainty_sentence(&self) -> Option<String> {
        let confidence = self.confidence?;
        let c = crate::confidence::Certainty {
            confidence,
            alternatives: self.alternatives.clone(),
            stages: Vec::new(),
        };
        Some(c.sentence(&crate::confidence::label(&self.named())))
    }
}

/// The base model's fit.
#[derive(Clone, Debug, Serialize)]
pub struct BaseFit {
    /// SpecFit model.
    pub model: Model,
    /// Free parameters.
    pub free: Vec<String>,
    /// SSR on the fitted rows (noise units).
    pub ssr: f64,
    /// Rows of the record.
    pub rows: usize,
    /// Rows fitted (bins of a thinned record).
    pub fitted_rows: usize,
    /// Reduced χ² on all rows.
    pub reduced_chi2: f64,
    /// Per-test misfit on all rows.
    pub tests: Vec<TestMisfit>,
    /// μ_s and μ_k beside the peak and residual stress ratios the record shows, and whether
    /// the base model keeps them.
    pub read_off: Vec<subfric_reading::ReadOff>,
    /// Coordinates of the base fit that ended at a bound of their box: the candidates are
    /// judged against a base the box stopped, which the report says.
    pub at_bounds: Vec<subfric_fit::AtBound>,
    /// How this base is fitted unlike `subfric fit` with its defaults on the same data, each
    /// a sentence: why the two commands' parameters can differ.
    pub unlike_fit: Vec<String>,
}

/// How each test starts.
#[derive(Clone, Debug, Serialize)]
pub struct TestStart {
    /// Test.
    pub test: String,
    /// The state.
    pub start: subfric_reading::StartKind,
    /// From `experiment.json`, or decided from the data.
    pub from_spec: bool,
    /// Why.
    pub reason: String,
    /// Noise SD of the measured column, and whether it is only a quantisation floor.
    pub noise_sd: f64,
    /// Noise is a floor.
    pub noise_floor: bool,
    /// A seating toe excluded from the start of the record (a rig artifact, not friction).
    pub seating_toe: Option<subfric_reading::SeatingToe>,
    /// Why the normal-stress column was held at its levels (its scatter the reading's, not
    /// followed by the shear), when it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal_held: Option<String>,
}

/// A complete diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    /// The verdict (first, for scripts).
    pub verdict: Verdict,
    /// Base fit.
    pub base: BaseFit,
    /// What the data contain.
    pub data: DataFeatures,
    /// Starts and noise of each test.
    pub starts: Vec<TestStart>,
    /// The elastic stiffness, when the data resolve it (then α_t is fitted).
    pub stiffness: Option<Stiffness>,
    /// The closures of the rig on first loading taken out of the travel (bedding), per test
    /// that showed one ([`subfric_fit::bedding`]).
    pub bedding: Vec<subfric_fit::Bedding>,
    /// The tests as diagnosed: prepared as given, with any bedding taken out of their travel
    /// (what the figures of the diagnosis draw).
    #[serde(skip)]
    pub prepared: Vec<subfric_reading::PreparedTest>,
    /// Where the base residual lies (all rows).
    pub localisation: Localisation,
    /// Every velocity step, hold and reversal read on its own, and what they say together.
    pub events: crate::events::EventAnalysis,
    /// Every form fitted to all data.
    pub forms: Vec<FormReport>,
    /// The best form of each family against the base, and the drift alternative.
    pub candidates: Vec<CandidateScore>,
    /// The forward selection, stage by stage.
    pub selection: Vec<SelectionStage>,
    /// Effects the forward selection took and the backward step dropped.
    pub dropped: Vec<DroppedEffect>,
    /// What the base model's held-out residual follows.
    pub evidence: ResidualEvidence,
    /// Where the residual lies with every named effect (all rows).
    pub remaining_by_segment: Vec<GroupMisfit>,
    /// The model with every named effect.
    pub final_model: Model,
    /// The final model's μ_s and μ_k beside the measured peak and residual.
    pub final_read_off: Vec<subfric_reading::ReadOff>,
    /// Held-out folds used.
    pub folds: Vec<String>,
    /// Pieces per kind.
    pub pieces: BTreeMap<String, usize>,
    /// Thresholds used.
    pub thresholds: Thresholds,
    /// Candidate forms left out on request.
    pub excluded_forms: Vec<String>,
    /// Registered families tried on request beyond the default library.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub with_families: Vec<String>,
    /// Wall time [s].
    pub elapsed_s: f64,
}
