//! The diagnosis: fit the base model to all tests, localise the residual, refit every candidate
//! effect, compare them on held-out data, name the effect (or none, or unexplained), and say how
//! much of the held-out gap it removes.

use crate::candidates::{library, Candidate, Effect};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;
use subfric_fit::lm::{levenberg_marquardt, LmOptions};
use subfric_fit::{
    calibrate, misfits, typical_rate, FitError, FitOptions, FitTest, Param, PreparedTest, Problem,
    Space, TestMisfit,
};
use subfric_model::Model;

/// Thresholds of the verdict.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Thresholds {
    /// A candidate must remove at least this fraction of the held-out gap.
    pub min_shrink: f64,
    /// ... and improve the in-sample BIC by at least this much.
    pub min_delta_bic: f64,
    /// Base misfit (reduced χ², noise units) above which a gap is real.
    pub gap_chi2: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            min_shrink: 0.7,
            min_delta_bic: 20.0,
            gap_chi2: 1.3,
        }
    }
}

/// Options of a diagnosis.
#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Seed of the base fit.
    pub seed: u64,
    /// Global-stage budget of the base fit.
    pub global_evaluations: usize,
    /// Local starts of the base fit.
    pub starts: usize,
    /// Fraction of each test held out at its end in the tail folds.
    pub tail_fraction: f64,
    /// Model supplying fixed parameters (α) and the first template.
    pub template: Model,
    /// Verdict thresholds.
    pub thresholds: Thresholds,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            seed: 1,
            global_evaluations: 2000,
            starts: 4,
            tail_fraction: 0.4,
            template: Model::base(subfric_model::Params::sample())
                .expect("sample parameters are valid"),
            thresholds: Thresholds::default(),
        }
    }
}

/// Misfit of a group of rows.
#[derive(Clone, Debug, Serialize)]
pub struct GroupMisfit {
    /// Group label.
    pub group: String,
    /// Rows in the group.
    pub rows: usize,
    /// RMS residual / noise SD (1 = noise level).
    pub rms_over_noise: f64,
    /// Share of the total excess misfit (SSR − rows, in noise units) in this group.
    pub share_of_gap: f64,
}

/// Where the base model's residual lies.
#[derive(Clone, Debug, Serialize)]
pub struct Localisation {
    /// Per test.
    pub by_test: Vec<GroupMisfit>,
    /// Per kind of segment, all tests together.
    pub by_segment: Vec<GroupMisfit>,
    /// Per test and kind of segment.
    pub by_test_segment: Vec<GroupMisfit>,
    /// Early vs late cycles (tests with cycles).
    pub by_cycle: Vec<GroupMisfit>,
    /// Per normal stress level.
    pub by_normal_stress: Vec<GroupMisfit>,
    /// Total excess misfit over the noise, in noise units.
    pub total_excess: f64,
}

/// Scores of one candidate.
#[derive(Clone, Debug, Serialize)]
pub struct CandidateScore {
    /// The effect.
    pub effect: Effect,
    /// Its form.
    pub variant: String,
    /// Fitted extra parameters.
    pub extra_parameters: BTreeMap<String, f64>,
    /// The fitted model.
    pub model: Model,
    /// In-sample SSR (noise units).
    pub fit_ssr: f64,
    /// In-sample reduced χ².
    pub fit_reduced_chi2: f64,
    /// BIC improvement over the base, n ln(SSR_base/SSR) − k ln n.
    pub delta_bic: f64,
    /// Held-out SSR over all folds (noise units).
    pub held_out_ssr: f64,
    /// Fraction of the base model's held-out excess misfit this candidate removes (0..1), on
    /// the tail folds (the last part of each test predicted after fitting everything else).
    pub held_out_shrink: f64,
    /// The same on leave-one-test-out folds (an extrapolation check: an effect seen in one
    /// test only cannot be learned without it).
    pub leave_one_test_out_shrink: f64,
    /// Held-out misfit per fold.
    pub folds: Vec<FoldScore>,
}

