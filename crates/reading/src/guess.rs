//! Physically informed first guesses read off the curves: the peak gives μ_s, the plateau the
//! steady friction (μ_k with ξ), the decay length κ + ξ/v, the rise ũ, hold recoveries ξ.

use crate::fit_test::FitTest;
use subfric_model::{Control, Model};

/// Features of the first monotonic loading of a slip-controlled test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveFeatures {
    /// Peak friction (shear/normal).
    pub peak: f64,
    /// Slip from the start to 90 % of the peak [mm].
    pub rise_mm: f64,
    /// Friction at the end of the first loading.
    pub plateau: f64,
    /// Slip over which the post-peak excess falls by e [mm]; `None` without softening.
    pub decay_mm: Option<f64>,
    /// Slip from the peak to the end of the first loading [mm].
    pub slide_after_peak_mm: f64,
    /// Mean slip rate of the loading [mm/s].
    pub rate: f64,
    /// Recovery after holds: (hold duration [s], friction before, peak after).
    pub holds: [Option<(f64, f64, f64)>; 1],
}

/// Reads the features of the first monotonic loading of a slip-controlled test.
pub fn features(t: &FitTest) -> Option<CurveFeatures> {
    if t.control != Control::Slip || t.len() < 10 {
        return None;
    }
    let u0 = t.imposed[0];
    let sign = {
        let far = t.imposed.iter().skip(1).find(|u| (**u - u0).abs() > 1e-9)?;
        (far - u0).signum()
    };
    let end = loading_end(t, 0, sign);
    if end < 8 {
        return None;
    }
    let f = friction(t, 0..end, sign)?;
    let (ip, &peak) = f.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    if peak <= 0.0 {
        return None;
    }
    let i90 = f.iter().position(|&v| v >= 0.9 * peak)?;
    let rise_mm = (sign * (t.imposed[i90] - u0)).max(1e-6);
    let tail = ((end - ip) / 10).max(1);
    let plateau = f[end - tail..end].iter().sum::<f64>() / tail as f64;
    let target = plateau + (peak - plateau) / std::f64::consts::E;
    let decay_mm = if peak - plateau > 0.02 * peak {
        f[ip..end]
            .iter()
            .position(|&v| v <= target)
            .map(|k| (sign * (t.imposed[ip + k] - t.imposed[ip])).max(1e-6))
    } else {
        None
    };
    let dt = t.time[end - 1] - t.time[0];
    let rate = (sign * (t.imposed[end - 1] - u0) / dt.max(1e-12)).max(1e-12);
    // A hold right after the first loading: recovery of friction on reloading.
    let mut holds = [None];
    if end + 2 < t.len() {
        let h0 = end - 1;
        let mut h1 = h0;
        while h1 + 1 < t.len() && (t.imposed[h1 + 1] - t.imposed[h0]).abs() <= 1e-9 {
            h1 += 1;
        }
        let duration = t.time[h1] - t.time[h0];
        if h1 > h0 && duration > 0.0 {
            let look = h1 + 1..(h1 + 41).min(t.len());
            let after = friction(t, look, sign)
                .unwrap_or_default()
                .into_iter()
                .fold(f64::MIN, f64::max);
            if after.is_finite() && after > f64::MIN {
                holds[0] = Some((duration, f[end - 1], after));
            }
        }
    }
    Some(CurveFeatures {
        peak,
        rise_mm,
        plateau,
        decay_mm,
        slide_after_peak_mm: sign * (t.imposed[end - 1] - t.imposed[ip]),
        rate,
        holds,
    })
}

/// One past the last row of the monotonic loading that starts at row `from` in direction
/// `sign`: until the imposed column reverses, or stands still for three rows (the loading then
/// ends at the first of them).
pub fn loading_end(t: &FitTest, from: usize, sign: f64) -> usize {
    let mut end = from + 1;
    let mut still = 0;
    while end < t.len() {
        let du = sign * (t.imposed[end] - t.imposed[end - 1]);
        if du < -1e-12 {
            break;
        }
        still = if du <= 1e-12 { still + 1 } else { 0 };
        if still >= 3 {
            end -= still - 1;
            break;
        }
        end += 1;
    }
    end
}

/// sign·shear/normal over `rows`, or `None` if a row cannot give one (normal stress not
/// positive, or a value not finite): the features would then be read off a meaningless number.
fn friction(t: &FitTest, rows: std::ops::Range<usize>, sign: f64) -> Option<Vec<f64>> {
    rows.map(|i| {
        let (s, n) = (t.measured[i], t.normal[i]);
        (s.is_finite() && n.is_finite() && n > 0.0).then(|| sign * s / n)
    })
    .collect()
}

