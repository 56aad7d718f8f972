//! One-dimensional contact: the paper's tests (direct shear, ring torsion, cyclic shear).

use crate::integrator::{
    clamp_likely_within, return_shear_as, return_slip_as, Consts, Local, Plastic, StepError,
    StepInput,
};
use crate::terms::StateSlots;
use crate::Model;
use std::f64::consts::FRAC_PI_2;

/// State of a 1-D contact at one instant (a begin or end state of a step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State1 {
    /// Total slip u [mm].
    pub slip: f64,
    /// Shear traction f_t = α_t ū^e [kPa], signed.
    pub shear: f64,
    /// Friction coefficient μ of Eq. (24).
    pub mu: f64,
    /// Normal-yield ratio r of Eqs. (21–22).
    pub r: f64,
    /// cos(π r / 2), kept alongside r so the step needs no inverse cosine.
    pub cos_r: f64,
    /// sin(π r / 2).
    pub sin_r: f64,
    /// Accumulated plastic slip ∫‖u̇^p‖ dt [mm].
    pub slip_path: f64,
    /// Time since the contact started [s] (used by registered terms, see [`crate::terms`]).
    pub time: f64,
    /// Plastic slip increment of the last step [mm] (signed).
    pub last_plastic: f64,
    /// Time increment of the last step [s].
    pub last_dt: f64,
    /// The state variables of the families that integrate one (rate, time healing; see
    /// [`crate::terms::StateLaw`]), addressed through the families: e.g.
    /// `model.ext.terms.state_value(&st.slots, "theta")`.
    pub slots: StateSlots,
}

impl State1 {
    /// Virgin state at slip `slip` and zero traction, μ = μ₀ and r = 0.
    pub fn virgin(model: &Model, slip: f64) -> Self {
        State1 {
            slip,
            shear: 0.0,
            mu: model.params.initial_mu(),
            r: 0.0,
            cos_r: 1.0,
            sin_r: 0.0,
            slip_path: 0.0,
            time: 0.0,
            last_plastic: 0.0,
            last_dt: 0.0,
            slots: model.ext.terms.initial_state(),
        }
    }

    /// Virgin state at normal stress `p`: μ₀ = μ_s as moved by a pressure effect on μ_s.
    pub fn virgin_at(model: &Model, slip: f64, p: f64) -> Self {
        let mut st = State1::virgin(model, slip);
        let l = Consts::new(&model.params, &model.ext).local(p, 1.0);
        st.mu = match model.params.mu_0 {
            Some(m0) => m0.clamp(l.mu_k, l.mu_s),
            None => l.mu_s,
        };
        st
    }

    /// Friction mobilised, shear / normal stress.
    pub fn friction(&self, normal_kpa: f64) -> f64 {
        self.shear / normal_kpa
    }
}

/// Integrator of a 1-D contact: the model's constants plus small caches of the hot loop.
#[derive(Clone, Debug)]
pub struct Contact1 {
    k: Consts,
    cached_dt: f64,
    cached_exp_xi_dt: f64,
    cached_key: (f64, f64),
    cached_local: Local,
}

impl Contact1 {
    /// A new integrator for `model` (parameters are assumed validated by [`Model::new`]).
    pub fn new(model: &Model) -> Self {
        let k = Consts::new(&model.params, &model.ext);
        Contact1 {
            cached_local: k.local(f64::NAN, 1.0),
            k,
            cached_dt: f64::NAN,
            cached_exp_xi_dt: 1.0,
            cached_key: (f64::NAN, 1.0),
        }
    }

    #[inline]
    fn exp_xi_dt(&mut self, dt: f64) -> f64 {
        // Equal steps read from a file differ in the last bits; exp(−ξΔt) does not, to round-off.
        if (dt - self.cached_dt).abs() > 1e-13 * dt || self.cached_dt.is_nan() {
            self.cached_dt = dt;
            self.cached_exp_xi_dt = (-self.k.xi * dt).exp();
        }
        self.cached_exp_xi_dt
    }

