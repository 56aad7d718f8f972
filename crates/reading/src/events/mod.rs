//! Step-by-step evidence, as friction labs read a record before any global model (xlook,
//! RSFit3000, the steadystate routine): every velocity step fitted on its own with a
//! spring-slider and rate-and-state friction ([`steps`]), every hold read for its relaxation
//! and the peak on reloading ([`holds`]), every reversal for the change of steady friction
//! ([`reversals`]). Their consistency across events is evidence for a family, and their
//! values seed the global fits of its forms.

pub mod holds;
pub mod reversals;
pub mod slider;
pub mod steps;

use crate::features::EventSeeds;
use crate::stats::upper_median;
use crate::{PreparedTest, Stiffness};
use rayon::prelude::*;
use serde::Serialize;
use subfric_model::Control;

pub use holds::{HealingTrend, HoldHealing};
pub use reversals::{DirectionAsymmetry, ReversalChange};
pub use steps::StepFit;

/// Evidence D a velocity step's fit must reach over its null model (no direct effect) for the
/// step to show a direct effect.
pub const STEP_EVIDENCE: f64 = 20.0;

/// Largest ratio between the springs of the velocity steps that still counts as one machine.
pub const SPRING_AGREEMENT: f64 = 3.0;

pub use crate::Estimate;

/// What the per-event reading found, and what it says about each family.
#[derive(Clone, Debug, Default, Serialize)]
pub struct EventAnalysis {
    /// Every velocity step fitted on its own.
    pub steps: Vec<StepFit>,
    /// Every hold.
    pub holds: Vec<HoldHealing>,
    /// The healing rate across holds.
    pub healing: Option<HealingTrend>,
    /// Every reversal.
    pub reversals: Vec<ReversalChange>,
    /// Forward against backward sliding.
    pub direction: Option<DirectionAsymmetry>,
    /// The rate-and-state reading across steps.
    pub rate: Option<RateConsensus>,
    /// Every test's peak and residual stress ratio, and their change with the normal stress
    /// and with slip.
    pub levels: crate::LevelReadings,
}

/// What the velocity steps say together.
#[derive(Clone, Debug, Serialize)]
pub struct RateConsensus {
    /// Steps fitted.
    pub steps: usize,
    /// Steps that show a direct effect ([`StepFit::significant`]).
    pub significant: usize,
    /// Medians over the significant steps (over all steps when none is).
    pub a: f64,
    /// Median b.
    pub b: f64,
    /// Median D_c [mm].
    pub d_c_mm: f64,
    /// Steps whose measured change of steady friction is larger than its uncertainty.
    pub changes_measured: usize,
    /// Of those, how many have a fitted a − b (its value) of the sign of the change.
    pub changes_agree: usize,
    /// Steps whose measured change of steady friction is larger than its uncertainty and whose
    /// fit determines the sign of a − b.
    pub signs_checked: usize,
    /// Of those, how many agree.
    pub signs_agree: usize,
    /// Steps whose measured change exceeds its uncertainty but whose fit does not determine
    /// a − b (no direct effect shown, or a − b's interval spans zero): no sign is claimed.
    pub signs_undetermined: usize,
    /// Steps whose transient the rows resolve ([`StepFit::resolves_transient`]): the ones
    /// that can show a direct effect or its absence.
    pub resolved: usize,
    /// Most of the steps that resolve their transient (at least two, and two thirds) show a
    /// direct effect.
    pub consistent: bool,
}

/// One test as the event readings see it.
pub(crate) struct TestView<'a> {
    pub name: &'a str,
    pub time: &'a [f64],
    pub slip: &'a [f64],
    pub shear: &'a [f64],
    pub normal: &'a [f64],
    pub segmentation: &'a crate::Segmentation,
    /// Noise SD in friction units.
    pub noise_friction: f64,
}

impl TestView<'_> {
    /// Friction (shear / normal) of row `i`.
    pub fn friction(&self, i: usize) -> f64 {
        self.shear[i] / self.normal[i]
    }
}

