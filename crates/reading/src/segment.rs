//! Segmentation of a test into loading phases: initial loading, steady sliding, velocity
//! steps, holds, unloading and reversals, with cycle numbers.
//!
//! # Conventions
//!
//! - Row `i` (for `i ≥ 1`) belongs to the interval from row `i-1` to row `i`: its kind is the
//!   kind of the motion that led to it. Row 0 takes the kind of row 1.
//! - Event rows are the rows at the instant of the event: the row at the extreme for a
//!   reversal, the last row at the old rate for a velocity step. The first row of the new phase
//!   is the next row.
//! - Holds are half-open row ranges `[start, end)`: the rows reached while the imposed column
//!   stays constant. The hold starts at time `time_s[start - 1]` (the last moving row) and lasts
//!   until `time_s[end - 1]`. A rest at the beginning or the end of a test is a hold too.
//! - Cycles: cycle 0 is everything up to and including the first reversal (the virgin
//!   loading). Cycle `k ≥ 1` starts after reversal `2k-1` (1-based) and ends with reversal
//!   `2k+1`, so each cycle holds two half-cycles and begins with the unloading from a peak.
//!   For a slip-controlled triangle `0 → +a → −a → +a …` cycle `k` is `+a → −a → +a`. For
//!   shear-controlled pulsating loading `0 → τ → 0 → τ …` cycle `k` runs from peak `k` to
//!   peak `k+1`; it contains exactly one return of the shear to its minimum, so the number of
//!   cycles (`cycles()`) is the number of returns to the minimum (the final one included).
//! - Slip control: after a start, a hold, a velocity step or a reversal the rows until the
//!   imposed slip has moved `transient_mm` are labelled with the transient kind, then
//!   [`SegmentKind::SteadySliding`]. [`SegmentKind::Unloading`] is not used.
//! - Shear control: rows where |shear| decreases are [`SegmentKind::Unloading`]; other moving
//!   rows carry the transient kind of the last event until the *measured* slip has moved
//!   `transient_mm`, then [`SegmentKind::SteadySliding`].

use serde::{Deserialize, Serialize};

use crate::condition::{analyze, Analysis, Conditioned};
use crate::imposed::velocity_steps;
pub use crate::imposed::SegmentOptions;
use crate::noise::estimate_noise;
use crate::stats::median;
use subfric_data::meta::{ControlColumn, InitialSpec};
use subfric_data::set::TestData;

/// Kind of a loading phase.
///
/// ```
/// use subfric_reading::SegmentKind;
/// assert_eq!(SegmentKind::AfterVelocityStep.name(), "after-velocity-step");
/// assert_eq!(serde_json::to_string(&SegmentKind::Hold).unwrap(), "\"hold\"");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SegmentKind {
    /// The transient at the start of the test (virgin loading).
    InitialLoading,
    /// Sliding at a steady imposed rate, away from any transient.
    SteadySliding,
    /// The transient after a change of the sliding rate.
    AfterVelocityStep,
    /// The imposed column is constant (slip hold, or creep at constant shear).
    Hold,
    /// The transient after a hold.
    AfterHold,
    /// Shear control: |shear| decreasing.
    Unloading,
    /// The transient after a reversal of the imposed direction.
    AfterReversal,
}

impl SegmentKind {
    /// All kinds.
    pub const ALL: [SegmentKind; 7] = [
        SegmentKind::InitialLoading,
        SegmentKind::SteadySliding,
        SegmentKind::AfterVelocityStep,
        SegmentKind::Hold,
        SegmentKind::AfterHold,
        SegmentKind::Unloading,
        SegmentKind::AfterReversal,
    ];

    /// Kebab-case name, as in JSON.
    pub fn name(self) -> &'static str {
        match self {
            SegmentKind::InitialLoading => "initial-loading",
            SegmentKind::SteadySliding => "steady-sliding",
            SegmentKind::AfterVelocityStep => "after-velocity-step",
            SegmentKind::Hold => "hold",
            SegmentKind::AfterHold => "after-hold",
            SegmentKind::Unloading => "unloading",
            SegmentKind::AfterReversal => "after-reversal",
        }
    }
}

