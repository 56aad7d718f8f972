//! The subloading-friction model of the paper, written from its equations for the generator
//! alone: it shares no code with `subfric_model` (the model under check), so a mistake there
//! cannot hide in the data made to check it.
//!
//! In one dimension, with the shear f, the normal stress p and the plastic slip rate λ̇:
//!
//! - elastic law f = K (u − u^p), K the interface's α_t (Eq. 15) in series with the rig's
//!   spring when the recorded displacement is the load point's;
//! - sliding condition |f| = r μ_eff p (Eqs. 21–22), μ_eff = μ with no effect ([`Effects`]);
//! - μ̇ = −κ(μ − μ_k) λ̇ + ξ(μ_s − μ), μ₀ = μ_s (Eq. 24);
//! - ṙ = ũ cot(πr/2) λ̇ (Eqs. 27, 29): with c = cos(πr/2), dc/dλ = −(π/2) ũ c, so c decays
//!   exponentially with plastic slip;
//! - loading is plastic when the trial shear leaves the current surface r μ_eff p, elastic
//!   otherwise (then r = |f|/(μ_eff p)); a shear that passes through zero restarts at r = 0.
//!
//! **Scheme.** Adaptive substeps. Within a substep the plastic increment Δλ is the root of the
//! sliding condition at the substep's end, `|f_trial| − K Δλ = r(Δλ) μ_eff(Δλ) p` (Brent's
//! method), with r from the exact exponential decay of c, μ from the trapezoidal
//! (Crank–Nicolson) step of Eq. (24), θ of the rate-and-state forms from the closed-form
//! solution at the substep's constant rate, and everything else at the substep's end. A
//! substep is accepted when μ, μ_eff and the shear change by less than fixed limits (scaled by
//! `accuracy`), else halved; accepted easily, the next one doubles.

use super::effects::{Condition, Effects, Local, Reading};
use std::f64::consts::FRAC_PI_2;

/// 1 kN/mm³ in kPa/mm.
pub const KPA_PER_MM_PER_KN_MM3: f64 = 1e6;

/// The paper's parameters (units of the data format: κ, ũ in 1/mm, ξ in 1/s, α_t in kN/mm³).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Base {
    /// μ_s.
    pub mu_s: f64,
    /// μ_k.
    pub mu_k: f64,
    /// κ.
    pub kappa: f64,
    /// ξ.
    pub xi: f64,
    /// ũ.
    pub u_tilde: f64,
    /// α_t.
    pub alpha_t: f64,
}

/// A seating or run-in toe on first loading: a gap of `gap_mm` that closes as the shear rises,
/// `gap (1 − exp(−f_max/force))` closed at the largest shear f_max reached so far (it does not
/// reopen), so the recorded displacement runs about `gap_mm` while the shear stays within a few
/// `force_kpa`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Toe {
    /// Travel of the toe [mm].
    pub gap_mm: f64,
    /// Shear scale over which it closes [kPa].
    pub force_kpa: f64,
}

/// The rig between the interface and the recorded displacement.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rig {
    /// Stiffness of the machine in series with the interface [kN/mm³] (`None`: a rigid machine,
    /// the recorded displacement is the interface's).
    pub machine_kn_mm3: Option<f64>,
    /// A seating toe on first forward loading.
    pub toe: Option<Toe>,
}

/// Why a run failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GenError {
    /// Under shear control the imposed shear exceeds what friction can carry.
    #[error(
        "t = {t} s: imposed shear {shear_kpa} kPa exceeds the friction capacity {capacity_kpa} kPa"
    )]
    Runaway {
        /// Time [s].
        t: f64,
        /// Imposed shear [kPa].
        shear_kpa: f64,
        /// Capacity at r → 1 [kPa].
        capacity_kpa: f64,
    },
    /// Substeps became vanishingly small.
    #[error("t = {t} s: no substep small enough (the step from {t} s could not be resolved)")]
    Unresolved {
        /// Time [s].
        t: f64,
    },
    /// A combination the generator does not make.
    #[error("{0}")]
    Unsupported(&'static str),
}

