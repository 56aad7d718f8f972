//! Tests a set already holds: `subfric plan` never proposes one of them again.
//!
//! A test is described by what the rig imposed, read off the data by the segmentation every
//! command uses (so that a measured test and a proposal simulated from its scenario are read
//! the same way): the control, the normal stress, the kind (monotonic, velocity steps, holds,
//! cycles), the imposed rates of its levels, its hold durations and its cycle amplitude. A
//! proposal repeats a test when the control, the normal stress and the kind are the same and
//! each of its rates, holds and amplitude is one the test already has.

use subfric_data::{ControlColumn, TestData, TestSpec};
use subfric_model::Control;
use subfric_reading::{segment, SegmentOptions, Segmentation};
use subfric_reading::{FitTest, PreparedTest};

/// Two rates, holds or amplitudes within this factor are the same.
const SAME_FACTOR: f64 = 1.3;

/// Two normal stresses within this factor are the same.
const SAME_NORMAL_FACTOR: f64 = 1.1;

/// A rate level counts when it covers at least this share of the imposed range: a slow
/// start over a few micrometres to resolve the rise of the traction is not a rate of the test.
const MIN_LEVEL_SHARE: f64 = 0.05;

/// What kind of test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// One rate, no hold, no reversal.
    Monotonic,
    /// Several rates.
    VelocitySteps,
    /// Holds.
    Holds,
    /// Reversals of the imposed direction.
    Cycles,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Monotonic => "monotonic",
            Kind::VelocitySteps => "velocity steps",
            Kind::Holds => "holds",
            Kind::Cycles => "cycles",
        }
    }
}

/// What a test imposed.
#[derive(Clone, Debug)]
pub struct Protocol {
    /// The test's name.
    pub name: String,
    /// Control.
    pub control: Control,
    /// Mean normal stress [kPa].
    pub normal_kpa: f64,
    /// Kind.
    pub kind: Kind,
    /// Distinct imposed rates of its levels (mm/s or kPa/s), ascending.
    pub rates: Vec<f64>,
    /// Hold durations [s].
    pub holds: Vec<f64>,
    /// Half the imposed range, for cycles (mm or kPa).
    pub amplitude: f64,
}

impl Protocol {
    /// A test as segmented.
    pub fn of(name: &str, t: &FitTest, seg: &Segmentation) -> Protocol {
        let (lo, hi) = t
            .imposed
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let range = (hi - lo).max(0.0);
        let mut rates: Vec<f64> = Vec::new();
        for l in &seg.levels {
            let end = l.end.min(t.len());
            if end <= l.start + 2 {
                continue;
            }
            let covered = (t.imposed[end - 1] - t.imposed[l.start]).abs();
            let r = l.rate.abs();
            if covered >= MIN_LEVEL_SHARE * range
                && r > 0.0
                && r.is_finite()
                && !rates.iter().any(|&x| same(x, r, SAME_FACTOR))
            {
                rates.push(r);
            }
        }
        rates.sort_by(f64::total_cmp);
        let holds: Vec<f64> = seg
            .holds
            .iter()
            .filter(|&&(s, _)| s > 1)
            .map(|&(s, e)| t.time[(e.max(1) - 1).min(t.len() - 1)] - t.time[s - 1])
            .collect();
        let kind = if seg.reversals.len() >= 2 {
            Kind::Cycles
        } else if !holds.is_empty() {
            Kind::Holds
        } else if rates.len() >= 2 {
            Kind::VelocitySteps
        } else {
            Kind::Monotonic
        };
        Protocol {
            name: name.to_string(),
            control: t.control,
            normal_kpa: t.normal.iter().sum::<f64>() / t.normal.len().max(1) as f64,
            kind,
            rates,
            holds,
            amplitude: 0.5 * range,
        }
    }

    /// A prepared test of the set.
    pub fn of_prepared(p: &PreparedTest) -> Protocol {
        Protocol::of(&p.full.name, &p.full, &p.segmentation)
    }

    /// A test simulated from a proposal's scenario, segmented as a measured test would be.
    pub fn of_simulated(t: &FitTest) -> Protocol {
        let data = test_data(t);
        let seg = segment(&data, &SegmentOptions::default());
        Protocol::of(&t.name, t, &seg)
    }

