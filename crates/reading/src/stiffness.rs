//! Whether the data resolve the elastic stiffness α_t, and a first guess of it.
//!
//! In the model, unloading after a reversal is elastic: the shear crosses zero after an imposed
//! travel τ/α. When the slip column is a load point's displacement, the machine's compliance
//! adds to it, and the crossing is spread over many resolution units of the record; then α_t is
//! a parameter the data determine (and must be fitted, or every unload and every hold would be
//! simulated against an infinitely stiff machine). On stiff generated or digitised curves the
//! crossing happens within a row or two, and α_t stays fixed. The slope of an unload (least
//! squares over its rows down to zero shear) is the stiffness; a reload (after an unload, or
//! after a hold in which the shear fell far) and a first loading from rest that rises as a
//! straight line over many resolution units (the model's own rise is curved from its start)
//! read it low, because plastic slip grows as they load: they count only when no unload does.
//! On generated rig sets the unload slope is within 20 % of the series stiffness where the
//! half-change travel of reloads read it 2 to 40 times too soft.

use crate::prepare::PreparedTest;
use crate::stats::upper_median;
use serde::Serialize;
use subfric_model::params::KN_PER_MM3_IN_KPA_PER_MM;
use subfric_model::{Control, Model};

/// Evidence that the elastic stiffness is resolved.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stiffness {
    /// First guess of α_t [kN/mm³] (median over the events that resolve it).
    pub alpha_t: f64,
    /// Events that resolve it.
    pub events: usize,
    /// In words.
    pub evidence: String,
}

impl Stiffness {
    /// The stiffness the decision goes with, into `model`: α_t, and α_n equal to it (lab data
    /// do not resolve the normal stiffness apart). `fit` starts its calibration there and the
    /// diagnosis its base fit, both after [`decide_stiffness`].
    pub fn set_in(&self, model: &mut Model) {
        model.params.alpha_t = self.alpha_t;
        model.params.alpha_n = self.alpha_t;
    }
}

/// Imposed travel, in bands, that the elastic change must need to count as resolved.
const RESOLVED_BANDS: f64 = 10.0;

/// Imposed travel, in bands, that an unload must span: one reversal hysteresis, 10 noise SDs of
/// the imposed column. The alternative it rules out is the stiff interface, whose unload is over
/// within a fraction of a band; the slope itself is refined by the fit, which then frees α_t.
const UNLOAD_BANDS: f64 = 1.0;

/// An unload is elastic, so a straight line: the share of the shear's variance over its rows
/// that a line in the imposed travel explains.
const UNLOAD_R2: f64 = 0.95;

/// Elastic slope estimates of one test [kPa/mm], in two kinds.
#[derive(Default)]
struct Slopes {
    /// Unloads: after a reversal the shear runs back toward zero. In the model this part is
    /// purely elastic (the subloading ratio r falls, no plastic slip), so its slope is the
    /// stiffness of interface and machine in series.
    unloads: Vec<f64>,
    /// Reloads (a reversal that starts near zero shear, the end of a hold in which the shear
    /// fell far) and a straight first loading: elastic at first, then softened by the plastic
    /// slip that grows with r, so their slope reads the stiffness low; used only when no unload
    /// resolves it.
    reloads: Vec<f64>,
}