/// The state of the contact at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// Time [s].
    pub t: f64,
    /// Recorded displacement (the load point's when the rig is compliant) [mm].
    pub u: f64,
    /// Shear [kPa], signed.
    pub f: f64,
    /// Normal stress [kPa].
    pub p: f64,
    /// Normal-yield ratio r.
    pub r: f64,
    /// μ of Eq. (24).
    pub mu: f64,
    /// μ_eff of the sliding condition.
    pub mu_eff: f64,
    /// Plastic slip [mm], signed.
    pub u_plastic: f64,
    /// Accumulated plastic slip ∫|λ̇| [mm].
    pub path: f64,
    /// Rate-and-state variable θ [s].
    pub theta: f64,
    /// The rate the rate terms saw last (the locked reading holds it at rest) [mm/s].
    pub v_rate: f64,
    /// Healing gain.
    pub healed: f64,
    /// Healing gain when the current rest began.
    pub heal_base: f64,
    /// Time the rig has held still [s].
    pub rest_t: f64,
    /// Largest forward shear so far (closes the seating toe) [kPa].
    pub toe_fmax: f64,
    /// Sliding direction, +1 or −1.
    pub dir: f64,
}

/// What drives a substep.
#[derive(Clone, Copy, Debug)]
enum Drive {
    /// The recorded displacement moves by this much [mm].
    Slip(f64),
    /// The shear moves by this much [kPa].
    Shear(f64),
}

/// One material point driven through a test.
#[derive(Clone, Debug)]
pub struct Contact {
    base: Base,
    fx: Effects,
    rig: Rig,
    k: f64,
    accuracy: f64,
    st: State,
    substeps: usize,
}

/// The end state of a substep for a trial plastic increment.
#[derive(Clone, Copy, Debug)]
struct Trial {
    mu: f64,
    mu_eff: f64,
    r: f64,
    path: f64,
    theta: f64,
    v: f64,
    healed: f64,
}

/// What a substep shares among its trial increments.
struct Step<'a> {
    c: &'a Contact,
    s: &'a State,
    dt: f64,
    p: f64,
    dir: f64,
    local: Local,
    cos_start: f64,
    resting: bool,
    /// The rig drives the contact forward, at this rate (locked reading) [mm/s].
    driven: Option<f64>,
}

impl Step<'_> {
    fn at(&self, dl: f64) -> Trial {
        let s = self.s;
        let b = &self.c.base;
        let l = &self.local;
        // Eq. (24), trapezoidal: μ₁ − μ₀ = −κ(μ̄ − μ_k)Δλ + ξ(μ_s − μ̄)Δt, μ̄ = (μ₀ + μ₁)/2.
        let x = l.kappa * dl + b.xi * self.dt;
        let mu = (s.mu * (1.0 - 0.5 * x) + l.kappa * dl * l.mu_k + b.xi * self.dt * l.mu_s)
            / (1.0 + 0.5 * x);
        // Eqs. (27, 29): c = cos(πr/2) decays as exp(−(π/2) ũ Δλ).
        let c = self.cos_start * (-FRAC_PI_2 * b.u_tilde * dl).exp();
        let r = c.clamp(-1.0, 1.0).acos() / FRAC_PI_2;
        let (v, v_theta) = match self.c.fx.rate.map(|r| r.reading) {
            Some(Reading::Locked) => match self.driven {
                Some(v) => (v, v),
                None => (s.v_rate, 0.0),
            },
            _ => {
                let v = if self.dt > 0.0 { dl / self.dt } else { 0.0 };
                (v, v)
            }
        };
        let theta = match self.c.fx.rate {
            Some(rate) => rate.evolve_theta(s.theta, v_theta, self.dt),
            None => s.theta,
        };
        let healed = match self.c.fx.healing {
            Some(h) if self.resting => {
                let from = if s.rest_t == 0.0 {
                    s.healed
                } else {
                    s.heal_base
                };
                from + h.gain(s.rest_t + self.dt)
            }
            Some(h) => s.healed * (-dl / h.d_h).exp(),
            None => 0.0,
        };
        let path = s.path + dl;
        let mu_eff = self.c.fx.mu_eff(
            mu,
            &Condition {
                p: self.p,
                dir: self.dir,
                v,
                theta,
                path,
                healed,
            },
        );
        Trial {
            mu,
            mu_eff,
            r,
            path,
            theta,
            v,
            healed,
        }
    }
}

