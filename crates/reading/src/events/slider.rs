//! A spring-slider with rate-and-state friction (Dieterich–Ruina), the model friction labs fit
//! to each velocity step on its own (xlook's `rsfit`, RSFit3000): a load point moving at v_lp
//! pulls a block through a spring of stiffness k (machine and sample together, in friction
//! per mm of load-point travel); the block slides at v with
//!
//! μ = μ₀ + a ln(v/v₀) + b ln(v₀θ/D_c),   dμ/dt = k (v_lp − v),
//!
//! and the state θ follows the ageing law dθ/dt = 1 − vθ/D_c or the slip law
//! dθ/dt = −(vθ/D_c) ln(vθ/D_c). It shares no code with the subloading model, on purpose: the
//! per-event fits are a second, independent reading of the record.
//!
//! With an infinitely stiff spring the block follows the load point (v = v_lp) and both laws
//! integrate exactly over a stretch of constant rate; with a finite spring the two equations are
//! integrated by backward Euler in (μ, ln θ) with Newton's method, in substeps of at most a
//! twentieth of D_c of slip while anything moves. Where the slider has settled (steady sliding
//! long after a step, the state relaxed within a row when D_c is short), substeps of a twentieth
//! of D_c change nothing and only cost: the substep then doubles as long as its local error
//! (half the gap between the backward and the forward Euler step) stays below
//! [`CALM_TOLERANCE`], and falls back to the finest one at every change of the load-point rate.

use serde::Serialize;

/// The evolution law of the state variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StateLaw {
    /// dθ/dt = 1 − vθ/D_c (Dieterich): the contact heals at rest.
    Ageing,
    /// dθ/dt = −(vθ/D_c) ln(vθ/D_c) (Ruina): no healing without slip.
    Slip,
}

/// How long the substeps of the compliant integration are: the finest doubled `doublings`
/// times, while the local error stays below `tolerance`; `substeps` counts them.
struct Pace {
    doublings: u32,
    tolerance: f64,
    substeps: usize,
}

/// Parameters of a spring-slider; the reference state is steady sliding at v₀ with μ = μ₀.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slider {
    /// State law.
    pub law: StateLaw,
    /// Direct-effect coefficient a.
    pub a: f64,
    /// Evolution coefficient b.
    pub b: f64,
    /// Characteristic slip D_c [mm].
    pub d_c: f64,
    /// Spring stiffness [friction per mm of load-point travel]; infinite for a rigid load.
    pub k: f64,
    /// Reference (initial) slip rate v₀ [mm/s].
    pub v0: f64,
    /// Steady friction at v₀.
    pub mu0: f64,
}

/// Largest slip per substep of the compliant integration, as a share of D_c.
const SUBSTEP_SHARE_OF_DC: f64 = 0.05;
/// Most substeps in one interval between rows: beyond it the parameters are absurd for the
/// record (a D_c far below the resolution) and the run is refused.
const MAX_SUBSTEPS: usize = 2_000;
/// Newton iterations of one backward-Euler substep.
const NEWTON_ITERATIONS: usize = 40;
/// Local error (in ln θ, and in μ per a) below which a substep longer than the finest is kept:
/// far below what a record resolves (a noise of 1e-4 in μ is a fine one, a of 1e-3 a small one),
/// so that only a settled slider takes the long substeps.
const CALM_TOLERANCE: f64 = 1e-6;
/// Largest doubling of the finest substep (2^20 substeps of D_c/20: far beyond any row).
const MAX_DOUBLINGS: u32 = 20;

impl Slider {
    /// Friction at each time of `time`, the load point moving at `v_lp[i]` over
    /// (`time[i−1]`, `time[i]`] (`v_lp[0]` is unused: the run starts steady at v₀). `None` when
    /// the integration fails (absurd parameters).
    pub fn friction(&self, time: &[f64], v_lp: &[f64]) -> Option<Vec<f64>> {
        self.integrate(time, v_lp, CALM_TOLERANCE).map(|(mu, _)| mu)
    }