/// Held-out misfit of the base model and a candidate on one fold.
#[derive(Clone, Debug, Serialize)]
pub struct FoldScore {
    /// Fold description.
    pub fold: String,
    /// Held-out rows.
    pub rows: usize,
    /// Base RMS/noise.
    pub base_rms_over_noise: f64,
    /// Candidate RMS/noise.
    pub candidate_rms_over_noise: f64,
}

/// Scores of the measurement-drift alternative: the base model plus, for each test, an offset
/// of the measured column growing linearly with time.
#[derive(Clone, Debug, Serialize)]
pub struct DriftScore {
    /// In-sample SSR.
    pub fit_ssr: f64,
    /// BIC improvement over the base (one slope per test).
    pub delta_bic: f64,
    /// Held-out shrink on the tail folds.
    pub held_out_shrink: f64,
}

/// The answer for scripts.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// The effect named.
    pub effect: Effect,
    /// Fraction of the held-out misfit removed by that effect (0 for none/unexplained).
    pub held_out_shrink: f64,
    /// Plain-language reason.
    pub explanation: String,
    /// Fitted extra parameters of the named effect.
    pub extra_parameters: BTreeMap<String, f64>,
}

/// How much of the held-out gap the named effect removes, per group of rows.
#[derive(Clone, Debug, Serialize)]
pub struct GroupShrink {
    /// Group label.
    pub group: String,
    /// Held-out rows in it.
    pub rows: usize,
    /// RMS/noise of the base model on them.
    pub base_rms_over_noise: f64,
    /// RMS/noise with the effect.
    pub effect_rms_over_noise: f64,
    /// Fraction of the excess removed (may be negative where the effect hurts).
    pub shrink: f64,
}

/// The base model's fit.
#[derive(Clone, Debug, Serialize)]
pub struct BaseFit {
    /// Fitted model.
    pub model: Model,
    /// SSR in noise units.
    pub ssr: f64,
    /// Rows.
    pub rows: usize,
    /// Reduced χ².
    pub reduced_chi2: f64,
    /// Per-test misfit.
    pub tests: Vec<TestMisfit>,
}

/// A complete diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    /// The verdict (first, for scripts).
    pub verdict: Verdict,
    /// Base fit.
    pub base: BaseFit,
    /// Where the base residual lies.
    pub localisation: Localisation,
    /// Every candidate's scores.
    pub candidates: Vec<CandidateScore>,
    /// Held-out folds used.
    pub folds: Vec<String>,
    /// Held-out rows of the tail folds.
    pub held_out_rows: usize,
    /// Held-out SSR of the base model on the tail folds.
    pub held_out_base_ssr: f64,
    /// Shrink of the named effect per kind of segment on held-out rows.
    pub shrink_by_segment: Vec<GroupShrink>,
    /// Shrink of the named effect per test on held-out rows.
    pub shrink_by_test: Vec<GroupShrink>,
    /// Where the remaining residual lies after the named effect (or the base when none).
    pub remaining_by_segment: Vec<GroupMisfit>,
    /// The measurement-drift alternative (not a friction effect).
    pub drift: DriftScore,
    /// Thresholds used.
    pub thresholds: Thresholds,
    /// Wall time [s].
    pub elapsed_s: f64,
}

/// Why a diagnosis could not run.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    /// The base fit failed.
    #[error("base fit: {0}")]
    Fit(#[from] FitError),
    /// Not enough data.
    #[error("a diagnosis needs at least one test with 20 rows or more")]
    TooLittleData,
}

/// A held-out fold: which test is left out whole, or whose tail is held out.
#[derive(Clone, Debug)]
struct Fold {
    name: String,
    /// True for a tail fold (the end of one test held out), false for leave-one-test-out.
    tail: bool,
    /// Per test: rows used for training.
    train: Vec<std::ops::Range<usize>>,
    /// Per test: held-out rows.
    held: Vec<std::ops::Range<usize>>,
}

