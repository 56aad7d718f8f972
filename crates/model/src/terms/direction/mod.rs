//! Direction dependence: forward and backward sliding differ — an asymmetric surface
//! (machining lay, a sawtooth profile), a fabric the first shearing gave the sand. Backward
//! sliding scales its target by 1 − d (in 3-D by 1 − d (1 − t̂·e₁)/2, smoothly with the
//! direction t̂ of sliding against the forward axis e₁). The forms differ in what is scaled: μ as a
//! whole, μ_s, μ_k, κ or ũ only, or μ_s and μ_k each by its own size (d and d_k: the general
//! form, which holds the whole-μ, μ_s-only and μ_k-only forms as special cases).
//!
//! In parameter files the form is the field `target` (`"direction": {"d": 0.1, "target":
//! "mu-k"}`), as it has always been written.

use super::{
    DataScales, EventReadings, FormGuess, Shows, TermEvidence, TermFile, TermForm, TermGuess,
    TermLaw, TermParam, MAX_TERM_PARAMS,
};
use crate::Target;

/// The direction family (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Direction;

const PARAMS: [TermParam; 2] = [
    TermParam {
        key: "direction.d",
        name: "d",
        unit: "",
        log_scale: false,
        bounds: (-0.9, 0.9),
        default: 0.0,
        expected: "a number in (-1, 1)",
        within: (-1.0, 1.0),
        reference: false,
    },
    TermParam {
        key: "direction.d_k",
        name: "d_k",
        unit: "",
        log_scale: false,
        bounds: (-0.9, 0.9),
        default: 0.0,
        expected: "a number in (-1, 1)",
        within: (-1.0, 1.0),
        reference: false,
    },
];

/// The forms, in the order of [`FORMS`]: what each scales.
const TARGETS: [Target; 6] = [
    Target::Friction,
    Target::MuS,
    Target::MuK,
    Target::Kappa,
    Target::UTilde,
    Target::Bounds,
];

const BOUNDS: usize = 5;

const FORMS: [TermForm; 6] = [
    TermForm {
        key: "friction",
        describe: "backward mu x (1 - d)",
        params: &[0],
    },
    TermForm {
        key: "mu-s",
        describe: "backward mu_s x (1 - d)",
        params: &[0],
    },
    TermForm {
        key: "mu-k",
        describe: "backward mu_k x (1 - d)",
        params: &[0],
    },
    TermForm {
        key: "kappa",
        describe: "backward kappa x (1 - d)",
        params: &[0],
    },
    TermForm {
        key: "u-tilde",
        describe: "backward u_tilde x (1 - d)",
        params: &[0],
    },
    TermForm {
        key: "bounds",
        describe: "backward mu_s x (1 - d), mu_k x (1 - d_k)",
        params: &[0, 1],
    },
];

/// 1 − d (1 − cos)/2: one forward (cos = 1), 1 − d backward (cos = −1).
fn scaled(d: f64, cos_forward: f64) -> f64 {
    1.0 - d * 0.5 * (1.0 - cos_forward)
}

impl TermLaw for Direction {
    fn name(&self) -> &'static str {
        "direction"
    }

    fn describe(&self) -> &'static str {
        "direction dependence: backward sliding differs from forward sliding"
    }

    fn params(&self) -> &'static [TermParam] {
        &PARAMS
    }

    fn forms(&self) -> &'static [TermForm] {
        &FORMS
    }

    fn adds_term(&self) -> bool {
        false
    }

    fn targets(&self, form: usize) -> &'static [Target] {
        std::slice::from_ref(&TARGETS[form])
    }

    fn factor_on(
        &self,
        form: usize,
        p: &[f64; MAX_TERM_PARAMS],
        target: Target,
        _normal_kpa: f64,
        cos_forward: f64,
    ) -> f64 {
        // d scales the form's target (μ_s under the general form), d_k μ_k.
        super::size_on(TARGETS[form], target).map_or(1.0, |i| scaled(p[i], cos_forward))
    }

    fn range_on(&self, form: usize, p: &[f64; MAX_TERM_PARAMS], target: Target) -> (f64, f64) {
        // Linear in the cosine: the ends are forward and backward sliding.
        let (a, b) = (
            self.factor_on(form, p, target, 0.0, 1.0),
            self.factor_on(form, p, target, 0.0, -1.0),
        );
        (a.min(b), a.max(b))
    }

    fn reads_direction(&self) -> bool {
        true
    }
}

impl TermFile for Direction {
    fn form_field(&self) -> &'static str {
        "target"
    }
}

impl TermGuess for Direction {
    fn guess(&self, form: usize, _data: &DataScales) -> FormGuess {
        if form == BOUNDS {
            FormGuess {
                starts: vec![vec![0.15, 0.15], vec![-0.15, -0.15], vec![0.15, -0.15]],
                neutral: vec![0.0, 0.0],
                bounds: vec![],
                references: vec![],
            }
        } else {
            FormGuess {
                starts: vec![vec![0.15], vec![-0.15]],
                neutral: vec![0.0],
                bounds: vec![],
                references: vec![],
            }
        }
    }
}

impl TermEvidence for Direction {
    fn shows(&self) -> &'static [Shows] {
        &[Shows::Reversals]
    }

    fn tried_by_default(&self) -> bool {
        true
    }

    fn applies(&self, data: &DataScales) -> bool {
        // Only a test that slides both ways can tell backward from forward.
        data.reversals > 0
    }

    fn corroborated(&self, events: &EventReadings) -> bool {
        // An asymmetry read over the reversals must be clear of zero, where one was read.
        events.backward_weakening.is_none_or(|d| d.excludes_zero())
    }
}

#[cfg(test)]
mod tests;
