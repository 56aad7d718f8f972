//! Evidence from the residual itself: the base model's held-out residual (in friction units) is
//! regressed on physical features of each row — log slip rate and its recent change, time at
//! rest, accumulated slip, normal stress, sliding direction, cycle number, time — by a sparse
//! (lasso) fit whose penalty is chosen by cross-validation over the same held-out pieces. The
//! features that carry the residual support or question the family the candidate fits chose,
//! and describe a gap no candidate explains ("grows with time, not with slip").

use crate::candidates::Effect;
use crate::folds::Piece;
use crate::score::HeldOut;
use serde::Serialize;
use subfric_model::Control;
use subfric_reading::PreparedTest;
use subfric_reading::SegmentKind;

/// A physical feature of a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Feature {
    /// ln(v / v_ref) of the imposed sliding rate (0 at rest).
    LogRate,
    /// ln(v / v_before) after a velocity step, fading with slip.
    RateChange,
    /// ln(1 + time at rest), in a hold and fading with slip after it.
    TimeAtRest,
    /// Accumulated imposed travel since the start of the test.
    AccumulatedSlip,
    /// ln(p / p_ref).
    NormalStress,
    /// +1 sliding forward, −1 backward.
    Direction,
    /// Cycle number.
    Cycle,
    /// Time since the start of the test.
    Time,
}

impl Feature {
    /// Every feature.
    pub const ALL: [Feature; FEATURES] = [
        Feature::LogRate,
        Feature::RateChange,
        Feature::TimeAtRest,
        Feature::AccumulatedSlip,
        Feature::NormalStress,
        Feature::Direction,
        Feature::Cycle,
        Feature::Time,
    ];

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Feature::LogRate => "log slip rate",
            Feature::RateChange => "recent change of log slip rate",
            Feature::TimeAtRest => "time at rest",
            Feature::AccumulatedSlip => "accumulated slip",
            Feature::NormalStress => "normal stress",
            Feature::Direction => "slip direction",
            Feature::Cycle => "cycle number",
            Feature::Time => "time",
        }
    }

    /// The effect family a feature points to (time points to none: a drift).
    pub fn family(self) -> Option<Effect> {
        match self {
            Feature::LogRate | Feature::RateChange => Effect::of_slip_rate(),
            Feature::TimeAtRest => Effect::of_time_at_rest(),
            Feature::AccumulatedSlip | Feature::Cycle => Effect::of_accumulated_slip(),
            Feature::NormalStress => Effect::of_normal_stress(),
            Feature::Direction => Effect::of_sliding_direction(),
            Feature::Time => None,
        }
    }
}

/// One feature's part in the sparse fit.
#[derive(Clone, Debug, Serialize)]
pub struct FeatureWeight {
    /// The feature.
    pub feature: Feature,
    /// Its name.
    pub name: String,
    /// The family it points to.
    pub family: Option<Effect>,
    /// Coefficient on the standardised feature (friction units).
    pub coefficient: f64,
    /// Share of the explained variance lost when it is left out.
    pub share: f64,
}

/// What the residual itself says.
#[derive(Clone, Debug, Serialize)]
pub struct ResidualEvidence {
    /// Cross-validated share of the residual's variance the sparse fit explains.
    pub r2: f64,
    /// Features with a non-zero coefficient, largest share first.
    pub features: Vec<FeatureWeight>,
    /// The family the strongest feature points to (None: time, a drift, or nothing).
    pub leading_family: Option<Effect>,
    /// In words.
    pub summary: String,
}

