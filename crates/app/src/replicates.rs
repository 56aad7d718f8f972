//! The verdict again at further seeds of the fits' random start (`diagnose --replicates N`).
//!
//! The seed of a diagnosis draws the base fit's global search (differential evolution) and
//! nothing else; every later fit starts from that base. Two seeds give bases alike to four or
//! five digits, yet on a record where a stage of the selection is decided by a margin the
//! fits' numerical path can move, they can end at different verdicts: the real till-gouge
//! record p446 (`../shared/real-dev/`) is named "rate + pressure" at seeds 1 and 3, "rate" at
//! 2, 4, 5, 6 and 8 and "pressure + slip hardening" at 7, each run stating its own confidence
//! (38–55 %). A verdict that moves
//! with the seed is one the data do not carry, whatever a single run says of itself; the
//! replicates say so, next to the verdict, with the seeds that reached each reading.

use crate::progress::Progress;
use anyhow::Result;
use serde::Serialize;
use std::fmt::Write as _;
use subfric_diagnose::{DiagnoseOptions, Diagnosis};
use subfric_fit::RunCounter;
use subfric_reading::PreparedTest;

/// Most replicates `diagnose --replicates` runs: each is a whole diagnosis.
pub const MAX_REPLICATES: usize = 64;

/// A count of diagnoses as `--replicates` takes it: 1 (the diagnosis alone) up to
/// [`MAX_REPLICATES`]; the error says the range.
pub fn parse_count(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (1..=MAX_REPLICATES).contains(&n) => Ok(n),
        _ => Err(format!(
            "expected a whole number of diagnoses from 1 (the diagnosis alone) to {MAX_REPLICATES}, got `{s}`"
        )),
    }
}

/// The verdict one seed reached.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeedVerdict {
    /// The seed of the fits' random start.
    pub seed: u64,
    /// The effects named, by name, in the order named (empty for none).
    pub effects: Vec<String>,
    /// The verdict as the report words it ("rate + pressure", "none").
    pub label: String,
    /// The confidence that run stated (`None` when nothing was judged).
    pub confidence: Option<f64>,
}

impl SeedVerdict {
    /// The verdict of diagnosis `d`, run at `seed`.
    pub fn of(seed: u64, d: &Diagnosis) -> SeedVerdict {
        let named = d.verdict.named();
        // As "how sure" words its alternatives; a verdict that names nothing by its own word
        // (none, or cannot judge, which the alternatives never are).
        let label = if named.is_empty() {
            d.verdict.effect.to_string()
        } else {
            subfric_diagnose::confidence::label(&named)
        };
        SeedVerdict {
            seed,
            effects: named.iter().map(|e| e.name().to_string()).collect(),
            label,
            confidence: d.verdict.confidence,
        }
    }

    /// What makes two verdicts the same: the effects named, in any order; a verdict that names
    /// none is its label (none, cannot judge).
    fn key(&self) -> Vec<String> {
        if self.effects.is_empty() {
            return vec![self.label.clone()];
        }
        let mut k = self.effects.clone();
        k.sort();
        k
    }
}

/// One reading and the seeds that reached it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reading {
    /// The verdict as the report words it (as the first seed to reach it worded it).
    pub label: String,
    /// The seeds that reached it, in the order run.
    pub seeds: Vec<u64>,
}

/// The verdict at several seeds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Replicates {
    /// Each seed's verdict, the diagnosis's own seed first.
    pub runs: Vec<SeedVerdict>,
    /// Each distinct verdict with the seeds that reached it, most seeds first (ties: the one
    /// reached first).
    pub readings: Vec<Reading>,
    /// Every seed reached the diagnosis's own verdict.
    pub stable: bool,
    /// The report's line ("replicates: …").
    pub sentence: String,
}