/// Whether a guess can be handed to the optimiser: the five base parameters finite and
/// positive, μ_k ≤ μ_s. An outlier read as a feature can make a guess absurd, but never
/// invalid.
fn usable(m: &Model) -> bool {
    let p = &m.params;
    [p.mu_s, p.mu_k, p.kappa, p.xi, p.u_tilde]
        .iter()
        .all(|v| v.is_finite() && *v > 0.0)
        && p.mu_k <= p.mu_s
}

/// Smallest μ_k of a guess, as a share of μ_s (a plateau reading may imply μ_k ≤ 0 when the
/// decay is split mostly into ξ).
const MIN_MU_K_SHARE: f64 = 0.02;

/// The template with the five base parameters [μ_s, μ_k, κ, ξ, ũ] set (μ₀ = μ_s).
fn guess(template: &Model, p: [f64; 5]) -> Model {
    let mut m = *template;
    m.params.mu_s = p[0];
    m.params.mu_k = p[1];
    m.params.kappa = p[2];
    m.params.xi = p[3];
    m.params.u_tilde = p[4];
    m.params.mu_0 = None;
    m
}

/// First guesses from traction-controlled tests: μ_s somewhat above the largest imposed
/// friction, ũ from the slip of the first loading (r rises from 0 to F/(μ_s p) over it, Eq. 29),
/// and a coarse grid of μ_k/μ_s, κ and ξ, which the ratcheting of later cycles sorts out.
pub fn traction_guesses(t: &FitTest, template: &Model) -> Vec<Model> {
    let mut out = Vec::new();
    if t.control != Control::Shear || t.len() < 5 {
        return out;
    }
    let f: Vec<f64> = (0..t.len())
        .map(|i| (t.imposed[i] / t.normal[i]).abs())
        .collect();
    if f.iter().any(|v| !v.is_finite()) || t.normal.iter().any(|n| *n <= 0.0) {
        return out;
    }
    let peak = f.iter().cloned().fold(0.0, f64::max);
    if peak <= 0.0 {
        return out;
    }
    // End of the first loading: the first row after which |shear| falls.
    let i1 = (1..t.len()).find(|&i| f[i] < f[i - 1]).unwrap_or(t.len()) - 1;
    let first_slip = (t.measured[i1] - t.measured[0]).abs().max(1e-6);
    for &factor in &[1.05, 1.2, 1.4, 1.7, 2.2] {
        let mu_s = peak * factor;
        let r = f[i1] / mu_s;
        let u_tilde = (-(std::f64::consts::FRAC_PI_2 * r).cos().ln()
            / (std::f64::consts::FRAC_PI_2 * first_slip))
            .max(0.2);
        for &q in &[0.5, 0.75, 0.9] {
            for &kappa in &[0.3, 1.5, 5.0] {
                for &xi in &[1e-4, 1e-3, 1e-2] {
                    out.push(guess(template, [mu_s, q * mu_s, kappa, xi, u_tilde]));
                }
            }
        }
    }
    out.retain(usable);
    out
}

