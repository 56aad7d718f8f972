//! The implicit step of the subloading-friction model and its scalar return mapping.
//!
//! Over a step with a constant plastic slip rate both evolution laws integrate in closed form:
//! - Eqs. (27, 29): ṙ = ũ cot(πr/2) λ̇  ⇒  cos(πr/2) = cos(πr₀/2) · exp(−(π/2) ũ Δλ);
//! - Eq. (24): μ̇ = −κ(μ − μ_k) λ̇ + ξ(μ_s − μ)  ⇒  μ relaxes towards
//!   μ* = (κΔλ μ_k + ξΔt μ_s)/(κΔλ + ξΔt) as exp(−(κΔλ + ξΔt)).
//!
//! The consistency condition ‖f_t‖ = r μ f_n (Eqs. 21–22) with the elastic law f = Ē ū^e
//! (Eq. 15) then becomes one scalar equation in the plastic slip increment Δλ, solved by a
//! Newton iteration safeguarded by bisection. A step that does not converge returns an error
//! value so the caller can retry with substeps.

use crate::extensions::MIN_MU_EFF_FRACTION;
use crate::terms::StateSlots;
use std::f64::consts::FRAC_PI_2;

mod consts;
mod states;

use states::{NoState, StateStep, WithStates};

pub(crate) use consts::{Consts, Local};

/// Why one integration step failed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The return mapping did not converge (retry with substeps).
    #[error("return mapping did not converge after {iterations} iterations (residual {residual:.3e} kPa)")]
    NoConvergence {
        /// Iterations spent.
        iterations: usize,
        /// Last residual of the consistency condition [kPa].
        residual: f64,
    },
    /// Under traction control the imposed shear exceeds what friction can carry.
    #[error("imposed shear {target_kpa:.3} kPa exceeds the friction capacity {capacity_kpa:.3} kPa: runaway sliding")]
    Runaway {
        /// Imposed shear magnitude [kPa].
        target_kpa: f64,
        /// Largest shear the contact can carry in this step [kPa].
        capacity_kpa: f64,
    },
}

const MAX_ITERATIONS: usize = 80;

/// Tolerance of the slip-controlled return on the consistency condition, per kPa of normal
/// stress.
pub(crate) const RETURN_TOLERANCE: f64 = 1e-10;

/// What the scalar return needs to know about one step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepInput {
    /// μ at the start of the step.
    pub mu_n: f64,
    /// cos(π r₀ / 2) of the surface the step starts from.
    pub c_start: f64,
    /// sin(π r₀ / 2).
    pub s_start: f64,
    /// r₀ of the surface the step starts from.
    pub r_start: f64,
    /// Normal stress [kPa].
    pub p: f64,
    /// Time increment [s].
    pub dt: f64,
    /// ξΔt of recovery over the step (zero under time healing).
    pub xi_dt: f64,
    /// exp(−ξΔt), cached by the caller.
    pub exp_xi_dt: f64,
    /// Accumulated plastic slip at the start [mm].
    pub s_acc: f64,
    /// Time at the end of the step, since the contact started [s] (registered terms).
    pub time: f64,
    /// The step's constants.
    pub local: Local,
    /// A first guess of λ (0: none), e.g. the previous plastic rate over this step.
    pub lam_guess: f64,
}

/// State of the evolution laws after a plastic increment λ, with derivatives w.r.t. λ.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Eval {
    pub r: f64,
    pub dr: f64,
    pub c: f64,
    pub sin: f64,
    pub mu: f64,
    pub dmu: f64,
    pub mu_eff: f64,
    pub dmu_eff: f64,
    /// The families' state at λ (zero for a model without state).
    pub state: StateSlots,
}

