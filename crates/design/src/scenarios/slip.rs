//! The proposals under slip control: slide–hold–slide, velocity steps, other constant rates,
//! two-way cycles and other normal stresses, sized from what the data determine (the sliding
//! rate, the decay length, the slip range, the sampling interval).

use super::{slide, um_s, Candidate, CYCLE_COUNT};
use crate::outcome::{ProposalKind, Rig};
use subfric_fit::{FitReport, Status};
use subfric_model::{Control, Scenario, Stage};

/// Rows of the slow start within the rise of the traction.
const RISE_ROWS: f64 = 8.0;

/// Plastic slip over which the traction rises from rest to 95 % of the friction: cos(πr/2)
/// decays as exp(−(π/2)ũλ), and r = 0.95 at (π/2)ũλ = 1.62.
const RISE_TIMES_U_TILDE: f64 = 1.62;

/// When the current data do not determine ũ because their rows do not resolve the rise of the
/// traction from rest (its slip is 1.6/ũ), every proposal starts at a slower rate that puts
/// [`RISE_ROWS`] rows in the rise at the fitted ũ, over ten rise lengths: (rate, distance).
pub(super) fn slow_start(rig: &Rig, report: &FitReport) -> Option<(f64, f64)> {
    let u = report.param("u_tilde")?;
    if matches!(u.status, Status::Determined | Status::Fixed) {
        return None;
    }
    let rise = RISE_TIMES_U_TILDE / u.value.max(1e-12);
    let rate = rise / (RISE_ROWS * rig.dt_s.max(1e-12));
    (rate < rig.rate_mm_s).then_some((rate, 10.0 * rise))
}

/// The candidates under slip control, each preceded by `start` (rate, distance) when given.
pub(super) fn slip_candidates(rig: &Rig, start: Option<(f64, f64)>) -> Vec<Candidate> {
    let mut out = slip_tests(rig);
    if let Some((rate, distance)) = start {
        for c in out.iter_mut() {
            c.scenario.stages.insert(0, slide(rate, distance));
            c.description = format!(
                "{} (starting with {:.2} µm at {} to resolve the rise of the traction)",
                c.description,
                1e3 * distance,
                um_s(rate)
            );
        }
    }
    out
}

/// Decay lengths 1/λ after which a transient counts as settled (e^−5 < 1 %).
const SETTLE_DECAY_LENGTHS: f64 = 5.0;

/// Fewest rows of a stretch that is to show a transient or a level.
const MIN_STRETCH_ROWS: f64 = 20.0;

/// Slip of the first slide from rest, in settle lengths: the rise from rest is slower than the
/// recovery after a perturbation.
const FIRST_SLIDE_SETTLES: f64 = 3.0;

/// Fewest holds of a slide–hold–slide series: the healing's growth with the hold needs three
/// points.
const MIN_HOLDS: usize = 3;

/// Lengths and levels of the slip-controlled proposals, from what the data determine.
struct SlipGeometry {
    /// Current sliding rate v [mm/s].
    v: f64,
    /// Slip of a monotonic test [mm]: the current range, at least ten rows at v.
    d: f64,
    /// Slip to settle after a perturbation [mm].
    settle: f64,
    /// Slip to reach steady sliding from rest [mm].
    first: f64,
    /// Normal stress [kPa].
    p: f64,
    /// Sampling interval [s].
    dt: f64,
}

impl SlipGeometry {
    fn of(rig: &Rig) -> Self {
        let v = rig.rate_mm_s;
        let d = rig.slip_range_mm.max(10.0 * v * rig.dt_s);
        let lam = rig.decay_rate_per_mm.max(1e-6);
        let settle = (SETTLE_DECAY_LENGTHS / lam)
            .max(MIN_STRETCH_ROWS * v * rig.dt_s)
            .min(d);
        SlipGeometry {
            v,
            d,
            settle,
            first: (FIRST_SLIDE_SETTLES * settle).min(d).max(settle),
            p: rig.normal_stress_kpa,
            dt: rig.dt_s,
        }
    }

    /// A slip-controlled scenario at the rig's sampling interval.
    fn scenario(&self, name: &str, normal: f64, stages: Vec<Stage>) -> Scenario {
        Scenario {
            name: name.into(),
            control: Control::Slip,
            normal_stress_kpa: normal,
            dt_s: self.dt,
            stages,
        }
    }
}

/// The slip-controlled candidates (without a slow start).
fn slip_tests(rig: &Rig) -> Vec<Candidate> {
    let g = SlipGeometry::of(rig);
    let mut out = slide_hold_slide(&g);
    out.extend(velocity_steps(&g));
    out.extend(constant_rates(&g));
    out.push(two_way_cycles(&g));
    out.extend(other_normal_stresses(&g));
    out
}

