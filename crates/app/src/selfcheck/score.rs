//! Scoring the diagnosis on sets whose effects it is not told (generated ones or a folder with a
//! `truth.json`): a confusion matrix, the share of sets fully right, the accuracy per form and
//! per rig-and-logger profile, the recall of two-effect sets, the rate of spurious second
//! effects and of false alarms.

use serde::Serialize;
use subfric_diagnose::{Diagnosis, Effect};

/// One diagnosed set and its truth.
#[derive(Clone, Debug, Serialize)]
pub struct Case {
    /// Set name.
    pub name: String,
    /// The families built in (empty: none; `unexplained`: a drift outside the library).
    pub truth: Vec<Effect>,
    /// The truth in words, with forms.
    pub truth_label: String,
    /// The families the diagnosis named (empty: none; `unexplained` when it says so).
    pub verdict: Vec<Effect>,
    /// Held-out shrink of the first effect named.
    pub shrink: f64,
    /// The rig and logger it was recorded with (the generator's profile: clean, logger, rig,
    /// lab; for a folder what its truth says, or empty).
    pub profile: String,
    /// Diagnosis time [s].
    pub elapsed_s: f64,
    /// The verdict's confidence (`None`: nothing judged).
    pub confidence: Option<f64>,
    /// What the selection weighed, stage by stage (to recalibrate the confidence offline).
    pub weighed: Vec<subfric_diagnose::confidence::StageWeighing>,
    /// The verdict the evidence points to with the first loadings left out.
    pub without_first_loadings: Option<Vec<Effect>>,
    /// The registered families the events read one by one show outright
    /// ([`subfric_diagnose::events::shows`]), named or not: where they and the verdict part,
    /// the confidence may be recalibrated on it offline.
    pub shown_by_events: Vec<Effect>,
    /// The coordinates of the base fit that ended at a bound of their box (the base bent before
    /// any candidate is tried: μ_k run to zero so that the recovery ξ carries the level, say),
    /// to recalibrate the confidence on offline.
    pub base_at_bounds: Vec<String>,
}

impl Case {
    /// Scores a diagnosis against the truth (`truth`: families; a drift is `Unexplained`).
    pub fn new(name: &str, truth: Vec<Effect>, label: String, d: &Diagnosis) -> Case {
        let verdict = d.verdict.named();
        Case {
            name: name.into(),
            truth,
            truth_label: label,
            verdict,
            shrink: d.verdict.held_out_shrink,
            profile: String::new(),
            elapsed_s: d.elapsed_s,
            confidence: d.verdict.confidence,
            weighed: d.verdict.weighed.clone(),
            without_first_loadings: d.verdict.without_first_loadings.clone(),
            shown_by_events: (0..subfric_model::terms::FAMILIES.len())
                .map(|i| Effect::Term(i as u8))
                .filter(|&e| subfric_diagnose::events::shows(&d.events, e))
                .collect(),
            base_at_bounds: d
                .base
                .at_bounds
                .iter()
                .map(|b| b.coordinate.clone())
                .collect(),
        }
    }

    /// The verdict is the truth: the same families (in any order), none for none, unexplained
    /// for a drift.
    pub fn right(&self) -> bool {
        let mut a = self.truth.clone();
        let mut b = self.verdict.clone();
        a.sort();
        b.sort();
        a == b
    }

    /// The first family named (or none / unexplained).
    pub fn first(&self) -> Effect {
        self.verdict.first().copied().unwrap_or(Effect::None)
    }

    /// A single-effect set got a second family named.
    pub fn spurious_second(&self) -> bool {
        self.truth.len() == 1
            && self.truth[0] != Effect::Unexplained
            && self.verdict.iter().any(|e| !self.truth.contains(e))
            && self.verdict.contains(&self.truth[0])
    }
}