    /// [`Slider::friction`] with substeps longer than the finest kept below the local error
    /// `calm_tolerance` (a negative one keeps every substep the finest), and the number of
    /// backward-Euler substeps taken.
    fn integrate(
        &self,
        time: &[f64],
        v_lp: &[f64],
        calm_tolerance: f64,
    ) -> Option<(Vec<f64>, usize)> {
        if !(self.a > 0.0 && self.d_c > 0.0 && self.v0 > 0.0 && self.k > 0.0) {
            return None;
        }
        let mut out = Vec::with_capacity(time.len());
        let mut mu = self.mu0;
        let mut psi = (self.d_c / self.v0).ln();
        // ln(v₀/D_c), once per run rather than once per row and substep (the same value).
        let ln_v0_dc = (self.v0 / self.d_c).ln();
        out.push(mu);
        // Doublings of the finest substep the slider has earned by settling (carried from row
        // to row, reset where the load-point rate changes: a transient starts there).
        let mut pace = Pace {
            doublings: 0,
            tolerance: calm_tolerance,
            substeps: 0,
        };
        for i in 1..time.len() {
            let dt = time[i] - time[i - 1];
            let v = v_lp[i].abs().max(1e-12 * self.v0);
            if v_lp[i] != v_lp[i - 1] {
                pace.doublings = 0;
            }
            if dt <= 0.0 {
                out.push(mu);
                continue;
            }
            if self.k.is_infinite() {
                psi = self.rigid_state(psi, v, dt);
                mu = self.mu0 + self.a * (v / self.v0).ln() + self.b * ln_v0_dc + self.b * psi;
            } else {
                (mu, psi) = self.compliant_interval(mu, psi, v, dt, ln_v0_dc, &mut pace)?;
            }
            if !mu.is_finite() {
                return None;
            }
            out.push(mu);
        }
        Some((out, pace.substeps))
    }

    /// ln θ after sliding at the constant rate `v` for `dt` (exact for both laws).
    fn rigid_state(&self, psi: f64, v: f64, dt: f64) -> f64 {
        let decay = (-v * dt / self.d_c).exp();
        match self.law {
            StateLaw::Ageing => {
                let ss = self.d_c / v;
                (ss + (psi.exp() - ss) * decay).ln()
            }
            StateLaw::Slip => {
                // ln(vθ/D_c) decays exponentially with slip.
                let l0 = psi + (v / self.d_c).ln();
                l0 * decay - (v / self.d_c).ln()
            }
        }
    }

    /// The slip rate v and ln(v/D_c), given `ln_v0_dc` = ln(v₀/D_c): the logarithm comes from
    /// the exponent, not from v (the integration's inner loop would take one per iteration).
    #[inline]
    fn rate_and_log(&self, mu: f64, psi: f64, ln_v0_dc: f64) -> (f64, f64) {
        let x = ((mu - self.mu0 - self.b * (psi + ln_v0_dc)) / self.a).min(200.0);
        (self.v0 * x.exp(), ln_v0_dc + x)
    }

    /// One interval of constant load-point rate `v_lp` under a finite spring (`ln_v0_dc` is
    /// ln(v₀/D_c)), in substeps of at most a twentieth of D_c of slip, doubled as `pace` allows
    /// while the slider stays settled (see the module's note).
    fn compliant_interval(
        &self,
        mu: f64,
        psi: f64,
        v_lp: f64,
        dt: f64,
        ln_v0_dc: f64,
        pace: &mut Pace,
    ) -> Option<(f64, f64)> {
        let mut start_rates = self.rates(mu, psi, ln_v0_dc);
        let travel = v_lp.max(start_rates.0) * dt;
        let n = ((travel / (SUBSTEP_SHARE_OF_DC * self.d_c)).ceil() as usize).max(1);
        if n > MAX_SUBSTEPS {
            return None;
        }
        let h = dt / n as f64;
        let (mut m, mut p) = (mu, psi);
        let mut done = 0;
        while done < n {
            let units = (1usize << pace.doublings).min(n - done);
            let hk = units as f64 * h;
            let (m1, p1, converged) = self.backward_euler(m, p, v_lp, hk, ln_v0_dc)?;
            pace.substeps += 1;
            let error = self.local_error((m, p), start_rates, (m1, p1), v_lp, hk);
            if units > 1 && !(converged && error <= pace.tolerance) {
                // Too long a substep for what moves: halve it and try again (from the same
                // start, its rates kept).
                pace.doublings -= 1;
                continue;
            }
            (m, p) = (m1, p1);
            start_rates = self.rates(m, p, ln_v0_dc);
            done += units;
            if error <= 0.25 * pace.tolerance && pace.doublings < MAX_DOUBLINGS {
                pace.doublings += 1;
            }
        }
        Some((m, p))
    }