/// e^(−x) for x ≥ 0; a degree-8 Taylor polynomial below 0.01 (error < 1e-20, i.e. exact in
/// double precision) avoids the library call in the hot loop, where x is usually tiny.
///
/// It lies on the step's critical path (λ → cos θ → r → the residual → the next λ), so the
/// terms from x³ on are summed in pairs (Estrin) rather than one after another (Horner): a
/// shorter chain of dependent operations. Their rounding reaches the result only through
/// x³ · 1e-17, far below its last bit, so the value is Horner's bit for bit in all but
/// vanishingly rare ties; the three leading terms keep Horner's order, whose rounding does
/// show.
#[inline]
pub(crate) fn exp_neg(x: f64) -> f64 {
    if x.abs() < 0.01 {
        let x = -x;
        let (x2, x4) = (x * x, (x * x) * (x * x));
        let tail = ((1.0 / 6.0 + x * (1.0 / 24.0)) + x2 * (1.0 / 120.0 + x * (1.0 / 720.0)))
            + x4 * (1.0 / 5040.0 + x * (1.0 / 40320.0));
        1.0 + x * (1.0 + x * (0.5 + x * tail))
    } else {
        (-x).exp()
    }
}

/// asin(x) for x in [−1, 1]; a Taylor polynomial below 0.01 (error < 1e-20). On the critical
/// path as [`exp_neg`], and summed the same way: the terms from x³ on in pairs, the leading
/// x in front.
#[inline]
fn asin_small(x: f64) -> f64 {
    if x.abs() < 0.01 {
        let (x2, x4) = (x * x, (x * x) * (x * x));
        let tail = (1.0 / 6.0 + x2 * (3.0 / 40.0)) + x4 * (5.0 / 112.0 + x2 * (35.0 / 1152.0));
        x * (1.0 + x2 * tail)
    } else {
        x.clamp(-1.0, 1.0).asin()
    }
}

/// `x.is_finite()`: x·0 is 0 for a finite x and NaN otherwise. Next to a comparison of the
/// same x, `is_finite` (or `x < ∞`) turns into a test of its class in some thirty integer
/// instructions, once per step in the return; this stays two floating-point ones.
#[inline(always)]
fn finite(x: f64) -> bool {
    x * 0.0 == 0.0
}

/// `x.clamp(lo, hi)` for an `x` that is almost always within the bounds. `clamp` compiles to a
/// max and a min, two operations on the step's chain of dependent ones (λ → the next λ, which
/// bounds the step's speed); a test instead is a branch the processor predicts, and the value
/// flows on without waiting for it. Same value, NaN and panics included. (`black_box` keeps
/// the compiler from turning the test back into the max and min: it cannot hoist it.)
#[inline(always)]
pub(crate) fn clamp_likely_within(x: f64, lo: f64, hi: f64) -> f64 {
    if x >= lo && x <= hi {
        x
    } else {
        std::hint::black_box(x.clamp(lo, hi))
    }
}

/// `x.min(hi)` as [`clamp_likely_within`], for an `x` almost always at most `hi`.
#[inline(always)]
pub(crate) fn min_likely_below(x: f64, hi: f64) -> f64 {
    // Strictly: min(−0, 0) and min(0, −0) are the library's to choose.
    if x < hi {
        x
    } else {
        std::hint::black_box(x.min(hi))
    }
}

/// `x.max(lo)` as [`clamp_likely_within`], for an `x` almost always at least `lo`.
#[inline(always)]
pub(crate) fn max_likely_above(x: f64, lo: f64) -> f64 {
    // Strictly, as `min_likely_below`.
    if x > lo {
        x
    } else {
        std::hint::black_box(x.max(lo))
    }
}

/// (1 − e^(−x))/x and its derivative, with series near 0.
#[inline]
pub(crate) fn relax_weight(x: f64, e: f64) -> (f64, f64) {
    if x > 1e-4 {
        let g = (1.0 - e) / x;
        (g, (e * (1.0 + x) - 1.0) / (x * x))
    } else {
        (1.0 - x * (0.5 - x / 6.0), -0.5 + x * (1.0 / 3.0 - x / 8.0))
    }
}

