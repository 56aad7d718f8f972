//! Three-dimensional (vector) contact: multidirectional sliding on a plane of unit normal n,
//! with Ē = α_t (I − n⊗n) + α_n n⊗n (Eq. 15) and tangential associated flow (Eq. 34).
//! The normal stress is imposed; the plastic return is radial in the tangential plane, so the
//! same scalar equation as in 1-D is solved, and collinear paths give the 1-D answer.

use crate::extensions::Target;
use crate::integrator::{return_slip, surface, Consts, Local, StepError, StepInput};
use crate::terms::StateSlots;
use crate::Model;
use std::f64::consts::FRAC_PI_2;

mod state;

pub use state::{State3, StateError};

/// A 3-vector.
pub type Vec3 = [f64; 3];

#[inline]
fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
fn axpy(a: f64, x: &Vec3, y: &Vec3) -> Vec3 {
    [a * x[0] + y[0], a * x[1] + y[1], a * x[2] + y[2]]
}
#[inline]
fn scale(a: f64, x: &Vec3) -> Vec3 {
    [a * x[0], a * x[1], a * x[2]]
}
#[inline]
fn norm(a: &Vec3) -> f64 {
    dot(a, a).sqrt()
}
#[inline]
fn outer(a: &Vec3, b: &Vec3) -> [[f64; 3]; 3] {
    [scale(a[0], b), scale(a[1], b), scale(a[2], b)]
}
#[inline]
fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for (ci, ai) in c.iter_mut().zip(a) {
        for (j, cij) in ci.iter_mut().enumerate() {
            *cij = ai[0] * b[0][j] + ai[1] * b[1][j] + ai[2] * b[2][j];
        }
    }
    c
}
/// Central difference of a smooth scalar function (for the step constants that extensions make
/// depend on the normal stress or the sliding direction).
#[inline]
fn central(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    (f(x + h) - f(x - h)) / (2.0 * h)
}

/// Step in a direction cosine of the central differences of the closed-form step constants:
/// they vary on the scale of the cosine (≤ 1), so the truncation error (∝ h²) is ~1e-10 while
/// the round-off (∝ ε/h) stays ~1e-11.
const COSINE_STEP: f64 = 1e-5;

/// The same step relative to the normal stress, for the derivatives in p.
const RELATIVE_PRESSURE_STEP: f64 = 1e-5;

/// I − n⊗n: projection onto the plane of unit normal `n`.
#[inline]
fn plane_projector(n: &Vec3) -> [[f64; 3]; 3] {
    let mut plane = [[0.0; 3]; 3];
    for (i, row) in plane.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = f64::from(u8::from(i == j)) - n[i] * n[j];
        }
    }
    plane
}

/// ∂f_t/∂u of a plastic step: α [(1 − a) n̂⊗n̂ + a p n̂⊗∇F + ‖f_t‖/T (P − n̂⊗n̂)] P, with
/// a = α/(α + h), `ratio` = ‖f_t‖/T and P = I − n⊗n (`plane`).
#[inline]
fn plastic_d_slip(
    alpha: f64,
    a: f64,
    p: f64,
    dir: &Vec3,
    grad_f: &Vec3,
    ratio: f64,
    plane: &[[f64; 3]; 3],
) -> [[f64; 3]; 3] {
    let along = outer(dir, dir);
    let coupling = outer(dir, grad_f);
    let mut k_trial = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            k_trial[i][j] = (1.0 - a) * along[i][j]
                + a * p * coupling[i][j]
                + ratio * (plane[i][j] - along[i][j]);
        }
    }
    mat_mul(&k_trial, plane).map(|row| scale(alpha, &row))
}

/// What the pieces of [`Contact3::tangent`] share about one step's trial traction.
struct TrialTraction {
    /// Normal stress [kPa].
    p: f64,
    /// Time step [s].
    dt: f64,
    /// Trial traction f_trial (elastic predictor).
    trial: Vec3,
    /// T = ‖f_trial‖ (> 0).
    magnitude: f64,
    /// n̂ = f_trial/T.
    dir: Vec3,
    /// Cosine of n̂ with the forward axis.
    cos_t: f64,
    /// Step constants at (p, cos_t).
    local: Local,
    /// μ after the elastic (resting) part of the step.
    mu_el: f64,
    /// The families' state after the elastic part of the step.
    slots_el: StateSlots,
    /// The friction μ gains at rest over the step, if a family adds to it (time healing).
    gain: Option<f64>,
    /// exp(−ξ dt).
    exp_xi_dt: f64,
    /// The step constants depend on the sliding direction.
    with_direction: bool,
    /// The step constants depend on the normal stress.
    with_pressure: bool,
}