/// The verdicts `runs` (the diagnosis's own first) read together.
pub fn summarise(runs: Vec<SeedVerdict>) -> Replicates {
    let mut keyed: Vec<(Vec<String>, Reading)> = Vec::new();
    for r in &runs {
        let key = r.key();
        match keyed.iter_mut().find(|(k, _)| *k == key) {
            Some((_, reading)) => reading.seeds.push(r.seed),
            None => keyed.push((
                key,
                Reading {
                    label: r.label.clone(),
                    seeds: vec![r.seed],
                },
            )),
        }
    }
    // A stable sort: among readings reached by as many seeds, the one reached first leads.
    keyed.sort_by_key(|(_, r)| std::cmp::Reverse(r.seeds.len()));
    let readings: Vec<Reading> = keyed.into_iter().map(|(_, r)| r).collect();
    let stable = readings.len() <= 1;
    let sentence = sentence(&runs, &readings);
    Replicates {
        runs,
        readings,
        stable,
        sentence,
    }
}

/// "the same verdict at all 4 seeds of the fits' random start (1–4): rate", or, when they
/// differ, each reading with its seeds and the reading a user should take from it.
fn sentence(runs: &[SeedVerdict], readings: &[Reading]) -> String {
    let n = runs.len();
    if readings.len() <= 1 {
        let label = readings.first().map_or("", |r| r.label.as_str());
        return format!(
            "the same verdict at all {n} seeds of the fits' random start ({}): {label}",
            seed_list(&runs.iter().map(|r| r.seed).collect::<Vec<_>>())
        );
    }
    let mut s = String::from("the verdict moves with the fits' random start: ");
    for (i, r) in readings.iter().enumerate() {
        let sep = if i == 0 { "" } else { ", " };
        let _ = write!(
            s,
            "{sep}{} at {} of {n} seeds ({})",
            r.label,
            r.seeds.len(),
            seed_list(&r.seeds)
        );
    }
    let own = &runs[0];
    let _ = write!(
        s,
        "; seed {} reached {}: the data do not carry one reading over the others — read it as uncertain between {}",
        own.seed,
        own.label,
        listed(&readings.iter().map(|r| r.label.as_str()).collect::<Vec<_>>())
    );
    s
}