/// The evolution laws and the friction surface at plastic increment `lam`, with the families'
/// state held as `states` ([`StateStep`]) starting from `start`.
#[inline(always)]
fn eval<S: StateStep>(k: &Consts, states: &S, s: &StepInput, start: &StateSlots, lam: f64) -> Eval {
    let l = &s.local;
    // cos θ = cos θ₀ · exp(−kr λ) with θ = πr/2; dr/dλ = ũ cot θ = ũ c / sin θ.
    // θ − θ₀ = asin(sin θ cos θ₀ − cos θ sin θ₀): small within a step, so no inverse cosine.
    let c = s.c_start * exp_neg(l.kr * lam);
    let sin = max_likely_above((1.0 - c) * (1.0 + c), 0.0).sqrt();
    let dtheta = asin_small(sin * s.c_start - c * s.s_start);
    let r = min_likely_below(s.r_start + dtheta * (1.0 / FRAC_PI_2), 1.0);
    let dr = if sin > 0.0 {
        l.u_tilde * c / sin
    } else {
        f64::INFINITY
    };

    // The families that integrate a state: their terms of friction at λ, and their state
    // there, which the step ends with when λ is the return's last iterate. A model without a
    // state moves no slots in the loop.
    let mut end = if S::ANY {
        *start
    } else {
        StateSlots::default()
    };
    let state = S::ANY.then(|| states.slide(start, s.dt, lam, &mut end));
    // The kinetic bound; a rate law may move it with v = λ/Δt.
    let (mu_k, dmu_k) = match &state {
        Some(t) if t.dmu_k != 0.0 => {
            let m = l.mu_k + t.mu_k_shift;
            if m > 0.0 && m < l.mu_s {
                (m, t.dmu_k)
            } else {
                (m.clamp(0.0, l.mu_s), 0.0)
            }
        }
        _ => (l.mu_k, 0.0),
    };

    // μ = μ_n E + w N with A = κλ + ξΔt, E = e^(−A), w = (1−E)/A, N = κλ μ_k + ξΔt μ_s.
    let kl = l.kappa * lam;
    let a = kl + s.xi_dt;
    let e = exp_neg(kl) * s.exp_xi_dt;
    let n = kl * mu_k + s.xi_dt * l.mu_s;
    let (w, e_minus_w_over_a) = if a > 1e-5 {
        let w = (1.0 - e) / a;
        (w, (e - w) / a)
    } else {
        (1.0 - a * (0.5 - a / 6.0), -0.5 + a / 3.0)
    };
    let mu = s.mu_n * e + w * n;
    let dmu = l.kappa * (-s.mu_n * e + e_minus_w_over_a * n + w * (mu_k + lam * dmu_k));

    // μ_eff = μ·m·V + R + T(s, t) + G (see `StateTerms`).
    let (mut mu_eff, mut dmu_eff) = (mu * l.mult, dmu * l.mult);
    if let Some(t) = state {
        (mu_eff, dmu_eff) = (
            mu_eff * t.factor + t.add,
            dmu_eff * t.factor + mu * l.mult * t.dfactor + t.dadd,
        );
    }
    if k.has_path_terms() {
        let (h, dh) = k.path_terms(s.s_acc + lam, s.time);
        mu_eff += h;
        dmu_eff += dh;
    }
    if let Some(t) = state {
        mu_eff += t.own;
        dmu_eff += t.down;
    }
    let floor = MIN_MU_EFF_FRACTION * l.mu_s;
    if mu_eff < floor {
        (mu_eff, dmu_eff) = (floor, 0.0);
    }
    Eval {
        r,
        dr,
        c,
        sin,
        mu,
        dmu,
        mu_eff,
        dmu_eff,
        state: end,
    }
}

/// Result of a plastic return.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plastic {
    pub lam: f64,
    pub r: f64,
    pub c: f64,
    pub s: f64,
    pub mu: f64,
    /// The families' state the step ends with: the one at the return's last evaluation,
    /// settled at `lam` ([`StateStep::settle`]); zero for a model without state.
    pub state: StateSlots,
}

impl Plastic {
    fn at(lam: f64, e: &Eval) -> Self {
        Plastic {
            lam,
            r: e.r,
            c: e.c,
            s: e.sin,
            mu: e.mu,
            state: e.state,
        }
    }
}

/// Slip control: find λ ≥ 0 with T − α λ = r(λ) μ_eff(λ) p, where T = ‖f_trial‖ exceeds the
/// starting surface (the caller has checked that the step is plastic).
/// `excess` is T − r₀ μ_eff(0) p > 0, the trial's distance outside the starting surface.
///
/// `slots` is the families' state at the start of the step. For a caller that does not compile
/// its step for a model with and without a state apart (see [`return_slip_as`]): the return
/// of a model with a state is out of line and works on copies of the step's input and state
/// (were their addresses to reach a call out of line, the step could no longer keep them in
/// registers, with or without a state).
#[inline]
pub(crate) fn return_slip(
    k: &Consts,
    s: &StepInput,
    slots: &StateSlots,
    trial: f64,
    excess: f64,
) -> Result<Plastic, StepError> {
    if k.has_state() {
        return_slip_with_state(k, *s, *slots, trial, excess)
    } else {
        return_slip_as::<false>(k, s, slots, trial, excess)
    }
}

