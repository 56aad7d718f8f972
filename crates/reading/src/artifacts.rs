//! Rig artifacts a record carries that no friction model should fit: a seating (run-in) toe on
//! first loading — the recorded displacement runs for 0.05–1 mm while the shear barely rises,
//! as gaps close and the specimen beds in. A model of the interface would have to bend its
//! parameters to swallow it; the rows of the toe are excluded instead, and the test starts
//! from rest where the shear begins to rise. When the whole first stroke is slack the gap may
//! not be closed at its end: what is left of it closes on the first reload in the same
//! direction ([`gap_remainder`]), and that travel is taken out of the imposed column.

use crate::segment::{Segmentation, StartKind};
use serde::Serialize;
use subfric_data::meta::ControlColumn;
use subfric_data::set::TestData;

/// A seating toe found at the start of a test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeatingToe {
    /// First row kept: where the shear begins to rise (rows before it are excluded).
    pub first_kept: usize,
    /// Imposed travel over the excluded rows [mm].
    pub travel_mm: f64,
    /// Largest |shear| over the toe (before the shear reached 5 % of the first loading's peak),
    /// as a share of that peak; when the whole first leg is slack, the leg's largest |shear| as
    /// a share of the largest the test reaches after it.
    pub shear_share: f64,
    /// Measured shear at the first row kept [kPa]: the test starts at rest under it.
    pub start_shear_kpa: f64,
    /// The whole first leg was slack, in this direction of travel (±1): the gap may not have
    /// closed at its end; `None` when the toe ended in a climb (the gap closed).
    pub slack_leg_direction: Option<f64>,
    /// What was left of the gap after a slack first leg, closed on the first reload in its
    /// direction and taken out of the imposed column (set where the test is prepared).
    pub remainder: Option<GapRemainder>,
    /// In words.
    pub reason: String,
}

/// The rest of a gap that a slack first stroke left open, closing on the first reload in the
/// stroke's direction: after the shear crosses zero it stays below 5 % of what the test reaches
/// for longer than the steep loading after it needs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GapRemainder {
    /// Last row before the reload's shear crosses zero (kept).
    pub from_row: usize,
    /// First row at or beyond 5 % of what the test reaches, where the loading is steep (kept;
    /// the rows between the two are left out).
    pub to_row: usize,
    /// Travel taken out of the imposed column from `to_row` on [mm]: what the reload travels
    /// from its reversal to 5 % of the peak beyond what the reloads after it need.
    pub travel_mm: f64,
}

/// Share of the first loading's peak below which the shear "barely rises".
const TOE_SHARE: f64 = 0.05;
/// Share of the peak the loading slope is measured up to (from [`TOE_SHARE`]).
const SLOPE_SHARE: f64 = 0.25;
/// A toe must travel at least this far [mm] ...
const MIN_TOE_MM: f64 = 0.02;
/// ... and this many times the travel the loading needs from 5 % to 25 % of its peak. A
/// loading from rest rises steepest at its start, so without a toe it reaches 5 % within a
/// quarter of that travel (the last reading under 5 % may lie a little later in a noisy
/// record); a toe is flat where the loading is steep. The margin is not larger because a soft
/// rig under a high normal stress needs a tenth or more of a mm to climb from 5 % to 25 %
/// (0.19 mm at 170 kPa/mm to a 160 kPa peak), as long as the toes of 0.05–0.8 mm beside it.
const TOE_OVER_RISE: f64 = 1.5;
/// A shorter toe counts when the climb from 5 % to 25 %, read on at least [`LINE_ROWS`] rows
/// as a straight line of shear on travel, reaches zero shear this many times the climb's
/// travel after the start (without a toe it reaches zero at or before the start).
const LINE_TOE_OVER_RISE: f64 = 0.25;
/// Rows the climb must hold to be read as a line.
const LINE_ROWS: usize = 6;

