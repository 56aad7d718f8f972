//! The families of a model that integrate a state, as the step calls them: their laws built
//! once for the model's parameters ([`States::new`]) and kept by their own types (a
//! [`FamilyLaw`], one arm per family), with where their slots are.
//!
//! The step is compiled for each way of holding them ([`StateStep`]): none ([`NoState`]); the
//! usual model's one family, by its law's own type, its slots the first ([`One`]) — the law is
//! then inlined in the step with its slots' length known, and whatever its terms leave as they
//! are costs nothing; several families, in a loop over their slots ([`Several`]). A model's
//! step picks one once per call ([`States::with`]).

use crate::terms::{
    FamilyLaw, FamilyState, LawOp, StateLaw, StateSlots, StateTerms, Terms, MAX_STATE_SLOTS,
};

/// The families of a model that integrate a state (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) struct States {
    /// Their laws and slots, in registry order: the first `count`.
    laws: [Option<FamilyState>; MAX_STATE_SLOTS],
    count: usize,
    /// How many slots they take; the step writes the rest as zeros.
    len: usize,
    /// The law of the family when it is the only one (its slots the first).
    alone: Option<FamilyLaw>,
}

impl States {
    /// The families of `terms` that integrate a state, their laws built.
    pub fn new(terms: &Terms) -> States {
        let mut laws = [None; MAX_STATE_SLOTS];
        let mut count = 0;
        for (slot, f) in laws.iter_mut().zip(terms.state_laws()) {
            *slot = Some(f);
            count += 1;
        }
        States {
            laws,
            count,
            len: terms.state_len().min(MAX_STATE_SLOTS),
            alone: match (count, laws[0]) {
                (1, Some(f)) => Some(f.law),
                _ => None,
            },
        }
    }

    /// True when a family integrates a state.
    #[inline]
    pub fn any(&self) -> bool {
        self.count > 0
    }

    /// Does `step` with the families as the model holds them: the only one by its law's own
    /// type, or several.
    #[inline(always)]
    pub fn with<W: WithStates>(&self, step: W) -> W::Output {
        match &self.alone {
            Some(law) => law.apply(Alone(step)),
            None => step.run(Several(self)),
        }
    }

    /// The state of a contact that has slid steadily at rate `v`, from `x`.
    pub fn steady(&self, x: &mut StateSlots, v: f64) {
        for f in self.laws[..self.count].iter().flatten() {
            f.law.steady(v, &mut x.0[f.slots()]);
        }
    }
}

/// Something the step does with the families' state, compiled for each way of holding them
/// ([`States::with`]).
pub(crate) trait WithStates {
    /// What it gives.
    type Output;

    /// Does it with `states`.
    fn run<S: StateStep>(self, states: S) -> Self::Output;
}

/// [`WithStates`] with the only family's law, by its own type.
struct Alone<W>(W);

impl<W: WithStates> LawOp for Alone<W> {
    type Output = W::Output;

    #[inline(always)]
    fn apply<L: StateLaw>(self, law: &L) -> W::Output {
        self.0.run(One(*law))
    }
}

/// The families' state as one compilation of the step calls it (see the module
/// documentation): [`StateLaw`]'s calls over every family on, each on its slots.
pub(crate) trait StateStep: Copy {
    /// Whether there is a state at all (false: the step carries no trace of one).
    const ANY: bool;

    /// Evolves `x` over an elastic step of `dt`; returns the friction μ itself gains over it,
    /// if a family adds to μ at rest. Slots no family uses come out zero.
    fn rest(&self, x: &mut StateSlots, dt: f64) -> Option<f64>;

    /// The families' terms of friction at rest with the state `x`.
    fn at_rest(&self, x: &StateSlots) -> StateTerms;

    /// The families' terms of friction at plastic increment `lam` over `dt` from the state
    /// `start`, writing the state at the end of that increment to `end` (one family's terms
    /// as it gives them; several combine, [`StateTerms::and`]).
    fn slide(&self, start: &StateSlots, dt: f64, lam: f64, end: &mut StateSlots) -> StateTerms;

    /// Settles the state a plastic return from `start` ended with, `end`, at its final λ
    /// `lam` ([`StateLaw::settle`]); slots no family uses come out zero.
    fn settle(&self, start: &StateSlots, lam: f64, end: &mut StateSlots);
}

