//! Held-out data that can credit a true effect: each test is cut into pieces at its events (the
//! initial loading, each velocity step, each hold with its reload, each reversal), and the
//! folds leave out whole pieces of each kind in turn, so every held-out piece has its like in
//! the fitted data. The tail of each test and each whole test are kept as extra folds for the
//! report.

use serde::Serialize;
use subfric_reading::SegmentKind;
use subfric_reading::{FitTest, PreparedTest};

/// What kind of situation a piece holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PieceKind {
    /// The first loading of a test.
    InitialLoading,
    /// A velocity step and the sliding after it.
    VelocityStep,
    /// A hold and the reload after it.
    Hold,
    /// A reversal of the direction and the sliding after it.
    Reversal,
    /// Unloading of the imposed traction (traction control).
    Unloading,
}

impl PieceKind {
    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            PieceKind::InitialLoading => "initial loading",
            PieceKind::VelocityStep => "velocity step",
            PieceKind::Hold => "hold",
            PieceKind::Reversal => "reversal",
            PieceKind::Unloading => "unloading",
        }
    }

    fn starting(kind: SegmentKind) -> Option<PieceKind> {
        match kind {
            SegmentKind::InitialLoading => Some(PieceKind::InitialLoading),
            SegmentKind::AfterVelocityStep => Some(PieceKind::VelocityStep),
            SegmentKind::Hold => Some(PieceKind::Hold),
            SegmentKind::AfterReversal => Some(PieceKind::Reversal),
            SegmentKind::Unloading => Some(PieceKind::Unloading),
            SegmentKind::SteadySliding | SegmentKind::AfterHold => None,
        }
    }
}

/// Rows `start..end` of the fitted rows of test `test`, of one kind.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Piece {
    /// Index of the test.
    pub test: usize,
    /// First fitted row.
    pub start: usize,
    /// One past the last fitted row.
    pub end: usize,
    /// The situation it holds.
    pub kind: PieceKind,
    /// Where along the variable its kind is read at the piece lies ([`read_at`]), as a natural
    /// log: a hold's duration in s, the slip rate a velocity step goes to in mm/s, the normal
    /// stress of a first loading in kPa; `None` for kinds read at no variable.
    pub at: Option<f64>,
    /// Held out in a fold whose training pieces of its kind all lie on one side of it
    /// ([`mark_beyond_training`]): its prediction carries the fitted law beyond every reading
    /// of its like, an extrapolation.
    pub beyond_training: bool,
}

impl Piece {
    /// A piece of `kind`, rows `start..end` of test `test`, read at no variable.
    pub fn new(test: usize, start: usize, end: usize, kind: PieceKind) -> Piece {
        Piece {
            test,
            start,
            end,
            kind,
            at: None,
            beyond_training: false,
        }
    }
}

/// Where piece `kind` (rows `rows` of `p`'s fitted rows) lies along the variable its kind is
/// read at, as the segmentation read it: the natural log of a hold's duration in s (the hold's
/// rows of the full record), the natural log of the slip rate after a velocity step (the rate
/// level the piece starts, slip control only), the natural log of the normal stress in kPa a
/// first loading is run at (the median over its rows: a first loading held out is predicted at
/// its own stress from the tests at the others). Other kinds, and pieces the segmentation holds
/// no such reading for, give `None`.
fn read_at(p: &PreparedTest, kind: PieceKind, rows: std::ops::Range<usize>) -> Option<f64> {
    let seg = &p.segmentation;
    let time = &p.full.time;
    // The record's row of the piece's first fitted row of `of` kind.
    let first = |of: SegmentKind| {
        rows.clone()
            .find(|&i| p.kind_of_fit_row(i) == of)
            .and_then(|i| p.kept.get(i).copied())
    };
    let positive_ln = |v: f64| (v.is_finite() && v > 0.0).then(|| v.ln());
    match kind {
        PieceKind::Hold => {
            let r = first(SegmentKind::Hold)?;
            let &(a, b) = seg.holds.iter().find(|h| h.0 <= r && r < h.1)?;
            positive_ln(time.get(b.checked_sub(1)?)? - time.get(a)?)
        }
        PieceKind::VelocityStep if p.full.control == subfric_model::Control::Slip => {
            let r = first(SegmentKind::AfterVelocityStep)?;
            let level = seg.levels.iter().find(|l| l.start <= r && r < l.end)?;
            positive_ln(level.rate.abs())
        }
        PieceKind::InitialLoading => {
            let mut normal: Vec<f64> = p.fit.normal.get(rows)?.to_vec();
            positive_ln(subfric_reading::stats::median(&mut normal)?)
        }
        _ => None,
    }
}