/// [`return_slip`] of a model with a state.
#[inline(never)]
fn return_slip_with_state(
    k: &Consts,
    s: StepInput,
    slots: StateSlots,
    trial: f64,
    excess: f64,
) -> Result<Plastic, StepError> {
    return_slip_as::<true>(k, &s, &slots, trial, excess)
}

/// [`return_slip`] compiled for a model that may have a state (`STATE`) or that has none: the
/// second (the base model's, the step the benchmark times) carries no trace of the state's
/// terms in its Newton loop, not even a test of whether there are any; the first is compiled
/// for each way the model may hold its families ([`states::States::with`]) and ends with their
/// state settled ([`StateStep::settle`]).
#[inline(always)]
pub(crate) fn return_slip_as<const STATE: bool>(
    k: &Consts,
    s: &StepInput,
    start: &StateSlots,
    trial: f64,
    excess: f64,
) -> Result<Plastic, StepError> {
    if !STATE {
        return solve_slip(k, &NoState, s, start, trial, excess);
    }
    k.states().with(SlipReturn {
        k,
        s,
        start,
        trial,
        excess,
    })
}

/// [`return_slip_as`] of a model with a state, as [`WithStates`].
struct SlipReturn<'a> {
    k: &'a Consts,
    s: &'a StepInput,
    start: &'a StateSlots,
    trial: f64,
    excess: f64,
}

impl WithStates for SlipReturn<'_> {
    type Output = Result<Plastic, StepError>;

    #[inline(always)]
    fn run<S: StateStep>(self, states: S) -> Self::Output {
        let mut pl = solve_slip(self.k, &states, self.s, self.start, self.trial, self.excess)?;
        states.settle(self.start, pl.lam, &mut pl.state);
        Ok(pl)
    }
}

/// The Newton iteration of [`return_slip_as`], with the families' state held as `states`.
#[inline(always)]
fn solve_slip<S: StateStep>(
    k: &Consts,
    states: &S,
    s: &StepInput,
    start: &StateSlots,
    trial: f64,
    excess: f64,
) -> Result<Plastic, StepError> {
    let alpha = k.alpha;
    // Precision floor: trial is computed as a sum of terms of size `trial`.
    let tol = RETURN_TOLERANCE * s.p + 8.0 * f64::EPSILON * trial;
    let mut lo = 0.0;
    let mut hi = trial / alpha;
    if !(hi > 0.0 && finite(hi) && finite(excess)) {
        // A trial traction beyond floating point (absurd input): no return to speak of.
        return Err(StepError::NoConvergence {
            iterations: 0,
            residual: excess,
        });
    }
    // Perfectly plastic estimate: the surface does not move; with rate terms the surface moves
    // with the rate, and the previous plastic rate is the better start.
    let mut lam = if s.lam_guess > 0.0 && s.lam_guess < hi {
        s.lam_guess
    } else {
        clamp_likely_within(excess / alpha, 0.0, hi)
    };
    if lam <= 0.0 {
        lam = 0.5 * hi;
    }
    let mut g = f64::NAN;
    for _ in 0..MAX_ITERATIONS {
        let e = eval(k, states, s, start, lam);
        g = trial - alpha * lam - e.r * e.mu_eff * s.p;
        if g.abs() <= tol {
            return Ok(Plastic::at(lam, &e));
        }
        if g > 0.0 {
            lo = lam;
        } else {
            hi = lam;
        }
        let hard = s.p * (e.dr * e.mu_eff + e.r * e.dmu_eff);
        let dg = -alpha - hard;
        let delta = -g / dg;
        // The correction is so small that a first-order update is exact to round-off:
        // skip the extra evaluation of the transcendental functions.
        if hard.is_finite() && (delta * hard).abs() <= tol && delta.abs() <= 1e-3 * lam {
            return Ok(Plastic {
                lam: lam + delta,
                r: clamp_likely_within(e.r + e.dr * delta, 0.0, 1.0),
                c: e.c * (1.0 - s.local.kr * delta),
                s: e.sin + e.c * FRAC_PI_2 * e.dr * delta,
                mu: e.mu + e.dmu * delta,
                // The families' state moves by O(δ) ≪ its own scale: the one at λ, unless a
                // family settles it at λ + δ (`StateStep::settle`).
                state: e.state,
            });
        }
        let next = lam + delta;
        lam = if dg < 0.0 && next.is_finite() && next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 4.0 * f64::EPSILON * hi {
            let e = eval(k, states, s, start, lam);
            return Ok(Plastic::at(lam, &e));
        }
    }
    Err(StepError::NoConvergence {
        iterations: MAX_ITERATIONS,
        residual: g,
    })
}

