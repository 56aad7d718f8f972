//! Conditioning of the normal-stress column: its row-to-row scatter read as the reading's
//! noise when the shear does not follow it.
//!
//! A direct-shear or interface rig holds the normal load with a servo or a dead weight; its
//! column carries the load cell's noise as well as any real change (stages of a multi-stage
//! test, the dilation of a constant-normal-stiffness test). The model is driven by the column
//! row by row, and the subloading surface slips plastically on any rise of the stress ratio:
//! a normal stress that dips by a reading's noise is a loading step, one that rises back is
//! an elastic one, so through a hold noise alone ratchets the modelled shear down (0.365 →
//! 0.345 in stress ratio over a 1000 s hold where the record stays at 0.360), and while
//! sliding the model's shear carries the normal's noise times the stress ratio, which the
//! measured shear does not.
//!
//! Whether the shear follows the column is read where it must if the changes are real: while
//! sliding steadily, friction holds the stress ratio, so a real change of the normal stress
//! moves the shear by the stress ratio times as much from one row to the next; a reading's
//! noise does not move it at all. Pair by pair, the nearer of the two for most pairs decides
//! ([`shear_follows`]). When the shear does not follow, the column is held at its level
//! between changes larger than the reading's noise can make ([`LEVEL_CHANGE_SDS`]) and each
//! stretch is replaced by its mean: stages and slow trends stay, the scatter goes.

use crate::noise::estimate_noise;
use crate::segment::SegmentKind;
use subfric_data::set::TestData;
use subfric_data::ControlColumn;

/// The normal-stress column after conditioning.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ConditionedNormal {
    /// The normal stress the model is given, one per row, kPa.
    pub values: Vec<f64>,
    /// Estimated noise SD of the raw column, kPa.
    pub noise_sd: f64,
    /// True when `values` differ from the raw column.
    pub changed: bool,
    /// Why the column was held at its levels (empty when it was not).
    pub reason: String,
}

impl ConditionedNormal {
    /// Why the column was held at its levels, when it was: what `check`, `fit` and `diagnose`
    /// say of the test.
    pub fn held_because(&self) -> Option<&str> {
        self.changed.then_some(self.reason.as_str())
    }
}

/// A reading off the column's current level by more than this many noise SDs, twice in a
/// row, starts a new level: as for a hold's level of the imposed column
/// ([`crate::condition`]), four SDs of one reading; a single reading that far is an outlier
/// of the same level.
pub const LEVEL_CHANGE_SDS: f64 = 4.0;

/// Fewest pairs of consecutive steadily sliding rows from which whether the shear follows the
/// normal stress is read; with fewer the column is kept as it is.
const MIN_SLIDING_PAIRS: usize = 10;

/// Conditions the normal-stress column of `test`, whose rows are classified by `row_kind`.
/// Only slip-controlled tests are conditioned: under traction control the measured column is
/// a slip, and whether the interface follows the normal stress is not read from it.
pub fn condition_normal(test: &TestData, row_kind: &[SegmentKind]) -> ConditionedNormal {
    let raw = &test.normal_kpa;
    let n = raw.len().min(row_kind.len()).min(test.time_s.len());
    let keep = |noise_sd: f64| ConditionedNormal {
        values: raw.clone(),
        noise_sd,
        changed: false,
        reason: String::new(),
    };
    if n < 3 || !raw.iter().chain(&test.shear_kpa).all(|v| v.is_finite()) {
        return keep(0.0);
    }
    let noise = estimate_noise(&test.time_s[..n], &raw[..n]);
    if test.spec.control != ControlColumn::Slip || noise.sd <= 0.0 || noise.floor {
        return keep(noise.sd);
    }
    if shear_follows(&test.shear_kpa[..n], &raw[..n], &row_kind[..n]) != Some(false) {
        return keep(noise.sd);
    }
    let band = (LEVEL_CHANGE_SDS * noise.sd).max(2.5 * noise.quantum);
    let (mut values, levels) = held_at_levels(&raw[..n], band);
    values.extend_from_slice(&raw[n..]);
    let changed = values.iter().zip(raw).any(|(a, b)| a != b);
    let reason = if changed {
        format!(
            "the normal stress column scatters by {:.3} kPa from row to row, and the shear does not follow it while sliding (a real change would move it by the stress ratio times as much): the scatter is the reading's, and the model is given the column held at its level between changes of more than {:.3} kPa ({levels} level{})",
            noise.sd,
            band,
            if levels == 1 { "" } else { "s" }
        )
    } else {
        String::new()
    };
    ConditionedNormal {
        values,
        noise_sd: noise.sd,
        changed,
        reason,
    }
}