/// Where the plastic return of a step starts.
struct RestartPoint {
    /// Normal-yield ratio r₀ at the start.
    r0: f64,
    /// cos(π r₀/2).
    c0: f64,
    /// sin(π r₀/2).
    s0: f64,
    /// When r₀ is the ratio of the elastic path's closest point: its gradient with respect to
    /// the trial traction, and its derivative in p.
    sens: Option<(Vec3, f64)>,
}

/// The consistent tangent of one slip-controlled step, from
/// [`Contact3::step_slip_with_tangent`] (units: kPa, mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangent3 {
    /// ∂f_t/∂u [kPa/mm]: `d_slip[i][j]` is the derivative of component i of the tangential
    /// traction at the end of the step with respect to component j of the imposed slip (global
    /// components; zero along the normal).
    pub d_slip: [[f64; 3]; 3],
    /// ∂f_t/∂p at fixed slip [kPa/kPa] (zero for an elastic step).
    pub d_pressure: Vec3,
    /// Plastic slip increment λ n̂ of the step [mm] (zero for an elastic step).
    pub plastic_slip: Vec3,
}

/// Integrator of a 3-D contact.
#[derive(Clone, Debug)]
pub struct Contact3 {
    k: Consts,
    normal: Vec3,
    forward: Vec3,
    alpha_n: f64,
}

impl Contact3 {
    /// A contact with unit normal `normal` and forward axis `forward` (used only by the
    /// direction effect); both are normalised, `forward` projected onto the plane.
    pub fn new(model: &Model, normal: Vec3, forward: Vec3) -> Self {
        let n = scale(1.0 / norm(&normal), &normal);
        let f = axpy(-dot(&forward, &n), &n, &forward);
        let fl = norm(&f);
        let forward = if fl > 0.0 {
            scale(1.0 / fl, &f)
        } else {
            [0.0; 3]
        };
        Contact3 {
            k: Consts::new(&model.params, &model.ext),
            normal: n,
            forward,
            alpha_n: model.params.alpha_n_kpa_per_mm(),
        }
    }

    /// The range of the friction coefficient μ of any state this model produces: within
    /// [μ_k, μ_s], as moved by the pressure and direction effects on the bounds over every
    /// normal stress and direction (down to 0 under the steady-state rate form, whose kinetic
    /// bound moves with the rate).
    pub fn mu_range(&self) -> (f64, f64) {
        let ext = &self.k.ext;
        let (lo_s, hi_s) = ext.bound_factor_range(Target::MuS);
        let (lo_k, _) = ext.bound_factor_range(Target::MuK);
        let floor = match self.k.rate {
            Some(r) if r.moves_kinetic_bound() => 0.0,
            _ => (self.k.mu_k * lo_k).min(self.k.mu_s * lo_s),
        };
        (floor, self.k.mu_s * hi_s)
    }

    /// The input of the plastic return of a step of `dt` from `st` at normal stress `p`, from
    /// the surface `(r₀, cos(πr₀/2), sin(πr₀/2))` under the step constants `local`.
    #[inline]
    fn plastic_input(
        &self,
        st: &State3,
        local: Local,
        (r_start, c_start, s_start): (f64, f64, f64),
        p: f64,
        dt: f64,
    ) -> StepInput {
        let xi_dt = self.k.plastic_recovery(dt);
        StepInput {
            mu_n: st.mu,
            c_start,
            s_start,
            r_start,
            p,
            dt,
            xi_dt,
            exp_xi_dt: (-xi_dt).exp(),
            s_acc: st.slip_path,
            time: st.time + dt,
            local,
            lam_guess: 0.0,
        }
    }