/// Features of every fitted row of each test (rows: per test, per fitted row).
fn row_features(tests: &[PreparedTest], v_ref: f64, p_ref: f64) -> Vec<Vec<[f64; FEATURES]>> {
    tests
        .iter()
        .map(|p| {
            let full = &p.full;
            let seg = &p.segmentation;
            let n = full.len();
            // Per full row: level rate, rate before the last step, travel since the last
            // event, time at rest.
            let mut rate = vec![0.0; n];
            for l in &seg.levels {
                for r in &mut rate[l.start.min(n)..l.end.min(n)] {
                    *r = l.rate;
                }
            }
            let fade = 0.05f64.max(0.25 * subfric_reading::SegmentOptions::default().transient_mm);
            let forward = seg
                .levels
                .first()
                .map_or(1.0, |l| if l.rate < 0.0 { -1.0 } else { 1.0 });
            let mut travel = vec![0.0; n];
            for i in 1..n {
                travel[i] = travel[i - 1] + (full.imposed[i] - full.imposed[i - 1]).abs();
            }
            let mut step_ln = vec![0.0; n];
            let mut step_at = vec![f64::NAN; n];
            let steps = seg.step_rates();
            for (&c, (a, b)) in seg.rate_changes.iter().zip(steps) {
                let ln = (b.abs() / a.abs()).ln();
                if ln.is_finite() {
                    for i in c + 1..n {
                        step_ln[i] = ln;
                        step_at[i] = travel[c];
                    }
                }
            }
            let mut rest = vec![0.0; n];
            let mut rest_end = vec![f64::NAN; n];
            for &(s, e) in &seg.holds {
                let t0 = full.time[s.saturating_sub(1)];
                for (r, t) in rest[s..e.min(n)].iter_mut().zip(&full.time[s..e.min(n)]) {
                    *r = (1.0 + t - t0).ln();
                }
                let d = (1.0 + full.time[(e - 1).min(n - 1)] - t0).ln();
                for i in e.min(n)..n {
                    rest[i] = d;
                    rest_end[i] = travel[(e - 1).min(n - 1)];
                }
            }
            p.kept
                .iter()
                .map(|&r| {
                    let sliding = seg.row_kind.get(r) != Some(&SegmentKind::Hold);
                    let v = rate[r].abs();
                    let fades = |at: f64| {
                        if at.is_finite() {
                            (-(travel[r] - at) / fade).exp()
                        } else {
                            1.0
                        }
                    };
                    [
                        if sliding && v > 0.0 {
                            (v / v_ref).ln()
                        } else {
                            0.0
                        },
                        step_ln[r] * fades(step_at[r]),
                        rest[r] * if sliding { fades(rest_end[r]) } else { 1.0 },
                        travel[r],
                        (full.normal[r] / p_ref).ln(),
                        if rate[r] * forward < 0.0 { -1.0 } else { 1.0 },
                        seg.cycle_of_row.get(r).copied().unwrap_or(0) as f64,
                        full.time[r] - full.time[0],
                    ]
                })
                .collect()
        })
        .collect()
}

/// Weighted lasso by coordinate descent on standardised columns; returns coefficients.
fn lasso(x: &[[f64; FEATURES]], y: &[f64], w: &[f64], lambda: f64) -> [f64; FEATURES] {
    let mut beta = [0.0; 8];
    let wsum: f64 = w.iter().sum();
    if wsum <= 0.0 {
        return beta;
    }
    let norm: Vec<f64> = (0..FEATURES)
        .map(|j| x.iter().zip(w).map(|(r, wi)| wi * r[j] * r[j]).sum::<f64>() / wsum)
        .collect();
    let mut resid: Vec<f64> = y.to_vec();
    for _ in 0..200 {
        let mut change = 0.0f64;
        for j in 0..FEATURES {
            if norm[j] <= 1e-12 {
                continue;
            }
            let rho: f64 = x
                .iter()
                .zip(&resid)
                .zip(w)
                .map(|((r, e), wi)| wi * r[j] * (e + beta[j] * r[j]))
                .sum::<f64>()
                / wsum;
            let new = if rho > lambda {
                (rho - lambda) / norm[j]
            } else if rho < -lambda {
                (rho + lambda) / norm[j]
            } else {
                0.0
            };
            let d = new - beta[j];
            if d != 0.0 {
                for (e, r) in resid.iter_mut().zip(x) {
                    *e -= d * r[j];
                }
                beta[j] = new;
                change = change.max(d.abs());
            }
        }
        if change < 1e-9 {
            break;
        }
    }
    beta
}

fn weighted_r2(x: &[[f64; FEATURES]], y: &[f64], w: &[f64], beta: &[f64; FEATURES]) -> f64 {
    let (mut sse, mut sst) = (0.0, 0.0);
    for ((r, yi), wi) in x.iter().zip(y).zip(w) {
        let pred: f64 = (0..FEATURES).map(|j| beta[j] * r[j]).sum();
        sse += wi * (yi - pred).powi(2);
        sst += wi * yi * yi;
    }
    if sst > 0.0 {
        1.0 - sse / sst
    } else {
        0.0
    }
}