/// Whether the shear follows the normal stress from one steadily sliding row to the next:
/// `Some(true)` when for most pairs of consecutive steadily sliding rows the change of `shear`
/// lies nearer the change of `normal` times the rows' stress ratio than no change at all,
/// `Some(false)` when for most it lies nearer no change, `None` with fewer than
/// [`MIN_SLIDING_PAIRS`] pairs. Counted pair by pair, not summed: the few rows of a real
/// change of stage, which the shear follows, would outweigh in a sum the many rows of a
/// reading's scatter, which it does not.
///
/// ```
/// use subfric_reading::normal::shear_follows;
/// use subfric_reading::SegmentKind;
/// let kind = vec![SegmentKind::SteadySliding; 40];
/// // A normal stress that wanders by ±1 kPa around 100.
/// let normal: Vec<f64> = (0..40).map(|i| 100.0 + if i % 3 == 0 { 1.0 } else { -0.5 }).collect();
/// // A shear that keeps the stress ratio 0.4 follows it; one read at 40 kPa throughout does not.
/// let following: Vec<f64> = normal.iter().map(|s| 0.4 * s).collect();
/// assert_eq!(shear_follows(&following, &normal, &kind), Some(true));
/// assert_eq!(shear_follows(&vec![40.0; 40], &normal, &kind), Some(false));
/// assert_eq!(shear_follows(&following[..5], &normal[..5], &kind[..5]), None);
/// ```
pub fn shear_follows(shear: &[f64], normal: &[f64], row_kind: &[SegmentKind]) -> Option<bool> {
    let n = shear.len().min(normal.len()).min(row_kind.len());
    let sliding = |i: usize| row_kind[i] == SegmentKind::SteadySliding;
    let (mut followed, mut pairs) = (0usize, 0usize);
    for i in 1..n {
        if !(sliding(i) && sliding(i - 1)) || normal[i] <= 0.0 || normal[i - 1] <= 0.0 {
            continue;
        }
        let ratio = 0.5 * (shear[i] / normal[i] + shear[i - 1] / normal[i - 1]);
        let d_shear = shear[i] - shear[i - 1];
        let d_normal = normal[i] - normal[i - 1];
        if (d_shear - ratio * d_normal).abs() < d_shear.abs() {
            followed += 1;
        }
        pairs += 1;
    }
    (pairs >= MIN_SLIDING_PAIRS).then_some(2 * followed > pairs)
}