    /// μ_eff of an elastic step of `dt` from `st` that ends with μ = `mu` and the families'
    /// state `slots`, under the step constants `l`.
    #[inline]
    fn elastic_mu_eff(&self, st: &State3, l: &Local, mu: f64, slots: &StateSlots, dt: f64) -> f64 {
        self.k
            .elastic_mu_eff::<true>(l, mu, slots, st.slip_path, st.time + dt)
    }

    /// Tangential part of a vector.
    pub fn tangential(&self, v: &Vec3) -> Vec3 {
        axpy(-dot(v, &self.normal), &self.normal, v)
    }

    /// Full traction vector f = f_t − p n (compression along −n) for a state at normal stress p.
    pub fn traction(&self, st: &State3, p: f64) -> Vec3 {
        axpy(-p, &self.normal, &st.shear)
    }

    /// Elastic normal displacement −p/α_n along n [mm].
    pub fn normal_slip(&self, p: f64) -> f64 {
        -p / self.alpha_n
    }

    /// Cosine of a tangential direction with the forward axis (1 when there is none).
    fn cos_forward(&self, dir: &Vec3) -> f64 {
        if self.forward == [0.0; 3] {
            1.0
        } else {
            dot(dir, &self.forward)
        }
    }

    /// One step under slip control: impose the slip vector `slip` (its tangential part is used).
    pub fn step_slip(
        &self,
        st: &State3,
        slip: &Vec3,
        p: f64,
        dt: f64,
    ) -> Result<State3, StepError> {
        let slip = self.tangential(slip);
        self.step(st, &axpy(-1.0, &st.slip, &slip), slip, p, dt)
    }

    /// One step under slip control given the slip increment `du` (its tangential part is
    /// used), as a finite-element code hands it over. The traction follows from the increment
    /// itself, never from a difference of accumulated slips, so it is exact however far the
    /// point has slid (at a slip of 10¹¹ mm, doubles are 10⁻⁵ mm apart, far more than the
    /// elastic slip of a stiff contact); `slip` in the end state is the record st.slip + Δu.
    pub fn step_increment(
        &self,
        st: &State3,
        du: &Vec3,
        p: f64,
        dt: f64,
    ) -> Result<State3, StepError> {
        let du = self.tangential(du);
        self.step(st, &du, axpy(1.0, &du, &st.slip), p, dt)
    }

    /// The step from `st` by the tangential increment `du`, ending at the slip `slip`.
    fn step(
        &self,
        st: &State3,
        du: &Vec3,
        slip: Vec3,
        p: f64,
        dt: f64,
    ) -> Result<State3, StepError> {
        let trial = axpy(self.k.alpha, du, &st.shear);
        let magnitude = norm(&trial);
        let (slots_el, gain) = self.k.rest_state::<true>(&st.slots, dt);
        let exp_xi_dt = (-self.k.xi * dt).exp();
        let elastic_end = |shear: Vec3, mu: f64, r: f64| {
            let (sin_r, cos_r) = (FRAC_PI_2 * r).sin_cos();
            State3 {
                slip,
                shear,
                mu,
                r,
                cos_r,
                sin_r,
                slip_path: st.slip_path,
                time: st.time + dt,
                slots: slots_el,
            }
        };
        if magnitude == 0.0 {
            let l = self.k.local(p, 1.0);
            return Ok(elastic_end(
                [0.0; 3],
                self.k.rest_mu(&l, st.mu, gain, exp_xi_dt),
                0.0,
            ));
        }
        let dir = scale(1.0 / magnitude, &trial);
        let local = self.k.local(p, self.cos_forward(&dir));
        let mu_el = self.k.rest_mu(&local, st.mu, gain, exp_xi_dt);
        // The elastic path from the current to the trial traction may pass closer to the
        // origin than both ends (unloading then reloading, e.g. a reversal): the subloading
        // surface shrinks to that point, and loading restarts from there.
        let d = axpy(-1.0, &st.shear, &trial);
        let dd = dot(&d, &d);
        let (mut r0, mut c0, mut s0) = (st.r, st.cos_r, st.sin_r);
        if dd > 0.0 {
            let s_min = -dot(&st.shear, &d) / dd;
            if s_min > 0.0 && s_min < 1.0 {
                let f_min = axpy(s_min, &d, &st.shear);
                let fm = norm(&f_min);
                let mu_eff = if fm > 0.0 {
                    let l = self.k.local(p, self.cos_forward(&scale(1.0 / fm, &f_min)));
                    self.elastic_mu_eff(st, &l, mu_el, &slots_el, dt)
                } else {
                    1.0
                };
                r0 = (fm / (mu_eff * p)).min(st.r);
                (s0, c0) = (FRAC_PI_2 * r0).sin_cos();
            }
        }
        let mu_eff0 = self.elastic_mu_eff(st, &local, mu_el, &slots_el, dt);
        if magnitude - r0 * mu_eff0 * p <= self.k.rest_tolerance(magnitude, p) {
            let r = (magnitude / (mu_eff0 * p)).min(1.0);
            return Ok(elastic_end(trial, mu_el, r));
        }
        let input = self.plastic_input(st, local, (r0, c0, s0), p, dt);
        let excess = magnitude - r0 * mu_eff0 * p;
        let pl = return_slip(&self.k, &input, &st.slots, magnitude, excess)?;
        Ok(State3 {
            slip,
            shear: scale(magnitude - self.k.alpha * pl.lam, &dir),
            mu: pl.mu.clamp(self.k.mu_floor(&local), local.mu_s),
            r: pl.r,
            cos_r: pl.c,
            sin_r: pl.s,
            slip_path: st.slip_path + pl.lam,
            time: st.time + dt,
            slots: pl.state,
        })
    }