/// The slopes of one test: each reversal, and each end of a hold in which the shear fell by
/// 30 % of its typical level, whose shear change spans `RESOLVED_BANDS` bands of imposed travel.
fn slopes(p: &PreparedTest) -> Slopes {
    let mut out = Slopes::default();
    let t = &p.full;
    if t.control != Control::Slip || t.len() < 10 {
        return out;
    }
    let seg = &p.segmentation;
    let band = seg.conditioned.band;
    let u = &t.imposed;
    let tau = &t.measured;
    let mut mags: Vec<f64> = tau.iter().map(|v| v.abs()).collect();
    let typical = upper_median(&mut mags).unwrap_or(0.0);
    let mut events: Vec<usize> = seg.reversals.clone();
    for &(s, e) in &seg.holds {
        let before = tau[s.saturating_sub(1)];
        let end = (e - 1).min(t.len() - 1);
        if (before - tau[end]).abs() >= 0.3 * typical && end + 1 < t.len() {
            events.push(end);
        }
    }
    if let Some(k) = first_loading_slope(p) {
        out.reloads.push(k);
    }
    let hold_starts: Vec<usize> = seg.holds.iter().map(|h| h.0).collect();
    for &r in &events {
        // The transient: until the imposed column has moved `travel` mm or the next reversal
        // (or hold, when `at_holds`).
        let transient_end = |travel: f64, at_holds: bool| {
            let mut j = r + 1;
            while j + 1 < t.len()
                && (u[j] - u[r]).abs() < travel
                && !seg.reversals.contains(&j)
                && !(at_holds && hold_starts.contains(&j))
            {
                j += 1;
            }
            j
        };
        let mut j = transient_end(0.2, false);
        if (tau[j] - tau[r]).abs() < 0.3 * typical {
            // A soft rig (a direct-shear box: 100–1000 kPa per mm) unloads 0.2 mm of travel
            // by less than a third of its shear: the elastic change needs up to a few mm, as
            // far as the next reversal or hold.
            j = transient_end(SOFT_TRANSIENT_MM, true);
        }
        if j <= r + 2 {
            continue;
        }
        let (from, to) = (tau[r], tau[j]);
        let change = to - from;
        if change.abs() < 0.3 * typical {
            continue;
        }
        let unload = seg.reversals.contains(&r)
            && from.abs() >= 0.3 * typical
            && change.signum() == -from.signum();
        if unload {
            if let Some(k) = unload_slope(u, tau, r, j, band) {
                out.unloads.push(k);
            }
            continue;
        }
        let half = from + 0.5 * change;
        let Some(k) = (r + 1..=j).find(|&k| (tau[k] - half) * change.signum() >= 0.0) else {
            continue;
        };
        let travel = (u[k] - u[r]).abs();
        if travel >= RESOLVED_BANDS * band && k >= r + 4 {
            out.reloads.push(0.5 * change.abs() / travel);
        }
    }
    out
}

/// The elastic slope of an unload that starts at row `r` and ends by row `j`: the
/// least-squares slope of shear on imposed travel over the rows until the shear crosses zero
/// or has covered three quarters of its change (beyond zero a full reversal loads plastically
/// in the other direction). It counts when at least four rows lie on a straight line
/// (R² ≥ [`UNLOAD_R2`]) over [`UNLOAD_BANDS`] bands of travel: an unload of a stiff record
/// happens within a row or two, or within the noise of the imposed column.
fn unload_slope(u: &[f64], tau: &[f64], r: usize, j: usize, band: f64) -> Option<f64> {
    let (from, change) = (tau[r], tau[j] - tau[r]);
    let target = from + 0.75 * change;
    let end = (r + 1..=j).find(|&k| {
        tau[k].signum() != from.signum() || (tau[k] - target) * change.signum() >= 0.0
    })?;
    if end < r + 3 || (u[end] - u[r]).abs() < UNLOAD_BANDS * band {
        return None;
    }
    let line = crate::stats::fit_line(&u[r..=end], &tau[r..=end])?;
    // The shear must fall as the travel reverses: a slope of the wrong sign is noise.
    (line.slope.is_finite() && line.slope > 0.0 && line.r2 >= UNLOAD_R2).then_some(line.slope)
}

/// The loading slope of a test that starts at rest, when the record resolves it as elastic:
/// the shear rises to two fifths of the first peak over many resolution units, and as a
/// straight line (neither fifth needs more than 1.5 times the travel of the other). The
/// rise of the subloading model itself is curved from the start (r grows from zero with
/// cot(πr/2): as the square root of the plastic slip, so its second fifth needs about three
/// times the travel of its first), so a straight rise is a spring in series: the machine's
/// compliance in the slip column, or a shear box's specimen (whose rise to 20 % of the peak
/// may take only six rows of 5 µm: two fifths over ten resolution bands is read where one fifth
/// was not). A rise that stiffens is neither (see [`Rise::stiffens`]).
fn first_loading_slope(p: &PreparedTest) -> Option<f64> {
    let r = first_rise(p)?;
    let straight = r.second <= LINEAR_RISE * r.first && !r.stiffens();
    let resolved = r.first + r.second >= RESOLVED_BANDS * r.band && r.rows >= 6;
    (straight && resolved).then(|| r.secant())
}