/// Traction control: find the smallest λ ≥ 0 with r(λ) μ_eff(λ) p = target, compiled for a
/// model that may have a state (`STATE`) or that has none, as [`return_slip_as`].
#[inline(always)]
pub(crate) fn return_shear_as<const STATE: bool>(
    k: &Consts,
    s: &StepInput,
    start: &StateSlots,
    target: f64,
    guess: f64,
) -> Result<Plastic, StepError> {
    if !STATE {
        return solve_shear(k, &NoState, s, start, target, guess);
    }
    k.states().with(ShearReturn {
        k,
        s,
        start,
        target,
        guess,
    })
}

/// [`return_shear_as`] of a model with a state, as [`WithStates`].
struct ShearReturn<'a> {
    k: &'a Consts,
    s: &'a StepInput,
    start: &'a StateSlots,
    target: f64,
    guess: f64,
}

impl WithStates for ShearReturn<'_> {
    type Output = Result<Plastic, StepError>;

    #[inline(always)]
    fn run<S: StateStep>(self, states: S) -> Self::Output {
        let mut pl = solve_shear(self.k, &states, self.s, self.start, self.target, self.guess)?;
        states.settle(self.start, pl.lam, &mut pl.state);
        Ok(pl)
    }
}

/// The bracketing and Newton iteration of [`return_shear_as`], with the families' state held
/// as `states`.
fn solve_shear<S: StateStep>(
    k: &Consts,
    states: &S,
    s: &StepInput,
    start: &StateSlots,
    target: f64,
    guess: f64,
) -> Result<Plastic, StepError> {
    // Tight: the slip is accumulated over thousands of steps and differentiated by fitting.
    let tol = 1e-13 * s.p.max(target);
    let h = |e: &Eval| e.r * e.mu_eff * s.p - target;
    let dh = |e: &Eval| s.p * (e.dr * e.mu_eff + e.r * e.dmu_eff);
    // Bracket the first root by marching out from λ = 0, where h < 0.
    let mut lo = 0.0;
    let mut lam = if guess.is_finite() && guess > 0.0 {
        guess
    } else {
        1e-6
    };
    let mut hi: f64;
    let mut best_capacity: f64 = 0.0;
    loop {
        let e = eval(k, states, s, start, lam);
        let hv = h(&e);
        best_capacity = best_capacity.max(e.r * e.mu_eff * s.p);
        if hv >= 0.0 {
            hi = lam;
            break;
        }
        let slope = dh(&e);
        if slope.is_nan() || slope <= 0.0 || lam > 1e6 {
            return Err(StepError::Runaway {
                target_kpa: target,
                capacity_kpa: best_capacity,
            });
        }
        lo = lam;
        lam = (lam - hv / slope).max(2.0 * lam);
    }
    let mut lam = 0.5 * (lo + hi);
    let mut res = f64::NAN;
    for _ in 0..MAX_ITERATIONS {
        let e = eval(k, states, s, start, lam);
        res = h(&e);
        if res.abs() <= tol || hi - lo <= 4.0 * f64::EPSILON * hi {
            return Ok(Plastic::at(lam, &e));
        }
        if res < 0.0 {
            lo = lam;
        } else {
            hi = lam;
        }
        let slope = dh(&e);
        let next = lam - res / slope;
        lam = if slope > 0.0 && next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    Err(StepError::NoConvergence {
        iterations: MAX_ITERATIONS,
        residual: res,
    })
}

/// The friction surface of a plastic step at plastic increment `lam`, for the consistent
/// tangent: F = r μ_eff, its derivative with respect to λ (so the hardening modulus is
/// h = p ∂F/∂λ) and with respect to the starting ratio r₀ at fixed λ (μ_eff does not depend
/// on r₀; cos θ = cos θ₀ e^(−kr λ) with θ = πr/2 gives ∂r/∂r₀ = sin θ₀ e^(−kr λ) / sin θ).
/// `slots` is the families' state at the start of the step.
pub(crate) fn surface(k: &Consts, s: &StepInput, slots: &StateSlots, lam: f64) -> Surface {
    let e = if k.has_state() {
        k.states().with(EvalAt {
            k,
            s,
            start: slots,
            lam,
        })
    } else {
        eval(k, &NoState, s, slots, lam)
    };
    let dr_dr0 = if e.r < 1.0 && e.sin > 0.0 {
        s.s_start * exp_neg(s.local.kr * lam) / e.sin
    } else {
        0.0
    };
    Surface {
        value: e.r * e.mu_eff,
        dlam: e.dr * e.mu_eff + e.r * e.dmu_eff,
        dr0: dr_dr0 * e.mu_eff,
    }
}

/// [`eval`] of a model with a state, as [`WithStates`].
struct EvalAt<'a> {
    k: &'a Consts,
    s: &'a StepInput,
    start: &'a StateSlots,
    lam: f64,
}