/// Figures of a self-check.
#[derive(Clone, Debug, Serialize)]
pub struct Scores {
    /// Labels of the confusion matrix (rows: truth, columns: first effect named), over sets
    /// with at most one effect.
    pub labels: Vec<String>,
    /// Counts.
    pub confusion: Vec<Vec<usize>>,
    /// Sets.
    pub sets: usize,
    /// Share of sets fully right.
    pub share_right: f64,
    /// Per form (truth label): (label, right, total).
    pub per_form: Vec<(String, usize, usize)>,
    /// Per profile of rig and logger: (profile, right, total).
    pub per_profile: Vec<(String, usize, usize)>,
    /// Two-effect sets with both named, and two-effect sets.
    pub two_effect_recall: (usize, usize),
    /// Single-effect sets with a spurious second effect, and single-effect sets.
    pub spurious_second: (usize, usize),
    /// Sets without an effect.
    pub no_effect_sets: usize,
    /// Of those, how many got an effect named (false alarms).
    pub false_alarms: usize,
    /// Median held-out shrink of the first effect over sets it was named right in.
    pub median_shrink: Option<f64>,
    /// Sets whose gap no candidate explains, and how many were called "unexplained".
    pub unexplained_right: (usize, usize),
    /// Median and largest diagnosis time [s].
    pub time_median_max_s: (f64, f64),
    /// Verdicts stated as confident (confidence at least
    /// [`subfric_diagnose::confidence::CONFIDENT`]): (right, stated).
    pub confident_right: (usize, usize),
    /// Reliability of the confidence: per bin of confidence (from, to, sets, right, mean
    /// confidence).
    pub calibration: Vec<CalibrationBin>,
    /// Brier score of the confidence as a forecast of "fully right" (0 perfect; 0.25 for a
    /// constant 50 %); `None` when no verdict carried a confidence.
    pub brier: Option<f64>,
}

/// Sets whose verdict was stated with a confidence in [from, to).
#[derive(Clone, Debug, Serialize)]
pub struct CalibrationBin {
    /// Lower end.
    pub from: f64,
    /// Upper end (the last bin includes 1).
    pub to: f64,
    /// Sets.
    pub sets: usize,
    /// Of those, fully right.
    pub right: usize,
    /// Mean confidence stated.
    pub mean_confidence: f64,
}

/// The bins of the reliability table.
const CALIBRATION_EDGES: [f64; 5] = [0.0, 0.5, 0.7, 0.9, 1.0];

fn calibration(cases: &[Case]) -> (Vec<CalibrationBin>, Option<f64>, (usize, usize)) {
    let judged: Vec<(f64, bool)> = cases
        .iter()
        .filter_map(|c| c.confidence.map(|p| (p, c.right())))
        .collect();
    let bins = CALIBRATION_EDGES
        .windows(2)
        .enumerate()
        .map(|(i, w)| {
            let last = i + 2 == CALIBRATION_EDGES.len();
            let inside: Vec<&(f64, bool)> = judged
                .iter()
                .filter(|(p, _)| *p >= w[0] && (*p < w[1] || (last && *p <= w[1])))
                .collect();
            CalibrationBin {
                from: w[0],
                to: w[1],
                sets: inside.len(),
                right: inside.iter().filter(|(_, r)| *r).count(),
                mean_confidence: inside.iter().map(|(p, _)| p).sum::<f64>()
                    / inside.len().max(1) as f64,
            }
        })
        .collect();
    let brier = (!judged.is_empty()).then(|| {
        judged
            .iter()
            .map(|(p, r)| (p - if *r { 1.0 } else { 0.0 }).powi(2))
            .sum::<f64>()
            / judged.len() as f64
    });
    let confident: Vec<&(f64, bool)> = judged
        .iter()
        .filter(|(p, _)| *p >= subfric_diagnose::confidence::CONFIDENT)
        .collect();
    let confident_right = (
        confident.iter().filter(|(_, r)| *r).count(),
        confident.len(),
    );
    (bins, brier, confident_right)
}

use subfric_reading::stats::median;