/// Readings of a kind whose ratio is within this are one reading (a 10 s hold logged as 9.8 s
/// beside one of 10.1 s, two steps to 0.030 and 0.0301 mm/s): the ratio within which the
/// features read normal stresses as one level ([`crate::features::STRESS_LEVEL_RATIO`]).
const SAME_READING_RATIO: f64 = crate::features::STRESS_LEVEL_RATIO;

/// Marks each held-out piece whose fold trains on pieces of its kind that all lie on one side
/// of it along their variable ([`Piece::at`]): the longest of three holds predicted from the
/// two shorter ones, the step to the highest rate from steps to lower ones. A fitted law is
/// tested there on its extrapolation, a matter of its form; between readings of its like it
/// is tested on what the readings share. A piece whose kind has no reading in its fold's
/// training is not marked.
pub fn mark_beyond_training(all: &mut [Piece], folds: &[Fold]) {
    for f in folds {
        for &k in &f.held {
            let (kind, Some(at)) = (all[k].kind, all[k].at) else {
                continue;
            };
            let trained: Vec<f64> = (0..all.len())
                .filter(|j| !f.held.contains(j))
                .filter(|&j| all[j].kind == kind)
                .filter_map(|j| all[j].at)
                .collect();
            if trained.is_empty() {
                continue;
            }
            let same = SAME_READING_RATIO.ln();
            let below = trained.iter().any(|&v| v <= at + same);
            let above = trained.iter().any(|&v| v >= at - same);
            all[k].beyond_training = !(below && above);
        }
    }
}

/// Cuts every test's fitted rows into pieces at its events.
pub fn pieces(tests: &[PreparedTest]) -> Vec<Piece> {
    let mut out = Vec::new();
    for (ti, p) in tests.iter().enumerate() {
        let n = p.fit.len();
        if n == 0 {
            continue;
        }
        let mut start = 0;
        let mut kind =
            PieceKind::starting(p.kind_of_fit_row(0)).unwrap_or(PieceKind::InitialLoading);
        let mut prev = p.kind_of_fit_row(0);
        for i in 1..n {
            let k = p.kind_of_fit_row(i);
            let new = (k != prev)
                .then(|| PieceKind::starting(k))
                .flatten()
                // a reload after a hold belongs to the hold's piece
                .filter(|_| !(prev == SegmentKind::Hold && k == SegmentKind::AfterHold));
            if let Some(nk) = new {
                out.push(Piece {
                    at: read_at(p, kind, start..i),
                    ..Piece::new(ti, start, i, kind)
                });
                start = i;
                kind = nk;
            }
            prev = k;
        }
        out.push(Piece {
            at: read_at(p, kind, start..n),
            ..Piece::new(ti, start, n, kind)
        });
    }
    out
}

/// A held-out fold: per test, the weight of each fitted row in training (0 when held out), and
/// the pieces held out.
#[derive(Clone, Debug)]
pub struct Fold {
    /// Description.
    pub name: String,
    /// Indices of the pieces held out.
    pub held: Vec<usize>,
    /// Per test, per row: held out.
    pub held_rows: Vec<Vec<bool>>,
}

impl Fold {
    fn from_pieces(name: String, tests: &[FitTest], all: &[Piece], held: Vec<usize>) -> Fold {
        let mut held_rows: Vec<Vec<bool>> = tests.iter().map(|t| vec![false; t.len()]).collect();
        for &k in &held {
            let p = &all[k];
            for r in &mut held_rows[p.test][p.start..p.end] {
                *r = true;
            }
        }
        Fold {
            name,
            held,
            held_rows,
        }
    }

    /// The tests as trained on in this fold: held rows weigh nothing.
    pub fn training(&self, tests: &[FitTest]) -> Vec<FitTest> {
        tests
            .iter()
            .zip(&self.held_rows)
            .map(|(t, held)| {
                let mut t = t.clone();
                let w: Vec<f64> = (0..t.len())
                    .map(|i| if held[i] { 0.0 } else { t.weight_of(i) })
                    .collect();
                t.row_weight = w;
                t
            })
            .collect()
    }
}

