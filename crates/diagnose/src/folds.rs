//! Held-out data that can credit a true effect: each test is cut into pieces at its events (the
//! initial loading, each velocity step, each hold with its reload, each reversal), and the
//! folds leave out whole pieces of each kind in turn, so every held-out piece has its like in
//! the fitted data. The tail of each test and each whole test are kept as extra folds for the
//! report.

use serde::Serialize;
use subfric_data::SegmentKind;
use subfric_fit::{FitTest, PreparedTest};

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
                    test: ti,
                    start,
                    end: i,
                    kind,
                });
                start = i;
                kind = nk;
            }
            prev = k;
        }
        out.push(Piece {
            test: ti,
            start,
            end: n,
            kind,
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