/// Regresses the held-out residual `held` (noise units, per fitted row) on the row features.
pub fn residual_evidence(
    tests: &[PreparedTest],
    pieces: &[Piece],
    held: &HeldOut,
    fold_of_piece: &[usize],
    v_ref: f64,
    p_ref: f64,
) -> ResidualEvidence {
    let mut rows = held_out_rows(tests, pieces, held, fold_of_piece, v_ref, p_ref);
    if rows.x.len() < MIN_EVIDENCE_ROWS {
        return ResidualEvidence {
            r2: 0.0,
            features: Vec::new(),
            leading_family: None,
            summary: "too few held-out rows to read the residual".into(),
        };
    }
    rows.standardise();
    let (cv_sse, lambda) = rows.cross_validated_lambda();
    let Rows { x, y, w, .. } = &rows;
    let sst: f64 = y.iter().zip(w).map(|(e, wi)| wi * e * e).sum();
    let r2 = if sst > 0.0 { 1.0 - cv_sse / sst } else { 0.0 };
    let beta = lasso(x, y, w, lambda);
    let full_r2 = weighted_r2(x, y, w, &beta);
    let mut features: Vec<FeatureWeight> = (0..FEATURES)
        .filter(|&j| beta[j] != 0.0)
        .map(|j| {
            let mut without = beta;
            without[j] = 0.0;
            let loss = (full_r2 - weighted_r2(x, y, w, &without)).max(0.0);
            FeatureWeight {
                feature: Feature::ALL[j],
                name: Feature::ALL[j].name().into(),
                family: Feature::ALL[j].family(),
                coefficient: beta[j],
                share: if full_r2 > 0.0 { loss / full_r2 } else { 0.0 },
            }
        })
        .collect();
    features.sort_by(|a, b| b.share.total_cmp(&a.share));
    let leading_family = if r2 > NOTHING_PREDICTED_R2 {
        features.first().and_then(|f| f.family)
    } else {
        None
    };
    let summary = describe(r2, &features);
    ResidualEvidence {
        r2,
        features,
        leading_family,
        summary,
    }
}

/// Number of features the residual is regressed on.
const FEATURES: usize = 8;

/// Held-out rows below which the residual is not read.
const MIN_EVIDENCE_ROWS: usize = 20;

/// Cross-validated R² at or below which no feature predicts the residual.
const NOTHING_PREDICTED_R2: f64 = 0.05;

/// Penalties tried for the lasso, log-spaced over this many decades below the largest useful.
const LAMBDA_GRID: usize = 20;
const LAMBDA_DECADES: f64 = 3.0;

/// The held-out rows the residual is regressed on: features, friction residual, weight and
/// the fold that held each row out.
struct Rows {
    x: Vec<[f64; FEATURES]>,
    y: Vec<f64>,
    w: Vec<f64>,
    fold: Vec<usize>,
}

/// The held-out residual of every piece as a friction residual (traction over normal stress
/// under slip control), each row weighted as the rows a bin stands for and each test as its
/// noise allows.
fn held_out_rows(
    tests: &[PreparedTest],
    pieces: &[Piece],
    held: &HeldOut,
    fold_of_piece: &[usize],
    v_ref: f64,
    p_ref: f64,
) -> Rows {
    let feats = row_features(tests, v_ref, p_ref);
    let mut rows = Rows {
        x: Vec::new(),
        y: Vec::new(),
        w: Vec::new(),
        fold: Vec::new(),
    };
    for (pi, piece) in pieces.iter().enumerate() {
        let t = &tests[piece.test].fit;
        for i in piece.start..piece.end.min(t.len()) {
            let r = held[piece.test][i];
            if !r.is_finite() {
                continue;
            }
            let wi = t.weight_of(i);
            let scale = t.noise_sd / (t.weight.sqrt() * wi.sqrt().max(1e-12));
            let unit = if t.control == Control::Slip {
                t.normal[i]
            } else {
                1.0
            };
            let sd = t.noise_sd / unit;
            rows.x.push(feats[piece.test][i]);
            rows.y.push(r * scale / unit);
            rows.w.push(wi / (sd * sd).max(1e-300));
            rows.fold.push(fold_of_piece[pi]);
        }
    }
    rows
}

impl Rows {
    /// Centres the residual and standardises each feature (weighted); a constant feature
    /// becomes 0.
    fn standardise(&mut self) {
        let wsum: f64 = self.w.iter().sum();
        let ym = self.y.iter().zip(&self.w).map(|(a, b)| a * b).sum::<f64>() / wsum;
        for v in self.y.iter_mut() {
            *v -= ym;
        }
        for j in 0..FEATURES {
            let weighted = |f: &dyn Fn(f64) -> f64| {
                self.x
                    .iter()
                    .zip(&self.w)
                    .map(|(r, wi)| wi * f(r[j]))
                    .sum::<f64>()
                    / wsum
            };
            let mean = weighted(&|v| v);
            let sd = weighted(&|v| (v - mean).powi(2)).sqrt();
            for r in self.x.iter_mut() {
                r[j] = if sd > 1e-12 { (r[j] - mean) / sd } else { 0.0 };
            }
        }
    }