/// Scores cases.
pub fn score(cases: &[Case]) -> Scores {
    let labels: Vec<Effect> = Effect::every();
    let idx = |e: Effect| labels.iter().position(|l| *l == e).unwrap_or(0);
    let mut confusion = vec![vec![0; labels.len()]; labels.len()];
    for c in cases.iter().filter(|c| c.truth.len() <= 1) {
        let t = c.truth.first().copied().unwrap_or(Effect::None);
        confusion[idx(t)][idx(c.first())] += 1;
    }
    let tally = |key: &dyn Fn(&Case) -> String| {
        let mut out: Vec<(String, usize, usize)> = Vec::new();
        for c in cases {
            let k = key(c);
            match out.iter_mut().find(|f| f.0 == k) {
                Some(f) => {
                    f.1 += c.right() as usize;
                    f.2 += 1;
                }
                None => out.push((k, c.right() as usize, 1)),
            }
        }
        out
    };
    let per_form = tally(&|c| c.truth_label.clone());
    let per_profile: Vec<(String, usize, usize)> = tally(&|c| c.profile.clone())
        .into_iter()
        .filter(|p| !p.0.is_empty())
        .collect();
    let two: Vec<&Case> = cases.iter().filter(|c| c.truth.len() == 2).collect();
    let single: Vec<&Case> = cases
        .iter()
        .filter(|c| c.truth.len() == 1 && c.truth[0] != Effect::Unexplained)
        .collect();
    let none: Vec<&Case> = cases.iter().filter(|c| c.truth.is_empty()).collect();
    let drift: Vec<&Case> = cases
        .iter()
        .filter(|c| c.truth == [Effect::Unexplained])
        .collect();
    let mut shrinks: Vec<f64> = cases
        .iter()
        .filter(|c| {
            !c.truth.is_empty() && c.truth[0] != Effect::Unexplained && c.truth.contains(&c.first())
        })
        .map(|c| c.shrink)
        .collect();
    let mut times: Vec<f64> = cases.iter().map(|c| c.elapsed_s).collect();
    let tmax = times.iter().cloned().fold(0.0, f64::max);
    let (calibration, brier, confident_right) = calibration(cases);
    Scores {
        labels: labels.iter().map(|e| e.name().to_string()).collect(),
        confusion,
        sets: cases.len(),
        share_right: cases.iter().filter(|c| c.right()).count() as f64 / cases.len().max(1) as f64,
        per_form,
        per_profile,
        two_effect_recall: (
            two.iter()
                .filter(|c| c.truth.iter().all(|e| c.verdict.contains(e)))
                .count(),
            two.len(),
        ),
        spurious_second: (
            single.iter().filter(|c| c.spurious_second()).count(),
            single.len(),
        ),
        no_effect_sets: none.len(),
        false_alarms: none.iter().filter(|c| !c.verdict.is_empty()).count(),
        median_shrink: median(&mut shrinks),
        unexplained_right: (
            drift.len(),
            drift
                .iter()
                .filter(|c| c.verdict == [Effect::Unexplained])
                .count(),
        ),
        time_median_max_s: (median(&mut times).unwrap_or(0.0), tmax),
        confident_right,
        calibration,
        brier,
    }
}

impl Scores {
    /// The confusion matrix of the sets with at most one effect (rows: truth, columns: the
    /// first effect named), rows without a set left out.
    fn write_confusion(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "confusion matrix of sets with at most one effect (rows: truth, columns: first effect named)"
        )?;
        write!(f, "{:>15}", "")?;
        for l in &self.labels {
            write!(f, " {:>14}", l)?;
        }
        writeln!(f)?;
        for (l, row) in self.labels.iter().zip(&self.confusion) {
            if row.iter().sum::<usize>() == 0 {
                continue;
            }
            write!(f, "{:>15}", l)?;
            for v in row {
                write!(f, " {:>14}", v)?;
            }
            writeln!(f)?;
        }
        Ok(())
    }

    /// The verdicts stated as confident and how the stated confidence compares with the share
    /// right, bin by bin (`brier`: the Brier score).
    fn write_calibration(&self, f: &mut std::fmt::Formatter<'_>, brier: f64) -> std::fmt::Result {
        writeln!(
            f,
            "verdicts stated as confident (confidence at least {:.0} %): {} right of {}; confident and wrong: {}",
            100.0 * subfric_diagnose::confidence::CONFIDENT,
            self.confident_right.0,
            self.confident_right.1,
            self.confident_right.1 - self.confident_right.0
        )?;
        writeln!(
            f,
            "confidence against the share right (Brier score {brier:.3}):"
        )?;
        for b in self.calibration.iter().filter(|b| b.sets > 0) {
            writeln!(
                f,
                "  {:>3.0}-{:<3.0}%  {:>3} sets, mean confidence {:>3.0} %, right {:>3.0} %",
                100.0 * b.from,
                100.0 * b.to,
                b.sets,
                100.0 * b.mean_confidence,
                100.0 * b.right as f64 / b.sets as f64
            )?;
        }
        Ok(())
    }
}