    /// [`Contact3::step_slip`] with its consistent tangent: the state is exactly the one
    /// `step_slip` returns, and the tangent is the derivative of that algorithm (not of the
    /// continuous model), as an implicit finite-element code needs it.
    ///
    /// With T = ‖f_trial‖, n̂ = f_trial/T and the converged return g(λ) = T − α λ − p F(λ) = 0,
    /// F = r μ_eff: dλ = (n̂ − p ∇F)·df_trial/(α + h), h = p ∂F/∂λ, and
    /// f_t = (T − α λ) n̂ gives
    ///
    /// ∂f_t/∂u = α [h/(α+h) n̂⊗n̂ + α p/(α+h) n̂⊗∇F + ‖f_t‖/T (I − n⊗n − n̂⊗n̂)],
    ///
    /// ∂f_t/∂p = α (F + p ∂F/∂p)/(α + h) n̂, and α (I − n⊗n), 0 for an elastic step. ∇F and
    /// ∂F/∂p at fixed λ are zero except when the step restarts from the point of its elastic
    /// path closest to the origin (r₀ then depends on the trial traction: analytic) and under a
    /// direction or pressure extension (the step constants depend on the direction or on p:
    /// central differences of those closed-form constants).
    pub fn step_slip_with_tangent(
        &self,
        st: &State3,
        slip: &Vec3,
        p: f64,
        dt: f64,
    ) -> Result<(State3, Tangent3), StepError> {
        let next = self.step_slip(st, slip, p, dt)?;
        let du = axpy(-1.0, &st.slip, &self.tangential(slip));
        let tangent = self.tangent(st, &next, &du, p, dt);
        Ok((next, tangent))
    }

    /// [`Contact3::step_increment`] with its consistent tangent (as
    /// [`Contact3::step_slip_with_tangent`]; the derivatives are the same, with respect to the
    /// increment).
    pub fn step_increment_with_tangent(
        &self,
        st: &State3,
        du: &Vec3,
        p: f64,
        dt: f64,
    ) -> Result<(State3, Tangent3), StepError> {
        let next = self.step_increment(st, du, p, dt)?;
        let tangent = self.tangent(st, &next, &self.tangential(du), p, dt);
        Ok((next, tangent))
    }