fn view(p: &PreparedTest) -> Option<TestView<'_>> {
    let t = &p.full;
    if t.control != Control::Slip || t.len() < 20 {
        return None;
    }
    let mut normals: Vec<f64> = t.normal.clone();
    let typical = upper_median(&mut normals)?;
    if !(typical > 0.0 && t.noise_sd.is_finite() && t.noise_sd > 0.0) {
        return None;
    }
    Some(TestView {
        name: &t.name,
        time: &t.time,
        slip: &t.imposed,
        shear: &t.measured,
        normal: &t.normal,
        segmentation: &p.segmentation,
        noise_friction: t.noise_sd / typical,
    })
}

/// Reads every event of every slip-controlled test. `stiffness` is the set's elastic
/// stiffness when the record resolves it: the step fits then also try a spring of that
/// stiffness (in friction per mm at each test's normal stress).
pub fn analyse(prepared: &[PreparedTest], stiffness: Option<&Stiffness>) -> EventAnalysis {
    let views: Vec<TestView> = prepared.iter().filter_map(view).collect();
    let windows: Vec<(usize, steps::Window, Option<f64>)> = views
        .iter()
        .enumerate()
        .flat_map(|(i, v)| {
            let normal = v.normal[0];
            let k = stiffness
                .map(|s| s.alpha_t * subfric_model::params::KN_PER_MM3_IN_KPA_PER_MM / normal);
            v.segmentation
                .rate_changes
                .iter()
                .filter_map(move |&c| steps::window(v, c).map(|w| (i, w, k)))
                .collect::<Vec<_>>()
        })
        .collect();
    let step_fits: Vec<StepFit> = windows
        .par_iter()
        .filter_map(|(i, w, k)| steps::fit_step(views[*i].name, w, *k))
        .collect();
    let holds: Vec<HoldHealing> = views.iter().flat_map(holds::holds).collect();
    let reversal_changes: Vec<ReversalChange> =
        views.iter().flat_map(reversals::reversals).collect();
    EventAnalysis {
        levels: crate::read_levels(prepared),
        rate: consensus(&step_fits),
        healing: holds::healing_trend(&holds),
        direction: reversals::asymmetry(&reversal_changes),
        steps: step_fits,
        holds,
        reversals: reversal_changes,
    }
}

impl EventAnalysis {
    /// The series stiffness of machine and interface the velocity steps resolve: the median of
    /// the fitted springs over the steps that show a direct effect and needed a finite spring,
    /// when at least two did, at least half of those steps, and their springs agree within a
    /// factor of [`SPRING_AGREEMENT`] (one soft spring alone can stand in for another misfit).
    pub fn stiffness(&self) -> Option<Stiffness> {
        let shown: Vec<&StepFit> = self.steps.iter().filter(|s| s.significant()).collect();
        let mut springs: Vec<f64> = shown
            .iter()
            .filter(|s| s.stiffness_per_mm.is_finite())
            .map(|s| s.stiffness_per_mm * s.normal_kpa)
            .collect();
        if springs.len() < 2 || 2 * springs.len() < shown.len() {
            return None;
        }
        let (lo, hi) = springs
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
        if hi > SPRING_AGREEMENT * lo {
            return None;
        }
        let n = springs.len();
        let kpa_per_mm = upper_median(&mut springs).unwrap_or(f64::NAN);
        let alpha_t = kpa_per_mm / subfric_model::params::KN_PER_MM3_IN_KPA_PER_MM;
        Some(Stiffness {
            alpha_t,
            events: n,
            evidence: format!(
                "{n} velocity step{} fitted on {} own need{} a spring of about {kpa_per_mm:.4e} kPa/mm \
                 (α_t {alpha_t:.3e} kN/mm³): the slip column includes a machine compliance",
                if n == 1 { "" } else { "s" },
                if n == 1 { "its" } else { "their" },
                if n == 1 { "s" } else { "" },
            ),
        })
    }
}

