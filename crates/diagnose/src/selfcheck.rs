//! Checking the diagnosis on sets whose effect it is not told: confusion matrix, share named
//! right, false alarms on sets without an effect, median held-out shrink where the effect is real.

use crate::candidates::Effect;
use crate::diagnose::{diagnose, prepare_for_diagnosis, DiagnoseOptions, Diagnosis};
use crate::synth::{generate_set, random_truth, rng, SynthOptions};
use serde::Serialize;

/// One diagnosed set and its truth.
#[derive(Clone, Debug, Serialize)]
pub struct Case {
    /// Set name.
    pub name: String,
    /// The effect it holds.
    pub truth: Effect,
    /// The effect the diagnosis named.
    pub verdict: Effect,
    /// Held-out shrink of the named effect.
    pub shrink: f64,
    /// Held-out shrink of the candidate for the true effect (when it is in the library).
    pub true_effect_shrink: Option<f64>,
    /// Diagnosis time [s].
    pub elapsed_s: f64,
}

impl Case {
    /// Scores a diagnosis against the truth.
    pub fn new(name: &str, truth: Effect, d: &Diagnosis) -> Case {
        Case {
            name: name.into(),
            truth,
            verdict: d.verdict.effect,
            shrink: d.verdict.held_out_shrink,
            true_effect_shrink: d
                .candidates
                .iter()
                .find(|c| c.effect == truth)
                .map(|c| c.held_out_shrink),
            elapsed_s: d.elapsed_s,
        }
    }
}

/// Figures of a self-check.
#[derive(Clone, Debug, Serialize)]
pub struct Scores {
    /// Labels of the confusion matrix (rows: truth, columns: verdict).
    pub labels: Vec<String>,
    /// Counts.
    pub confusion: Vec<Vec<usize>>,
    /// Sets.
    pub sets: usize,
    /// Share of sets named right.
    pub share_right: f64,
    /// Sets without an effect.
    pub no_effect_sets: usize,
    /// Of those, how many got an effect named (false alarms).
    pub false_alarms: usize,
    /// Median held-out shrink of the named effect over sets with a library effect named right.
    pub median_shrink: Option<f64>,
    /// Sets whose gap no candidate explains, and how many were called "unexplained".
    pub unexplained_right: (usize, usize),
    /// Median and largest diagnosis time [s].
    pub time_median_max_s: (f64, f64),
}

fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// Scores cases.
pub fn score(cases: &[Case]) -> Scores {
    let labels: Vec<Effect> = Effect::ALL.to_vec();
    let idx = |e: Effect| labels.iter().position(|l| *l == e).unwrap_or(0);
    let mut confusion = vec![vec![0; labels.len()]; labels.len()];
    for c in cases {
        confusion[idx(c.truth)][idx(c.verdict)] += 1;
    }
    let right = cases.iter().filter(|c| c.truth == c.verdict).count();
    let none: Vec<&Case> = cases.iter().filter(|c| c.truth == Effect::None).collect();
    let unexpl: Vec<&Case> = cases
        .iter()
        .filter(|c| c.truth == Effect::Unexplained)
        .collect();
    let mut shrinks: Vec<f64> = cases
        .iter()
        .filter(|c| c.truth == c.verdict && !matches!(c.truth, Effect::None | Effect::Unexplained))
        .map(|c| c.shrink)
        .collect();
    let mut times: Vec<f64> = cases.iter().map(|c| c.elapsed_s).collect();
    let tmax = times.iter().cloned().fold(0.0, f64::max);
    Scores {
        labels: labels.iter().map(|e| e.name().to_string()).collect(),
        confusion,
        sets: cases.len(),
        share_right: right as f64 / cases.len().max(1) as f64,
        no_effect_sets: none.len(),
        false_alarms: none.iter().filter(|c| c.verdict != Effect::None).count(),
        median_shrink: median(&mut shrinks),
        unexplained_right: (
            unexpl.len(),
            unexpl
                .iter()
                .filter(|c| c.verdict == Effect::Unexplained)
                .count(),
        ),
        time_median_max_s: (median(&mut times).unwrap_or(0.0), tmax),
    }
}

impl std::fmt::Display for Scores {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "confusion matrix (rows: truth, columns: verdict)")?;
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
        writeln!(
            f,
            "named right: {:.0}% of {} sets",
            100.0 * self.share_right,
            self.sets
        )?;
        writeln!(
            f,
            "false alarms: {} of {} sets without an effect",
            self.false_alarms, self.no_effect_sets
        )?;
        match self.median_shrink {
            Some(m) => writeln!(
                f,
                "median held-out shrink where the effect is real and named: {:.0}%",
                100.0 * m
            )?,
            None => writeln!(f, "median held-out shrink: no effect named right")?,
        }
        writeln!(
            f,
            "gaps no candidate explains: {} of {} called unexplained",
            self.unexplained_right.1, self.unexplained_right.0
        )?;
        write!(
            f,
            "diagnosis time: median {:.1} s, max {:.1} s",
            self.time_median_max_s.0, self.time_median_max_s.1
        )
    }
}

/// Options of a self-check run.
#[derive(Clone, Debug)]
pub struct SelfcheckOptions {
    /// Classes to generate.
    pub classes: Vec<Effect>,
    /// Sets per class.
    pub per_class: usize,
    /// Seed.
    pub seed: u64,
    /// Generator settings.
    pub synth: SynthOptions,
    /// Diagnosis settings.
    pub diagnose: DiagnoseOptions,
}

impl Default for SelfcheckOptions {
    fn default() -> Self {
        SelfcheckOptions {
            classes: Effect::ALL.to_vec(),
            per_class: 2,
            seed: 7,
            synth: SynthOptions::default(),
            diagnose: DiagnoseOptions::default(),
        }
    }
}

/// Generates sets with withheld effects, diagnoses each and scores the verdicts.
pub fn selfcheck(opts: &SelfcheckOptions, progress: &dyn Fn(&Case)) -> (Vec<Case>, Scores) {
    let mut cases = Vec::new();
    let mut r = rng(opts.seed);
    for (ci, &effect) in opts.classes.iter().enumerate() {
        for k in 0..opts.per_class {
            let name = format!("synthetic-{}-{}", effect.name(), k + 1);
            let truth = random_truth(effect, &mut r);
            let set = generate_set(&name, &truth, &opts.synth, &mut r);
            let prepared = prepare_for_diagnosis(&set);
            let mut dopts = opts.diagnose.clone();
            dopts.seed = opts.seed.wrapping_add((ci * 1000 + k) as u64);
            let case = match diagnose(&prepared, &dopts) {
                Ok(d) => Case::new(&name, effect, &d),
                Err(_) => Case {
                    name: name.clone(),
                    truth: effect,
                    verdict: Effect::Unexplained,
                    shrink: 0.0,
                    true_effect_shrink: None,
                    elapsed_s: 0.0,
                },
            };
            progress(&case);
            cases.push(case);
        }
    }
    let s = score(&cases);
    (cases, s)
}