    /// The step constants at normal stress `p` for sliding in direction `sign`.
    #[inline]
    fn local(&mut self, p: f64, sign: f64) -> Local {
        if (p, sign) != self.cached_key {
            self.cached_key = (p, sign);
            self.cached_local = self.k.local(p, sign);
        }
        self.cached_local
    }

    /// Surface the step starts from: a traction passing through zero restarts loading at r = 0.
    /// A reversal is rare; as a predicted branch (`black_box` keeps the compiler from making it
    /// a select) r₀ reaches the excess without waiting for the test (see
    /// [`crate::integrator::clamp_likely_within`]).
    #[inline]
    fn start_surface(st: &State1, new_shear_sign: f64) -> (f64, f64, f64) {
        if st.shear * new_shear_sign < 0.0 {
            std::hint::black_box((0.0, 1.0, 0.0))
        } else {
            (st.r, st.cos_r, st.sin_r)
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn elastic(
        st: &State1,
        shear: f64,
        slip: f64,
        mu_el: f64,
        mu_eff: f64,
        p: f64,
        dt: f64,
        slots: StateSlots,
    ) -> State1 {
        let r = (shear.abs() / (mu_eff * p)).min(1.0);
        let (sin_r, cos_r) = (FRAC_PI_2 * r).sin_cos();
        State1 {
            slip,
            shear,
            mu: mu_el,
            r,
            cos_r,
            sin_r,
            slip_path: st.slip_path,
            time: st.time + dt,
            last_plastic: 0.0,
            last_dt: dt,
            slots,
        }
    }

    /// The part both controls share: from the traction the step would reach elastically,
    /// either the elastic end state, or what the plastic return starts from. `STATE` false:
    /// the model has no state (see [`Contact1::step_slip`]).
    #[inline(always)]
    fn begin<const STATE: bool>(
        &mut self,
        st: &State1,
        traction: f64,
        slip_if_elastic: f64,
        p: f64,
        dt: f64,
    ) -> Begin {
        // The direction of the step decides the constants (direction effects); at zero
        // traction the contact keeps the direction it had.
        let sign = if traction != 0.0 {
            traction.signum()
        } else if st.shear < 0.0 {
            -1.0
        } else {
            1.0
        };
        let local = self.local(p, sign);
        let exp_xi_dt = self.exp_xi_dt(dt);
        let (slots_el, gain) = self.k.rest_state::<STATE>(&st.slots, dt);
        let mu_el = self.k.rest_mu(&local, st.mu, gain, exp_xi_dt);
        if traction == 0.0 {
            return Begin::Elastic(Self::elastic(
                st,
                0.0,
                slip_if_elastic,
                mu_el,
                1.0,
                p,
                dt,
                slots_el,
            ));
        }
        let (r0, c0, s0) = Self::start_surface(st, sign);
        let mu_eff0 =
            self.k
                .elastic_mu_eff::<STATE>(&local, mu_el, &slots_el, st.slip_path, st.time + dt);
        let magnitude = traction.abs();
        let excess = magnitude - r0 * mu_eff0 * p;
        if excess <= self.k.rest_tolerance(magnitude, p) {
            return Begin::Elastic(Self::elastic(
                st,
                traction,
                slip_if_elastic,
                mu_el,
                mu_eff0,
                p,
                dt,
                slots_el,
            ));
        }
        let (xi_dt, exp_xi_dt) = if self.k.recovery() {
            (self.k.xi * dt, exp_xi_dt)
        } else {
            (0.0, 1.0)
        };
        Begin::Plastic {
            sign,
            magnitude,
            excess,
            input: StepInput {
                mu_n: st.mu,
                c_start: c0,
                s_start: s0,
                r_start: r0,
                p,
                dt,
                xi_dt,
                exp_xi_dt,
                s_acc: st.slip_path,
                time: st.time + dt,
                local,
                lam_guess: if self.k.rate.is_some() && st.last_dt > 0.0 {
                    st.last_plastic.abs() * dt / st.last_dt
                } else {
                    0.0
                },
            },
        }
    }

    /// End state of a plastic step.
    #[inline]
    fn plastic(
        &self,
        st: &State1,
        slip: f64,
        shear: f64,
        sign: f64,
        input: &StepInput,
        pl: &Plastic,
    ) -> State1 {
        let local = &input.local;
        State1 {
            slip,
            shear,
            mu: clamp_likely_within(pl.mu, self.k.mu_floor(local), local.mu_s),
            r: pl.r,
            cos_r: pl.c,
            sin_r: pl.s,
            slip_path: st.slip_path + pl.lam,
            time: st.time + input.dt,
            last_plastic: sign * pl.lam,
            last_dt: input.dt,
            slots: pl.state,
        }
    }

    /// One step under slip control: impose the total slip `slip` at normal stress `p` [kPa]
    /// after `dt` seconds. Returns the end state, or an error value (retry with substeps).
    ///
    /// The step is compiled twice, for a model whose families integrate a state and for one
    /// whose do not: the second (the base model's, the step the benchmark times) carries no
    /// trace of the state, not even a test of whether there is one; the first has the
    /// families' laws inlined in it, by their own types (built once, when the contact is).
    #[inline]
    pub fn step_slip(
        &mut self,
        st: &State1,
        slip: f64,
        p: f64,
        dt: f64,
    ) -> Result<State1, StepError> {
        if self.k.has_state() {
            self.step_slip_as::<true>(st, slip, p, dt)
        } else {
            self.step_slip_as::<false>(st, slip, p, dt)
        }
    }

    /// [`Contact1::step_slip`] for a model with (`STATE`) or without a state.
    #[inline(always)]
    fn step_slip_as<const STATE: bool>(
        &mut self,
        st: &State1,
        slip: f64,
        p: f64,
        dt: f64,
    ) -> Result<State1, StepError> {
        let trial = st.shear + self.k.alpha * (slip - st.slip);
        match self.begin::<STATE>(st, trial, slip, p, dt) {
            Begin::Elastic(end) => Ok(end),
            Begin::Plastic {
                sign,
                magnitude,
                excess,
                input,
            } => {
                let pl = return_slip_as::<STATE>(&self.k, &input, &st.slots, magnitude, excess)?;
                let shear = sign * (magnitude - self.k.alpha * pl.lam);
                Ok(self.plastic(st, slip, shear, sign, &input, &pl))
            }
        }
    }

    /// One step under traction control: impose the shear `shear` [kPa] at normal stress `p`
    /// after `dt` seconds; the slip follows. A shear above the friction capacity is
    /// [`StepError::Runaway`]. Compiled twice, as [`Contact1::step_slip`].
    pub fn step_shear(
        &mut self,
        st: &State1,
        shear: f64,
        p: f64,
        dt: f64,
    ) -> Result<State1, StepError> {
        if self.k.has_state() {
            self.step_shear_as::<true>(st, shear, p, dt)
        } else {
            self.step_shear_as::<false>(st, shear, p, dt)
        }
    }

    /// [`Contact1::step_shear`] for a model with (`STATE`) or without a state.
    #[inline(always)]
    fn step_shear_as<const STATE: bool>(
        &mut self,
        st: &State1,
        shear: f64,
        p: f64,
        dt: f64,
    ) -> Result<State1, StepError> {
        let elastic_slip = st.slip + (shear - st.shear) / self.k.alpha;
        match self.begin::<STATE>(st, shear, elastic_slip, p, dt) {
            Begin::Elastic(end) => Ok(end),
            Begin::Plastic {
                sign,
                magnitude,
                input,
                ..
            } => {
                let guess = st.last_plastic.abs();
                let pl = return_shear_as::<STATE>(&self.k, &input, &st.slots, magnitude, guess)?;
                Ok(self.plastic(st, elastic_slip + sign * pl.lam, shear, sign, &input, &pl))
            }
        }
    }
}

/// How a step begins: elastic all the way, or plastic from a surface.
enum Begin {
    Elastic(State1),
    Plastic {
        sign: f64,
        magnitude: f64,
        excess: f64,
        input: StepInput,
    },
}