impl EventAnalysis {
    /// What the events read say, for the registered families
    /// ([`subfric_model::terms::TermEvidence::corroborated`]).
    pub fn readings(&self) -> subfric_model::terms::EventReadings {
        let reading = |e: &Estimate| subfric_model::terms::Reading {
            value: e.value,
            lo: e.lo,
            hi: e.hi,
        };
        subfric_model::terms::EventReadings {
            backward_weakening: self
                .direction
                .as_ref()
                .map(|d| reading(&d.backward_weakening)),
            healing_per_decade: self.healing.as_ref().map(|h| reading(&h.per_decade)),
            holds_with_peak: self.holds.iter().filter(|h| h.peak_gain.lo > 0.0).count(),
            steps_agree_on_rate_and_state: self.rate.as_ref().map(|r| r.consistent),
            steps_read: self.rate.as_ref().map_or(0, |r| r.steps),
            steps_with_direct_effect: self.rate.as_ref().map_or(0, |r| r.significant),
            peak_change_per_efold: self
                .levels
                .peak
                .as_ref()
                .map(|t| reading(&t.relative_per_efold)),
            residual_change_per_efold: self
                .levels
                .residual
                .as_ref()
                .map(|t| reading(&t.relative_per_efold)),
            slip_change_relative: self.levels.slip_change_relative.as_ref().map(reading),
        }
    }
}

/// The steps' reading together.
fn consensus(steps: &[StepFit]) -> Option<RateConsensus> {
    if steps.is_empty() {
        return None;
    }
    let significant: Vec<&StepFit> = steps.iter().filter(|s| s.significant()).collect();
    let pool: Vec<&StepFit> = if significant.is_empty() {
        steps.iter().collect()
    } else {
        significant.clone()
    };
    let resolved = steps.iter().filter(|s| s.resolves_transient()).count();
    let checked: Vec<bool> = steps.iter().filter_map(|s| s.sign_agrees).collect();
    let measured: Vec<&StepFit> = steps.iter().filter(|s| s.steady_change_measured).collect();
    Some(RateConsensus {
        steps: steps.len(),
        significant: significant.len(),
        a: upper_median(&mut pool.iter().map(|s| s.a.value).collect::<Vec<_>>())
            .unwrap_or(f64::NAN),
        b: upper_median(&mut pool.iter().map(|s| s.b.value).collect::<Vec<_>>())
            .unwrap_or(f64::NAN),
        d_c_mm: upper_median(&mut pool.iter().map(|s| s.d_c_mm.value).collect::<Vec<_>>())
            .unwrap_or(f64::NAN),
        signs_checked: checked.len(),
        signs_agree: checked.iter().filter(|&&x| x).count(),
        changes_measured: measured.len(),
        changes_agree: measured
            .iter()
            .filter(|s| s.a_minus_b_agrees_with_measured_change())
            .count(),
        signs_undetermined: steps
            .iter()
            .filter(|s| s.steady_change_measured && s.sign_agrees.is_none())
            .count(),
        resolved,
        // A step too fast for its rows says nothing for or against a direct effect.
        consistent: significant.len() >= 2 && 3 * significant.len() >= 2 * resolved,
    })
}

impl EventAnalysis {
    /// The first guesses this analysis gives the global fits of the forms
    /// ([`crate::features::EventSeeds`]).
    pub fn seeds(&self) -> EventSeeds {
        let e = self;
        let finite = |v: f64| v.is_finite().then_some(v);
        EventSeeds {
            rate_and_state: e.rate.as_ref().and_then(|r| {
                (r.a.is_finite() && r.b.is_finite() && r.d_c_mm.is_finite())
                    .then_some((r.a, r.b, r.d_c_mm))
            }),
            healing_per_decade: e.healing.as_ref().and_then(|h| finite(h.per_decade.value)),
            backward_weakening: e
                .direction
                .as_ref()
                .and_then(|d| finite(d.backward_weakening.value)),
            // A reading within its uncertainty of zero is no guess (the generic starts hold
            // the neutral already): a start from it only moves the screening to another basin
            // (a hyperbolic slip hardening at its bound, standing in for the rise the model
            // lacks).
            stress_trend: (
                e.levels
                    .peak
                    .as_ref()
                    .filter(|t| t.changes())
                    .and_then(|t| finite(t.relative_per_efold.value)),
                e.levels
                    .residual
                    .as_ref()
                    .filter(|t| t.changes())
                    .and_then(|t| finite(t.relative_per_efold.value)),
            ),
            slip_slope_per_mm: e
                .levels
                .slip_slope_per_mm
                .filter(|s| s.excludes_zero())
                .and_then(|s| finite(s.value)),
            slip_to_peak_mm: upper_median(
                &mut e
                    .levels
                    .tests
                    .iter()
                    .filter_map(|t| t.slip_to_peak_mm)
                    .filter(|s| s.is_finite() && *s > 0.0)
                    .collect::<Vec<_>>(),
            ),
        }
    }
}