/// The piece folds: pieces of each kind that occurs at least twice are dealt round-robin to
/// `k` folds (kinds starting at different folds, so folds stay balanced); a kind seen once is
/// never held out (it has no like to learn from).
pub fn piece_folds(tests: &[FitTest], all: &[Piece], k: usize) -> Vec<Fold> {
    let mut by_kind: std::collections::BTreeMap<PieceKind, Vec<usize>> = Default::default();
    for (i, p) in all.iter().enumerate() {
        by_kind.entry(p.kind).or_default().push(i);
    }
    let k = k.max(2);
    let mut held: Vec<Vec<usize>> = vec![Vec::new(); k];
    let mut offset = 0;
    for list in by_kind.values() {
        if list.len() < 2 {
            continue;
        }
        for (j, &piece) in list.iter().enumerate() {
            held[(j + offset) % k].push(piece);
        }
        offset += list.len();
    }
    held.into_iter()
        .enumerate()
        .filter(|(_, h)| !h.is_empty())
        .map(|(i, h)| Fold::from_pieces(format!("pieces {}/{k}", i + 1), tests, all, h))
        .collect()
}

/// Extra folds for the report: the last `fraction` of each test, and each whole test (when
/// there are several).
pub fn extra_folds(tests: &[FitTest], fraction: f64) -> (Vec<Fold>, Vec<Fold>) {
    let mut tail = Vec::new();
    let mut loto = Vec::new();
    for (ti, t) in tests.iter().enumerate() {
        let n = t.len();
        let cut = ((1.0 - fraction) * n as f64).round() as usize;
        if cut >= 10 && cut < n {
            let mut held_rows: Vec<Vec<bool>> =
                tests.iter().map(|t| vec![false; t.len()]).collect();
            for r in &mut held_rows[ti][cut..] {
                *r = true;
            }
            tail.push(Fold {
                name: format!("last {:.0}% of {}", 100.0 * fraction, t.name),
                held: Vec::new(),
                held_rows,
            });
        }
        if tests.len() >= 2 {
            let mut held_rows: Vec<Vec<bool>> =
                tests.iter().map(|t| vec![false; t.len()]).collect();
            held_rows[ti] = vec![true; n];
            loto.push(Fold {
                name: format!("leave out {}", t.name),
                held: Vec::new(),
                held_rows,
            });
        }
    }
    (tail, loto)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(kind: PieceKind, at: Option<f64>) -> Piece {
        Piece {
            at,
            ..Piece::new(0, 0, 1, kind)
        }
    }

    fn holding(held: Vec<usize>) -> Fold {
        Fold {
            name: format!("{held:?}"),
            held,
            held_rows: Vec::new(),
        }
    }

    #[test]
    fn a_piece_predicted_beyond_every_reading_of_its_like_is_marked_and_one_between_them_is_not() {
        // Holds of 10, 100 and 1000 s, one per fold, and a reversal read at no variable.
        let mut all = vec![
            read(PieceKind::Hold, Some(10f64.ln())),
            read(PieceKind::Hold, Some(100f64.ln())),
            read(PieceKind::Hold, Some(1000f64.ln())),
            read(PieceKind::Reversal, None),
        ];
        let folds = vec![holding(vec![0]), holding(vec![1, 3]), holding(vec![2])];
        mark_beyond_training(&mut all, &folds);
        let marked: Vec<bool> = all.iter().map(|p| p.beyond_training).collect();
        assert_eq!(marked, [true, false, true, false]);
        // A reading equal to a trained one, or within a level of it, is not beyond it (two
        // steps to 0.003 mm/s read as 0.00300 and 0.00303).
        let mut same = vec![
            read(PieceKind::VelocityStep, Some(0.003f64.ln())),
            read(PieceKind::VelocityStep, Some(0.00303f64.ln())),
        ];
        mark_beyond_training(&mut same, &[holding(vec![0]), holding(vec![1])]);
        assert!(same.iter().all(|p| !p.beyond_training));
        // Twice as fast is another reading.
        let mut apart = vec![
            read(PieceKind::VelocityStep, Some(0.003f64.ln())),
            read(PieceKind::VelocityStep, Some(0.006f64.ln())),
        ];
        mark_beyond_training(&mut apart, &[holding(vec![0]), holding(vec![1])]);
        assert!(apart.iter().all(|p| p.beyond_training));
        // Of two holds each is predicted from the other alone: both beyond.
        let mut two = vec![
            read(PieceKind::Hold, Some(10f64.ln())),
            read(PieceKind::Hold, Some(100f64.ln())),
        ];
        mark_beyond_training(&mut two, &[holding(vec![0]), holding(vec![1])]);
        assert!(two.iter().all(|p| p.beyond_training));
        // Held out with every piece of its kind: no reading trained, nothing to be beyond.
        let mut alone = vec![
            read(PieceKind::Hold, Some(10f64.ln())),
            read(PieceKind::Hold, Some(100f64.ln())),
        ];
        mark_beyond_training(&mut alone, &[holding(vec![0, 1])]);
        assert!(alone.iter().all(|p| !p.beyond_training));
    }
}