/// The seating toe of a slip-controlled test that starts at rest, if it has one.
pub fn seating_toe(test: &TestData, seg: &Segmentation) -> Option<SeatingToe> {
    if test.spec.control != ControlColumn::Slip || seg.start.kind != StartKind::Rest {
        return None;
    }
    let u = &seg.conditioned.values;
    let tau = &test.shear_kpa;
    let n = test.len();
    // The first loading: until the first reversal or hold.
    let end = seg
        .reversals
        .iter()
        .copied()
        .chain(seg.holds.iter().map(|h| h.0))
        .min()
        .unwrap_or(n)
        .min(n);
    if end < 10 {
        return None;
    }
    let sign = (u[end - 1] - u[0]).signum();
    if sign == 0.0 {
        return None;
    }
    let peak = tau[..end].iter().map(|v| sign * v).fold(f64::MIN, f64::max);
    if !(peak.is_finite() && peak > 0.0) {
        return None;
    }
    // A first leg whose shear stays below 5 % of what the test reaches after it (a cyclic test
    // whose first stroke is shorter than the gap to close) is slack as a whole: the test starts
    // at rest where that leg ends.
    let later = tau[end..].iter().map(|v| v.abs()).fold(0.0, f64::max);
    if peak < TOE_SHARE * later {
        return slack_first_leg(test, seg, end, sign, (peak, later));
    }
    let first_above = |share: f64| (0..end).find(|&i| sign * tau[i] >= share * peak);
    let i_rise = first_above(SLOPE_SHARE)?;
    // The toe ends where the climb to a quarter of the peak begins: the last row below 5 %
    // before it (a noise spike above 5 % inside a long toe does not end it).
    let i_toe = (0..i_rise)
        .rev()
        .find(|&i| sign * tau[i] < TOE_SHARE * peak)
        .map_or(0, |i| i + 1);
    let toe = (u[i_toe] - u[0]).abs();
    let rise = (u[i_rise] - u[i_toe]).abs().max(1e-12);
    let resolution = 10.0 * seg.conditioned.band;
    if toe < MIN_TOE_MM.max(resolution) || i_toe < 3 {
        return None;
    }
    let mut reached_back = None;
    if toe < TOE_OVER_RISE * rise {
        // A toe shorter than the climb after it (a soft rig under a high normal stress) counts
        // only where that climb reaches back far enough into the test.
        let reaches_back = climb_reaches_back(u, tau, (i_toe, i_rise), sign, peak);
        if reaches_back < MIN_TOE_MM.max(resolution) || reaches_back < LINE_TOE_OVER_RISE * rise {
            return None;
        }
        reached_back = Some(reaches_back);
    }
    // The toe closes as the shear rises and its last part overlaps the steep loading: the
    // record is kept from where the shear first reaches a quarter of the peak, where the
    // loading is steep and the toe closed, and the test starts there at rest under that
    // traction (on the model's loading surface, as a virgin loading would be).
    let first_kept = i_rise.max(1);
    let travel = (u[first_kept] - u[0]).abs();
    let shear_share = tau[..i_toe].iter().map(|v| v.abs()).fold(0.0, f64::max) / peak;
    let start_shear_kpa = tau[first_kept];
    Some(SeatingToe {
        first_kept,
        travel_mm: travel,
        shear_share,
        start_shear_kpa,
        slack_leg_direction: None,
        remainder: None,
        reason: format!(
            "seating toe: the first {:.3} mm of travel raised the shear to at most {:.1} % of its first peak, where the loading then needs {rise:.4} mm to go from 5 % to 25 %{}: the first {travel:.3} mm ({first_kept} rows) excluded, the test starts at rest under {start_shear_kpa:.2} kPa (25 % of the peak) at row {first_kept}",
            toe,
            100.0 * shear_share,
            reached_back.map_or(String::new(), |b| format!(
                ", a straight climb that reaches zero shear {b:.3} mm into the test"
            )),
        ),
    })
}