/// The rise of a test's first loading from rest to two fifths of its peak.
struct Rise {
    /// Travel to one fifth of the peak [mm].
    first: f64,
    /// Travel from one fifth to two fifths [mm].
    second: f64,
    /// Rows to two fifths.
    rows: usize,
    /// The peak's shear [kPa].
    peak: f64,
    /// The imposed column's resolution band [mm].
    band: f64,
}

impl Rise {
    /// The secant slope to two fifths of the peak [kPa/mm].
    fn secant(&self) -> f64 {
        0.4 * self.peak / (self.first + self.second)
    }

    /// Whether the rise stiffens: its first fifth needs more than [`LINEAR_RISE`] times the
    /// travel of its second. Neither a spring (straight) nor the model's plastic slip (which
    /// only adds travel as the shear rises) stiffens; a closure of the rig does: gaps between
    /// the specimen, the box and the plate take up travel at low shear and stop once closed,
    /// the toe of a seating (ASTM D3080 corrects it before reading a stiffness). Its secant
    /// reads the closure, not the elastic stiffness, so it neither resolves α_t nor starts
    /// the trial of a free α_t: a toe read as a spring made α_t 3–30 times too soft, and the
    /// closure, left in the travel, was then not taken out as a bedding (generated sets with
    /// a seating and no unload to read the stiffness from).
    fn stiffens(&self) -> bool {
        self.first > LINEAR_RISE * self.second
    }
}

fn first_rise(p: &PreparedTest) -> Option<Rise> {
    let t = &p.full;
    let seg = &p.segmentation;
    // A test whose seating toe was excluded starts at rest under a quarter of its peak, on
    // the steep loading: the rest of that loading is as elastic as a loading from zero.
    let from_rest = seg.start.kind == crate::StartKind::Rest || p.toe.is_some();
    if !from_rest || t.len() < 10 {
        return None;
    }
    let end = seg
        .reversals
        .iter()
        .copied()
        .chain(seg.holds.iter().map(|h| h.0))
        .min()
        .unwrap_or(t.len())
        .min(t.len());
    let (u, tau) = (&t.imposed, &t.measured);
    let sign = (u[end - 1] - u[0]).signum();
    let peak = tau[..end].iter().map(|v| sign * v).fold(f64::MIN, f64::max);
    if !(peak > 0.0 && peak.is_finite()) {
        return None;
    }
    let reach = |share: f64| (0..end).find(|&i| sign * (tau[i] - tau[0]) >= share * peak);
    let (i20, i40) = (reach(0.2)?, reach(0.4)?);
    Some(Rise {
        first: (u[i20] - u[0]).abs(),
        second: (u[i40] - u[i20]).abs(),
        rows: i40,
        peak,
        band: seg.conditioned.band,
    })
}

/// Rows a first loading's rise to two fifths of its peak must span for its secant to start a
/// trial of α_t (`subfric_fit::stiffness_by_trial`).
const TRIAL_ROWS: usize = 4;

/// The secants [kN/mm³] of the first loadings from rest of the slip-controlled tests that rise
/// to two fifths of their peak over at least [`TRIAL_ROWS`] rows, in the tests' order: where
/// no unload, reload or straight rise resolves the stiffness, their median starts a trial of a
/// free α_t (`subfric_fit::stiffness_by_trial`).
pub fn rise_secants(tests: &[PreparedTest]) -> Vec<f64> {
    tests
        .iter()
        .filter(|t| t.full.control == Control::Slip)
        .filter_map(first_rise)
        .filter(|r| r.rows >= TRIAL_ROWS && !r.stiffens())
        .map(|r| r.secant() / KN_PER_MM3_IN_KPA_PER_MM)
        .filter(|a| a.is_finite() && *a > 0.0)
        .collect()
}

/// Travel [mm] within which the elastic change after an event is looked for on a soft rig.
const SOFT_TRANSIENT_MM: f64 = 3.0;

/// Either fifth of a straight rise needs at most this many times the travel of the other.
const LINEAR_RISE: f64 = 1.5;

/// What a record says of the elastic stiffness α_t before any trial, best first (see
/// [`decide_stiffness`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StiffnessReadings {
    /// From the unloads and reloads some test resolves ([`resolved_stiffness`]).
    pub resolved: Option<Stiffness>,
    /// From the springs the velocity steps needed, each step fitted with a spring-slider on
    /// its own (the diagnosis reads the steps one by one; `fit` does not, and gives none).
    pub springs: Option<Stiffness>,
}