impl std::fmt::Display for Scores {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.write_confusion(f)?;
        writeln!(
            f,
            "accuracy per form (every named effect right, nothing more):"
        )?;
        for (label, right, total) in &self.per_form {
            writeln!(
                f,
                "  {:<72} {:>3}/{:<3} {:>4.0}%",
                label,
                right,
                total,
                100.0 * *right as f64 / (*total).max(1) as f64
            )?;
        }
        if !self.per_profile.is_empty() {
            writeln!(f, "fully right per rig and logger profile:")?;
            for (profile, right, total) in &self.per_profile {
                writeln!(f, "  {:<10} {:>3}/{:<3}", profile, right, total)?;
            }
        }
        writeln!(
            f,
            "fully right: {:.0}% of {} sets",
            100.0 * self.share_right,
            self.sets
        )?;
        if self.two_effect_recall.1 > 0 {
            writeln!(
                f,
                "two-effect sets with both effects named: {} of {}",
                self.two_effect_recall.0, self.two_effect_recall.1
            )?;
        }
        writeln!(
            f,
            "single-effect sets with a spurious second effect: {} of {}",
            self.spurious_second.0, self.spurious_second.1
        )?;
        writeln!(
            f,
            "false alarms: {} of {} sets without an effect",
            self.false_alarms, self.no_effect_sets
        )?;
        match self.median_shrink {
            Some(m) => writeln!(
                f,
                "median held-out shrink where the first effect is real and named: {:.0}%",
                100.0 * m
            )?,
            None => writeln!(f, "median held-out shrink: no effect named right")?,
        }
        writeln!(
            f,
            "gaps no candidate explains: {} of {} called unexplained",
            self.unexplained_right.1, self.unexplained_right.0
        )?;
        if let Some(brier) = self.brier {
            self.write_calibration(f, brier)?;
        }
        write!(
            f,
            "diagnosis time: median {:.1} s, max {:.1} s",
            self.time_median_max_s.0, self.time_median_max_s.1
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(truth: &[Effect], verdict: &[Effect], profile: &str) -> Case {
        Case {
            name: "s".into(),
            truth: truth.to_vec(),
            truth_label: format!("{truth:?}"),
            verdict: verdict.to_vec(),
            shrink: 0.5,
            profile: profile.into(),
            elapsed_s: 1.0,
            confidence: None,
            weighed: Vec::new(),
            without_first_loadings: None,
            shown_by_events: Vec::new(),
            base_at_bounds: Vec::new(),
        }
    }

    #[test]
    fn scores_count_what_they_say() {
        use Effect::*;
        let slip = Effect::from_name("slip-hardening").unwrap();
        let pressure = Effect::from_name("pressure").unwrap();
        let rate = Effect::from_name("rate").unwrap();
        let cases = [
            case(&[], &[], "lab"),
            case(&[], &[Unexplained], "rig"),
            case(&[rate], &[rate], "lab"),
            case(&[rate], &[rate, slip], "clean"),
            case(&[rate, pressure], &[pressure, rate], "rig"),
            case(&[slip, pressure], &[slip], "rig"),
            case(&[Unexplained], &[Unexplained], "clean"),
        ];
        let s = score(&cases);
        assert_eq!(s.sets, 7);
        assert!((s.share_right - 4.0 / 7.0).abs() < 1e-12);
        assert_eq!((s.no_effect_sets, s.false_alarms), (2, 1));
        assert_eq!(s.two_effect_recall, (1, 2));
        assert_eq!(s.spurious_second, (1, 2));
        assert_eq!(s.unexplained_right, (1, 1));
        assert_eq!(
            s.per_profile,
            vec![
                ("lab".to_string(), 2, 2),
                ("rig".to_string(), 1, 3),
                ("clean".to_string(), 1, 2)
            ]
        );
        // Order does not matter; a verdict of none on a none set is right.
        assert!(cases[4].right() && cases[0].right() && !cases[1].right());
    }
}