/// The seating toe of a first leg (rows `..end`, travelling in direction `sign`) whose shear
/// stays below 5 % of what the test reaches after it (`(peak, later)`: the leg's largest shear
/// and the test's after it) — a cyclic test whose first stroke is shorter than the gap to
/// close: the leg is slack as a whole, and the test starts at rest at its reversal (or where
/// its hold begins), at the leg's furthest travel (one row earlier it would still be moving
/// into the gap). `None` when the leg travels less than the toe's least travel.
fn slack_first_leg(
    test: &TestData,
    seg: &Segmentation,
    end: usize,
    sign: f64,
    (peak, later): (f64, f64),
) -> Option<SeatingToe> {
    let (u, tau) = (&seg.conditioned.values, &test.shear_kpa);
    let first_kept = end.min(test.len() - 1);
    let travel = (u[first_kept] - u[0]).abs();
    if travel < MIN_TOE_MM.max(10.0 * seg.conditioned.band) {
        return None;
    }
    let start_shear_kpa = tau[first_kept];
    Some(SeatingToe {
        first_kept,
        travel_mm: travel,
        shear_share: peak / later,
        start_shear_kpa,
        slack_leg_direction: Some(sign),
        remainder: None,
        reason: format!(
            "seating toe: the whole first leg ({travel:.3} mm) raised the shear to at most {:.1} % of what the test reaches after it: its {first_kept} rows excluded, the test starts at rest under {start_shear_kpa:.2} kPa where that leg ends",
            100.0 * peak / later
        ),
    })
}

/// How far into the test [mm] the first loading's climb from 5 % to 25 % of its peak (rows
/// `i_toe..=i_rise`, travelling in direction `sign`), a straight line of shear on travel,
/// reaches back to zero shear: where the contact began to carry load — before the start
/// without a toe (a loading from rest is steepest at its start), past it after one. Read on
/// many rows, that line is not moved by the noise that moves the last reading under 5 %. 0
/// when too few rows lie on the climb or it does not rise.
fn climb_reaches_back(
    u: &[f64],
    tau: &[f64],
    (i_toe, i_rise): (usize, usize),
    sign: f64,
    peak: f64,
) -> f64 {
    let rows: Vec<usize> = (i_toe..=i_rise)
        .filter(|&i| {
            let f = sign * tau[i];
            f >= TOE_SHARE * peak && f <= SLOPE_SHARE * peak
        })
        .collect();
    let travel: Vec<f64> = rows.iter().map(|&i| sign * (u[i] - u[0])).collect();
    let shear: Vec<f64> = rows.iter().map(|&i| sign * tau[i]).collect();
    // Shear on travel (the travel is the precise column: a line of travel on a noisy shear
    // would be flattened by the noise and reach back too far).
    (rows.len() >= LINE_ROWS)
        .then(|| crate::stats::fit_line(&travel, &shear))
        .flatten()
        .filter(|l| l.slope > 0.0)
        .map_or(0.0, |l| -l.intercept / l.slope)
}

