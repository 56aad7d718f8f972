//! The state a registered family integrates, in generic slots.
//!
//! A family whose friction depends on its history (rate and state: θ and the rate terms a
//! locked form keeps at rest; time healing: the contact's age and a gain of its own) declares
//! its state variables ([`StateLaw::vars`]) and how they start, evolve at rest and while
//! sliding, act on friction and what values are valid. The contact states ([`crate::State1`],
//! [`crate::State3`]) carry every family's variables as one fixed array of doubles,
//! [`StateSlots`], which the families switched on in a model share in registry order, each
//! taking as many slots as it declares; the integrator and the C interface address them only
//! through the family (its [`StateLaw`] and the slots' layout, [`Terms::state_laws`]), never
//! by name. A fixed array keeps the states `Copy` and the step free of allocation.
//!
//! A family builds its law once for its form and parameters ([`StateFamily::law`], a type of
//! its own), and the integrator keeps the built laws of a model in [`FamilyLaw`], the enum the
//! registry generates from its lines marked `with state`: the step calls a law by its own type,
//! inlined, with no call through a trait object and nothing rebuilt from the parameters.

use super::{FamilyLaw, TermLaw, Terms, MAX_TERM_PARAMS};

/// Most state variables the families switched on in one model may integrate together (rate
/// takes three, time healing two); the C interface carries this many doubles.
pub const MAX_STATE_SLOTS: usize = 5;

/// The names of unused slots, for messages about a state handed in from outside (the first
/// [`MAX_STATE_SLOTS`]).
const UNUSED_SLOT_NAMES: [&str; 12] = [
    "slots[0]",
    "slots[1]",
    "slots[2]",
    "slots[3]",
    "slots[4]",
    "slots[5]",
    "slots[6]",
    "slots[7]",
    "slots[8]",
    "slots[9]",
    "slots[10]",
    "slots[11]",
];
const _: () = assert!(MAX_STATE_SLOTS <= UNUSED_SLOT_NAMES.len());

/// The state variables of the families switched on in a model, in registry order, each
/// family's as many consecutive slots as it declares ([`Terms::state_laws`] gives the layout);
/// unused slots are zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StateSlots(pub [f64; MAX_STATE_SLOTS]);

/// One state variable a family integrates.
#[derive(Clone, Copy, Debug)]
pub struct StateVar {
    /// Name in messages about a state (`theta`, `age`, ...): `state.theta = -1 (expected ...)`.
    pub name: &'static str,
    /// What it is, with its unit.
    pub describe: &'static str,
}

/// What a family's state does to friction over a step, and the slopes of that in the plastic
/// increment λ (zero at rest). The integrator forms μ_eff = μ·m·V + R + T(s, t) + G from μ and
/// the multiplier m of the pressure and direction effects, the terms T of slip and time, and
/// these; while sliding, the kinetic bound of Eq. (24) becomes μ_k + Δμ_k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateTerms {
    /// V, a factor on μ.
    pub factor: f64,
    /// ∂V/∂λ.
    pub dfactor: f64,
    /// R, added to μ·m·V.
    pub add: f64,
    /// ∂R/∂λ.
    pub dadd: f64,
    /// Δμ_k, the shift of the kinetic bound while sliding.
    pub mu_k_shift: f64,
    /// ∂Δμ_k/∂λ.
    pub dmu_k: f64,
    /// G, a friction of its own added after the terms of slip and time.
    pub own: f64,
    /// ∂G/∂λ.
    pub down: f64,
}

impl StateTerms {
    /// No effect on friction. What adds is −0, the exact additive identity (x + (−0) is x for
    /// every x, +0 and −0 alike), and what multiplies is 1: where the step knows a family's
    /// terms, the compiler drops those it leaves as they are.
    pub const NONE: StateTerms = StateTerms {
        factor: 1.0,
        dfactor: 0.0,
        add: -0.0,
        dadd: -0.0,
        mu_k_shift: -0.0,
        dmu_k: -0.0,
        own: -0.0,
        down: -0.0,
    };

    /// These terms and `other` together: factors multiply, the rest adds up. Identity parts
    /// are exact (× 1, + 0), so one family's terms come out bit for bit as it gave them.
    #[inline]
    pub fn and(self, other: StateTerms) -> StateTerms {
        let dfactor = if other.dfactor == 0.0 {
            self.dfactor * other.factor
        } else if self.dfactor == 0.0 {
            self.factor * other.dfactor
        } else {
            self.dfactor * other.factor + self.factor * other.dfactor
        };
        StateTerms {
            factor: self.factor * other.factor,
            dfactor,
            add: self.add + other.add,
            dadd: self.dadd + other.dadd,
            mu_k_shift: self.mu_k_shift + other.mu_k_shift,
            dmu_k: self.dmu_k + other.dmu_k,
            own: self.own + other.own,
            down: self.down + other.down,
        }
    }
}

/// A registered family whose friction depends on its history: it builds its state law for a
/// form and parameters ([`StateFamily::law`]), once per model, and the integrator keeps that
/// law by its own type (one arm of [`FamilyLaw`], which the registry generates from the lines
/// marked `with state`), so that the return mapping calls it directly at each iterate.
pub trait StateFamily: TermLaw {
    /// The family's state law with a form and parameters fixed.
    type Law: StateLaw;

    /// The law of form `form` with parameters `p` (indexed as [`TermLaw::params`]).
    fn law(&self, form: usize, p: &[f64; MAX_TERM_PARAMS]) -> Self::Law;
}