impl WithStates for EvalAt<'_> {
    type Output = Eval;

    #[inline(always)]
    fn run<S: StateStep>(self, states: S) -> Eval {
        eval(self.k, &states, self.s, self.start, self.lam)
    }
}

/// See [`surface`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Surface {
    /// F = r μ_eff.
    pub value: f64,
    /// ∂F/∂λ.
    pub dlam: f64,
    /// ∂F/∂r₀ at fixed λ.
    pub dr0: f64,
}

#[cfg(test)]
mod tests {
    use super::{asin_small, clamp_likely_within, exp_neg, max_likely_above, min_likely_below};

    /// The branches give what `clamp`, `min` and `max` give, bit for bit, NaN and zeros included.
    #[test]
    fn likely_bounds_are_the_library_bounds() {
        let xs = [
            -2.0,
            -0.0,
            0.0,
            0.3,
            1.0,
            1.5,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        for x in xs {
            assert!(
                same(clamp_likely_within(x, 0.0, 1.0), x.clamp(0.0, 1.0)),
                "{x}"
            );
            assert!(same(min_likely_below(x, 1.0), x.min(1.0)), "{x}");
            assert!(same(max_likely_above(x, 0.0), x.max(0.0)), "{x}");
        }
    }

    /// The series summed in pairs are the library's functions to round-off, and the value the
    /// same series summed one term after another (Horner) gave, bit for bit over a dense sweep.
    #[test]
    fn series_summed_in_pairs_match_the_library_and_horner() {
        let horner_exp = |x: f64| {
            let x = -x;
            1.0 + x
                * (1.0
                    + x * (0.5
                        + x * (1.0 / 6.0
                            + x * (1.0 / 24.0
                                + x * (1.0 / 120.0
                                    + x * (1.0 / 720.0 + x * (1.0 / 5040.0 + x / 40320.0)))))))
        };
        let horner_asin = |x: f64| {
            let x2 = x * x;
            x * (1.0
                + x2 * (1.0 / 6.0 + x2 * (3.0 / 40.0 + x2 * (5.0 / 112.0 + x2 * (35.0 / 1152.0)))))
        };
        let (mut differ, n) = (0, 100_000);
        for i in 0..n {
            let x = 0.01 * (i as f64 + 0.5) / n as f64;
            assert!((exp_neg(x) - (-x).exp()).abs() <= 2.0 * f64::EPSILON);
            assert!((asin_small(x) - x.asin()).abs() <= 2.0 * f64::EPSILON * x);
            differ += usize::from(exp_neg(x) != horner_exp(x));
            differ += usize::from(asin_small(x) != horner_asin(x));
        }
        assert_eq!(differ, 0);
    }
}
