//! The state of a 3-D contact, and the check of a state handed in from outside (a
//! finite-element code's state array).

use super::{norm, Contact3, Vec3};
use crate::terms::StateSlots;
use crate::Model;
use std::f64::consts::FRAC_PI_2;

/// State of a 3-D contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State3 {
    /// Tangential slip vector [mm].
    pub slip: Vec3,
    /// Tangential traction vector f_t [kPa].
    pub shear: Vec3,
    /// Friction coefficient μ.
    pub mu: f64,
    /// Normal-yield ratio r.
    pub r: f64,
    /// cos(π r / 2).
    pub cos_r: f64,
    /// sin(π r / 2).
    pub sin_r: f64,
    /// Accumulated plastic slip [mm].
    pub slip_path: f64,
    /// Time since the contact started [s] (used by registered terms, see [`crate::terms`]).
    pub time: f64,
    /// The state variables of the families that integrate one (rate, time healing; see
    /// [`crate::terms::StateLaw`]), addressed through the families.
    pub slots: StateSlots,
}

impl State3 {
    /// Virgin state at the given tangential slip.
    pub fn virgin(model: &Model, slip: Vec3) -> Self {
        State3 {
            slip,
            shear: [0.0; 3],
            mu: model.params.initial_mu(),
            r: 0.0,
            cos_r: 1.0,
            sin_r: 0.0,
            slip_path: 0.0,
            time: 0.0,
            slots: model.ext.terms.initial_state(),
        }
    }
}

/// A state that the model cannot have produced (e.g. read back from a finite-element code's
/// state array): the field, its value and what the model allows.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("state.{field} = {value} (expected {expected})")]
pub struct StateError {
    /// The field.
    pub field: &'static str,
    /// Its value, as text.
    pub value: String,
    /// What the model allows.
    pub expected: String,
}

/// How far cos_r and sin_r of a state may be from cos(πr/2) and sin(πr/2): the integrator
/// carries them alongside r to round-off (a first-order update inside a converged return adds
/// ~1e-12), so a larger gap is a state the model did not write.
const STATE_TRIG_TOLERANCE: f64 = 1e-6;

/// Relative slack on the range of μ (round-off of the relaxation towards a bound).
const STATE_MU_SLACK: f64 = 1e-9;

impl Contact3 {
    /// Checks a state handed in from outside: finite, r in [0, 1] with cos_r and sin_r its
    /// cosine and sine of πr/2, μ within [`Contact3::mu_range`], accumulated slip and time ≥ 0,
    /// and each family's state variables what the family allows (age ≥ 0, θ > 0 under a
    /// rate-and-state form, ...; [`crate::terms::StateLaw::invalid`]), named as the family
    /// names them. An all-zero array fails (cos_r = 0 is not cos 0): it is no state, and a new
    /// contact point starts from [`State3::virgin`].
    pub fn check_state(&self, st: &State3) -> Result<(), StateError> {
        let bad = |field, value: String, expected: &str| {
            Err(StateError {
                field,
                value,
                expected: expected.to_string(),
            })
        };
        for (field, v) in [("slip", st.slip), ("shear", st.shear)] {
            if !(v.iter().all(|x| x.is_finite()) && norm(&v).is_finite()) {
                let text = format!("[{}, {}, {}]", v[0], v[1], v[2]);
                return bad(field, text, "finite numbers");
            }
        }
        let scalars = [
            ("mu", st.mu),
            ("r", st.r),
            ("cos_r", st.cos_r),
            ("sin_r", st.sin_r),
            ("slip_path", st.slip_path),
            ("time", st.time),
        ];
        let slots = self.k.ext.terms.slot_names().into_iter().zip(st.slots.0);
        for (field, v) in scalars.into_iter().chain(slots) {
            if !v.is_finite() {
                return bad(field, v.to_string(), "a finite number");
            }
        }
        if !(0.0..=1.0).contains(&st.r) {
            return bad("r", st.r.to_string(), "a number in [0, 1]");
        }
        let (sin, cos) = (FRAC_PI_2 * st.r).sin_cos();
        if (st.cos_r - cos).abs() > STATE_TRIG_TOLERANCE
            || (st.sin_r - sin).abs() > STATE_TRIG_TOLERANCE
        {
            return bad(
                "cos_r, sin_r",
                format!("{}, {}", st.cos_r, st.sin_r),
                &format!(
                    "cos(πr/2) = {cos}, sin(πr/2) = {sin} of r = {}: not a state of the model \
                     (an all-zero state is none: a new contact point starts from the virgin state)",
                    st.r
                ),
            );
        }
        let (lo, hi) = self.mu_range();
        let slack = STATE_MU_SLACK * hi.min(f64::MAX);
        if !(st.mu >= lo - slack && st.mu <= hi + slack) {
            return bad(
                "mu",
                st.mu.to_string(),
                &format!("a friction coefficient in [{lo}, {hi}], the range of this model"),
            );
        }
        // What only accumulates cannot be negative.
        for (field, v, expected) in [
            ("slip_path", st.slip_path, "an accumulated slip >= 0 [mm]"),
            ("time", st.time, "a time >= 0 [s]"),
        ] {
            if v < 0.0 {
                return bad(field, v.to_string(), expected);
            }
        }
        // Each family's variables, as the family allows them.
        if let Some((field, v, expected)) = self.k.ext.terms.invalid_state(&st.slots) {
            return bad(field, v.to_string(), expected);
        }
        Ok(())
    }
}