/// `x` held at its levels: a new level starts where a reading and the next lie on the same
/// side of the current level's mean by more than `band`; each level is replaced by its mean.
/// Returns the values and the number of levels.
fn held_at_levels(x: &[f64], band: f64) -> (Vec<f64>, usize) {
    let mut out = Vec::with_capacity(x.len());
    let mut levels = 0;
    let (mut start, mut sum) = (0usize, 0.0);
    let mut close = |from: usize, to: usize, sum: f64, out: &mut Vec<f64>| {
        let mean = sum / (to - from) as f64;
        out.extend(std::iter::repeat_n(mean, to - from));
        levels += 1;
    };
    for i in 0..x.len() {
        if i > start {
            let mean = sum / (i - start) as f64;
            let off = |v: f64| v - mean;
            let leaves = off(x[i]).abs() > band
                && x.get(i + 1).is_some_and(|&next| {
                    off(next).abs() > band && off(next).signum() == off(x[i]).signum()
                });
            if leaves {
                close(start, i, sum, &mut out);
                start = i;
                sum = 0.0;
            }
        }
        sum += x[i];
    }
    if x.len() > start {
        close(start, x.len(), sum, &mut out);
    }
    (out, levels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfric_data::meta::TestSpec;

    /// A pseudo-random reading's noise of SD about `sd`, reproducible.
    fn noise(i: usize, sd: f64) -> f64 {
        let h = (i as u64)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .rotate_left(17)
            ^ 0x5DEE_CE66;
        let u = (h % 10_000) as f64 / 10_000.0;
        (u - 0.5) * sd * 12f64.sqrt()
    }

    /// A slip-controlled test of `n` rows at 1 s sliding at 0.01 mm/s.
    fn test(shear: Vec<f64>, normal: Vec<f64>) -> TestData {
        let n = shear.len();
        TestData {
            spec: TestSpec::new("mono", "mono.csv", ControlColumn::Slip, 100.0),
            path: "mono.csv".into(),
            time_s: (0..n).map(|i| i as f64).collect(),
            slip_mm: (0..n).map(|i| 0.01 * i as f64).collect(),
            shear_kpa: shear,
            normal_kpa: normal,
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: vec![],
            channels: vec![],
        }
    }

    #[test]
    fn a_scatter_the_shear_does_not_follow_is_held_at_its_levels_and_a_stage_kept() {
        // Two stages, 100 then 200 kPa, read with 0.5 kPa of noise; the shear is the friction
        // at the stage's load with its own noise, and does not follow the readings.
        let n = 600;
        let stage = |i: usize| if i < 300 { 100.0 } else { 200.0 };
        let normal: Vec<f64> = (0..n).map(|i| stage(i) + noise(i, 0.5)).collect();
        let shear: Vec<f64> = (0..n)
            .map(|i| 0.4 * stage(i) + noise(i + 7919, 0.05))
            .collect();
        let kind = vec![SegmentKind::SteadySliding; n];
        let c = condition_normal(&test(shear, normal.clone()), &kind);
        assert!(c.changed && !c.reason.is_empty(), "{c:?}");
        // Each stage is one level at its mean: the scatter is gone, the stage is kept.
        assert!(c.values[..300].iter().all(|&v| v == c.values[0]));
        assert!(c.values[300..].iter().all(|&v| v == c.values[300]));
        assert!((c.values[0] - 100.0).abs() < 0.2 && (c.values[300] - 200.0).abs() < 0.2);
    }

    #[test]
    fn a_normal_stress_the_shear_follows_is_kept_as_read() {
        // A servo that hunts: the load really moves by ±1 kPa and the sliding shear follows it
        // at the stress ratio.
        let n = 400;
        let normal: Vec<f64> = (0..n).map(|i| 100.0 + noise(i, 1.0)).collect();
        let shear: Vec<f64> = normal
            .iter()
            .enumerate()
            .map(|(i, s)| 0.4 * s + noise(i + 7919, 0.05))
            .collect();
        let kind = vec![SegmentKind::SteadySliding; n];
        let c = condition_normal(&test(shear, normal.clone()), &kind);
        assert!(!c.changed && c.values == normal, "{c:?}");
    }

    #[test]
    fn traction_control_and_a_column_without_scatter_are_kept() {
        let n = 100;
        let normal: Vec<f64> = (0..n).map(|i| 100.0 + noise(i, 0.5)).collect();
        let kind = vec![SegmentKind::SteadySliding; n];
        let mut t = test(vec![40.0; n], normal.clone());
        t.spec.control = ControlColumn::Shear;
        assert_eq!(condition_normal(&t, &kind).values, normal);
        let flat = test(vec![40.0; n], vec![100.0; n]);
        assert!(!condition_normal(&flat, &kind).changed);
        // Too few sliding rows to read it from: kept.
        let held = vec![SegmentKind::Hold; n];
        assert!(!condition_normal(&test(vec![40.0; n], normal), &held).changed);
    }

    #[test]
    fn one_reading_far_off_is_an_outlier_of_its_level_not_a_new_one() {
        let mut x = vec![100.0; 50];
        x[20] = 110.0;
        let (v, levels) = held_at_levels(&x, 1.0);
        assert_eq!(levels, 1);
        assert!(v.iter().all(|&a| (a - 100.2).abs() < 1e-9), "{v:?}");
    }
}