    /// The slip rate v and the state's rate dψ/dt at (`mu`, `psi`) (`ln_v0_dc` is ln(v₀/D_c)).
    fn rates(&self, mu: f64, psi: f64, ln_v0_dc: f64) -> (f64, f64) {
        let (v, ln_v_dc) = self.rate_and_log(mu, psi, ln_v0_dc);
        let g = match self.law {
            StateLaw::Ageing => (-psi).exp() - v / self.d_c,
            StateLaw::Slip => -(v / self.d_c) * (ln_v_dc + psi),
        };
        (v, g)
    }

    /// The local error of a backward-Euler substep of length `h` from `start` (where the slip
    /// rate and the state's rate are `(v, g)`) to `end`: half the gap between it and the
    /// forward-Euler step from `start`, the larger of ln θ's and μ's (μ's per a).
    fn local_error(
        &self,
        (mu_n, psi_n): (f64, f64),
        (v, g): (f64, f64),
        (mu, psi): (f64, f64),
        v_lp: f64,
        h: f64,
    ) -> f64 {
        let mu_gap = (mu - mu_n - h * self.k * (v_lp - v)).abs() / self.a;
        let psi_gap = (psi - psi_n - h * g).abs();
        0.5 * mu_gap.max(psi_gap)
    }

    /// One backward-Euler substep of length `h` in (μ, ln θ), solved by Newton's method
    /// (`ln_v0_dc` is ln(v₀/D_c)), and whether Newton's method converged.
    fn backward_euler(
        &self,
        mu_n: f64,
        psi_n: f64,
        v_lp: f64,
        h: f64,
        ln_v0_dc: f64,
    ) -> Option<(f64, f64, bool)> {
        let (a, b, dc, k) = (self.a, self.b, self.d_c, self.k);
        let (mut mu, mut psi) = (mu_n, psi_n);
        for _ in 0..NEWTON_ITERATIONS {
            let (v, ln_v_dc) = self.rate_and_log(mu, psi, ln_v0_dc);
            // ∂v/∂μ = v/a, ∂v/∂ψ = −v b/a.
            let (dv_mu, dv_psi) = (v / a, -v * b / a);
            let f1 = mu - mu_n - h * k * (v_lp - v);
            let (g, dg_mu, dg_psi) = match self.law {
                StateLaw::Ageing => {
                    let e = (-psi).exp();
                    (e - v / dc, -dv_mu / dc, -e - dv_psi / dc)
                }
                StateLaw::Slip => {
                    let l = ln_v_dc + psi;
                    (
                        -(v / dc) * l,
                        -(dv_mu / dc) * (l + 1.0),
                        -(dv_psi / dc) * l - (v / dc) * (dv_psi / v + 1.0),
                    )
                }
            };
            let f2 = psi - psi_n - h * g;
            let (j11, j12) = (1.0 + h * k * dv_mu, h * k * dv_psi);
            let (j21, j22) = (-h * dg_mu, 1.0 - h * dg_psi);
            let det = j11 * j22 - j12 * j21;
            if !(det.is_finite() && det != 0.0) {
                return None;
            }
            let d_mu = (f1 * j22 - f2 * j12) / det;
            let d_psi = (j11 * f2 - j21 * f1) / det;
            // A step in μ of many a makes v jump by many e-folds: damp it.
            let limit = 2.0 * a;
            let scale = if d_mu.abs() > limit {
                limit / d_mu.abs()
            } else {
                1.0
            };
            mu -= scale * d_mu;
            psi -= scale * d_psi;
            if !(mu.is_finite() && psi.is_finite()) {
                return None;
            }
            if d_mu.abs() < 1e-12 && d_psi.abs() < 1e-10 {
                return Some((mu, psi, true));
            }
        }
        Some((mu, psi, false))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step_history(v0: f64, v1: f64, dt: f64, n0: usize, n1: usize) -> (Vec<f64>, Vec<f64>) {
        let mut t = vec![0.0];
        let mut v = vec![v0];
        for i in 1..=n0 + n1 {
            t.push(i as f64 * dt);
            v.push(if i <= n0 { v0 } else { v1 });
        }
        (t, v)
    }

    fn slider(law: StateLaw, k: f64) -> Slider {
        Slider {
            law,
            a: 0.01,
            b: 0.008,
            d_c: 0.02,
            k,
            v0: 0.001,
            mu0: 0.6,
        }
    }

    #[test]
    fn a_settled_slider_takes_long_substeps_and_keeps_the_finest_substeps_answer() {
        // A step up and a step down under a stiff spring with a short D_c: every row slides
        // 5 D_c, so the finest substeps are a hundred a row, and after each transient the
        // slider is steady for hundreds of rows.
        for law in [StateLaw::Ageing, StateLaw::Slip] {
            let mut s = slider(law, 500.0);
            s.d_c = 0.002;
            let (mut t, mut v) = step_history(0.001, 0.01, 1.0, 100, 400);
            let end = *t.last().unwrap();
            for i in 1..=400 {
                t.push(end + i as f64);
                v.push(0.003);
            }
            let (finest, finest_substeps) = s.integrate(&t, &v, -1.0).unwrap();
            let (paced, paced_substeps) = s.integrate(&t, &v, CALM_TOLERANCE).unwrap();
            assert_eq!(paced, s.friction(&t, &v).unwrap());
            let worst = finest
                .iter()
                .zip(&paced)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            // Far below the first-order scheme's own error (about 1e-3 here against substeps
            // ten times finer) and below any record's noise.
            assert!(worst < 1e-6, "{law:?}: {worst}");
            // The transients keep the finest substeps; the settled rows do not.
            assert!(
                paced_substeps * 5 < finest_substeps,
                "{law:?}: {paced_substeps} of {finest_substeps}"
            );
        }
    }

    #[test]
    fn a_rigid_step_jumps_by_a_and_settles_by_a_minus_b_per_e_fold() {
        for law in [StateLaw::Ageing, StateLaw::Slip] {
            let s = slider(law, f64::INFINITY);
            let (t, v) = step_history(0.001, 0.01, 0.01, 100, 2000);
            let mu = s.friction(&t, &v).unwrap();
            let jump = mu[101] - mu[100];
            let ln = 10f64.ln();
            // The first row after the step has slid 1e-4 mm = D_c/200: the state has barely
            // moved.
            assert!((jump - s.a * ln).abs() < 0.02 * s.a * ln, "{law:?}: {jump}");
            // After 0.2 mm = 10 D_c the state is within e⁻¹⁰ of steady state at the new rate:
            // the remainder is exact for each law (θ relaxes linearly in the ageing law,
            // ln(vθ/D_c) exponentially in the slip law).
            let decay = (-0.2f64 / s.d_c).exp();
            let remainder = match law {
                StateLaw::Ageing => s.b * (1.0 + 9.0 * decay).ln(),
                StateLaw::Slip => s.b * ln * decay,
            };
            let end = *mu.last().unwrap() - s.mu0;
            assert!(
                (end - (s.a - s.b) * ln - remainder).abs() < 1e-9,
                "{law:?}: {end}"
            );
        }
    }

    #[test]
    fn a_stiff_spring_follows_the_rigid_answer_and_a_soft_one_lags() {
        for law in [StateLaw::Ageing, StateLaw::Slip] {
            let (t, v) = step_history(0.001, 0.01, 0.01, 100, 2000);
            let rigid = slider(law, f64::INFINITY).friction(&t, &v).unwrap();
            let stiff = slider(law, 1e5).friction(&t, &v).unwrap();
            let worst = rigid
                .iter()
                .zip(&stiff)
                .skip(102)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst < 0.05 * 0.01 * 10f64.ln(), "{law:?}: {worst}");
            // A soft spring: friction rises over an elastic travel of about a/k after the step.
            let soft = slider(law, 5.0).friction(&t, &v).unwrap();
            assert!(soft[101] - soft[100] < 0.2 * (rigid[101] - rigid[100]));
            let end = *soft.last().unwrap() - 0.6;
            assert!((end - 0.002 * 10f64.ln()).abs() < 1e-4, "{law:?}: {end}");
        }
    }

    #[test]
    fn ageing_heals_during_a_slow_stretch_and_slip_law_needs_slip() {
        // A hundredfold slower stretch stands in for a hold: the ageing law's θ grows with
        // time, the slip law's with slip only.
        let (t, v) = step_history(0.001, 0.00001, 1.0, 10, 100);
        let age = slider(StateLaw::Ageing, f64::INFINITY)
            .friction(&t, &v)
            .unwrap();
        let slip = slider(StateLaw::Slip, f64::INFINITY)
            .friction(&t, &v)
            .unwrap();
        assert!(age.last().unwrap() > slip.last().unwrap());
    }

    #[test]
    fn absurd_parameters_fail_instead_of_returning_nonsense() {
        let mut s = slider(StateLaw::Ageing, 10.0);
        s.d_c = 1e-12;
        let (t, v) = step_history(0.001, 0.01, 1.0, 5, 5);
        assert!(s.friction(&t, &v).is_none());
        s.d_c = 0.02;
        s.a = 0.0;
        assert!(s.friction(&t, &v).is_none());
    }
}