impl std::fmt::Display for SegmentKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A run of consecutive rows of one kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// Kind of the phase.
    pub kind: SegmentKind,
    /// First row.
    pub start: usize,
    /// One past the last row.
    pub end: usize,
    /// Mean imposed rate over the segment, per s (mm/s or kPa/s), signed.
    pub rate: f64,
    /// Cycle number (see the module documentation).
    pub cycle: u32,
}

/// A stretch of sliding at one rate, between holds, reversals and velocity steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RateLevel {
    /// First row.
    pub start: usize,
    /// One past the last row.
    pub end: usize,
    /// Mean imposed rate, per s, signed.
    pub rate: f64,
}

/// Result of [`segment`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Segmentation {
    /// Consecutive segments covering all rows.
    pub segments: Vec<Segment>,
    /// Kind of each row.
    pub row_kind: Vec<SegmentKind>,
    /// Cycle of each row.
    pub cycle_of_row: Vec<u32>,
    /// Rows at the reversals of the imposed direction.
    pub reversals: Vec<usize>,
    /// Holds as half-open row ranges.
    pub holds: Vec<(usize, usize)>,
    /// Rows of the velocity steps (last row at the old rate).
    pub rate_changes: Vec<usize>,
    /// Sliding stretches at one rate.
    pub levels: Vec<RateLevel>,
    /// Typical sliding rate (distance-weighted median |rate|), per s.
    pub reference_rate: f64,
    /// The conditioned imposed column the segmentation works on.
    pub conditioned: Conditioned,
    /// How the test starts, and why that was decided.
    pub start: Start,
    /// The normal-stress column the model is given ([`crate::normal::condition_normal`]).
    pub normal: crate::normal::ConditionedNormal,
}

/// How a test starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StartKind {
    /// An unloaded interface at rest.
    Rest,
    /// At rest, or not yet sliding, under a traction well away from zero.
    Loaded,
    /// Already sliding at the first row (a segment cut out of a longer run).
    Sliding,
}

/// The initial state of a test, from the `initial` field or decided from the data.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Start {
    /// The state.
    pub kind: StartKind,
    /// Measured traction at the start [kPa] (slip control; the imposed one under traction
    /// control).
    pub shear_kpa: f64,
    /// Imposed rate at the start (mm/s or kPa/s), signed; 0 in a hold.
    pub rate: f64,
    /// True when the `initial` field of `experiment.json` said it, false when decided here.
    pub from_spec: bool,
    /// Why, in words.
    pub reason: String,
}

impl Segmentation {
    /// Number of cycles: the largest cycle number.
    pub fn cycles(&self) -> u32 {
        self.cycle_of_row.iter().copied().max().unwrap_or(0)
    }

    /// Duration (s) of each hold of `test`, in the order of `holds`.
    pub fn hold_durations(&self, test: &TestData) -> Vec<f64> {
        self.holds
            .iter()
            .map(|&(s, e)| {
                let t = &test.time_s;
                match (t.get(s.saturating_sub(1)), t.get(e.saturating_sub(1))) {
                    (Some(a), Some(b)) => b - a,
                    _ => 0.0,
                }
            })
            .collect()
    }