fn folds(tests: &[FitTest], tail_fraction: f64) -> Vec<Fold> {
    let n = tests.len();
    let mut out = Vec::new();
    if n >= 2 {
        for k in 0..n {
            out.push(Fold {
                name: format!("leave out {}", tests[k].name),
                tail: false,
                train: (0..n)
                    .map(|i| if i == k { 0..0 } else { 0..tests[i].len() })
                    .collect(),
                held: (0..n)
                    .map(|i| if i == k { 0..tests[i].len() } else { 0..0 })
                    .collect(),
            });
        }
    }
    for k in 0..n {
        let len = tests[k].len();
        let cut = ((1.0 - tail_fraction) * len as f64).round() as usize;
        if cut < 10 || cut >= len {
            continue;
        }
        out.push(Fold {
            name: format!(
                "hold out the last {:.0}% of {}",
                100.0 * tail_fraction,
                tests[k].name
            ),
            tail: true,
            train: (0..n)
                .map(|i| if i == k { 0..cut } else { 0..tests[i].len() })
                .collect(),
            held: (0..n)
                .map(|i| if i == k { cut..len } else { 0..0 })
                .collect(),
        });
    }
    out
}

fn with_rows(tests: &[FitTest], rows: &[std::ops::Range<usize>]) -> Vec<FitTest> {
    tests
        .iter()
        .zip(rows)
        .map(|(t, r)| {
            let mut t = t.clone();
            t.fit_rows = r.clone();
            t
        })
        .collect()
}

/// Per-row residuals (noise units) of a model on every test; NaN where it cannot simulate.
fn row_residuals(tests: &[FitTest], m: &Model) -> Vec<Vec<f64>> {
    tests
        .iter()
        .map(|t| match t.predict(m) {
            Ok(p) => p
                .iter()
                .zip(&t.measured)
                .map(|(a, b)| (a - b) / t.noise_sd)
                .collect(),
            Err(_) => vec![f64::NAN; t.len()],
        })
        .collect()
}

fn ssr_of(r: &[f64]) -> f64 {
    r.iter()
        .map(|v| if v.is_finite() { v * v } else { 1e6 })
        .sum()
}

/// Row labels used to group residuals.
struct Labels {
    test: Vec<String>,
    segment: Vec<Vec<&'static str>>,
    cycle: Vec<Vec<Option<&'static str>>>,
    stress: Vec<String>,
}

fn labels(prepared: &[PreparedTest]) -> Labels {
    Labels {
        test: prepared.iter().map(|p| p.fit.name.clone()).collect(),
        segment: prepared
            .iter()
            .map(|p| p.segmentation.row_kind.iter().map(|k| k.name()).collect())
            .collect(),
        cycle: prepared
            .iter()
            .map(|p| {
                let n = p.segmentation.cycles();
                p.segmentation
                    .cycle_of_row
                    .iter()
                    .map(|&c| {
                        if n < 2 {
                            None
                        } else if c <= n / 2 {
                            Some("early cycles")
                        } else {
                            Some("late cycles")
                        }
                    })
                    .collect()
            })
            .collect(),
        stress: prepared
            .iter()
            .map(|p| {
                let t = &p.fit;
                let mean = t.normal.iter().sum::<f64>() / t.normal.len().max(1) as f64;
                format!("{:.0} kPa", mean)
            })
            .collect(),
    }
}

fn group_misfit<F: Fn(usize, usize) -> Option<String>>(
    res: &[Vec<f64>],
    key: F,
) -> Vec<GroupMisfit> {
    let mut acc: BTreeMap<String, (usize, f64)> = BTreeMap::new();
    for (t, r) in res.iter().enumerate() {
        for (i, v) in r.iter().enumerate() {
            if let Some(k) = key(t, i) {
                let e = acc.entry(k).or_insert((0, 0.0));
                e.0 += 1;
                e.1 += if v.is_finite() { v * v } else { 1e6 };
            }
        }
    }
    let total: f64 = acc.values().map(|(n, s)| (s - *n as f64).max(0.0)).sum();
    acc.into_iter()
        .map(|(group, (rows, ssr))| GroupMisfit {
            group,
            rows,
            rms_over_noise: (ssr / rows.max(1) as f64).sqrt(),
            share_of_gap: if total > 0.0 {
                (ssr - rows as f64).max(0.0) / total
            } else {
                0.0
            },
        })
        .collect()
}