impl Contact {
    /// A contact at rest under normal stress `p0` at time 0 and displacement 0: unloaded,
    /// r = 0, μ = μ_s. `accuracy` scales the substep limits (1: the generator's; 0.5: halved).
    pub fn new(base: Base, fx: Effects, rig: Rig, p0: f64, accuracy: f64) -> Contact {
        let k_interface = base.alpha_t * KPA_PER_MM_PER_KN_MM3;
        let k = match rig.machine_kn_mm3 {
            Some(m) => 1.0 / (1.0 / k_interface + 1.0 / (m * KPA_PER_MM_PER_KN_MM3)),
            None => k_interface,
        };
        let local = fx.local(base.mu_s, base.mu_k, base.kappa, p0, 1.0);
        // The rate the rate terms see at rest: v* for the locked reading (neutral until the rig
        // drives), none for the creep reading.
        let v_star = match fx.rate {
            Some(r) if r.reading == Reading::Locked => r.v_star,
            _ => 0.0,
        };
        let theta = fx.rate.map_or(0.0, |r| r.theta0());
        let mut st = State {
            t: 0.0,
            u: 0.0,
            f: 0.0,
            p: p0,
            r: 0.0,
            mu: local.mu_s,
            mu_eff: 0.0,
            u_plastic: 0.0,
            path: 0.0,
            theta,
            v_rate: v_star,
            healed: 0.0,
            heal_base: 0.0,
            rest_t: 0.0,
            toe_fmax: 0.0,
            dir: 1.0,
        };
        st.mu_eff = fx.mu_eff(
            st.mu,
            &Condition {
                p: p0,
                dir: 1.0,
                v: v_star,
                theta,
                path: 0.0,
                healed: 0.0,
            },
        );
        Contact {
            base,
            fx,
            rig,
            k,
            accuracy: accuracy.clamp(1e-3, 10.0),
            st,
            substeps: 0,
        }
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.st
    }

    /// Stiffness between the plastic slip and the recorded displacement [kPa/mm]: α_t, or α_t in
    /// series with the machine.
    pub fn series_stiffness(&self) -> f64 {
        self.k
    }

    /// Substeps taken so far.
    pub fn substeps(&self) -> usize {
        self.substeps
    }

    /// Moves the recorded displacement linearly to `u1` at time `t1`, the normal stress to `p1`.
    pub fn slide_to(&mut self, t1: f64, u1: f64, p1: f64) -> Result<(), GenError> {
        let (t0, u0, p0) = (self.st.t, self.st.u, self.st.p);
        self.advance(t1, p1, |frac| Drive::Slip(frac * (u1 - u0)), t0, p0)
    }

    /// Moves the shear linearly to `f1` at time `t1` (shear control), the normal stress to
    /// `p1`.
    pub fn load_to(&mut self, t1: f64, f1: f64, p1: f64) -> Result<(), GenError> {
        if self.fx.rate.is_some_and(|r| r.reading == Reading::Locked) {
            return Err(GenError::Unsupported(
                "the locked rate reading follows the rig's displacement rate: slip control only",
            ));
        }
        let (t0, f0, p0) = (self.st.t, self.st.f, self.st.p);
        self.advance(t1, p1, |frac| Drive::Shear(frac * (f1 - f0)), t0, p0)
    }

    /// Adaptive substeps from the current state to `t1`; `drive(frac)` is the change of the
    /// imposed column over the fraction `frac` of the whole interval.
    fn advance(
        &mut self,
        t1: f64,
        p1: f64,
        drive: impl Fn(f64) -> Drive,
        t0: f64,
        p0: f64,
    ) -> Result<(), GenError> {
        let span = t1 - t0;
        if span <= 0.0 {
            return Ok(());
        }
        let mut done = 0.0_f64; // fraction of the interval done
        let mut h = 1.0_f64; // fraction per substep
        let mut prev = drive(0.0);
        while done < 1.0 {
            let step = h.min(1.0 - done);
            let end = if done + step >= 1.0 - 1e-15 {
                1.0
            } else {
                done + step
            };
            let total = drive(end);
            let d = match (total, prev) {
                (Drive::Slip(a), Drive::Slip(b)) => Drive::Slip(a - b),
                (Drive::Shear(a), Drive::Shear(b)) => Drive::Shear(a - b),
                _ => unreachable!("one drive per interval"),
            };
            let dt = (end - done) * span;
            let p_end = p0 + end * (p1 - p0);
            let next = self.substep(&self.st, dt, d, p_end)?;
            let w = self.worst(&self.st, &next);
            if w > 1.0 {
                if step < 1e-13 {
                    return Err(GenError::Unresolved { t: self.st.t });
                }
                h = 0.5 * step;
                continue;
            }
            self.st = next;
            self.st.t = t0 + end * span;
            self.substeps += 1;
            done = end;
            prev = total;
            if w < 0.5 {
                h = (2.0 * step).min(1.0);
            }
        }
        Ok(())
    }