    /// Segments of one kind.
    pub fn of_kind(&self, kind: SegmentKind) -> impl Iterator<Item = &Segment> + '_ {
        self.segments.iter().filter(move |s| s.kind == kind)
    }

    /// Mean rates (per s, signed) just before and just after each velocity step.
    pub fn step_rates(&self) -> Vec<(f64, f64)> {
        self.rate_changes
            .iter()
            .map(|&c| {
                let before = self
                    .levels
                    .iter()
                    .find(|l| l.end == c + 1)
                    .map_or(f64::NAN, |l| l.rate);
                let after = self
                    .levels
                    .iter()
                    .find(|l| l.start == c + 1)
                    .map_or(f64::NAN, |l| l.rate);
                (before, after)
            })
            .collect()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Event {
    Start,
    HoldEnd,
    Step,
    Reversal,
}

fn rate_between(t: &[f64], y: &[f64], a: usize, b: usize) -> f64 {
    let dt = t[b] - t[a];
    if dt > 0.0 {
        (y[b] - y[a]) / dt
    } else {
        0.0
    }
}

/// Segments a test into loading phases (see the module documentation for the conventions).
///
/// Works on the conditioned imposed column ([`crate::condition_imposed`]) and time, with
/// windowed rate estimates so that noise does not create segments.
///
/// ```
/// use subfric_data::{ControlColumn, TestData, TestSpec};
/// use subfric_reading::{segment, SegmentKind, SegmentOptions};
/// // slip-controlled triangle 0 → 1 → -1 → 1 mm at 0.01 mm/s
/// let time: Vec<f64> = (0..=500).map(|i| i as f64).collect();
/// let slip: Vec<f64> = time.iter().map(|&t| {
///     if t <= 100.0 { 0.01 * t } else if t <= 300.0 { 1.0 - 0.01 * (t - 100.0) } else { -1.0 + 0.01 * (t - 300.0) }
/// }).collect();
/// let n = time.len();
/// let test = TestData {
///     spec: TestSpec::new("cyc", "cyc.csv", ControlColumn::Slip, 100.0), path: "cyc.csv".into(),
///     time_s: time, slip_mm: slip, shear_kpa: vec![0.0; n], normal_kpa: vec![100.0; n],
///     friction_given: false, line_of_row: (2..n + 2).collect(), comments: vec![],
///     reading_notes: vec![],
///     channels: vec![],
/// };
/// let seg = segment(&test, &SegmentOptions::default());
/// assert_eq!(seg.reversals, vec![100, 300]);
/// assert_eq!(seg.cycles(), 1);
/// assert_eq!(seg.row_kind[10], SegmentKind::InitialLoading);
/// assert_eq!(seg.row_kind[110], SegmentKind::AfterReversal);
/// assert_eq!(seg.row_kind[200], SegmentKind::SteadySliding);
/// ```
pub fn segment(test: &TestData, opts: &SegmentOptions) -> Segmentation {
    let n = test.time_s.len().min(test.imposed().len());
    let t = &test.time_s[..n];
    let an = analyze(t, &test.imposed()[..n], opts);
    // The rows are classified on the conditioned column before the levels are smoothed.
    let y = an.conditioned.values.clone();
    let mut seg = Segmentation {
        segments: Vec::new(),
        row_kind: vec![SegmentKind::InitialLoading; n],
        cycle_of_row: vec![0; n],
        reversals: an.reversals.clone(),
        holds: an.holds.clone(),
        rate_changes: Vec::new(),
        levels: Vec::new(),
        reference_rate: an.ref_rate,
        conditioned: an.conditioned.clone(),
        start: Start {
            kind: StartKind::Rest,
            shear_kpa: 0.0,
            rate: 0.0,
            from_spec: false,
            reason: String::new(),
        },
        normal: crate::normal::ConditionedNormal {
            values: test.normal_kpa.clone(),
            noise_sd: 0.0,
            changed: false,
            reason: String::new(),
        },
    };
    if n == 0 {
        return seg;
    }
    let in_hold = hold_mask(n, &seg.holds);
    let rise_end = seating_rise_end(test, n, &seg);
    find_rate_levels(t, &y, &in_hold, &an, opts, rise_end, &mut seg);
    smooth_levels(
        t,
        &mut seg.conditioned.values,
        &seg.levels,
        LEVEL_SMOOTHING_BANDS * seg.conditioned.band,
    );
    let event_at = events_at_rows(n, &seg);
    classify_rows(test, &y, &in_hold, &event_at, opts, &mut seg);
    seg.segments = collect_segments(t, &y, &event_at, &seg);
    seg.start = decide_start(test, &seg);
    seg.normal = crate::normal::condition_normal(test, &seg.row_kind);
    seg
}

/// Share of the first run's largest traction below which a slip-controlled test's first
/// loading is still rising from rest.
const RISE_SHARE_OF_PEAK: f64 = 0.5;

/// One past the last row of a slip-controlled test's first rise from rest — the rows before
/// its measured traction first reaches [`RISE_SHARE_OF_PEAK`] of the largest it reaches
/// before the first hold or reversal — or 0 (traction control, a test that starts loaded or
/// sliding, a first run of one row). While the shear is low a box seats: gaps close and the
/// specimen beds in, and the travel column counts that closure as slip, fast at first and
/// slowing as the load comes on. The rate of the travel there is not the drive's, and a change
/// of it is not a velocity step: a lab does not step the drive before the first peak, and a
/// seating read as a step from 0.04 to 0.01 mm/s would make a test at one rate look like two.
fn seating_rise_end(test: &TestData, n: usize, seg: &Segmentation) -> usize {
    if test.spec.control != ControlColumn::Slip || n < 2 {
        return 0;
    }
    let first_event = seg
        .holds
        .iter()
        .map(|h| h.0)
        .chain(seg.reversals.iter().copied())
        .min()
        .unwrap_or(n)
        .min(n);
    // A file that starts in a hold (or reverses at once) has no rise from rest to read.
    let Some(shear) = test.shear_kpa.get(..first_event).filter(|s| s.len() >= 2) else {
        return 0;
    };
    let peak = shear
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if peak <= 0.0 || !shear[0].is_finite() || shear[0].abs() >= RISE_SHARE_OF_PEAK * peak {
        return 0;
    }
    shear
        .iter()
        .position(|v| v.abs() >= RISE_SHARE_OF_PEAK * peak)
        .unwrap_or(0)
}

/// Which of the `n` rows lie in a hold.
fn hold_mask(n: usize, holds: &[(usize, usize)]) -> Vec<bool> {
    let mut in_hold = vec![false; n];
    for &(s, e) in holds {
        for v in &mut in_hold[s..e.min(n)] {
            *v = true;
        }
    }
    in_hold
}

/// Run index of each of the `n` rows: row i is in run k when k reversals lie before i.
fn run_index(n: usize, reversals: &[usize]) -> Vec<usize> {
    let mut run_of = vec![0usize; n];
    let mut k = 0;
    for (i, r) in run_of.iter_mut().enumerate() {
        while k < reversals.len() && reversals[k] < i {
            k += 1;
        }
        *r = k;
    }
    run_of
}

/// The constant-rate levels and the velocity steps between them, stretch by stretch: a
/// stretch is a maximal range of rows in one run, outside holds (no steps are looked for
/// across a reversal or a hold, which are events of their own). Nothing is found when a
/// value is not finite.
fn find_rate_levels(
    t: &[f64],
    y: &[f64],
    in_hold: &[bool],
    an: &Analysis,
    opts: &SegmentOptions,
    rise_end: usize,
    seg: &mut Segmentation,
) {
    let n = t.len();
    let run_of = run_index(n, &seg.reversals);
    let finite = y.iter().chain(t).all(|v| v.is_finite());
    let mut i = 1;
    while finite && i < n {
        if in_hold[i] {
            i += 1;
            continue;
        }
        let s = i;
        while i < n && !in_hold[i] && run_of[i] == run_of[s] {
            i += 1;
        }
        // intervals s..i (rows s-1 ..= i-1)
        let (p, q) = (s - 1, i - 1);
        let mut steps = velocity_steps(t, y, p, q, an.chunk_travel, opts);
        // A change of the travel's rate while the first loading rises from rest is the rig
        // seating, not the drive (see [`seating_rise_end`]).
        steps.retain(|&c| c >= rise_end);
        let mut a = p;
        for &c in steps.iter().chain(std::iter::once(&q)) {
            if c > a {
                seg.levels.push(RateLevel {
                    start: a + 1,
                    end: c + 1,
                    rate: rate_between(t, y, a, c),
                });
            }
            a = c;
        }
        seg.rate_changes.extend(steps);
    }
    seg.rate_changes.sort_unstable();
}

impl Event {
    /// Which event wins when several fall on one row: a reversal over the end of a hold over
    /// a velocity step over the start.
    fn rank(self) -> u8 {
        match self {
            Event::Start => 0,
            Event::Step => 1,
            Event::HoldEnd => 2,
            Event::Reversal => 3,
        }
    }
}

/// The event at each of the `n` rows (the end of a hold, a velocity step, a reversal), the
/// most significant one kept when several coincide.
fn events_at_rows(n: usize, seg: &Segmentation) -> Vec<Option<Event>> {
    let mut event_at: Vec<Option<Event>> = vec![None; n];
    let mut set_event = |row: usize, e: Event| {
        if row < n && event_at[row].is_none_or(|old| e.rank() > old.rank()) {
            event_at[row] = Some(e);
        }
    };
    for &(s, e) in &seg.holds {
        // a rest before any motion ends in the start of the test, not in an after-hold phase
        let ev = if s <= 1 { Event::Start } else { Event::HoldEnd };
        set_event(e - 1, ev);
    }
    for &c in &seg.rate_changes {
        set_event(c, Event::Step);
    }
    for &r in &seg.reversals {
        set_event(r, Event::Reversal);
    }
    event_at
}

/// Kind and cycle of every row: a row is in the transient after the last event until the
/// slip since that event exceeds [`SegmentOptions::transient_mm`] (under traction control the
/// measured slip, whose largest excursion counts), steady sliding after.
fn classify_rows(
    test: &TestData,
    y: &[f64],
    in_hold: &[bool],
    event_at: &[Option<Event>],
    opts: &SegmentOptions,
    seg: &mut Segmentation,
) {
    let n = event_at.len();
    let control = test.spec.control;
    let measured_slip = &test.slip_mm;
    let mut current = (0usize, Event::Start);
    let mut travel = 0.0f64;
    let mut reversals_before = 0usize;
    for i in 1..n {
        if let Some(e) = event_at[i - 1] {
            current = (i - 1, e);
            travel = 0.0;
        }
        while reversals_before < seg.reversals.len() && seg.reversals[reversals_before] < i {
            reversals_before += 1;
        }
        seg.cycle_of_row[i] = reversals_before.div_ceil(2) as u32;
        let e = current.0;
        travel = match control {
            ControlColumn::Slip => (y[i] - y[e]).abs(),
            ControlColumn::Shear => {
                let d = match (measured_slip.get(i), measured_slip.get(e)) {
                    (Some(a), Some(b)) if (a - b).is_finite() => (a - b).abs(),
                    _ => 0.0,
                };
                travel.max(d)
            }
        };
        let kind = if in_hold[i] {
            SegmentKind::Hold
        } else if control == ControlColumn::Shear && unloading(y, i) {
            SegmentKind::Unloading
        } else if travel <= opts.transient_mm {
            match current.1 {
                Event::Start => SegmentKind::InitialLoading,
                Event::HoldEnd => SegmentKind::AfterHold,
                Event::Step => SegmentKind::AfterVelocityStep,
                Event::Reversal => SegmentKind::AfterReversal,
            }
        } else {
            SegmentKind::SteadySliding
        };
        seg.row_kind[i] = kind;
    }
    if n > 1 {
        seg.row_kind[0] = seg.row_kind[1];
    }
}

/// The segments: maximal runs of rows of one kind and cycle, also cut at every event.
fn collect_segments(
    t: &[f64],
    y: &[f64],
    event_at: &[Option<Event>],
    seg: &Segmentation,
) -> Vec<Segment> {
    let n = event_at.len();
    let mut segments = Vec::new();
    let mut start = 0usize;
    for i in 1..=n {
        let boundary = i == n
            || seg.row_kind[i] != seg.row_kind[start]
            || seg.cycle_of_row[i] != seg.cycle_of_row[start]
            || event_at[i - 1].is_some();
        if boundary {
            let from = start.saturating_sub(1);
            let to = i - 1;
            segments.push(Segment {
                kind: seg.row_kind[start],
                start,
                end: i,
                rate: if to > from {
                    rate_between(t, y, from, to)
                } else {
                    0.0
                },
                cycle: seg.cycle_of_row[start],
            });
            start = i;
        }
    }
    segments
}

/// Rows at most over which the traction at the start is taken (while the imposed column has
/// not moved): enough for a median to reject a spike, few enough to stay at the start.
const START_ROWS: usize = 5;

/// The imposed column has "not moved" while within this many noise SDs of its first value
/// (three: a noisy still column stays inside with 99.7 % probability per row).
const STILL_BAND_SDS: f64 = 3.0;

/// A first traction within this many noise SDs of zero is rest …
const REST_NOISE_SDS: f64 = 5.0;

/// … or within this share of the typical traction (for quiet data, where 5 SDs is tiny).
const REST_SHARE_OF_LEVEL: f64 = 0.05;

/// A test that starts moving below this share of the typical traction is loaded but not yet
/// sliding; at or above it, already sliding (a segment cut out of a longer run starts at about
/// the sliding level, a test from rest well below it).
const SLIDING_SHARE_OF_LEVEL: f64 = 0.8;

/// The initial state: the `initial` field when given, else from the first rows — a traction
/// within the noise of zero is rest; a traction well below the sliding level, or a file that
/// starts in a hold, is loaded; a file that starts moving at about the sliding level is a
/// segment of a run that was already sliding.
fn decide_start(test: &TestData, seg: &Segmentation) -> Start {
    let n = test.len();
    let measured_shear = &test.shear_kpa;
    // The traction at the start: over the first rows that have not moved beyond the noise of the
    // imposed column (at most [`START_ROWS`]).
    let noise = &seg.conditioned.noise;
    let band = (STILL_BAND_SDS * noise.sd).max(0.5 * noise.quantum);
    let imposed = test.imposed();
    let still = imposed
        .iter()
        .take(START_ROWS)
        .take_while(|v| (*v - imposed[0]).abs() <= band)
        .count()
        .max(1);
    let shear0 = {
        let mut v: Vec<f64> = measured_shear[..still.min(n)].to_vec();
        median(&mut v).unwrap_or(0.0)
    };
    let rate0 = seg
        .levels
        .first()
        .filter(|l| l.start <= 2)
        .map_or(0.0, |l| l.rate);
    let in_hold = seg.holds.first().is_some_and(|h| h.0 <= 1);
    let control = test.spec.control;
    let shear_at_start = match control {
        ControlColumn::Slip => shear0,
        ControlColumn::Shear => test.shear_kpa.first().copied().unwrap_or(0.0),
    };
    let make = |kind, from_spec, reason: String| Start {
        kind,
        shear_kpa: shear_at_start,
        rate: if in_hold { 0.0 } else { rate0 },
        from_spec,
        reason,
    };
    match test.spec.initial {
        Some(InitialSpec::Rest) => {
            return make(StartKind::Rest, true, "`initial`: rest".into());
        }
        Some(InitialSpec::Sliding) if control == ControlColumn::Slip && in_hold => {
            return make(
                StartKind::Loaded,
                true,
                format!(
                    "`initial`: sliding, but the file starts in a hold: loaded at {shear0:.4} kPa"
                ),
            );
        }
        Some(InitialSpec::Sliding) => {
            return make(StartKind::Sliding, true, "`initial`: sliding".into());
        }
        None => {}
    }
    if control == ControlColumn::Shear || n < 3 {
        return make(StartKind::Rest, false, "from rest".into());
    }
    let noise = estimate_noise(&test.time_s, measured_shear).sd;
    let mut mags: Vec<f64> = measured_shear.iter().map(|v| v.abs()).collect();
    let level = median(&mut mags).unwrap_or(0.0);
    if shear0.abs() <= (REST_NOISE_SDS * noise).max(REST_SHARE_OF_LEVEL * level) {
        return make(
            StartKind::Rest,
            false,
            format!("first traction {shear0:.4} kPa is within the noise of zero: from rest"),
        );
    }
    if in_hold {
        return make(
            StartKind::Loaded,
            false,
            format!("starts still under a traction of {shear0:.4} kPa: loaded at rest"),
        );
    }
    if shear0.abs() < SLIDING_SHARE_OF_LEVEL * level {
        return make(
            StartKind::Loaded,
            false,
            format!(
                "starts moving at {shear0:.4} kPa, {:.0}% of the typical traction: loaded, not yet sliding",
                100.0 * shear0.abs() / level
            ),
        );
    }
    make(
        StartKind::Sliding,
        false,
        format!(
            "starts moving at {shear0:.4} kPa, {:.0}% of the typical traction: already sliding (a segment of a longer run)",
            100.0 * shear0.abs() / level
        ),
    )
}

/// Window of the smoothing of the imposed column within a level, in bands: wide enough that the
/// *rate* of the smoothed column is resolved (its error is about √12·σ/(W√n), under 1 % for
/// the noise and row spacing of lab files), since rate-dependent models turn imposed-column
/// noise into friction noise.
const LEVEL_SMOOTHING_BANDS: f64 = 15.0;

/// Smooths the imposed column within each sliding level at the scale of its noise: each
/// interior row is replaced by the straight line fitted to the rows within `window / 2` of
/// travel on either side (never across the level's ends, which stay as they are). A compliant
/// machine turns imposed-column noise into simulated traction noise; below the resolution of
/// the column there is no signal to keep. Where rows are farther apart than the window nothing
/// changes.
///
/// A line in time stands for the column only while it moves at the level's rate: an interval
/// whose travel departs from the level's rate times its duration by more than half the window
/// (a stretch of rows taken out of the record, a stall too short to read as a hold) is a
/// break, and each side is smoothed on its own — a line across it would move the rows next to
/// it by a share of that departure, several kPa of an elastic reload on a stiff rig. (One band
/// would catch smaller departures, but quantised readings at a jittered clock cross it often
/// enough on a real record to leave its levels unsmoothed: p446's base fit failed, 20 986× the
/// noise.)
fn smooth_levels(t: &[f64], y: &mut [f64], levels: &[RateLevel], window: f64) {
    let half = 0.5 * window;
    for l in levels {
        let (a, b) = (
            l.start.saturating_sub(1),
            l.end.saturating_sub(1).min(y.len() - 1),
        );
        let mut from = a;
        for k in a..b {
            let departure = (y[k + 1] - y[k] - l.rate * (t[k + 1] - t[k])).abs();
            if departure > half {
                smooth_stretch(t, y, from, k, half);
                from = k + 1;
            }
        }
        smooth_stretch(t, y, from, b, half);
    }
}

/// [`smooth_levels`] over rows `a..=b` of one level, which move at one rate.
fn smooth_stretch(t: &[f64], y: &mut [f64], a: usize, b: usize, half: f64) {
    if b <= a + 2 {
        return;
    }
    let src: Vec<f64> = y[a..=b].to_vec();
    let tt: Vec<f64> = t[a..=b].iter().map(|v| v - t[a]).collect();
    // Sums over the window src[lo..=hi]; both ends only move forward (src is monotone).
    let mut sums = [0.0f64; 5]; // n, Σt, Σu, Σt², Σtu
    let add = |s: &mut [f64; 5], k: usize, sign: f64| {
        s[0] += sign;
        s[1] += sign * tt[k];
        s[2] += sign * src[k];
        s[3] += sign * tt[k] * tt[k];
        s[4] += sign * tt[k] * src[k];
    };
    let (mut lo, mut hi) = (0usize, 0usize);
    add(&mut sums, 0, 1.0);
    for i in 1..src.len() - 1 {
        while hi < i || (hi + 1 < src.len() && (src[hi + 1] - src[i]).abs() <= half) {
            hi += 1;
            add(&mut sums, hi, 1.0);
        }
        while lo < i && (src[i] - src[lo]).abs() > half {
            add(&mut sums, lo, -1.0);
            lo += 1;
        }
        let [n, st, su, stt, stu] = sums;
        if n >= 3.0 {
            let tm = st / n;
            let var = stt / n - tm * tm;
            if var > 1e-12 * (tm * tm).max(1e-300) {
                let slope = (stu / n - tm * su / n) / var;
                y[a + i] = su / n + slope * (tt[i] - tm);
            }
        }
    }
    // Keep the level monotone and within its ends.
    let (ya, yb) = (src[0], src[src.len() - 1]);
    let (lo_v, hi_v) = (ya.min(yb), ya.max(yb));
    let up = yb >= ya;
    for i in a + 1..b {
        y[i] = y[i].clamp(lo_v, hi_v);
        let prev = y[i - 1];
        if (up && y[i] < prev) || (!up && y[i] > prev) {
            y[i] = prev;
        }
    }
}

/// Shear control: is |shear| decreasing over the interval ending at row `i`?
fn unloading(y: &[f64], i: usize) -> bool {
    let d = y[i] - y[i - 1];
    let mid = 0.5 * (y[i] + y[i - 1]);
    d * mid < 0.0
}

#[cfg(test)]
#[path = "segment_tests.rs"]
mod tests;