/// The α_t decision, the one function `fit` and the diagnosis both call (the fit in the
/// application layer, `subfric_app`'s `fit/stiffness.rs::starting_stiffness`; the diagnosis in
/// `subfric_diagnose`'s `diagnose/mod.rs::elastic_stiffness`), in one order: what unloads and
/// reloads resolve; else what the velocity steps' springs read (the diagnosis reads the steps
/// one by one; `fit` does not, and gives none); else `trial` (where a first loading rises over
/// several rows, α_t free against α_t held with the caller's other parameters —
/// `subfric_fit::stiffness_by_trial` — kept when the rise decides it); `None` when nothing
/// decides it, and α_t is held. The trial runs only when nothing before it decides. The
/// stiffness that goes with the decision is set by [`Stiffness::set_in`].
pub fn decide_stiffness(
    readings: StiffnessReadings,
    trial: impl FnOnce() -> Option<Stiffness>,
) -> Option<Stiffness> {
    readings.resolved.or(readings.springs).or_else(trial)
}

/// The elastic stiffness, when some test of the set resolves it.
pub fn resolved_stiffness(tests: &[PreparedTest]) -> Option<Stiffness> {
    let (mut unloads, mut reloads) = (Vec::new(), Vec::new());
    for t in tests {
        let s = slopes(t);
        unloads.extend(s.unloads);
        reloads.extend(s.reloads);
    }
    let from_unloads = !unloads.is_empty();
    let mut all = if from_unloads { unloads } else { reloads };
    let slope = upper_median(&mut all)?;
    let alpha_t = slope / KN_PER_MM3_IN_KPA_PER_MM;
    Some(Stiffness {
        alpha_t,
        events: all.len(),
        evidence: if from_unloads {
            format!(
                "{} unload{} on a straight line over at least {UNLOAD_BANDS:.0} resolution band of \
                 the imposed column: elastic stiffness about {alpha_t:.3e} kN/mm³ (load-point \
                 compliance included)",
                all.len(),
                if all.len() == 1 { "" } else { "s" },
            )
        } else {
            format!(
                "{} reload{} or straight first loading{} spread over more than {RESOLVED_BANDS:.0} \
                 resolution units of the imposed column: elastic stiffness about {alpha_t:.3e} \
                 kN/mm³ (load-point compliance included; no unload resolves it, and a reload reads \
                 it low as plastic slip grows)",
                all.len(),
                if all.len() == 1 { "" } else { "s" },
                if all.len() == 1 { "" } else { "s" },
            )
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepare::prepare_test;

    fn reading(alpha_t: f64, evidence: &str) -> Stiffness {
        Stiffness {
            alpha_t,
            events: 2,
            evidence: evidence.into(),
        }
    }

    #[test]
    fn the_stiffness_is_decided_in_one_order_and_the_trial_runs_only_when_nothing_decides() {
        let tried = std::cell::Cell::new(0);
        let trial = || {
            tried.set(tried.get() + 1);
            Some(reading(3.0, "trial"))
        };
        let both = StiffnessReadings {
            resolved: Some(reading(1.0, "unloads")),
            springs: Some(reading(2.0, "springs")),
        };
        assert_eq!(decide_stiffness(both, trial).unwrap().evidence, "unloads");
        let springs = StiffnessReadings {
            resolved: None,
            springs: Some(reading(2.0, "springs")),
        };
        assert_eq!(
            decide_stiffness(springs, trial).unwrap().evidence,
            "springs"
        );
        assert_eq!(tried.get(), 0, "a trial ran where the readings decided");
        let none = StiffnessReadings::default();
        assert_eq!(
            decide_stiffness(none.clone(), trial).unwrap().evidence,
            "trial"
        );
        assert_eq!(tried.get(), 1);
        assert_eq!(decide_stiffness(none, || None), None);
    }
    use crate::SegmentOptions;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    use subfric_data::{ControlColumn, TestData, TestSpec};
    use subfric_model::{simulate, Model, Params, Protocol};

    /// A slide to 2 mm at 10 µm/s logged every 0.4 s, an unload of the load point by `back` mm
    /// over six rows 4 s apart, a hold of three rows and a reload, at 100 kPa on an interface
    /// whose elastic stiffness is `alpha_t` (the machine's compliance in series); a 10 nm
    /// encoder with 12 nm of noise and 0.05 kPa of shear noise.
    fn unload_test(alpha_t: f64, back: f64) -> TestData {
        let (mut time, mut slip) = (vec![0.0], vec![0.0]);
        let mut push = |dt: f64, du: f64| {
            let (t, u) = (*time.last().unwrap(), *slip.last().unwrap());
            time.push(t + dt);
            slip.push(u + du);
        };
        for _ in 0..500 {
            push(0.4, 0.004);
        }
        for _ in 0..6 {
            push(4.0, -back / 6.0);
        }
        for _ in 0..3 {
            push(4.0, 0.0);
        }
        for _ in 0..100 {
            push(0.4, 0.004);
        }
        let mut params = Params::sample();
        params.alpha_t = alpha_t;
        params.alpha_n = alpha_t;
        let model = Model::base(params).unwrap();
        let normal = vec![100.0; time.len()];
        let shear = simulate(
            &model,
            &Protocol {
                control: subfric_model::Control::Slip,
                time: &time,
                imposed: &slip,
                normal: &normal,
                initial_slip: 0.0,
                initial: Default::default(),
            },
        )
        .unwrap()
        .shear;
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let (du, dtau) = (
            Normal::new(0.0, 1.2e-5).unwrap(),
            Normal::new(0.0, 0.05).unwrap(),
        );
        let slip_mm: Vec<f64> = slip
            .iter()
            .map(|u| ((u + du.sample(&mut rng)) / 1e-5).round() * 1e-5)
            .collect();
        let shear_kpa: Vec<f64> = shear.iter().map(|s| s + dtau.sample(&mut rng)).collect();
        let n = time.len();
        TestData {
            spec: TestSpec::new("unload", "unload.csv", ControlColumn::Slip, 100.0),
            path: "unload.csv".into(),
            time_s: time,
            slip_mm,
            shear_kpa,
            normal_kpa: normal,
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        }
    }

    #[test]
    fn an_unload_through_a_compliant_rig_reads_the_series_stiffness() {
        // 5000 kPa/mm: the unload of about 25 kPa over 5 µm is elastic, and its slope is the
        // stiffness; the reload after the hold is elastic-plastic and would read it low.
        for alpha_t in [0.005, 0.002] {
            let test = unload_test(alpha_t, 0.005 * 0.005 / alpha_t);
            let prepared = prepare_test(&test, "unload".into(), &SegmentOptions::default());
            let found = resolved_stiffness(&[prepared]).expect("the unload resolves α_t");
            assert!(
                (found.alpha_t / alpha_t - 1.0).abs() < 0.05,
                "α_t {alpha_t}: read {} ({})",
                found.alpha_t,
                found.evidence
            );
            assert!(found.evidence.contains("unload"), "{}", found.evidence);
        }
    }

    /// A monotonic test at 200 kPa logged every 5 µm (a 1 µm encoder reading 0.5 µm of noise, a
    /// shear box's displacement gauge; 0.2 kPa of shear noise) whose shear follows `shear(u)`.
    fn monotonic(shear: impl Fn(f64) -> f64) -> TestData {
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let (du, dtau) = (
            Normal::new(0.0, 5e-4).unwrap(),
            Normal::new(0.0, 0.2).unwrap(),
        );
        let u: Vec<f64> = (0..=1200).map(|i| 0.005 * i as f64).collect();
        let n = u.len();
        TestData {
            spec: TestSpec::new("box", "box.csv", ControlColumn::Slip, 200.0),
            path: "box.csv".into(),
            time_s: u.iter().map(|x| 60.0 * x).collect(),
            slip_mm: u
                .iter()
                .map(|x| ((x + du.sample(&mut rng)) / 1e-3).round() * 1e-3)
                .collect(),
            shear_kpa: u
                .iter()
                .map(|x| shear(*x) + dtau.sample(&mut rng))
                .collect(),
            normal_kpa: vec![200.0; n],
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        }
    }

    #[test]
    fn a_shear_box_rising_straight_over_a_few_rows_resolves_its_stiffness() {
        // A dense sand in a shear box: a rise linear at first (1200 kPa/mm), 20 % of the peak
        // within about seven rows of 5 µm and 40 % within fourteen, then softening; the gauge's
        // resolution band is 6 µm. Two fifths of the peak span ten bands; one fifth did not,
        // and the stiffness went unread (α_t held at 1000 kN/mm³).
        let sand = |u: f64| 200.0 * (0.9 * (u / 0.15).tanh() - 0.2 * (1.0 - (-u / 1.5).exp()));
        let prepared = prepare_test(&monotonic(sand), "box".into(), &SegmentOptions::default());
        let found = resolved_stiffness(&[prepared]).expect("the straight rise resolves α_t");
        let kpa_per_mm = found.alpha_t * KN_PER_MM3_IN_KPA_PER_MM;
        // The secant to 40 % of the peak reads the initial slope 180/0.15 = 1200 kPa/mm a
        // little low (tanh bends by then).
        assert!(
            (1000.0..1250.0).contains(&kpa_per_mm),
            "{kpa_per_mm} kPa/mm ({})",
            found.evidence
        );
        // The subloading model's own rise on a stiff interface is curved from its start (r
        // grows as the square root of the plastic slip): nothing resolved.
        let mut params = Params::sample();
        params.u_tilde = 3.0;
        let prepared = prepare_test(
            &model_slide(params),
            "box".into(),
            &SegmentOptions::default(),
        );
        assert!(resolved_stiffness(&[prepared]).is_none());
    }

    #[test]
    fn a_rise_that_stiffens_is_a_closure_and_reads_no_stiffness() {
        // The same shear box seated on a closing gap: the travel at a shear τ counts a closure
        // of the hyperbola of a closing joint (Bandis et al. 1983), 0.08 mm at most, half of
        // it closed at 15 kPa, on top of the interface's slip. The first fifth of the peak
        // then needs more travel than the second: read as a spring, it would make α_t about
        // five times too soft, and neither the reading nor the trial may take it.
        let sand = |u: f64| 200.0 * (0.9 * (u / 0.15).tanh() - 0.2 * (1.0 - (-u / 1.5).exp()));
        let closure = |tau: f64| 0.08 * tau.max(0.0) / (tau.max(0.0) + 15.0);
        let straight = prepare_test(&monotonic(sand), "box".into(), &SegmentOptions::default());
        let rise = first_rise(&straight).expect("a rise from rest");
        assert!(!rise.stiffens(), "{} then {} mm", rise.first, rise.second);
        let seated = prepare_test(
            &monotonic_through(sand, closure),
            "box".into(),
            &SegmentOptions::default(),
        );
        let rise = first_rise(&seated).expect("a rise from rest");
        assert!(rise.stiffens(), "{} then {} mm", rise.first, rise.second);
        assert!(resolved_stiffness(std::slice::from_ref(&seated)).is_none());
        assert!(rise_secants(&[seated]).is_empty());
        // The straight rise still starts the trial.
        assert_eq!(rise_secants(&[straight]).len(), 1);
    }

    /// [`monotonic`] with the recorded travel at interface slip u counting `closure(shear)`
    /// of the running peak of the shear as well.
    fn monotonic_through(shear: impl Fn(f64) -> f64, closure: impl Fn(f64) -> f64) -> TestData {
        let mut test = monotonic(&shear);
        let mut peak = f64::MIN;
        for (i, slip) in test.slip_mm.iter_mut().enumerate() {
            peak = peak.max(shear(0.005 * i as f64));
            *slip = ((*slip + closure(peak)) / 1e-3).round() * 1e-3;
        }
        test
    }

    /// A monotonic slide to 6 mm at 200 kPa of the model with `params`, logged every 5 µm as
    /// [`monotonic`] logs it.
    fn model_slide(params: Params) -> TestData {
        let model = Model::base(params).unwrap();
        let u: Vec<f64> = (0..=1200).map(|i| 0.005 * i as f64).collect();
        let curve = simulate(
            &model,
            &Protocol {
                control: subfric_model::Control::Slip,
                time: &u.iter().map(|x| 60.0 * x).collect::<Vec<_>>(),
                imposed: &u,
                normal: &vec![200.0; u.len()],
                initial_slip: 0.0,
                initial: Default::default(),
            },
        )
        .unwrap()
        .shear;
        monotonic(|x| curve[(x / 0.005).round() as usize])
    }

    #[test]
    fn an_unload_of_a_stiff_interface_resolves_nothing() {
        // The paper's 1000 kN/mm³: the unload is over within a row of the imposed column.
        let test = unload_test(1000.0, 0.005);
        let prepared = prepare_test(&test, "unload".into(), &SegmentOptions::default());
        assert!(resolved_stiffness(&[prepared]).is_none());
    }
}