/// What is left of a gap after a slack first stroke (travel in `direction`), in a test that
/// starts where that stroke ended (`test`, segmented as `seg`). Every reversal's reload
/// travels from the reversal to a share of what the test reaches on the other side; once the
/// gap is closed that travel is elastic, so it is proportional to the change of shear. The first
/// reload in `direction` is compared with the median of the reloads after it: what it travels
/// beyond them is the rest of the gap. It is read at [`REMAINDER_LEVELS`] of the peak, where the
/// closing contact has stiffened, not at the first 5 % (a contact closes softly: the first
/// reload reaches 5 % before the gap has closed, and the remainder read there was 5.1 µm of a
/// 7.6 µm gap, which left the elastic rows after it several kPa off).
pub fn gap_remainder(test: &TestData, seg: &Segmentation, direction: f64) -> Option<GapRemainder> {
    let u = &seg.conditioned.values;
    let tau = &test.shear_kpa;
    let n = test.len();
    let later = tau.iter().map(|v| v.abs()).fold(0.0, f64::max);
    if later.is_nan() || later <= 0.0 || n < 4 {
        return None;
    }
    // Each reload at one level: (reversal row, direction, row reaching the level, travel to
    // it, shear change).
    let reloads_at = |level: f64| {
        let mut reloads = Vec::new();
        for (k, &r) in seg.reversals.iter().enumerate() {
            if r + 1 >= n {
                continue;
            }
            let d = (u[r + 1] - u[r]).signum();
            let end = seg.reversals.get(k + 1).copied().unwrap_or(n).min(n);
            let Some(i_level) = (r + 1..end).find(|&i| d * tau[i] >= level) else {
                continue;
            };
            let u_level = slip_at_level(u, tau, d, i_level - 1, level);
            let change = level - d * tau[r];
            if change > 0.0 {
                reloads.push((r, d, i_level, (u_level - u[r]).abs(), change));
            }
        }
        reloads
    };
    // At each level: the first reload's travel beyond the later ones' (with its row, the
    // elastic travel expected, and the later reloads' spread of compliance times its change).
    let extra_at = |level: f64| {
        let reloads = reloads_at(level);
        let first = reloads.iter().position(|l| l.1 == direction)?;
        let mut compliance: Vec<f64> = reloads[first + 1..].iter().map(|l| l.3 / l.4).collect();
        if compliance.len() < 2 {
            return None;
        }
        // Sorts `compliance` in place: the spread is read off its ends.
        let typical = crate::stats::upper_median(&mut compliance)?;
        let spread = compliance[compliance.len() - 1] - compliance[0];
        let (r, _, i_level, travel, change) = reloads[first];
        let expected = typical * change;
        Some((r, i_level, travel - expected, expected, spread * change))
    };
    let [low, high] = REMAINDER_LEVELS;
    let (r, i_low, extra_low, expected, scatter) = extra_at(low * later)?;
    let (r_high, _, extra_high, _, _) = extra_at(high * later)?;
    if r_high != r {
        return None;
    }
    let extra = 0.5 * (extra_low + extra_high);
    // Beyond what the later reloads' own scatter allows (three times its range), a quarter of
    // the reload's elastic travel (a first reload may load a little differently without any
    // gap), and the imposed column's resolution (a travel is the difference of two readings,
    // each within a band).
    let least = (3.0 * scatter)
        .max(0.25 * expected)
        .max(2.0 * seg.conditioned.band);
    if extra < least {
        return None;
    }
    // The gap lies where the shear is near zero: from the last row before it crosses zero, to
    // the first at the lower level, where the contact has closed.
    let from = (r + 1..i_low)
        .find(|&i| direction * tau[i] >= 0.0)
        .map_or(r, |i| i - 1);
    if (u[i_low] - u[r]).abs() <= extra {
        return None;
    }
    Some(GapRemainder {
        from_row: from,
        to_row: i_low,
        travel_mm: extra,
    })
}

/// Shares of the peak shear at which the rest of a gap is read ([`gap_remainder`]): above the
/// soft end of the closing contact, below the plastic transition of the reload.
const REMAINDER_LEVELS: [f64; 2] = [0.15, 0.25];