    /// The lasso penalty with the least held-out error, chosen by cross-validation over the
    /// folds that held the pieces out; returns (that error, the penalty).
    fn cross_validated_lambda(&self) -> (f64, f64) {
        let (x, y, w, fold) = (&self.x, &self.y, &self.w, &self.fold);
        let wsum: f64 = w.iter().sum();
        // The smallest penalty that keeps every coefficient at zero.
        let lambda_max = (0..FEATURES)
            .map(|j| {
                (x.iter()
                    .zip(y)
                    .zip(w)
                    .map(|((r, e), wi)| wi * r[j] * e)
                    .sum::<f64>()
                    / wsum)
                    .abs()
            })
            .fold(0.0, f64::max);
        let folds = fold.iter().copied().max().unwrap_or(0) + 1;
        let mut best = (f64::INFINITY, lambda_max);
        for k in 0..LAMBDA_GRID {
            let lambda =
                lambda_max * 10f64.powf(-LAMBDA_DECADES * k as f64 / (LAMBDA_GRID - 1) as f64);
            let mut sse = 0.0;
            for f in 0..folds {
                let train: Vec<usize> = (0..x.len()).filter(|&i| fold[i] != f).collect();
                let xs: Vec<[f64; FEATURES]> = train.iter().map(|&i| x[i]).collect();
                let ys: Vec<f64> = train.iter().map(|&i| y[i]).collect();
                let ws: Vec<f64> = train.iter().map(|&i| w[i]).collect();
                let b = lasso(&xs, &ys, &ws, lambda);
                for i in (0..x.len()).filter(|&i| fold[i] == f) {
                    let pred: f64 = (0..FEATURES).map(|j| b[j] * x[i][j]).sum();
                    sse += w[i] * (y[i] - pred).powi(2);
                }
            }
            if sse < best.0 {
                best = (sse, lambda);
            }
        }
        best
    }
}

fn describe(r2: f64, features: &[FeatureWeight]) -> String {
    if r2 <= NOTHING_PREDICTED_R2 || features.is_empty() {
        return format!(
            "no feature predicts the held-out residual (cross-validated R² {:.2}): it looks like noise or a shape none of the features describes",
            r2.max(0.0)
        );
    }
    let top: Vec<String> = features
        .iter()
        .take(3)
        .map(|f| format!("{} ({:.0}%)", f.name, 100.0 * f.share))
        .collect();
    let mut s = format!(
        "the held-out residual follows {} (cross-validated R² {:.2})",
        top.join(", "),
        r2
    );
    let has = |f: Feature| features.iter().any(|w| w.feature == f && w.share > 0.1);
    if features[0].feature == Feature::Time && !has(Feature::AccumulatedSlip) {
        s.push_str(": it grows with time, not with slip, as a drift of the measurement would");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows of eight features that are uncorrelated by construction (sines of distinct
    /// frequencies over whole periods).
    fn design(n: usize) -> Vec<[f64; FEATURES]> {
        (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                let mut r = [0.0; FEATURES];
                for (j, v) in r.iter_mut().enumerate() {
                    *v = ((j + 1) as f64 * t).sin();
                }
                r
            })
            .collect()
    }

    #[test]
    fn the_lasso_finds_the_two_features_a_residual_follows_and_their_signs() {
        let x = design(400);
        let y: Vec<f64> = x.iter().map(|r| 2.0 * r[0] - 1.0 * r[3]).collect();
        let w = vec![1.0; x.len()];
        let beta = lasso(&x, &y, &w, 1e-6);
        assert!((beta[0] - 2.0).abs() < 1e-3, "{beta:?}");
        assert!((beta[3] + 1.0).abs() < 1e-3, "{beta:?}");
        for (j, b) in beta.iter().enumerate() {
            if j != 0 && j != 3 {
                assert!(b.abs() < 1e-3, "feature {j}: {b}");
            }
        }
        assert!((weighted_r2(&x, &y, &w, &beta) - 1.0).abs() < 1e-6);
        // A penalty above every correlation keeps nothing, and then nothing is explained.
        let none = lasso(&x, &y, &w, 10.0);
        assert_eq!(none, [0.0; FEATURES]);
        assert_eq!(weighted_r2(&x, &y, &w, &none), 0.0);
    }

    #[test]
    fn the_lasso_shrinks_by_the_penalty_and_weights_count() {
        let x = design(400);
        let y: Vec<f64> = x.iter().map(|r| r[1]).collect();
        let w = vec![1.0; x.len()];
        // Soft thresholding on a standardised column of variance 1/2: β = (ρ − λ)/(1/2).
        let beta = lasso(&x, &y, &w, 0.1);
        assert!((beta[1] - (0.5 - 0.1) / 0.5).abs() < 1e-3, "{beta:?}");
        // Rows of zero weight do not count: corrupting them changes nothing.
        let mut y2 = y.clone();
        let mut w2 = w.clone();
        for k in (0..x.len()).step_by(7) {
            y2[k] += 100.0;
            w2[k] = 0.0;
        }
        let b2 = lasso(&x, &y2, &w2, 1e-6);
        assert!((b2[1] - 1.0).abs() < 0.05, "{b2:?}");
    }
}
