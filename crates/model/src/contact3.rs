//! Three-dimensional (vector) contact: multidirectional sliding on a plane of unit normal n,
//! with Ē = α_t (I − n⊗n) + α_n n⊗n (Eq. 15) and tangential associated flow (Eq. 34).
//! The normal stress is imposed; the plastic return is radial in the tangential plane, so the
//! same scalar equation as in 1-D is solved, and collinear paths give the 1-D answer.

use crate::integrator::{return_slip, Consts, StepError, StepInput};
use crate::Model;
use std::f64::consts::FRAC_PI_2;

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
    /// Time since plastic sliding [s].
    pub age: f64,
    /// State variable θ of the rate-and-state forms [s] (unused otherwise).
    pub theta: f64,
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
            age: 0.0,
            theta: model.ext.rate.map_or(0.0, |r| r.neutral_theta()),
        }
    }
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
        let du = axpy(-1.0, &st.slip, &slip);
        let trial = axpy(self.k.alpha, &du, &st.shear);
        let magnitude = norm(&trial);
        let theta_el = self.k.rest_theta(st.theta, dt);
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
                age: st.age + dt,
                theta: theta_el,
            }
        };
        if magnitude == 0.0 {
            let l = self.k.local(p, 1.0);
            return Ok(elastic_end(
                [0.0; 3],
                self.k.rest_mu(&l, st.mu, st.age, dt, exp_xi_dt),
                0.0,
            ));
        }
        let dir = scale(1.0 / magnitude, &trial);
        let local = self.k.local(p, self.cos_forward(&dir));
        let mu_el = self.k.rest_mu(&local, st.mu, st.age, dt, exp_xi_dt);
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
                    self.k.elastic_mu_eff(&l, mu_el, theta_el, st.slip_path)
                } else {
                    1.0
                };
                r0 = (fm / (mu_eff * p)).min(st.r);
                (s0, c0) = (FRAC_PI_2 * r0).sin_cos();
            }
        }
        let mu_eff0 = self.k.elastic_mu_eff(&local, mu_el, theta_el, st.slip_path);
        if magnitude <= r0 * mu_eff0 * p {
            let r = (magnitude / (mu_eff0 * p)).min(1.0);
            return Ok(elastic_end(trial, mu_el, r));
        }
        let xi_dt = self.k.plastic_recovery(dt);
        let input = StepInput {
            mu_n: st.mu,
            c_start: c0,
            s_start: s0,
            r_start: r0,
            p,
            dt,
            xi_dt,
            exp_xi_dt: (-xi_dt).exp(),
            s_acc: st.slip_path,
            theta: st.theta,
            local,
            lam_guess: 0.0,
        };
        let pl = return_slip(&self.k, &input, magnitude, magnitude - r0 * mu_eff0 * p)?;
        Ok(State3 {
            slip,
            shear: scale(magnitude - self.k.alpha * pl.lam, &dir),
            mu: pl.mu.clamp(self.k.mu_floor(&local), local.mu_s),
            r: pl.r,
            cos_r: pl.c,
            sin_r: pl.s,
            slip_path: st.slip_path + pl.lam,
            age: 0.0,
            theta: pl.theta,
        })
    }
}
