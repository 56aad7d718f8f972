//! Checking the diagnosis on sets whose effects it is not told: every form of every family,
//! sets with two effects at once, sets without an effect, a measurement drift no candidate
//! models, each also with lab-like sampling or a mid-run start. Scored as a confusion matrix,
//! the share of sets fully right, the accuracy per form, the recall of two-effect sets and the
//! rate of spurious second effects.

use crate::candidates::Effect;
use crate::diagnose::{diagnose, prepare_for_diagnosis, DiagnoseOptions, Diagnosis};
use crate::synth::{form_names, generate_set, random_truth, rng, Built, SynthOptions};
use serde::Serialize;

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
    /// The set had lab-like sampling.
    pub lab_like: bool,
    /// Its velocity-step test started mid-run.
    pub mid_run: bool,
    /// Diagnosis time [s].
    pub elapsed_s: f64,
}

impl Case {
    /// Scores a diagnosis against the truth (`truth`: families; a drift is `Unexplained`).
    pub fn new(name: &str, truth: Vec<Effect>, label: String, d: &Diagnosis) -> Case {
        let named: Vec<Effect> = d.verdict.effects.iter().map(|e| e.effect).collect();
        let verdict = match d.verdict.effect {
            Effect::None => Vec::new(),
            Effect::Unexplained if named.is_empty() => vec![Effect::Unexplained],
            _ => named,
        };
        Case {
            name: name.into(),
            truth,
            truth_label: label,
            verdict,
            shrink: d.verdict.held_out_shrink,
            lab_like: false,
            mid_run: false,
            elapsed_s: d.elapsed_s,
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
    for c in cases.iter().filter(|c| c.truth.len() <= 1) {
        let t = c.truth.first().copied().unwrap_or(Effect::None);
        confusion[idx(t)][idx(c.first())] += 1;
    }
    let mut per_form: Vec<(String, usize, usize)> = Vec::new();
    for c in cases {
        match per_form.iter_mut().find(|f| f.0 == c.truth_label) {
            Some(f) => {
                f.1 += c.right() as usize;
                f.2 += 1;
            }
            None => per_form.push((c.truth_label.clone(), c.right() as usize, 1)),
        }
    }
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
    Scores {
        labels: labels.iter().map(|e| e.name().to_string()).collect(),
        confusion,
        sets: cases.len(),
        share_right: cases.iter().filter(|c| c.right()).count() as f64 / cases.len().max(1) as f64,
        per_form,
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
    }
}

impl std::fmt::Display for Scores {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
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
        writeln!(
            f,
            "accuracy per form (every named effect right, nothing more):"
        )?;
        for (label, right, total) in &self.per_form {
            writeln!(
                f,
                "  {:<62} {:>3}/{:<3} {:>4.0}%",
                label,
                right,
                total,
                100.0 * *right as f64 / (*total).max(1) as f64
            )?;
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
        write!(
            f,
            "diagnosis time: median {:.1} s, max {:.1} s",
            self.time_median_max_s.0, self.time_median_max_s.1
        )
    }
}

/// A class of generated sets: the effects built in (empty: none).
pub type Class = Vec<Built>;

/// Every single form of every family, none, a drift, and six pairs of effects.
pub fn all_classes() -> Vec<Class> {
    let mut out: Vec<Class> = vec![Vec::new()];
    for effect in [
        Effect::Rate,
        Effect::Pressure,
        Effect::SlipHardening,
        Effect::LogHealing,
        Effect::Direction,
    ] {
        for form in 0..form_names(effect).len() {
            out.push(vec![Built { effect, form }]);
        }
    }
    out.push(vec![Built {
        effect: Effect::Unexplained,
        form: 0,
    }]);
    let b = |effect, form| Built { effect, form };
    out.extend([
        vec![b(Effect::Rate, 0), b(Effect::Pressure, 0)],
        vec![b(Effect::SlipHardening, 0), b(Effect::Pressure, 1)],
        vec![b(Effect::Rate, 2), b(Effect::SlipHardening, 1)],
        vec![b(Effect::LogHealing, 0), b(Effect::Direction, 0)],
        vec![b(Effect::Pressure, 4), b(Effect::Direction, 1)],
        vec![b(Effect::Rate, 3), b(Effect::SlipHardening, 2)],
    ]);
    out
}

/// Options of a self-check run.
#[derive(Clone, Debug)]
pub struct SelfcheckOptions {
    /// Classes to generate.
    pub classes: Vec<Class>,
    /// Sets per class: the first plain, the second lab-like, the third started mid-run, then
    /// both, in turn.
    pub per_class: usize,
    /// Seed.
    pub seed: u64,
    /// Generator settings (lab-like and mid-run are set per set as above).
    pub synth: SynthOptions,
    /// Diagnosis settings.
    pub diagnose: DiagnoseOptions,
    /// Diagnose each set without the candidate forms that generated it: the family must be
    /// named through another of its forms (effects in forms the library does not list).
    pub unlisted: bool,
}

impl Default for SelfcheckOptions {
    fn default() -> Self {
        SelfcheckOptions {
            classes: all_classes(),
            per_class: 2,
            seed: 7,
            synth: SynthOptions::default(),
            diagnose: DiagnoseOptions::default(),
            unlisted: false,
        }
    }
}

/// Generates sets with withheld effects, diagnoses each and scores the verdicts; `keep` sees
/// every generated set and its truth before it is diagnosed.
pub fn selfcheck(
    opts: &SelfcheckOptions,
    progress: &dyn Fn(&Case),
    keep: &dyn Fn(&subfric_data::ExperimentSet, &crate::synth::Truth),
) -> (Vec<Case>, Scores) {
    let mut cases = Vec::new();
    let mut r = rng(opts.seed);
    for (ci, class) in opts.classes.iter().enumerate() {
        for k in 0..opts.per_class {
            let truth = random_truth(class, &mut r);
            let synth = SynthOptions {
                lab_like: k % 4 == 1 || k % 4 == 3,
                mid_run: k % 4 == 2 || k % 4 == 3,
                ..opts.synth
            };
            let name = format!("synthetic-{:02}-{}", ci + 1, k + 1);
            let set = generate_set(&name, &truth, &synth, &mut r);
            keep(&set, &truth);
            let prepared = prepare_for_diagnosis(&set);
            let mut dopts = opts.diagnose.clone();
            dopts.seed = opts.seed.wrapping_add((ci * 1000 + k) as u64);
            if opts.unlisted {
                dopts.excluded_forms = truth
                    .effects
                    .iter()
                    .filter_map(|&b| crate::synth::library_name(b))
                    .map(String::from)
                    .collect();
            }
            let families = truth.families();
            let mut case = match diagnose(&prepared, &dopts) {
                Ok(d) => Case::new(&name, families, truth.label(), &d),
                Err(_) => Case {
                    name: name.clone(),
                    truth: families,
                    truth_label: truth.label(),
                    verdict: vec![Effect::Unexplained],
                    shrink: 0.0,
                    lab_like: false,
                    mid_run: false,
                    elapsed_s: 0.0,
                },
            };
            case.lab_like = synth.lab_like;
            case.mid_run = synth.mid_run;
            progress(&case);
            cases.push(case);
        }
    }
    let s = score(&cases);
    (cases, s)
}