/// How a family's state variables start, evolve and act on friction, as the integrator asks
/// it (see the module documentation), for one form and parameters ([`StateFamily::law`]).
/// Every method receives only the family's own slots, `x`, in the order of
/// [`StateLaw::vars`].
pub trait StateLaw: Copy + std::fmt::Debug {
    /// The state variables, in slot order.
    fn vars(&self) -> &'static [StateVar];

    /// The values of a contact with no history.
    fn initial(&self, x: &mut [f64]);

    /// The values of a contact that has slid steadily at rate `v` [mm/s] (a record that starts
    /// mid-slide), from the initial ones. By default the initial ones.
    fn steady(&self, _v: f64, _x: &mut [f64]) {}

    /// The first variable of `x` that is not one the law can have, with what it allows; the
    /// values are finite (checked before).
    fn invalid(&self, x: &[f64]) -> Option<(usize, &'static str)>;

    /// Evolves `x` over `dt` [s] at rest (an elastic step). Returns the friction μ itself
    /// gains over it, if the family adds to μ at rest (the integrator caps μ at μ_s).
    fn rest(&self, x: &mut [f64], dt: f64) -> Option<f64>;

    /// The family's terms of friction at rest, with its variables `x` at the end of the rest.
    fn at_rest(&self, _x: &[f64]) -> StateTerms {
        StateTerms::NONE
    }

    /// The family's terms of friction, and their slopes, at plastic increment `lam` [mm] over
    /// a step of `dt` [s] from `start`; writes the variables at the end of that increment to
    /// `end`. The return mapping calls it at each of its iterates.
    fn slide(&self, start: &[f64], dt: f64, lam: f64, end: &mut [f64]) -> StateTerms;

    /// The variables a plastic step ends with once the return has settled on `lam`: by default
    /// those of its last iterate (`end`, already written by [`StateLaw::slide`] at a λ within
    /// one first-order correction of `lam`, which moves them by far less than their scale); a
    /// family may evaluate them at `lam` itself, or finish a variable that `slide` leaves in a
    /// working form (the rate family's θ, as ln θ until here: one exponential a step). The
    /// return always settles what it ends with, so no one else reads `end` before this.
    fn settle(&self, _start: &[f64], _lam: f64, _end: &mut [f64]) {}
}

/// Something done with a family's state law by the law's own type
/// ([`FamilyLaw::apply`](super::FamilyLaw::apply)): the integrator's steps, compiled for each
/// family with its slots' length known.
pub(crate) trait LawOp {
    /// What it gives.
    type Output;

    /// Does it with `law`.
    fn apply<L: StateLaw>(self, law: &L) -> Self::Output;
}

/// A family switched on in a model that integrates a state: its law, built, and where its
/// slots are.
#[derive(Clone, Copy, Debug)]
pub struct FamilyState {
    /// The family's state law for its form and parameters.
    pub law: FamilyLaw,
    /// The first of its slots.
    pub at: usize,
    /// How many slots it takes.
    pub len: usize,
}

impl FamilyState {
    /// Its slots, from `at` for `len`.
    #[inline]
    pub fn slots(&self) -> std::ops::Range<usize> {
        self.at..self.at + self.len
    }
}

impl Terms {
    /// The families on that integrate a state, with their slots: in registry order, each
    /// after the previous one's. Families beyond [`MAX_STATE_SLOTS`] are left out (a model
    /// with them is refused, [`Terms::issues`]).
    pub fn state_laws(&self) -> impl Iterator<Item = FamilyState> + '_ {
        let mut at = 0;
        self.iter().filter_map(move |e| {
            let law = FamilyLaw::of(e)?;
            let len = law.vars().len();
            let out = FamilyState { law, at, len };
            at += len;
            (at <= MAX_STATE_SLOTS).then_some(out)
        })
    }

    /// How many slots the families on need.
    pub fn state_len(&self) -> usize {
        self.iter()
            .filter_map(FamilyLaw::of)
            .map(|law| law.vars().len())
            .sum()
    }

    /// The state of a contact with no history: each family's initial values, zeros elsewhere.
    pub fn initial_state(&self) -> StateSlots {
        let mut out = StateSlots::default();
        for f in self.state_laws() {
            f.law.initial(&mut out.0[f.slots()]);
        }
        out
    }

    /// The names of the slots, as the families on declare them (`slots[i]` for unused ones).
    pub fn slot_names(&self) -> [&'static str; MAX_STATE_SLOTS] {
        let mut out: [&'static str; MAX_STATE_SLOTS] =
            std::array::from_fn(|i| UNUSED_SLOT_NAMES[i]);
        for f in self.state_laws() {
            for (name, var) in out[f.slots()].iter_mut().zip(f.law.vars()) {
                *name = var.name;
            }
        }
        out
    }

    /// The slot of the state variable `name` of a family on (`theta`, `age`, ...).
    pub fn slot_of(&self, name: &str) -> Option<usize> {
        self.slot_names()
            .iter()
            .zip(0..self.state_len().min(MAX_STATE_SLOTS))
            .find(|(n, _)| **n == name)
            .map(|(_, i)| i)
    }

    /// The value of the state variable `name` in `slots`, when a family on has it.
    pub fn state_value(&self, slots: &StateSlots, name: &str) -> Option<f64> {
        self.slot_of(name).map(|i| slots.0[i])
    }

    /// The first state variable in `slots` that is not one the families on can have: its
    /// name, value and what it allows (finiteness is for the caller to check).
    pub fn invalid_state(&self, slots: &StateSlots) -> Option<(&'static str, f64, &'static str)> {
        self.state_laws().find_map(|f| {
            let x = &slots.0[f.slots()];
            f.law
                .invalid(x)
                .map(|(i, expected)| (f.law.vars()[i].name, x[i], expected))
        })
    }
}