/// First guesses for the base parameters from the slip-controlled tests (several splits of
/// the decay between κ and ξ, which one rate cannot tell apart). Others come from `template`.
pub fn first_guesses(tests: &[FitTest], template: &Model) -> Vec<Model> {
    let mut out = Vec::new();
    for t in tests {
        out.extend(traction_guesses(t, template));
        let Some(c) = features(t) else { continue };
        let u_tilde = 1.181 / c.rise_mm;
        let decay = c.decay_mm.map(|l| 1.0 / l);
        for &mu_s_factor in &[1.02, 1.15] {
            let mu_s = c.peak * mu_s_factor;
            let mu_ss = c.plateau.min(mu_s);
            let lambdas: Vec<f64> = match decay {
                Some(l) => vec![l],
                None => vec![1.0, 30.0],
            };
            let mut xis: Vec<f64> = Vec::new();
            if let Some((dur, before, after)) = c.holds[0] {
                let gap = (mu_s - before).max(1e-6);
                let frac = ((after - before) / gap).clamp(1e-4, 0.999);
                xis.push(-(1.0 - frac).ln() / dur);
            }
            for &lam in &lambdas {
                // Splits of the decay rate λ = κ + ξ/v: fixed shares, and ξ from a hold recovery.
                let splits = [0.02, 0.3, 0.7]
                    .iter()
                    .map(|phi| ((1.0 - phi) * lam, phi * lam * c.rate))
                    .chain(
                        xis.iter()
                            .map(|&xi| ((lam - xi / c.rate).max(0.05 * lam), xi)),
                    );
                for (kappa, xi) in splits {
                    // μ_k that gives the plateau: μ_ss = (κv μ_k + ξ μ_s)/(κv + ξ).
                    let kv = kappa * c.rate;
                    // Kept above a floor, but μ_k ≤ μ_ss wins when the plateau lies below it (an
                    // outlier read as the peak): `f64::clamp` would panic on min > max.
                    let mu_k = ((mu_ss * (kv + xi) - xi * mu_s) / kv)
                        .max(MIN_MU_K_SHARE * mu_s)
                        .min(mu_ss);
                    out.push(guess(template, [mu_s, mu_k, kappa, xi, u_tilde]));
                }
            }
        }
    }
    out.retain(usable);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfric_model::{simulate, Params, Protocol};

    /// A slide at 0.01 mm/s from the sample parameters (peak, softening, plateau), a hold of
    /// 200 s and a reload: every feature the guesses read.
    fn slide_hold_slide() -> FitTest {
        let truth = Model::base(Params::sample()).unwrap();
        let mut time = Vec::new();
        let mut slip = Vec::new();
        for i in 0..=300 {
            time.push(i as f64);
            slip.push(0.01 * i as f64);
        }
        for i in 1..=200 {
            time.push(300.0 + i as f64);
            slip.push(3.0);
        }
        for i in 1..=100 {
            time.push(500.0 + i as f64);
            slip.push(3.0 + 0.01 * i as f64);
        }
        let normal = vec![100.0; time.len()];
        let proto = Protocol {
            control: Control::Slip,
            time: &time,
            imposed: &slip,
            normal: &normal,
            initial_slip: 0.0,
            initial: Default::default(),
        };
        let shear = simulate(&truth, &proto).unwrap().shear;
        FitTest::new("shs", Control::Slip, time, slip, shear, normal)
    }

    fn assert_valid(guesses: &[Model]) {
        assert!(!guesses.is_empty());
        for g in guesses {
            let p = &g.params;
            for (name, v) in [
                ("mu_s", p.mu_s),
                ("mu_k", p.mu_k),
                ("kappa", p.kappa),
                ("xi", p.xi),
                ("u_tilde", p.u_tilde),
            ] {
                assert!(v.is_finite() && v > 0.0, "{name} = {v} in {p:?}");
            }
            assert!(p.mu_k <= p.mu_s, "{p:?}");
        }
    }

    #[test]
    fn clean_curves_give_valid_guesses_near_the_truth() {
        let template = Model::base(Params::sample()).unwrap();
        let g = first_guesses(&[slide_hold_slide()], &template);
        assert_valid(&g);
        let truth = Params::sample();
        assert!(g
            .iter()
            .any(|m| (m.params.mu_s - truth.mu_s).abs() < 0.15 * truth.mu_s));
    }

    #[test]
    fn one_shear_value_fifty_times_the_plateau_does_not_panic() {
        // Issue 13: the spike becomes the "peak", 2 % of which exceeds the plateau, and
        // clamping μ_k into [0.02 μ_s, μ_ss] had min > max.
        let mut t = slide_hold_slide();
        let plateau = t.measured[290];
        t.measured[150] = 50.0 * plateau;
        assert_valid(&first_guesses(
            &[t],
            &Model::base(Params::sample()).unwrap(),
        ));
    }

    #[test]
    fn one_normal_stress_row_of_1_kpa_does_not_panic() {
        let mut t = slide_hold_slide();
        t.normal[150] = 1.0;
        assert_valid(&first_guesses(
            &[t],
            &Model::base(Params::sample()).unwrap(),
        ));
    }

    #[test]
    fn non_finite_or_zero_rows_give_no_guess_rather_than_a_nan_one() {
        let template = Model::base(Params::sample()).unwrap();
        for bad in [0.0, f64::NAN, f64::INFINITY, -100.0] {
            let mut t = slide_hold_slide();
            t.normal[150] = bad;
            let g = first_guesses(std::slice::from_ref(&t), &template);
            assert!(g.iter().all(|m| m.params.mu_s.is_finite()), "normal {bad}");
            let mut t = slide_hold_slide();
            t.measured[150] = bad;
            for m in first_guesses(&[t], &template) {
                assert!(
                    [m.params.mu_s, m.params.mu_k, m.params.kappa, m.params.xi]
                        .iter()
                        .all(|v| v.is_finite()),
                    "measured {bad}: {m:?}"
                );
            }
        }
    }

    #[test]
    fn traction_guesses_survive_a_row_of_zero_normal_stress() {
        let s = slide_hold_slide();
        let mut t = FitTest::new(
            "pulsating",
            Control::Shear,
            s.time.clone(),
            s.measured.clone(),
            s.imposed.clone(),
            s.normal.clone(),
        );
        t.normal[10] = 0.0;
        for m in traction_guesses(&t, &Model::base(Params::sample()).unwrap()) {
            assert!(
                m.params.mu_s.is_finite() && m.params.u_tilde.is_finite(),
                "{m:?}"
            );
        }
    }
}