fn localise(prepared: &[PreparedTest], res: &[Vec<f64>]) -> Localisation {
    let l = labels(prepared);
    let seg = |t: usize, i: usize| l.segment[t].get(i).map(|s| s.to_string());
    Localisation {
        by_test: group_misfit(res, |t, _| Some(l.test[t].clone())),
        by_segment: group_misfit(res, seg),
        by_test_segment: group_misfit(res, |t, i| {
            l.segment[t]
                .get(i)
                .map(|s| format!("{} / {}", l.test[t], s))
        }),
        by_cycle: group_misfit(res, |t, i| {
            l.cycle[t].get(i).copied().flatten().map(String::from)
        }),
        by_normal_stress: group_misfit(res, |t, _| Some(l.stress[t].clone())),
        total_excess: res
            .iter()
            .map(|r| ssr_of(r) - r.len() as f64)
            .sum::<f64>()
            .max(0.0),
    }
}

fn shrink_groups<F: Fn(usize, usize) -> Option<String>>(
    base: &[Vec<f64>],
    eff: &[Vec<f64>],
    key: F,
) -> Vec<GroupShrink> {
    let mut acc: BTreeMap<String, (usize, f64, f64)> = BTreeMap::new();
    for t in 0..base.len() {
        for i in 0..base[t].len() {
            let (b, e) = (base[t][i], eff[t][i]);
            if b.is_nan() || e.is_nan() {
                continue;
            }
            if let Some(k) = key(t, i) {
                let a = acc.entry(k).or_insert((0, 0.0, 0.0));
                a.0 += 1;
                a.1 += b * b;
                a.2 += e * e;
            }
        }
    }
    acc.into_iter()
        .map(|(group, (rows, sb, se))| {
            let gap = sb - rows as f64;
            GroupShrink {
                group,
                rows,
                base_rms_over_noise: (sb / rows.max(1) as f64).sqrt(),
                effect_rms_over_noise: (se / rows.max(1) as f64).sqrt(),
                shrink: if gap > 0.0 { (sb - se) / gap } else { 0.0 },
            }
        })
        .collect()
}

/// Space of base + candidate parameters.
fn candidate_space(template: &Model, cand: Option<&Candidate>, v_ref: f64) -> Space {
    let mut free: Vec<Param> = Param::BASE.to_vec();
    if let Some(c) = cand {
        free.extend(c.params.iter().copied());
    }
    let mut base = *template;
    if let Some(c) = cand {
        base.ext = merge(&base.ext, &c.template);
        for (p, v) in c.params.iter().zip(&c.neutral) {
            p.set(&mut base, *v);
        }
    }
    Space::with_rate(base, &free, &[], v_ref)
}

/// Extensions of `a` with those set in `b` switched on.
fn merge(
    a: &subfric_model::Extensions,
    b: &subfric_model::Extensions,
) -> subfric_model::Extensions {
    subfric_model::Extensions {
        rate: b.rate.or(a.rate),
        pressure: b.pressure.or(a.pressure),
        slip_hardening: b.slip_hardening.or(a.slip_hardening),
        healing: b.healing.or(a.healing),
        direction: b.direction.or(a.direction),
    }
}

fn start_point(
    space: &Space,
    base_model: &Model,
    cand: Option<&Candidate>,
    extra: &[f64],
) -> Vec<f64> {
    let mut m = *base_model;
    if let Some(c) = cand {
        for (p, v) in c.params.iter().zip(extra) {
            p.set(&mut m, *v);
        }
    }
    space.point_of(&m)
}

fn lm(p: &Problem, x0: &[f64], iters: usize) -> (Vec<f64>, f64) {
    let r = levenberg_marquardt(
        p,
        x0,
        None,
        &LmOptions {
            max_iterations: iters,
            ..LmOptions::default()
        },
    );
    (r.x, r.ssr)
}