/// A model without state: the step never asks.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NoState;

impl StateStep for NoState {
    const ANY: bool = false;

    #[inline(always)]
    fn rest(&self, _x: &mut StateSlots, _dt: f64) -> Option<f64> {
        None
    }

    #[inline(always)]
    fn at_rest(&self, _x: &StateSlots) -> StateTerms {
        StateTerms::NONE
    }

    #[inline(always)]
    fn slide(&self, _start: &StateSlots, _dt: f64, _lam: f64, _end: &mut StateSlots) -> StateTerms {
        StateTerms::NONE
    }

    #[inline(always)]
    fn settle(&self, _start: &StateSlots, _lam: f64, _end: &mut StateSlots) {}
}

/// The only family with a state, by its law's own type: its slots the first.
#[derive(Clone, Copy, Debug)]
pub(crate) struct One<L>(L);

impl<L: StateLaw> One<L> {
    /// How many slots the family takes.
    #[inline(always)]
    fn len(&self) -> usize {
        self.0.vars().len()
    }
}

impl<L: StateLaw> StateStep for One<L> {
    const ANY: bool = true;

    #[inline(always)]
    fn rest(&self, x: &mut StateSlots, dt: f64) -> Option<f64> {
        let (own, others) = x.0.split_at_mut(self.len());
        others.fill(0.0);
        self.0.rest(own, dt)
    }

    #[inline(always)]
    fn at_rest(&self, x: &StateSlots) -> StateTerms {
        self.0.at_rest(&x.0[..self.len()])
    }

    #[inline(always)]
    fn slide(&self, start: &StateSlots, dt: f64, lam: f64, end: &mut StateSlots) -> StateTerms {
        let n = self.len();
        self.0.slide(&start.0[..n], dt, lam, &mut end.0[..n])
    }

    #[inline(always)]
    fn settle(&self, start: &StateSlots, lam: f64, end: &mut StateSlots) {
        let (own, others) = end.0.split_at_mut(self.len());
        others.fill(0.0);
        self.0.settle(&start.0[..own.len()], lam, own);
    }
}

/// Several families, each on its slots.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Several<'a>(&'a States);

impl Several<'_> {
    /// The families, with their slots.
    #[inline(always)]
    fn iter(&self) -> impl Iterator<Item = &FamilyState> {
        self.0.laws[..self.0.count].iter().flatten()
    }

    /// Zeroes the slots no family uses (element by element: a fill of a variable length would
    /// call out to `memset` at every step).
    #[inline(always)]
    fn clear_unused(&self, x: &mut StateSlots) {
        for (i, v) in x.0.iter_mut().enumerate() {
            if i >= self.0.len {
                *v = 0.0;
            }
        }
    }
}

impl StateStep for Several<'_> {
    const ANY: bool = true;

    #[inline(always)]
    fn rest(&self, x: &mut StateSlots, dt: f64) -> Option<f64> {
        let mut gain: Option<f64> = None;
        for f in self.iter() {
            if let Some(g) = f.law.rest(&mut x.0[f.slots()], dt) {
                gain = Some(gain.map_or(g, |sum| sum + g));
            }
        }
        self.clear_unused(x);
        gain
    }

    #[inline(always)]
    fn at_rest(&self, x: &StateSlots) -> StateTerms {
        let mut terms = StateTerms::NONE;
        for f in self.iter() {
            terms = terms.and(f.law.at_rest(&x.0[f.slots()]));
        }
        terms
    }

    #[inline(always)]
    fn slide(&self, start: &StateSlots, dt: f64, lam: f64, end: &mut StateSlots) -> StateTerms {
        let mut terms = StateTerms::NONE;
        for f in self.iter() {
            let r = f.slots();
            terms = terms.and(f.law.slide(&start.0[r.clone()], dt, lam, &mut end.0[r]));
        }
        terms
    }

    #[inline(always)]
    fn settle(&self, start: &StateSlots, lam: f64, end: &mut StateSlots) {
        for f in self.iter() {
            let r = f.slots();
            f.law.settle(&start.0[r.clone()], lam, &mut end.0[r]);
        }
        self.clear_unused(end);
    }
}