    /// The tangent of the step from `st` by the tangential increment `du` to `next` (which
    /// `step` returned). The set-up repeats `step`'s expressions in the same order, so it
    /// takes the same branch.
    fn tangent(&self, st: &State3, next: &State3, du: &Vec3, p: f64, dt: f64) -> Tangent3 {
        let alpha = self.k.alpha;
        let plane = plane_projector(&self.normal);
        let elastic = Tangent3 {
            d_slip: plane.map(|row| scale(alpha, &row)),
            d_pressure: [0.0; 3],
            plastic_slip: [0.0; 3],
        };
        let trial = axpy(alpha, du, &st.shear);
        let magnitude = norm(&trial);
        if magnitude == 0.0 {
            return elastic;
        }
        let t = self.trial_traction(st, trial, magnitude, p, dt);
        let start = self.restart_point(st, &t);
        let mu_eff0 = self.elastic_mu_eff(st, &t.local, t.mu_el, &t.slots_el, t.dt);
        if magnitude - start.r0 * mu_eff0 * p <= self.k.rest_tolerance(magnitude, p) {
            return elastic;
        }
        let input = self.plastic_input(st, t.local, (start.r0, start.c0, start.s0), p, dt);
        // λ from the end state: the return converged, so g(λ) = 0 there.
        let shear = norm(&next.shear);
        let lam = (magnitude - shear) / alpha;
        let surf = surface(&self.k, &input, &st.slots, lam);
        let h = p * surf.dlam;
        let a = if h.is_finite() {
            alpha / (alpha + h)
        } else {
            0.0
        };
        let (grad_f, df_dp) =
            self.surface_sensitivity(&t, (&input, &st.slots), lam, surf.dr0, start.sens);
        Tangent3 {
            d_slip: plastic_d_slip(alpha, a, p, &t.dir, &grad_f, shear / magnitude, &plane),
            d_pressure: scale(a * (surf.value + p * df_dp), &t.dir),
            plastic_slip: scale(lam, &t.dir),
        }
    }

    /// What the tangent's pieces share about the trial traction of a step (as `step_slip`
    /// computes it).
    #[inline]
    fn trial_traction(
        &self,
        st: &State3,
        trial: Vec3,
        magnitude: f64,
        p: f64,
        dt: f64,
    ) -> TrialTraction {
        let (slots_el, gain) = self.k.rest_state::<true>(&st.slots, dt);
        let exp_xi_dt = (-self.k.xi * dt).exp();
        let dir = scale(1.0 / magnitude, &trial);
        let cos_t = self.cos_forward(&dir);
        let local = self.k.local(p, cos_t);
        let mu_el = self.k.rest_mu(&local, st.mu, gain, exp_xi_dt);
        TrialTraction {
            p,
            dt,
            trial,
            magnitude,
            dir,
            cos_t,
            local,
            mu_el,
            slots_el,
            gain,
            exp_xi_dt,
            with_direction: self.k.ext.terms.reads_direction() && self.forward != [0.0; 3],
            with_pressure: self.k.ext.terms.reads_normal_stress(),
        }
    }

    /// μ_eff of the elastic path's closest point, as a function of p and of the directions
    /// of the trial (cosine `ct`) and of that point (`cm`), through the step constants only.
    #[inline]
    fn closest_mu_eff(&self, st: &State3, t: &TrialTraction, p: f64, ct: f64, cm: f64) -> f64 {
        let lt = self.k.local(p, ct);
        let mu = self.k.rest_mu(&lt, st.mu, t.gain, t.exp_xi_dt);
        let lm = self.k.local(p, cm);
        self.elastic_mu_eff(st, &lm, mu, &t.slots_el, t.dt)
    }

    /// ∇ of the direction cosine of a vector `v` of length `len` with respect to `v`
    /// (`v_hat` = v/len); zero without a direction effect.
    #[inline]
    fn grad_cos(&self, t: &TrialTraction, v_hat: &Vec3, len: f64) -> Vec3 {
        if t.with_direction {
            scale(
                1.0 / len,
                &axpy(-dot(&self.forward, v_hat), v_hat, &self.forward),
            )
        } else {
            [0.0; 3]
        }
    }