    /// How far a substep went, against its limits (≤ 1: accepted).
    fn worst(&self, s: &State, n: &State) -> f64 {
        let a = self.accuracy;
        let plastic = n.path > s.path;
        let mut w = (n.mu - s.mu).abs() / (0.002 * a);
        if n.dir == s.dir {
            // What μ_eff did beyond the jumps of its inputs: a new rig rate (locked reading),
            // normal stress or direction change it at once, which is no integration error.
            let v = match self.fx.rate.map(|r| r.reading) {
                Some(Reading::Locked) => n.v_rate,
                _ => s.v_rate,
            };
            let jumped = self.fx.mu_eff(
                s.mu,
                &Condition {
                    p: n.p,
                    dir: n.dir,
                    v,
                    theta: s.theta,
                    path: s.path,
                    healed: s.healed,
                },
            );
            // Weighted by r: the shear is r μ_eff p, so a change of μ_eff near r = 0 (the
            // creep reading's rise of the rate on first loading) moves nothing recorded.
            w = w.max(n.r.max(s.r) * (n.mu_eff - jumped).abs() / (0.002 * a));
        }
        if plastic {
            w = w.max((self.base.kappa * (n.path - s.path)) / (0.5 * a));
        }
        if s.f * n.f < 0.0 {
            // A substep through zero shear restarts the surface at r = 0 for all of it: kept
            // short on the far side.
            w = w.max(n.f.abs() / (0.005 * a * self.base.mu_s * n.p.max(1e-9)));
        }
        w = w.max(self.base.xi * (n.t - s.t) / (0.5 * a));
        if s.theta > 0.0 && n.theta > 0.0 {
            w = w.max((n.theta / s.theta).ln().abs() / (0.1 * a));
        }
        w
    }

    /// The displacement the seating toe has taken up once the forward shear reached `fmax`.
    fn closure(&self, fmax: f64) -> f64 {
        self.rig
            .toe
            .map_or(0.0, |t| -t.gap_mm * (-fmax.max(0.0) / t.force_kpa).exp_m1())
    }

    /// The shear after the recorded displacement moves by `x` mm more than the plastic slip,
    /// from `s`: the springs give x K, and while the toe closes (forward loading above the
    /// largest shear so far) part of `x` goes into it, solved exactly.
    fn shear_after(&self, s: &State, x: f64) -> f64 {
        let linear = s.f + self.k * x;
        let Some(toe) = self.rig.toe else {
            return linear;
        };
        if x <= 0.0 || linear <= s.toe_fmax || s.toe_fmax > 40.0 * toe.force_kpa {
            return linear;
        }
        let c0 = self.closure(s.toe_fmax);
        let h = |f: f64| (f - s.f) / self.k + self.closure(f.max(s.toe_fmax)) - c0 - x;
        let lo = s.f.max(s.toe_fmax.min(linear));
        let lo = if h(lo) > 0.0 { s.f } else { lo };
        brent(h, lo, linear, 1e-13 * linear.abs().max(1.0), 0.0).unwrap_or(linear)
    }