/// Slide–hold–slide series of holds 1, 3, 10, 30, 100 × 3, 10 or 30 s (holds shorter than
/// three rows dropped; a series needs [`MIN_HOLDS`]).
fn slide_hold_slide(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, settle, first) = (g.v, g.settle, g.first);
    let mut out = Vec::new();
    for t0 in [3.0, 10.0, 30.0] {
        let holds: Vec<f64> = [1.0, 3.0, 10.0, 30.0, 100.0]
            .iter()
            .map(|f| f * t0)
            .filter(|h| *h >= 3.0 * g.dt)
            .collect();
        if holds.len() < MIN_HOLDS {
            continue;
        }
        let mut stages = vec![slide(v, first)];
        for h in &holds {
            stages.push(Stage::Hold { duration_s: *h });
            stages.push(slide(v, 0.5 * settle));
        }
        let name = format!(
            "slide-hold-slide-{:.0}-{:.0}s",
            holds[0],
            holds[holds.len() - 1]
        );
        out.push(Candidate {
            description: format!(
                "slide {first:.3} mm at {}, then holds of {} s, each followed by {:.3} mm of sliding",
                um_s(v),
                holds
                    .iter()
                    .map(|h| format!("{h:.0}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                0.5 * settle
            ),
            scenario: g.scenario(&name, g.p, stages),
            name,
            kind: ProposalKind::SlideHoldSlide,
        });
    }
    out
}

/// Velocity steps ×3 and ×10 up from v, back, down and back.
fn velocity_steps(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, first) = (g.v, g.first);
    let mut out = Vec::new();
    for f in [3.0, 10.0] {
        let name = format!("velocity-steps-x{f:.0}");
        // Each step long enough to settle, and to hold 20 rows at the fastest rate.
        let step = g.settle.max(MIN_STRETCH_ROWS * f * v * g.dt).min(g.d);
        out.push(Candidate {
            description: format!(
                "slide {first:.3} mm at {}, then steps to {}, {}, {} and back to {}, {step:.3} mm each",
                um_s(v),
                um_s(f * v),
                um_s(v),
                um_s(v / f),
                um_s(v)
            ),
            scenario: g.scenario(
                &name,
                g.p,
                vec![
                    slide(v, first),
                    Stage::VelocitySteps {
                        rates_mm_s: vec![f * v, v, v / f, v],
                        distance_mm: step,
                    },
                ],
            ),
            name,
            kind: ProposalKind::VelocitySteps,
        });
    }
    out
}

/// A monotonic test at another constant rate (÷10, ÷3, ×3, ×10).
fn constant_rates(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, d) = (g.v, g.d);
    [
        (0.1, "div10"),
        (1.0 / 3.0, "div3"),
        (3.0, "x3"),
        (10.0, "x10"),
    ]
    .into_iter()
    .map(|(f, tag)| {
        let name = format!("constant-rate-{tag}");
        Candidate {
            description: format!(
                "a monotonic test over {d:.3} mm at {} instead of {}",
                um_s(f * v),
                um_s(v)
            ),
            scenario: g.scenario(&name, g.p, vec![slide(f * v, d)]),
            name,
            kind: ProposalKind::ConstantRate,
        }
    })
    .collect()
}

/// Two-way cycles whose amplitude lets the transient after each reversal settle.
fn two_way_cycles(g: &SlipGeometry) -> Candidate {
    let amplitude = (2.0 * g.settle).max(0.25 * g.d).min(0.5 * g.d);
    Candidate {
        name: "two-way-cycles".into(),
        kind: ProposalKind::TwoWayCycles,
        description: format!(
            "three two-way cycles of ±{amplitude:.3} mm at {}",
            um_s(g.v)
        ),
        scenario: g.scenario(
            "two-way-cycles",
            g.p,
            vec![Stage::Cycles {
                amplitude_mm: amplitude,
                rate_mm_s: g.v,
                count: CYCLE_COUNT,
            }],
        ),
    }
}

/// The monotonic test under twice and half the normal stress.
fn other_normal_stresses(g: &SlipGeometry) -> Vec<Candidate> {
    let (v, d, p) = (g.v, g.d, g.p);
    [(2.0, "x2"), (0.5, "half")]
        .into_iter()
        .map(|(f, tag)| {
            let name = format!("normal-stress-{tag}");
            Candidate {
                description: format!(
                    "a monotonic test over {d:.3} mm at {} under {:.0} kPa instead of {p:.0} kPa",
                    um_s(v),
                    f * p
                ),
                scenario: g.scenario(&name, f * p, vec![slide(v, d)]),
                name,
                kind: ProposalKind::NormalStress,
            }
        })
        .collect()
}
