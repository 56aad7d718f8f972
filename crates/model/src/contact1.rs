//! One-dimensional contact: the paper's tests (direct shear, ring torsion, cyclic shear).

use crate::integrator::{return_shear, return_slip, Consts, Plastic, StepError, StepInput};
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
    /// Time since plastic sliding last occurred [s] (used by log healing).
    pub age: f64,
    /// Plastic slip increment of the last step [mm] (signed).
    pub last_plastic: f64,
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
            age: 0.0,
            last_plastic: 0.0,
        }
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
    cached_p: f64,
    cached_pressure_factor: f64,
}

impl Contact1 {
    /// A new integrator for `model` (parameters are assumed validated by [`Model::new`]).
    pub fn new(model: &Model) -> Self {
        Contact1 {
            k: Consts::new(&model.params, &model.ext),
            cached_dt: f64::NAN,
            cached_exp_xi_dt: 1.0,
            cached_p: f64::NAN,
            cached_pressure_factor: 1.0,
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

    #[inline]
    fn pressure_factor(&mut self, p: f64) -> f64 {
        if p != self.cached_p {
            self.cached_p = p;
            self.cached_pressure_factor = self.k.ext.pressure_factor(p);
        }
        self.cached_pressure_factor
    }

    /// μ after an elastic step of `dt`: exponential (or logarithmic) recovery towards μ_s.
    #[inline]
    fn recovered_mu(&mut self, st: &State1, dt: f64) -> f64 {
        let e = self.exp_xi_dt(dt);
        self.k.rest_mu(st.mu, st.age, dt, e)
    }

    /// Surface the step starts from: a traction passing through zero restarts loading at r = 0.
    #[inline]
    fn start_surface(st: &State1, new_shear_sign: f64) -> (f64, f64, f64) {
        if st.shear * new_shear_sign < 0.0 {
            (0.0, 1.0, 0.0)
        } else {
            (st.r, st.cos_r, st.sin_r)
        }
    }

    #[inline]
    fn step_input(
        &mut self,
        st: &State1,
        surface: (f64, f64, f64),
        p: f64,
        dt: f64,
        sign: f64,
    ) -> StepInput {
        let (r0, c0, s0) = surface;
        let mult = self.pressure_factor(p) * self.k.ext.direction_factor(sign);
        let (xi_dt, exp_xi_dt) = if self.k.ext.log_healing.is_some() {
            (0.0, 1.0)
        } else {
            (self.k.xi * dt, self.exp_xi_dt(dt))
        };
        StepInput {
            mu_n: st.mu,
            c_start: c0,
            s_start: s0,
            r_start: r0,
            p,
            dt,
            xi_dt,
            exp_xi_dt,
            mult,
            s_acc: st.slip_path,
        }
    }

    /// μ_eff of an elastic step (slip rate zero).
    #[inline]
    fn elastic_mu_eff(&self, mu_el: f64, mult: f64, slip_path: f64) -> f64 {
        mu_el * mult + self.k.slip_term(slip_path).0
    }

    fn elastic(
        st: &State1,
        shear: f64,
        slip: f64,
        mu_el: f64,
        mu_eff: f64,
        p: f64,
        dt: f64,
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
            age: st.age + dt,
            last_plastic: 0.0,
        }
    }

    /// The part both controls share: from the traction the step would reach elastically,
    /// either the elastic end state, or what the plastic return starts from.
    #[inline]
    fn begin(
        &mut self,
        st: &State1,
        traction: f64,
        slip_if_elastic: f64,
        p: f64,
        dt: f64,
    ) -> Begin {
        let mu_el = self.recovered_mu(st, dt);
        if traction == 0.0 {
            return Begin::Elastic(Self::elastic(st, 0.0, slip_if_elastic, mu_el, 1.0, p, dt));
        }
        let sign = traction.signum();
        let (r0, c0, s0) = Self::start_surface(st, sign);
        let input = self.step_input(st, (r0, c0, s0), p, dt, sign);
        let mu_eff0 = self.elastic_mu_eff(mu_el, input.mult, st.slip_path);
        let magnitude = traction.abs();
        let excess = magnitude - r0 * mu_eff0 * p;
        if excess <= 0.0 {
            return Begin::Elastic(Self::elastic(
                st,
                traction,
                slip_if_elastic,
                mu_el,
                mu_eff0,
                p,
                dt,
            ));
        }
        Begin::Plastic {
            sign,
            magnitude,
            excess,
            input,
        }
    }

    /// End state of a plastic step.
    #[inline]
    fn plastic(&self, st: &State1, slip: f64, shear: f64, sign: f64, pl: &Plastic) -> State1 {
        State1 {
            slip,
            shear,
            mu: pl.mu.clamp(self.k.mu_k, self.k.mu_s),
            r: pl.r,
            cos_r: pl.c,
            sin_r: pl.s,
            slip_path: st.slip_path + pl.lam,
            age: 0.0,
            last_plastic: sign * pl.lam,
        }
    }

    /// One step under slip control: impose the total slip `slip` at normal stress `p` [kPa]
    /// after `dt` seconds. Returns the end state, or an error value (retry with substeps).
    #[inline]
    pub fn step_slip(
        &mut self,
        st: &State1,
        slip: f64,
        p: f64,
        dt: f64,
    ) -> Result<State1, StepError> {
        let trial = st.shear + self.k.alpha * (slip - st.slip);
        match self.begin(st, trial, slip, p, dt) {
            Begin::Elastic(end) => Ok(end),
            Begin::Plastic {
                sign,
                magnitude,
                excess,
                input,
            } => {
                let pl = return_slip(&self.k, &input, magnitude, excess)?;
                let shear = sign * (magnitude - self.k.alpha * pl.lam);
                Ok(self.plastic(st, slip, shear, sign, &pl))
            }
        }
    }

    /// One step under traction control: impose the shear `shear` [kPa] at normal stress `p`
    /// after `dt` seconds; the slip follows. A shear above the friction capacity is
    /// [`StepError::Runaway`].
    pub fn step_shear(
        &mut self,
        st: &State1,
        shear: f64,
        p: f64,
        dt: f64,
    ) -> Result<State1, StepError> {
        let elastic_slip = st.slip + (shear - st.shear) / self.k.alpha;
        match self.begin(st, shear, elastic_slip, p, dt) {
            Begin::Elastic(end) => Ok(end),
            Begin::Plastic {
                sign,
                magnitude,
                input,
                ..
            } => {
                let pl = return_shear(&self.k, &input, magnitude, st.last_plastic.abs())?;
                Ok(self.plastic(st, elastic_slip + sign * pl.lam, shear, sign, &pl))
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