    /// Whether this (a proposal) repeats `old` (a test of the set).
    pub fn repeats(&self, old: &Protocol) -> bool {
        let within = |new: &[f64], old: &[f64]| {
            new.iter()
                .all(|&a| old.iter().any(|&b| same(a, b, SAME_FACTOR)))
        };
        self.control == old.control
            && same(self.normal_kpa, old.normal_kpa, SAME_NORMAL_FACTOR)
            && self.kind == old.kind
            && within(&self.rates, &old.rates)
            && within(&self.holds, &old.holds)
            && (self.kind != Kind::Cycles || same(self.amplitude, old.amplitude, SAME_FACTOR))
    }

    /// Why a proposal is not proposed: the test of the set it repeats.
    pub fn repeat_reason(&self, old: &Protocol) -> String {
        format!(
            "the set already has this test: `{}` ({} at {:.0} kPa, the same rates{})",
            old.name,
            old.kind.name(),
            old.normal_kpa,
            match old.kind {
                Kind::Holds => " and holds",
                Kind::Cycles => " and amplitude",
                _ => "",
            }
        )
    }
}

/// The first test of `set` that `proposal` repeats, as a reason for not proposing it.
pub fn repeated_test(proposal: &FitTest, set: &[Protocol]) -> Option<String> {
    let p = Protocol::of_simulated(proposal);
    set.iter()
        .find(|old| p.repeats(old))
        .map(|old| p.repeat_reason(old))
}

fn same(a: f64, b: f64, factor: f64) -> bool {
    a > 0.0 && b > 0.0 && a.max(b) <= factor * a.min(b)
}

/// A simulated test as the data layer holds a measured one.
fn test_data(t: &FitTest) -> TestData {
    let (slip, shear, control) = match t.control {
        Control::Slip => (t.imposed.clone(), t.measured.clone(), ControlColumn::Slip),
        Control::Shear => (t.measured.clone(), t.imposed.clone(), ControlColumn::Shear),
    };
    let normal = t.normal.iter().sum::<f64>() / t.normal.len().max(1) as f64;
    TestData {
        spec: TestSpec::new(&t.name, "proposal.csv", control, normal),
        path: std::path::PathBuf::from(format!("{}.csv", t.name)),
        time_s: t.time.clone(),
        slip_mm: slip,
        shear_kpa: shear,
        normal_kpa: t.normal.clone(),
        friction_given: false,
        line_of_row: (0..t.len()).collect(),
        comments: Vec::new(),
        reading_notes: Vec::new(),
        channels: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn protocol(kind: Kind, rates: &[f64], holds: &[f64], normal: f64) -> Protocol {
        Protocol {
            name: "t".into(),
            control: Control::Slip,
            normal_kpa: normal,
            kind,
            rates: rates.to_vec(),
            holds: holds.to_vec(),
            amplitude: 1.0,
        }
    }

    #[test]
    fn the_same_kind_rates_and_stress_repeat_a_test() {
        let set = protocol(Kind::VelocitySteps, &[0.001, 0.01, 0.1], &[], 100.0);
        // x10 steps about the same rate: a repeat, whatever the order or a small rate error.
        assert!(protocol(Kind::VelocitySteps, &[0.00105, 0.01, 0.099], &[], 100.0).repeats(&set));
        // x3 steps: other rates.
        assert!(!protocol(Kind::VelocitySteps, &[0.0033, 0.01, 0.03], &[], 100.0).repeats(&set));
        // The same steps under another normal stress, or another kind of test.
        assert!(!protocol(Kind::VelocitySteps, &[0.001, 0.01, 0.1], &[], 200.0).repeats(&set));
        assert!(!protocol(Kind::Monotonic, &[0.01], &[], 100.0).repeats(&set));
        // Holds must be holds the set has.
        let shs = protocol(Kind::Holds, &[0.01], &[30.0, 300.0, 3000.0], 100.0);
        assert!(protocol(Kind::Holds, &[0.01], &[30.0, 300.0], 100.0).repeats(&shs));
        assert!(!protocol(Kind::Holds, &[0.01], &[3.0, 30.0, 300.0], 100.0).repeats(&shs));
    }
}
