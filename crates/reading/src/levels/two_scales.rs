//! The decay past the peak read on two scales: the peak's own decay from μ_s towards μ_k
//! (the paper's κ, over a fraction of a millimetre) and a slow change with slip that goes on
//! over much of the slide (slip softening or hardening: wear, crushing, dilation).
//!
//! The first reading of the decay length takes the tail of the curve for its plateau. Where
//! friction keeps falling to the end of the slide, that "plateau" sits below the decayed
//! peak, the 1/e point of the excess lies far down the slope, and three such lengths past the
//! peak reach beyond the end: no residual and no slope are read, and a softening of 10–15 % over
//! the slide goes unseen. Here the curve past the peak is fitted with one scale,
//! level + A e^(−x/l), and with two, level + A e^(−x/l) + B e^(−x/L), the short one brief
//! enough that the slow change has a stretch of its own (three short lengths within half the
//! slide) and the long one at least three times longer (a slow change that has not saturated is
//! the long scale far beyond the slide, a straight line). The two are taken only where the
//! evidence for them, n_eff ln(SSR₁/SSR₂) less ln n_eff for each of the two parameters they
//! add (a BIC on the effective rows of what the two leave, as the held-out scores count), is
//! positive: a single slow decay (a small κ) leaves nothing for a second scale and is not cut
//! in two.
/// Share of the slide past the peak that three of the short scale's decay lengths may take at
/// most: the other half is where the trend is read on its own.
const DECAYED_WITHIN: f64 = 0.5;

/// Parameters the second scale adds (its length and its amplitude).
const ADDED_PARAMS: f64 = 2.0;

/// Rows the scales are searched on at most (every k-th row of a longer curve).
const SEARCH_ROWS: usize = 1000;

/// The long scale is at least this many times the short one.
const SCALES_APART: f64 = 3.0;

/// Decay lengths tried on each scale, per e-fold of their range, before the golden sections.
const GRID_PER_EFOLD: f64 = 4.0;

/// The short decay length of the curve `f` on `u` past its peak at row `ip` when it shows two
/// scales (see the module documentation); `decays` is how many decay lengths the residual is
/// read after, `rise_mm` the slip the loading took to rise to 90 % of its peak.
pub(super) fn short_decay(
    u: &[f64],
    f: &[f64],
    ip: usize,
    decays: f64,
    rise_mm: f64,
) -> Option<f64> {
    // From half the rise past the peak: the rounding of the peak itself is no decay.
    let start = u.iter().position(|&v| v >= u[ip] + 0.5 * rise_mm)?;
    let stride = (u.len() - start).div_ceil(SEARCH_ROWS).max(1);
    let (x, y): (Vec<f64>, Vec<f64>) = (start..u.len())
        .step_by(stride)
        .map(|i| (u[i] - u[ip], f[i]))
        .unzip();
    let after = *x.last()?;
    if x.len() < 4 * super::MIN_ROWS || after.is_nan() || after <= 0.0 {
        return None;
    }
    let shortest = (after / 500.0).max(1e-6);
    let one = best_over(shortest, 4.0 * after, |l| ssr(&fitted(&x, &y, l, None)))?;
    let short_most = DECAYED_WITHIN * after / decays;
    if short_most.is_nan() || short_most <= shortest {
        return None;
    }
    // The long scale on a grid from three short ones to far beyond the slide; for each, the
    // short one by golden sections.
    let steps = ((4000.0 * after / shortest).ln() * GRID_PER_EFOLD).ceil() as usize;
    let two = (0..=steps)
        .map(|k| shortest * (4000.0 * after / shortest).powf(k as f64 / steps as f64))
        .filter_map(|long| {
            let hi = short_most.min(long / SCALES_APART);
            let (l, s) = best_over(shortest, hi, |l| ssr(&fitted(&x, &y, l, Some(long))))?;
            Some((l, long, s))
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))?;
    // Independent rows of what the two scales leave: n (1 − ρ)/(1 + ρ) from its lag-1
    // autocorrelation ρ.
    let left = fitted(&x, &y, two.0, Some(two.1));
    let (_, inflation) = super::spread(&left, 5);
    let n_eff = left.len() as f64 / (inflation * inflation);
    let evidence = n_eff * (one.1 / two.2).ln() - ADDED_PARAMS * n_eff.max(1.0).ln();
    (evidence > 0.0).then_some(two.0)
}

fn ssr(r: &[f64]) -> f64 {
    let s: f64 = r.iter().map(|v| v * v).sum();
    if s.is_nan() {
        f64::INFINITY
    } else {
        s
    }
}