    /// Where the plastic return starts, as in `step_slip`: the current r, or the ratio r₀ of
    /// the elastic path's closest point to the origin when the path passes closer than both
    /// ends (a reversal). In the latter case r₀ depends on the trial traction, and its
    /// gradient and p-derivative are returned with it.
    #[inline]
    fn restart_point(&self, st: &State3, t: &TrialTraction) -> RestartPoint {
        let p = t.p;
        let d = axpy(-1.0, &st.shear, &t.trial);
        let dd = dot(&d, &d);
        let mut out = RestartPoint {
            r0: st.r,
            c0: st.cos_r,
            s0: st.sin_r,
            sens: None,
        };
        if dd <= 0.0 {
            return out;
        }
        let s_min = -dot(&st.shear, &d) / dd;
        if !(s_min > 0.0 && s_min < 1.0) {
            return out;
        }
        let f_min = axpy(s_min, &d, &st.shear);
        let fm = norm(&f_min);
        let mu_eff = if fm > 0.0 {
            let l = self.k.local(p, self.cos_forward(&scale(1.0 / fm, &f_min)));
            self.elastic_mu_eff(st, &l, t.mu_el, &t.slots_el, t.dt)
        } else {
            1.0
        };
        let r0 = (fm / (mu_eff * p)).min(st.r);
        out.r0 = r0;
        (out.s0, out.c0) = (FRAC_PI_2 * r0).sin_cos();
        // Capped by the current r, r₀ does not move with the trial.
        if !(fm > 0.0 && fm / (mu_eff * p) < st.r) {
            return out;
        }
        let f_hat = scale(1.0 / fm, &f_min);
        let cos_m = self.cos_forward(&f_hat);
        // |f_min| moves as s_min f̂_min with the trial (f_min ⊥ d).
        let mut grad = scale(s_min / (mu_eff * p), &f_hat);
        let mut dp = -r0 / p;
        if t.with_direction {
            // ∇ cos_min = Jᵀ w, J = ∂f_min/∂d, w = ∂cos_min/∂f_min.
            let w = self.grad_cos(t, &f_hat, fm);
            let q = dot(&st.shear, &d);
            let dw = dot(&d, &w);
            let grad_cm = axpy(
                2.0 * q * dw / (dd * dd),
                &d,
                &axpy(-dw / dd, &st.shear, &scale(-q / dd, &w)),
            );
            let m_ct = central(
                |c| self.closest_mu_eff(st, t, p, c, cos_m),
                t.cos_t,
                COSINE_STEP,
            );
            let m_cm = central(
                |c| self.closest_mu_eff(st, t, p, t.cos_t, c),
                cos_m,
                COSINE_STEP,
            );
            let g = axpy(
                m_cm,
                &grad_cm,
                &scale(m_ct, &self.grad_cos(t, &t.dir, t.magnitude)),
            );
            grad = axpy(-r0 / mu_eff, &g, &grad);
        }
        if t.with_pressure {
            let m_p = central(
                |q| self.closest_mu_eff(st, t, q, t.cos_t, cos_m),
                p,
                RELATIVE_PRESSURE_STEP * p,
            );
            dp -= r0 / mu_eff * m_p;
        }
        out.sens = Some((grad, dp));
        out
    }

    /// ∇F (with respect to the trial traction) and ∂F/∂p at fixed λ, F = r μ_eff: through r₀
    /// when the step restarts from the closest point (`r0_sens`, weighted by ∂F/∂r₀ = `dr0`),
    /// and through the step constants under a direction or pressure extension.
    #[inline]
    fn surface_sensitivity(
        &self,
        t: &TrialTraction,
        (input, slots): (&StepInput, &StateSlots),
        lam: f64,
        dr0: f64,
        r0_sens: Option<(Vec3, f64)>,
    ) -> (Vec3, f64) {
        let f_at = |p: f64, ct: f64| {
            let l = self.k.local(p, ct);
            surface(&self.k, &StepInput { local: l, ..*input }, slots, lam).value
        };
        let (mut grad_f, mut df_dp) = match r0_sens {
            Some((g, dp)) => (scale(dr0, &g), dr0 * dp),
            None => ([0.0; 3], 0.0),
        };
        if t.with_direction {
            let f_ct = central(|c| f_at(t.p, c), t.cos_t, COSINE_STEP);
            grad_f = axpy(f_ct, &self.grad_cos(t, &t.dir, t.magnitude), &grad_f);
        }
        if t.with_pressure {
            df_dp += central(|q| f_at(q, t.cos_t), t.p, RELATIVE_PRESSURE_STEP * t.p);
        }
        (grad_f, df_dp)
    }
}