/// "a and b", "a, b and c".
fn listed(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// Seeds as "1, 3" or, consecutive, "1–4".
fn seed_list(seeds: &[u64]) -> String {
    let consecutive = seeds.windows(2).all(|w| w[1] == w[0].wrapping_add(1));
    match seeds {
        [first, .., last] if seeds.len() > 2 && consecutive => format!("{first}–{last}"),
        _ => seeds
            .iter()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The seeds after `seed` that `replicates` runs in all take: `seed + 1`, `seed + 2`, ….
pub fn further_seeds(seed: u64, replicates: usize) -> Vec<u64> {
    (1..replicates as u64)
        .map(|k| seed.wrapping_add(k))
        .collect()
}

/// Diagnoses `prepared` again at each seed after `opts.seed` (`replicates` runs in all,
/// `own` the first), one after the other (each uses every core), and reads them together.
/// A replicate that fails or ends with a number that is not finite is an error, as the
/// diagnosis itself would be.
pub fn replicate(
    prepared: &[PreparedTest],
    opts: &DiagnoseOptions,
    own: SeedVerdict,
    replicates: usize,
    finite: &dyn Fn(&Diagnosis) -> Result<()>,
    progress: &dyn Progress,
) -> Result<Replicates> {
    let seeds = further_seeds(opts.seed, replicates);
    let mut runs = vec![own];
    for (i, seed) in seeds.iter().enumerate() {
        progress.stage(
            &format!(
                "replicate {}/{}: the diagnosis again at seed {seed}",
                i + 1,
                seeds.len()
            ),
            None,
        );
        let at = DiagnoseOptions {
            seed: *seed,
            ..opts.clone()
        };
        // Its own count of model runs, which the progress adds to the diagnosis's.
        let runs_counted = RunCounter::new();
        progress.watch_runs(&runs_counted);
        let d = subfric_diagnose::diagnose_reporting(prepared, &at, &|_| {}, &runs_counted)?;
        finite(&d)?;
        runs.push(SeedVerdict::of(*seed, &d));
    }
    Ok(summarise(runs))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(seed: u64, effects: &[&str], label: &str) -> SeedVerdict {
        SeedVerdict {
            seed,
            effects: effects.iter().map(|e| e.to_string()).collect(),
            label: label.to_string(),
            confidence: Some(0.5),
        }
    }

    #[test]
    fn seeds_that_agree_are_stable_and_said_once() {
        let r = summarise(vec![
            run(1, &["rate"], "rate"),
            run(2, &["rate"], "rate"),
            run(3, &["rate"], "rate"),
        ]);
        assert!(r.stable);
        assert_eq!(r.readings.len(), 1);
        assert_eq!(r.readings[0].seeds, [1, 2, 3]);
        assert_eq!(
            r.sentence,
            "the same verdict at all 3 seeds of the fits' random start (1–3): rate"
        );
    }

    #[test]
    fn seeds_that_differ_are_counted_the_majority_first_and_read_as_uncertain() {
        let r = summarise(vec![
            run(1, &["rate", "pressure"], "rate + pressure"),
            run(2, &["rate"], "rate"),
            run(3, &["pressure", "rate"], "pressure + rate"),
            run(4, &["rate"], "rate"),
            run(5, &["rate"], "rate"),
        ]);
        assert!(!r.stable);
        // The same two effects named in another order are the same verdict.
        assert_eq!(r.readings.len(), 2);
        assert_eq!(r.readings[0].label, "rate");
        assert_eq!(r.readings[0].seeds, [2, 4, 5]);
        assert_eq!(r.readings[1].label, "rate + pressure");
        assert_eq!(r.readings[1].seeds, [1, 3]);
        assert!(
            r.sentence.starts_with(
                "the verdict moves with the fits' random start: rate at 3 of 5 seeds (2, 4, 5), rate + pressure at 2 of 5 seeds (1, 3); seed 1 reached rate + pressure"
            ),
            "{}",
            r.sentence
        );
        assert!(r
            .sentence
            .ends_with("read it as uncertain between rate and rate + pressure"));
    }

    #[test]
    fn three_readings_are_listed_as_a_sentence_lists_them() {
        let r = summarise(vec![
            run(1, &["rate", "pressure"], "rate + pressure"),
            run(2, &["rate"], "rate"),
            run(
                3,
                &["pressure", "slip-hardening"],
                "pressure + slip-hardening",
            ),
        ]);
        assert!(
            r.sentence
                .ends_with("uncertain between rate + pressure, rate and pressure + slip-hardening"),
            "{}",
            r.sentence
        );
    }

    #[test]
    fn none_and_unexplained_are_different_verdicts_and_a_tie_keeps_the_first_reached_first() {
        let r = summarise(vec![
            run(7, &[], "none"),
            run(8, &["unexplained"], "unexplained"),
        ]);
        assert!(!r.stable);
        assert_eq!(r.readings[0].label, "none");
        assert_eq!(r.readings[1].label, "unexplained");
        // Two verdicts that both name nothing are told apart by their label.
        let r = summarise(vec![run(1, &[], "none"), run(2, &[], "cannot judge")]);
        assert!(!r.stable);
    }

    #[test]
    fn the_further_seeds_follow_the_own_one_and_wrap() {
        assert_eq!(further_seeds(1, 4), [2, 3, 4]);
        assert_eq!(further_seeds(9, 1), Vec::<u64>::new());
        assert_eq!(further_seeds(u64::MAX, 3), [0, 1]);
        assert_eq!(seed_list(&[u64::MAX, 0, 1]), format!("{}–1", u64::MAX));
        assert_eq!(seed_list(&[4, 5]), "4, 5");
    }
}