/// Held-out residuals (per test, NaN outside the held rows) of a model refitted on each fold.
fn held_out(
    tests: &[FitTest],
    folds: &[Fold],
    space: &Space,
    starts: &[Model],
) -> Vec<Vec<Vec<f64>>> {
    folds
        .par_iter()
        .map(|f| {
            let train = with_rows(tests, &f.train);
            let detrend = tests.iter().any(|t| t.detrend);
            let p = Problem::new(&train, space.clone());
            // Several starts (the full-data fit, and the effect switched off); on a tie the
            // later one (switched off) wins, so effects the training rows cannot see stay off.
            let mut best: Option<(Vec<f64>, f64)> = None;
            for m in starts {
                let (x, ssr) = lm(&p, &space.point_of(m), 30);
                if best.as_ref().is_none_or(|b| ssr <= b.1 + 1.0) {
                    best = Some((x, ssr));
                }
            }
            let model = space.model_at(&best.map(|b| b.0).unwrap_or_default());
            let mut res = row_residuals(tests, &model);
            if detrend {
                // The drift of each test is learned from its training rows only.
                for ((r, t), rows) in res.iter_mut().zip(tests).zip(&f.train) {
                    let c = t.drift_coefficient(r, rows.clone());
                    for (i, v) in r.iter_mut().enumerate() {
                        *v -= c * (t.time[i] - t.time[0]);
                    }
                }
            }
            res.into_iter()
                .zip(&f.held)
                .map(|(r, h)| {
                    r.into_iter()
                        .enumerate()
                        .map(|(i, v)| if h.contains(&i) { v } else { f64::NAN })
                        .collect()
                })
                .collect()
        })
        .collect()
}

/// Sum over the selected folds of held-out squared residuals (NaN rows skipped), and rows.
fn held_ssr_where(res: &[Vec<Vec<f64>>], keep: impl Fn(usize) -> bool) -> (f64, usize) {
    let mut s = 0.0;
    let mut n = 0;
    for (fi, f) in res.iter().enumerate() {
        if !keep(fi) {
            continue;
        }
        for t in f {
            for v in t {
                if !v.is_nan() {
                    s += if v.is_finite() { v * v } else { 1e6 };
                    n += 1;
                }
            }
        }
    }
    (s, n)
}

fn held_ssr(res: &[Vec<Vec<f64>>]) -> (f64, usize) {
    held_ssr_where(res, |_| true)
}