/// The slip where `direction` × shear reaches `level`, read linearly between rows `i` and
/// `i + 1` (row `i + 1` when the shear does not rise between them).
fn slip_at_level(u: &[f64], tau: &[f64], direction: f64, i: usize, level: f64) -> f64 {
    let (y0, y1) = (direction * tau[i], direction * tau[i + 1]);
    let f = if y1 > y0 {
        ((level - y0) / (y1 - y0)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    u[i] + f * (u[i + 1] - u[i])
}

/// `test` with a gap remainder taken out: the rows over which the gap closes (between the
/// last row before the reload's shear crosses zero and the first at 5 % of the peak) are left
/// out ([`without_gap_rows`]), and every row after them moves back by the remainder's travel.
/// Rows, not travel, are removed: an imposed column standing still there would read as a hold
/// that swallows the reversal before it.
pub fn close_gap(test: &TestData, gap: &GapRemainder, direction: f64) -> TestData {
    let mut t = without_gap_rows(test, gap);
    for u in &mut t.slip_mm[gap.from_row + 1..] {
        *u -= direction * gap.travel_mm;
    }
    t
}

/// `test` without the rows over which a gap remainder closes, every column as recorded.
pub fn without_gap_rows(test: &TestData, gap: &GapRemainder) -> TestData {
    let dropped = gap.from_row + 1..gap.to_row;
    fn kept<T: Copy>(v: &[T], dropped: &std::ops::Range<usize>) -> Vec<T> {
        v.iter()
            .enumerate()
            .filter(|(i, _)| !dropped.contains(i))
            .map(|(_, x)| *x)
            .collect()
    }
    let mut t = test.clone();
    t.time_s = kept(&test.time_s, &dropped);
    t.slip_mm = kept(&test.slip_mm, &dropped);
    t.shear_kpa = kept(&test.shear_kpa, &dropped);
    t.normal_kpa = kept(&test.normal_kpa, &dropped);
    t.line_of_row = kept(&test.line_of_row, &dropped);
    for c in &mut t.channels {
        c.values = kept(&c.values, &dropped);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::{segment, SegmentOptions};
    use subfric_data::meta::TestSpec;

    /// A loading at 0.01 mm/s that closes a gap of `gap` mm first (shear 0.2 % of the peak per
    /// 0.1 mm there), then rises like tanh over 0.05 mm to 60 kPa.
    fn loading(gap: f64) -> TestData {
        let slip: Vec<f64> = (0..=400).map(|i| 0.01 * i as f64).collect();
        let shear: Vec<f64> = slip
            .iter()
            .map(|&u| {
                if u < gap {
                    0.12 * u / 0.1
                } else {
                    0.12 * gap / 0.1 + 60.0 * ((u - gap) / 0.05).tanh()
                }
            })
            .collect();
        slip_test("mono", slip, shear)
    }

    /// A slip-controlled test at 100 kPa, one row per second.
    fn slip_test(name: &str, slip: Vec<f64>, shear: Vec<f64>) -> TestData {
        let n = slip.len();
        TestData {
            spec: TestSpec::new(name, &format!("{name}.csv"), ControlColumn::Slip, 100.0),
            path: format!("{name}.csv").into(),
            time_s: (0..n).map(|i| i as f64).collect(),
            slip_mm: slip,
            shear_kpa: shear,
            normal_kpa: vec![100.0; n],
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        }
    }

    #[test]
    fn a_gap_closing_before_contact_is_found_and_cut_where_the_loading_is_steep() {
        for gap in [0.08, 0.3, 0.8] {
            let t = loading(gap);
            let seg = segment(&t, &SegmentOptions::default());
            let toe = seating_toe(&t, &seg).unwrap_or_else(|| panic!("gap {gap}: no toe"));
            // Cut at the first row where the shear reaches a quarter of the peak: the rise
            // 60 tanh(s/0.05) gets there 0.0128 mm after the gap (rows are 0.01 mm apart).
            let peak = 0.12 * gap / 0.1 + 60.0;
            assert!(
                toe.travel_mm >= gap + 0.0128 - 1e-9 && toe.travel_mm <= gap + 0.0128 + 0.0101,
                "gap {gap}: cut after {} mm",
                toe.travel_mm
            );
            assert!(
                toe.start_shear_kpa >= 0.25 * peak && toe.start_shear_kpa < 0.45 * peak,
                "gap {gap}: starts under {} kPa",
                toe.start_shear_kpa
            );
            assert!(toe.shear_share < 0.05, "{}", toe.shear_share);
        }
    }

    /// A loading at 0.002 mm per row that closes a gap of `gap` mm (flat), then rises like
    /// 160 tanh(s/0.9) kPa: a soft rig under 400 kPa, 0.19 mm from 5 % to 25 % of the peak;
    /// `noise_kpa` of deterministic scatter (a fixed pseudo-random sequence).
    fn soft_loading(gap: f64, noise_kpa: f64) -> TestData {
        let slip: Vec<f64> = (0..=2000).map(|i| 0.002 * i as f64).collect();
        let mut state = 12345u64;
        let shear: Vec<f64> = slip
            .iter()
            .map(|&u| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let e = ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.46;
                160.0 * ((u - gap).max(0.0) / 0.9).tanh() + noise_kpa * e
            })
            .collect();
        slip_test("soft", slip, shear)
    }

    #[test]
    fn a_toe_before_a_soft_loading_under_a_high_normal_stress_is_found() {
        // The climb from 5 % to 25 % of the peak takes 0.185 mm: a 0.4 mm toe is twice that.
        // Found and cut where the loading reaches a quarter of its peak (0.231 mm after the
        // gap), noisy or not.
        for noise in [0.0, 2.0] {
            let t = soft_loading(0.4, noise);
            let seg = segment(&t, &SegmentOptions::default());
            let toe = seating_toe(&t, &seg)
                .unwrap_or_else(|| panic!("noise {noise}: the toe is not found"));
            assert!(
                (toe.travel_mm - 0.631).abs() < 0.02,
                "noise {noise}: cut after {} mm",
                toe.travel_mm
            );
        }
    }

    #[test]
    fn a_toe_shorter_than_the_soft_loading_after_it_is_found_where_the_climb_reaches_back() {
        // 0.15 mm of toe before a climb of 0.185 mm from 5 % to 25 %: the climb's line reaches
        // zero shear 0.15 mm after the start, noisy or not; the test is cut where the shear
        // reaches a quarter of its peak, 0.231 mm after the gap.
        for noise in [0.0, 2.0] {
            let t = soft_loading(0.15, noise);
            let seg = segment(&t, &SegmentOptions::default());
            let toe = seating_toe(&t, &seg)
                .unwrap_or_else(|| panic!("noise {noise}: the toe is not found"));
            assert!(
                (toe.travel_mm - 0.381).abs() < 0.02,
                "noise {noise}: cut after {} mm",
                toe.travel_mm
            );
        }
    }

    #[test]
    fn a_soft_loading_without_a_toe_is_left_alone_in_a_noisy_record() {
        // No toe: the loading reaches 5 % of its peak after 0.045 mm; with the load cell
        // scattering by 2.5 % of the peak (SD), the last reading under 5 % lies later, but not
        // one and a half times the 0.185 mm climb from 5 % to 25 %.
        for noise in [0.0, 4.0] {
            let t = soft_loading(0.0, noise);
            let seg = segment(&t, &SegmentOptions::default());
            assert_eq!(seating_toe(&t, &seg), None, "noise {noise}");
        }
    }

    #[test]
    fn a_noise_spike_inside_a_toe_does_not_end_it() {
        // A single reading of 8 % of the peak a third of the way along a 0.6 mm toe (a noisy
        // load cell): the toe still runs to where the climb to the peak begins.
        let mut t = loading(0.6);
        t.shear_kpa[20] = 0.08 * 60.0;
        let seg = segment(&t, &SegmentOptions::default());
        let toe = seating_toe(&t, &seg).expect("the toe is found");
        assert!(
            toe.travel_mm >= 0.6 && toe.travel_mm <= 0.6 + 0.0128 + 0.0101,
            "cut after {} mm",
            toe.travel_mm
        );
    }

    #[test]
    fn a_loading_without_a_toe_is_left_alone() {
        let t = loading(0.0);
        let seg = segment(&t, &SegmentOptions::default());
        assert_eq!(seating_toe(&t, &seg), None);
        // A slow but steady rise (a soft contact, not a toe) is not cut either: its steepest
        // part is its start.
        let mut soft = loading(0.0);
        for (s, u) in soft.shear_kpa.iter_mut().zip(&soft.slip_mm) {
            *s = 60.0 * (u / 1.5).tanh();
        }
        let seg = segment(&soft, &SegmentOptions::default());
        assert_eq!(seating_toe(&soft, &seg), None);
    }
    /// A cyclic test at 0.01 mm/s, 0.01 mm per row: a first stroke to +`stroke` mm, then legs
    /// to −0.6 and +0.6 mm. The first stroke crosses slack (0.12 kPa per 0.1 mm) when `slack`,
    /// or loads like the legs after it; each leg rises like 60 tanh(s/0.05) from its reversal.
    fn cyclic(stroke: f64, slack: bool) -> TestData {
        let mut slip = vec![0.0];
        let mut shear = vec![0.0];
        let leg = |to: f64, first: bool, slip: &mut Vec<f64>, shear: &mut Vec<f64>| {
            let (from, tau0) = (*slip.last().unwrap(), *shear.last().unwrap());
            let dir = (to - from).signum();
            let rows = ((to - from).abs() / 0.01).round() as usize;
            for i in 1..=rows {
                let travel = 0.01 * i as f64;
                slip.push(from + dir * travel);
                shear.push(if first && slack {
                    0.12 * travel / 0.1
                } else {
                    tau0 + (dir * 60.0 - tau0) * (travel / 0.05).tanh()
                });
            }
        };
        leg(stroke, true, &mut slip, &mut shear);
        leg(-0.6, false, &mut slip, &mut shear);
        leg(0.6, false, &mut slip, &mut shear);
        slip_test("cyclic", slip, shear)
    }

    /// A cyclic test like [`cyclic`] with a slack first stroke to +0.4 mm and four legs after
    /// it, whose first reload in + crosses `rest` mm of slack where its shear crosses zero (what
    /// the stroke left of the gap) before it loads like the others.
    fn cyclic_with_rest_of_gap(rest: f64) -> TestData {
        cyclic_with_rest_of_gap_closing(rest, 0.0)
    }

    /// As [`cyclic_with_rest_of_gap`], the contact closing over a travel of about `soft` mm
    /// instead of at once (its engaged travel a softplus of that width).
    fn cyclic_with_rest_of_gap_closing(rest: f64, soft: f64) -> TestData {
        let softplus = |x: f64| {
            if soft > 0.0 {
                soft * (x / soft).exp().ln_1p()
            } else {
                x.max(0.0)
            }
        };
        let mut slip = vec![0.0];
        let mut shear = vec![0.0];
        for i in 1..=40 {
            slip.push(0.01 * i as f64);
            shear.push(0.12 * 0.01 * i as f64 / 0.1);
        }
        let mut first_forward = true;
        for to in [-0.6, 0.6, -0.6, 0.6] {
            let (from, tau0) = (*slip.last().unwrap(), *shear.last().unwrap());
            let dir = f64::signum(to - from);
            let gap = if dir > 0.0 && first_forward {
                rest
            } else {
                0.0
            };
            first_forward &= dir < 0.0;
            let curve = |s: f64| tau0 + (dir * 60.0 - tau0) * (s / 0.05).tanh();
            // Travel where the shear crosses zero.
            let cross = 0.05 * (-tau0 / (dir * 60.0 - tau0)).atanh();
            let rows = ((to - from).abs() / 0.01).round() as usize;
            for i in 1..=rows {
                let s = 0.01 * i as f64;
                let engaged = if s < cross {
                    s
                } else {
                    cross + softplus(s - cross - gap) - softplus(-gap)
                };
                slip.push(from + dir * s);
                shear.push(curve(engaged));
            }
        }
        slip_test("cyclic", slip, shear)
    }

    /// The rest of the gap found on the trimmed test (as the fit prepares it).
    fn rest_found(t: &TestData) -> Option<GapRemainder> {
        let seg = segment(t, &SegmentOptions::default());
        let toe = seating_toe(t, &seg).expect("the slack stroke is a toe");
        let direction = toe.slack_leg_direction.expect("a slack leg");
        let trimmed = t.rows_from(toe.first_kept);
        let seg = segment(&trimmed, &SegmentOptions::default());
        gap_remainder(&trimmed, &seg, direction)
    }

    #[test]
    fn the_rest_of_a_gap_is_read_where_the_closing_contact_has_stiffened() {
        // The contact closes over about 0.005 mm: the first reload reaches 5 % of the peak
        // before the gap has closed, and the remainder read there is short by about that much.
        for rest in [0.05, 0.1] {
            let t = cyclic_with_rest_of_gap_closing(rest, 0.005);
            let gap = rest_found(&t).unwrap_or_else(|| panic!("rest {rest}: not found"));
            assert!(
                (gap.travel_mm - rest).abs() <= 0.005,
                "rest {rest}: {} mm taken out",
                gap.travel_mm
            );
        }
    }

    #[test]
    fn the_rest_of_a_gap_a_slack_stroke_left_open_is_taken_out_of_the_first_reload() {
        // 0.01 mm: a third of the reload's elastic travel to 15 % of the peak (0.033 mm), far more
        // than the later reloads differ by (they do not: no noise), so it is found.
        for rest in [0.01, 0.05, 0.12] {
            let t = cyclic_with_rest_of_gap(rest);
            let gap = rest_found(&t).unwrap_or_else(|| panic!("rest {rest}: not found"));
            assert!(
                (gap.travel_mm - rest).abs() <= 0.012,
                "rest {rest}: {} mm taken out",
                gap.travel_mm
            );
            // Taken out, the first reload loads like the others: nothing is left to find.
            let seg = segment(&t, &SegmentOptions::default());
            let toe = seating_toe(&t, &seg).expect("toe");
            let trimmed = t.rows_from(toe.first_kept);
            let closed = close_gap(&trimmed, &gap, 1.0);
            let seg = segment(&closed, &SegmentOptions::default());
            assert_eq!(gap_remainder(&closed, &seg, 1.0), None, "rest {rest}");
            // The rows over the gap are left out, every row after it moved back by its travel,
            // rows before it did not move.
            let left_out = gap.to_row - gap.from_row - 1;
            assert!(left_out >= 1, "rest {rest}: {gap:?}");
            assert_eq!(closed.len(), trimmed.len() - left_out);
            let (a, b) = (closed.len() - 1, trimmed.len() - 1);
            assert!((trimmed.slip_mm[b] - closed.slip_mm[a] - gap.travel_mm).abs() < 1e-12);
            assert_eq!(
                closed.slip_mm[..=gap.from_row],
                trimmed.slip_mm[..=gap.from_row]
            );
            assert_eq!(
                closed.line_of_row[gap.from_row + 1],
                trimmed.line_of_row[gap.to_row]
            );
        }
        // A stroke that closed the whole gap leaves nothing.
        assert_eq!(rest_found(&cyclic_with_rest_of_gap(0.0)), None);
    }

    #[test]
    fn a_first_stroke_shorter_than_the_gap_is_slack_as_a_whole() {
        // The stroke (0.4 mm) ends before the gap has closed: the shear never passes 1 % of
        // what the legs after it reach, so no climb exists to cut at; the whole stroke is left
        // out and the test starts at rest where it reverses.
        let t = cyclic(0.4, true);
        let seg = segment(&t, &SegmentOptions::default());
        let toe = seating_toe(&t, &seg).expect("the slack stroke is a toe");
        assert!(
            (toe.travel_mm - 0.40).abs() <= 0.0051,
            "cut after {} mm",
            toe.travel_mm
        );
        assert!(toe.start_shear_kpa < 1.0, "{}", toe.start_shear_kpa);
        assert!(toe.reason.contains("whole first leg"), "{}", toe.reason);
        // A first stroke that loads the interface like the legs after it is no toe.
        let t = cyclic(0.4, false);
        let seg = segment(&t, &SegmentOptions::default());
        assert_eq!(seating_toe(&t, &seg), None);
    }
}