    /// One substep of `dt` seconds from `s` (its `t` is set by the caller).
    fn substep(&self, s: &State, dt: f64, drive: Drive, p: f64) -> Result<State, GenError> {
        let b = &self.base;
        let (f_trial, resting, rig_move) = match drive {
            Drive::Slip(du) => (self.shear_after(s, du), du == 0.0, du),
            Drive::Shear(df) => (s.f + df, df == 0.0, 0.0),
        };
        let dir = direction_of(f_trial, s.dir);
        let reversed = s.f * f_trial < 0.0;
        let r_start = if reversed { 0.0 } else { s.r };
        let driven = (rig_move * dir > 0.0 && dt > 0.0).then(|| rig_move.abs() / dt);
        let step = Step {
            c: self,
            s,
            dt,
            p,
            dir,
            local: self.fx.local(b.mu_s, b.mu_k, b.kappa, p, dir),
            cos_start: (FRAC_PI_2 * r_start).cos(),
            resting,
            driven,
        };
        let magnitude = f_trial.abs();
        let at0 = step.at(0.0);
        let finish = |tr: Trial, f: f64, u: f64, dl: f64, r: f64| State {
            t: s.t,
            u,
            f,
            p,
            r,
            mu: tr.mu,
            mu_eff: tr.mu_eff,
            u_plastic: s.u_plastic + dir * dl,
            path: tr.path,
            theta: tr.theta,
            v_rate: tr.v,
            healed: tr.healed,
            heal_base: if resting && s.rest_t == 0.0 {
                s.healed
            } else {
                s.heal_base
            },
            rest_t: if resting { s.rest_t + dt } else { 0.0 },
            toe_fmax: s.toe_fmax.max(f),
            dir,
        };
        let inside = magnitude <= r_start * at0.mu_eff * p * (1.0 + 1e-12);
        match drive {
            Drive::Slip(du) => {
                if inside || magnitude == 0.0 {
                    let r = (magnitude / (at0.mu_eff * p)).min(1.0);
                    return Ok(finish(at0, f_trial, s.u + du, 0.0, r));
                }
                let g = |dl: f64| {
                    let tr = step.at(dl);
                    dir * self.shear_after(s, du - dir * dl) - tr.r * tr.mu_eff * p
                };
                // At hi the springs are back to zero shear.
                let hi = dir * (s.f / self.k + du);
                let dl = brent(g, 0.0, hi, 1e-15 * hi.max(1e-300), 1e-11 * p)
                    .ok_or(GenError::Unresolved { t: s.t })?;
                let tr = step.at(dl);
                let f = self.shear_after(s, du - dir * dl);
                let f = if f * dir < 0.0 { 0.0 } else { f };
                Ok(finish(tr, f, s.u + du, dl, tr.r))
            }
            Drive::Shear(df) => {
                let springs =
                    df / self.k + self.closure(s.toe_fmax.max(f_trial)) - self.closure(s.toe_fmax);
                let elastic_u = s.u + springs;
                if inside || magnitude == 0.0 {
                    let r = (magnitude / (at0.mu_eff * p)).min(1.0);
                    return Ok(finish(at0, f_trial, elastic_u, 0.0, r));
                }
                let h = |dl: f64| {
                    let tr = step.at(dl);
                    tr.r * tr.mu_eff * p - magnitude
                };
                let mut hi = 1e-9_f64.max(s.path * 1e-9);
                while h(hi) < 0.0 {
                    hi *= 4.0;
                    if hi > 1e3 {
                        return Err(GenError::Runaway {
                            t: s.t + dt,
                            shear_kpa: f_trial,
                            capacity_kpa: step.at(hi).mu_eff * p,
                        });
                    }
                }
                let dl = brent(h, 0.0, hi, 1e-15 * hi, 1e-11 * p)
                    .ok_or(GenError::Unresolved { t: s.t })?;
                let tr = step.at(dl);
                Ok(finish(tr, f_trial, elastic_u + dir * dl, dl, tr.r))
            }
        }
    }
}

/// The sliding direction a trial shear `f_trial` loads in: its sign, or `previous` at zero
/// shear (the contact keeps the direction it had).
fn direction_of(f_trial: f64, previous: f64) -> f64 {
    if f_trial > 0.0 {
        1.0
    } else if f_trial < 0.0 {
        -1.0
    } else {
        previous
    }
}

/// A root of `g` in [a, b] where g(a) and g(b) differ in sign (Brent's method: inverse
/// quadratic interpolation, secant and bisection), to |Δx| ≤ `xtol` or |g| ≤ `ftol`.
pub fn brent(g: impl Fn(f64) -> f64, a: f64, b: f64, xtol: f64, ftol: f64) -> Option<f64> {
    let (mut a, mut b) = (a, b);
    let (mut fa, mut fb) = (g(a), g(b));
    if fa == 0.0 {
        return Some(a);
    }
    if fb == 0.0 {
        return Some(b);
    }
    if fa * fb > 0.0 || !fa.is_finite() || !fb.is_finite() {
        return None;
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if fb * fc > 0.0 {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * xtol;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb.abs() <= ftol {
            return Some(b);
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qa = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qa * (qa - r) - (b - a) * (r - 1.0));
                q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = g(b);
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_roots_of_steep_and_flat_functions() {
        let r = brent(|x| x * x - 2.0, 0.0, 2.0, 1e-15, 0.0).unwrap();
        assert!((r - 2f64.sqrt()).abs() < 1e-12);
        let r = brent(
            |x| 1e9 * (x - 1e-7) + (x * 1e7).ln_1p(),
            0.0,
            1.0,
            1e-20,
            0.0,
        )
        .unwrap();
        assert!((1e9 * (r - 1e-7) + (r * 1e7).ln_1p()).abs() < 1e-6);
        assert!(brent(|x| x + 1.0, 0.0, 1.0, 1e-12, 0.0).is_none());
    }
}
