//! Each velocity step fitted on its own, as friction labs read a record: a window from the
//! steady sliding before the step to the end of the new rate, a linear trend in load-point
//! travel read off the sliding before the step and removed (the detrend window of xlook and of
//! the steadystate routine), then a spring-slider with rate and state ([`super::slider`]) in the
//! better of the ageing and slip laws, the spring stiffness fitted when the record resolves it.
//! The trend is not fitted with a, b and D_c: over the new rate a free trend trades against
//! a − b (a slow wander of the record after the transient reads as either), so the record
//! before the step decides it, and its uncertainty is carried into a, b and D_c. The null
//! model has no direct effect: a smooth change of level over a slip distance, which is all the
//! base model can do at a velocity step.

mod fitting;
mod null;
mod readings;
mod rows;

use super::slider::StateLaw;
use super::Estimate;
use rows::dc_floor_for;
use serde::Serialize;

pub(super) use fitting::fit_step;
pub(super) use rows::window;

/// One velocity step fitted on its own.
#[derive(Clone, Debug, Serialize)]
pub struct StepFit {
    /// Test.
    pub test: String,
    /// Row of the record where the step happens (last row at the old rate).
    pub row: usize,
    /// Time of the step [s].
    pub time_s: f64,
    /// Load-point rate before and after [mm/s].
    pub rate_before: f64,
    /// Rate after [mm/s].
    pub rate_after: f64,
    /// Rows of the window fitted.
    pub rows: usize,
    /// The state law that fits it better.
    pub law: StateLaw,
    /// Direct effect a (95 % interval).
    pub a: Estimate,
    /// Evolution effect b.
    pub b: Estimate,
    /// Characteristic slip D_c [mm].
    pub d_c_mm: Estimate,
    /// a − b: the change of steady friction per e-fold of rate.
    pub a_minus_b: Estimate,
    /// Spring stiffness [friction per mm] (infinite: the record does not resolve a compliance).
    pub stiffness_per_mm: f64,
    /// Normal stress of the window [kPa] (median), which turns the stiffness into kPa/mm.
    pub normal_kpa: f64,
    /// Slope of the linear trend removed, read off the sliding before the step [friction per
    /// mm of travel].
    pub trend_per_mm: f64,
    /// RMS misfit of the fit over the noise.
    pub rms_over_noise: f64,
    /// Evidence for a direct effect: (SSR of the null model − SSR of the rate-and-state fit)
    /// over the fit's variance scale (deviance units, like the diagnosis's D).
    pub evidence: f64,
    /// The change of steady friction measured on the record: the mean over the last 20 % of
    /// the new rate minus what the trend before the step extrapolates to at that time.
    pub measured_steady_change: Estimate,
    /// Whether the sign of (a − b) ln(v₁/v₀) agrees with the measured change, where that change
    /// exceeds its 95 % uncertainty and the fit determines a − b (a direct effect shown, the
    /// interval of a − b clear of zero); `None` elsewhere.
    pub sign_agrees: Option<bool>,
    /// The measured change of steady friction exceeds its 95 % uncertainty.
    pub steady_change_measured: bool,
    /// The least-squares runs converged.
    pub converged: bool,
    /// The load-point travel between two rows after the step (median) [mm].
    pub row_travel_mm: f64,
    /// The slip over which the best fit without a direct effect (the null model behind
    /// `evidence`) moves friction to its new level [mm].
    pub null_length_mm: f64,
}

impl StepFit {
    /// Whether (a − b) ln(v₁/v₀), by its value, has the sign of the measured change of steady
    /// friction (whether or not either is clear of zero).
    pub fn a_minus_b_agrees_with_measured_change(&self) -> bool {
        let ln = (self.rate_after / self.rate_before).ln();
        (self.a_minus_b.value * ln).signum() == self.measured_steady_change.value.signum()
    }

    /// A direct effect the record shows: strong evidence over the null model, and an a the
    /// step determines (its interval closed and within a factor of ten).
    pub fn significant(&self) -> bool {
        self.evidence >= super::STEP_EVIDENCE
            && self.a.lo > 0.0
            && self.a.hi.is_finite()
            && self.a.hi < 10.0 * self.a.lo
    }

    /// Whether the step can show a direct effect or its absence. Where either fit moves
    /// friction within a row — the best fit without a direct effect (an e-folding slip
    /// shorter than the travel between two rows), or the rate-and-state fit, its state
    /// relaxing within a row (D_c within twice the shortest the rows resolve: only a − b is
    /// read) — a jump of a ln(v₁/v₀) and an evolution that fast look the same, and the step
    /// counts neither way. A step that shows a direct effect resolves it.
    pub fn resolves_transient(&self) -> bool {
        self.significant()
            || (self.null_length_mm > self.row_travel_mm
                && self.d_c_mm.value > 2.0 * dc_floor_for(self.row_travel_mm))
    }
}

/// A velocity step's window in friction units: time, load-point travel from the step, rate.
pub(super) struct Window {
    pub time: Vec<f64>,
    pub travel: Vec<f64>,
    pub v_lp: Vec<f64>,
    pub mu: Vec<f64>,
    /// Index of the last row at the old rate.
    pub step: usize,
    pub v0: f64,
    pub v1: f64,
    /// Noise SD in friction.
    pub sigma: f64,
    /// Row of the record of the window's first row.
    pub first_row: usize,
    /// Median normal stress over the window [kPa].
    pub normal: f64,
}

// The names the tests read through `super::*` that only the submodules use.
#[cfg(test)]
use {super::slider::Slider, readings::measured_change};

#[cfg(test)]
#[path = "steps_tests.rs"]
mod tests;