/// The residuals of `y` on `x` about level + A e^(−x/l) (+ B e^(−x/L) with a long scale
/// `long` = L), the linear coefficients by least squares (infinite where they are not
/// determined).
fn fitted(x: &[f64], y: &[f64], l: f64, long: Option<f64>) -> Vec<f64> {
    let basis = |x: f64| {
        [
            1.0,
            (-x / l).exp(),
            long.map_or(0.0, |big| (-x / big).exp()),
        ]
    };
    let n = if long.is_some() { 3 } else { 2 };
    // Normal equations on the first n basis functions.
    let mut m = [[0.0; 4]; 3];
    for (&xi, &yi) in x.iter().zip(y) {
        let p = basis(xi);
        for r in 0..n {
            for c in 0..n {
                m[r][c] += p[r] * p[c];
            }
            m[r][3] += p[r] * yi;
        }
    }
    let Some(c) = solve(&mut m, n) else {
        return vec![f64::INFINITY];
    };
    x.iter()
        .zip(y)
        .map(|(&xi, &yi)| {
            let p = basis(xi);
            yi - (0..n).map(|k| c[k] * p[k]).sum::<f64>()
        })
        .collect()
}

/// Gauss–Jordan on the n × n system in `m` (right-hand side in column 3).
fn solve(m: &mut [[f64; 4]; 3], n: usize) -> Option<[f64; 3]> {
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[piv][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, piv);
        let d = m[col][col];
        for v in m[col].iter_mut() {
            *v /= d;
        }
        let pivot_row = m[col];
        for (r, row) in m.iter_mut().enumerate().take(n) {
            if r != col {
                let k = row[col];
                for (v, p) in row.iter_mut().zip(&pivot_row) {
                    *v -= k * p;
                }
            }
        }
    }
    let c = [m[0][3], m[1][3], if n > 2 { m[2][3] } else { 0.0 }];
    c.iter().all(|v| v.is_finite()).then_some(c)
}

/// The decay length in [lo, hi] with the least `ssr`, and that least: a grid in ln l, then
/// golden sections about its best point.
fn best_over(lo: f64, hi: f64, ssr_of: impl Fn(f64) -> f64) -> Option<(f64, f64)> {
    if !(hi > lo && lo > 0.0) {
        return None;
    }
    let steps = ((hi / lo).ln() * GRID_PER_EFOLD).ceil().max(2.0) as usize;
    let grid: Vec<f64> = (0..=steps)
        .map(|k| lo * (hi / lo).powf(k as f64 / steps as f64))
        .collect();
    let l = super::least_over_grid(&grid, &ssr_of)?;
    let s = ssr_of(l);
    s.is_finite().then_some((l, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A loading past its peak at 0.1 mm: an excess of 0.04 decaying over `l` mm, a trend of
    /// `g` per mm, and a small noise.
    fn curve(l: f64, g: f64) -> (Vec<f64>, Vec<f64>) {
        let u: Vec<f64> = (0..2500).map(|i| i as f64 * 0.002).collect();
        let f = u
            .iter()
            .enumerate()
            .map(|(i, &u)| {
                let x = (u - 0.1).max(0.0);
                let rise = (u / 0.1).min(1.0);
                let noise = 4e-4 * ((i as f64 * 2.3).sin() + (i as f64 * 0.7).cos());
                rise * (0.38 + 0.04 * (-x / l).exp() + g * x) + noise
            })
            .collect();
        (u, f)
    }

    #[test]
    fn a_quick_decay_then_a_softening_reads_the_quick_decay() {
        let (u, f) = curve(0.25, -0.01);
        let l = short_decay(&u, &f, 50, 3.0, 0.09).expect("two scales");
        assert!((l - 0.25).abs() < 0.05, "{l}");
    }

    #[test]
    fn a_quick_decay_then_a_softening_that_saturates_reads_the_quick_decay() {
        // The slow change itself levels off: 0.05 lost over a 2.5 mm scale.
        let (u, f) = curve(0.25, 0.0);
        let f: Vec<f64> = u
            .iter()
            .zip(&f)
            .map(|(&u, &f)| f - 0.05 * (1.0 - (-(u - 0.1).max(0.0) / 2.5).exp()))
            .collect();
        let l = short_decay(&u, &f, 50, 3.0, 0.09).expect("two scales");
        assert!((l - 0.25).abs() < 0.05, "{l}");
    }

    #[test]
    fn one_slow_decay_is_not_cut_into_a_decay_and_a_trend() {
        // κ small: the excess decays over 2 mm of a 5 mm slide, nothing else.
        let (u, f) = curve(2.0, 0.0);
        assert_eq!(short_decay(&u, &f, 50, 3.0, 0.09), None);
        // Nor a quick decay with no trend: one scale describes it.
        let (u, f) = curve(0.25, 0.0);
        assert_eq!(short_decay(&u, &f, 50, 3.0, 0.09), None);
    }
}