/// Fraction of the base model's held-out excess misfit removed.
fn shrink_of(base: f64, cand: f64, rows: usize) -> f64 {
    let gap = base - rows as f64;
    if gap > 0.0 {
        ((base - cand) / gap).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Runs the whole diagnosis on prepared tests of one interface.
pub fn diagnose(
    prepared: &[PreparedTest],
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let t0 = Instant::now();
    if prepared.iter().all(|p| p.fit.len() < 20) {
        return Err(DiagnoseError::TooLittleData);
    }
    let tests: Vec<FitTest> = prepared.iter().map(|p| p.fit.clone()).collect();
    let v_ref = typical_rate(&tests);
    let n_rows: usize = tests.iter().map(|t| t.len()).sum();

    // 1. Base fit.
    let base_space = candidate_space(&opts.template, None, v_ref);
    let base_fit = calibrate(
        &tests,
        base_space.clone(),
        &FitOptions {
            seed: opts.seed,
            global_evaluations: opts.global_evaluations,
            starts: opts.starts,
            profiles: false,
            ..FitOptions::default()
        },
        &|_| {},
    )?;
    let base_model = base_fit.model;
    let base_res = row_residuals(&tests, &base_model);
    let base_ssr: f64 = base_res.iter().map(|r| ssr_of(r)).sum();
    let localisation = localise(prepared, &base_res);

    // 2. Every candidate fitted to all tests, from several starts, in parallel.
    let lib = library(v_ref);
    let full: Vec<(Space, Model, f64)> = lib
        .par_iter()
        .map(|c| {
            let space = candidate_space(&base_model, Some(c), v_ref);
            let p = Problem::new(&tests, space.clone());
            let best = c
                .starts
                .par_iter()
                .map(|s| lm(&p, &start_point(&space, &base_model, Some(c), s), 60))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or_else(|| (space.point_of(&base_model), base_ssr));
            let model = space.model_at(&best.0);
            (space, model, best.1)
        })
        .collect();

    // 3. Held-out comparison.
    let folds = folds(&tests, opts.tail_fraction);
    let base_ho = held_out(&tests, &folds, &base_space, &[base_model]);
    let cand_ho: Vec<Vec<Vec<Vec<f64>>>> = lib
        .iter()
        .zip(&full)
        .map(|(c, (space, model, _))| {
            let mut off = *model;
            for (p, v) in c.params.iter().zip(&c.neutral) {
                p.set(&mut off, *v);
            }
            held_out(&tests, &folds, space, &[*model, off])
        })
        .collect();
    let is_tail = |fi: usize| folds[fi].tail;
    let (base_tail, tail_rows) = held_ssr_where(&base_ho, is_tail);
    let (base_loto, loto_rows) = held_ssr_where(&base_ho, |fi| !is_tail(fi));

    let mut candidates: Vec<CandidateScore> = lib
        .iter()
        .zip(&full)
        .zip(&cand_ho)
        .map(|((c, (_, model, ssr)), ho)| {
            let (ho_ssr, _) = held_ssr(ho);
            let (tail, _) = held_ssr_where(ho, is_tail);
            let (loto, _) = held_ssr_where(ho, |fi| !is_tail(fi));
            let per_fold = folds
                .iter()
                .enumerate()
                .map(|(fi, f)| {
                    let (b, n) = held_ssr(&base_ho[fi..fi + 1]);
                    let (c, _) = held_ssr(&ho[fi..fi + 1]);
                    FoldScore {
                        fold: f.name.clone(),
                        rows: n,
                        base_rms_over_noise: (b / n.max(1) as f64).sqrt(),
                        candidate_rms_over_noise: (c / n.max(1) as f64).sqrt(),
                    }
                })
                .collect();
            let k = c.params.len() as f64;
            let n = n_rows as f64;
            CandidateScore {
                effect: c.effect,
                variant: c.variant.to_string(),
                extra_parameters: c
                    .params
                    .iter()
                    .map(|p| (p.key().to_string(), p.get(model).unwrap_or(f64::NAN)))
                    .collect(),
                model: *model,
                fit_ssr: *ssr,
                fit_reduced_chi2: ssr / (n - 5.0 - k).max(1.0),
                delta_bic: n * (base_ssr / ssr.max(1e-300)).ln() - k * n.ln(),
                held_out_ssr: ho_ssr,
                held_out_shrink: shrink_of(base_tail, tail, tail_rows),
                leave_one_test_out_shrink: shrink_of(base_loto, loto, loto_rows),
                folds: per_fold,
            }
        })
        .collect();

    // 3b. A non-physical alternative: a drift of each test's measurement linear in time.
    let drift = {
        let mut dt = tests.clone();
        for t in dt.iter_mut() {
            t.detrend = true;
        }
        let p = Problem::new(&dt, base_space.clone());
        let (x, ssr) = lm(&p, &base_space.point_of(&base_model), 60);
        let model = base_space.model_at(&x);
        let ho = held_out(&dt, &folds, &base_space, &[model, base_model]);
        let (tail, _) = held_ssr_where(&ho, is_tail);
        let n = n_rows as f64;
        let k = tests.len() as f64;
        DriftScore {
            fit_ssr: ssr,
            delta_bic: n * (base_ssr / ssr.max(1e-300)).ln() - k * n.ln(),
            held_out_shrink: shrink_of(base_tail, tail, tail_rows),
        }
    };

    // 4. Verdict.
    let th = opts.thresholds;
    let base_chi2 = base_ssr / (n_rows as f64 - 5.0).max(1.0);
    let best = (0..candidates.len()).max_by(|&a, &b| {
        let key = |c: &CandidateScore| (c.held_out_shrink, c.delta_bic);
        key(&candidates[a])
            .partial_cmp(&key(&candidates[b]))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let physical_best = best.map(|i| candidates[i].held_out_shrink).unwrap_or(0.0);
    let drift_wins = drift.held_out_shrink >= th.min_shrink
        && drift.delta_bic >= th.min_delta_bic
        && drift.held_out_shrink > physical_best + 0.1;
    let (effect, chosen, explanation) = match best {
        _ if drift_wins && base_chi2 > th.gap_chi2 => (
            Effect::Unexplained,
            None,
            format!(
                "the base misfit is {:.2}× the noise variance; no physical candidate explains it (best {:.0}%), but a drift of each measurement linear in time removes {:.0}% of the held-out misfit: the gap looks like a drift of the measurement, not friction",
                base_chi2,
                100.0 * physical_best,
                100.0 * drift.held_out_shrink
            ),
        ),
        Some(i)
            if candidates[i].held_out_shrink >= th.min_shrink
                && candidates[i].delta_bic >= th.min_delta_bic
                && base_chi2 > 1.0 + 0.5 * (th.gap_chi2 - 1.0) =>
        {
            let c = &candidates[i];
            (
                c.effect,
                Some(i),
                format!(
                    "{}: it removes {:.0}% of the held-out misfit (ΔBIC {:.0}); base misfit {:.2}× the noise variance",
                    c.effect.describe(),
                    100.0 * c.held_out_shrink,
                    c.delta_bic,
                    base_chi2
                ),
            )
        }
        _ if base_chi2 > th.gap_chi2 => {
            let worst = localisation
                .by_test_segment
                .iter()
                .max_by(|a, b| a.share_of_gap.total_cmp(&b.share_of_gap))
                .map(|g| format!("{} ({:.0}% of the gap, {:.1}× noise)", g.group, 100.0 * g.share_of_gap, g.rms_over_noise))
                .unwrap_or_default();
            let best_text = best
                .map(|i| format!("the best candidate, {}, removes only {:.0}% of the held-out misfit", candidates[i].effect, 100.0 * candidates[i].held_out_shrink))
                .unwrap_or_default();
            (
                Effect::Unexplained,
                None,
                format!(
                    "the base misfit is {:.2}× the noise variance but none of the candidates explains it: {}; the largest share of the residual lies in {}",
                    base_chi2, best_text, worst
                ),
            )
        }
        _ => (
            Effect::None,
            None,
            format!(
                "the base model fits at {:.2}× the noise variance and no candidate removes enough of the held-out misfit: the gap is noise",
                base_chi2
            ),
        ),
    };

    let l = labels(prepared);
    let flatten = |ho: &[Vec<Vec<f64>>]| -> Vec<Vec<f64>> {
        // Concatenate the tail folds per test (NaN rows are skipped by the grouping).
        (0..tests.len())
            .map(|t| {
                ho.iter()
                    .enumerate()
                    .filter(|(fi, _)| folds[*fi].tail)
                    .flat_map(|(_, f)| f[t].iter().copied())
                    .collect()
            })
            .collect()
    };
    let base_flat = flatten(&base_ho);
    let (shrink_by_segment, shrink_by_test, remaining) = match chosen {
        Some(i) => {
            let eff_flat = flatten(&cand_ho[i]);
            let len = |t: usize| tests[t].len();
            let seg = |t: usize, i: usize| l.segment[t].get(i % len(t)).map(|s| s.to_string());
            let eff_res = row_residuals(&tests, &candidates[i].model);
            (
                shrink_groups(&base_flat, &eff_flat, seg),
                shrink_groups(&base_flat, &eff_flat, |t, _| Some(l.test[t].clone())),
                localise(prepared, &eff_res).by_segment,
            )
        }
        None => (Vec::new(), Vec::new(), localisation.by_segment.clone()),
    };
    let verdict = Verdict {
        effect,
        held_out_shrink: chosen.map(|i| candidates[i].held_out_shrink).unwrap_or(0.0),
        explanation,
        extra_parameters: chosen
            .map(|i| candidates[i].extra_parameters.clone())
            .unwrap_or_default(),
    };
    candidates.sort_by(|a, b| a.held_out_ssr.total_cmp(&b.held_out_ssr));
    Ok(Diagnosis {
        verdict,
        base: BaseFit {
            model: base_model,
            ssr: base_ssr,
            rows: n_rows,
            reduced_chi2: base_chi2,
            tests: misfits(&tests, &base_model),
        },
        localisation,
        candidates,
        folds: folds.iter().map(|f| f.name.clone()).collect(),
        held_out_rows: tail_rows,
        held_out_base_ssr: base_tail,
        shrink_by_segment,
        shrink_by_test,
        remaining_by_segment: remaining,
        drift,
        thresholds: th,
        elapsed_s: t0.elapsed().as_secs_f64(),
    })
}
