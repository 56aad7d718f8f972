//! The proposals under traction control: pulsating cycles at other periods, creep holds,
//! two-way traction cycles and another normal stress.

use super::{Candidate, CYCLE_COUNT};
use crate::outcome::{ProposalKind, Rig};
use subfric_model::{Control, Model, Scenario, Stage};

/// Cycles of a pulsating proposal.
const PULSE_COUNT: u32 = 5;

/// Period of the traction cycles when the rig's could not be read off the tests, in rows.
const DEFAULT_PERIOD_ROWS: f64 = 200.0;

/// Creep levels stay below this share of the static capacity μ_s p, so that they hold rather
/// than run away.
const CREEP_CAPACITY_SHARE: f64 = 0.95;

/// Each creep hold lasts this many periods of the rig's traction cycles: long against the
/// time scale the current tests resolve.
const CREEP_HOLD_PERIODS: f64 = 5.0;

/// Levels and times of the traction-controlled proposals.
struct ShearGeometry {
    /// Normal stress [kPa].
    p: f64,
    /// Largest imposed traction [kPa].
    tmax: f64,
    /// Period of the traction cycles [s].
    period: f64,
    /// Loading rate of those cycles [kPa/s].
    ramp: f64,
    /// Sampling interval [s].
    dt: f64,
}

impl ShearGeometry {
    fn of(rig: &Rig) -> Self {
        let tmax = rig.max_shear_kpa.max(1e-6);
        let period = if rig.period_s > 0.0 {
            rig.period_s
        } else {
            DEFAULT_PERIOD_ROWS * rig.dt_s
        };
        ShearGeometry {
            p: rig.normal_stress_kpa,
            tmax,
            period,
            ramp: 2.0 * tmax / period,
            dt: rig.dt_s,
        }
    }

    /// A traction-controlled scenario at the rig's sampling interval.
    fn scenario(&self, name: &str, normal: f64, stages: Vec<Stage>) -> Scenario {
        Scenario {
            name: name.into(),
            control: Control::Shear,
            normal_stress_kpa: normal,
            dt_s: self.dt,
            stages,
        }
    }
}

/// The candidates under traction control.
pub(super) fn shear_candidates(rig: &Rig, fit: &Model) -> Vec<Candidate> {
    let g = ShearGeometry::of(rig);
    let mut out = pulsating_periods(&g);
    out.push(creep_holds(&g, fit));
    out.push(shear_cycles(&g));
    out.push(pulsating_double_normal_stress(&g));
    out
}

/// Pulsating cycles at a tenth and ten times the period.
fn pulsating_periods(g: &ShearGeometry) -> Vec<Candidate> {
    let (tmax, period) = (g.tmax, g.period);
    [(0.1, "div10"), (10.0, "x10")]
        .into_iter()
        .map(|(f, tag)| {
            let name = format!("pulsating-period-{tag}");
            Candidate {
                description: format!(
                    "five pulsating cycles 0 → {tmax:.1} kPa → 0 with a period of {:.0} s instead of {period:.0} s",
                    f * period
                ),
                scenario: g.scenario(
                    &name,
                    g.p,
                    vec![Stage::Pulsating {
                        max_kpa: tmax,
                        period_s: f * period,
                        count: PULSE_COUNT,
                    }],
                ),
                name,
                kind: ProposalKind::Pulsating,
            }
        })
        .collect()
}

/// Creep: traction held at levels between the largest imposed and the static capacity.
fn creep_holds(g: &ShearGeometry, fit: &Model) -> Candidate {
    let cap = CREEP_CAPACITY_SHARE * fit.params.mu_s * g.p;
    let levels: Vec<f64> = [1.0, 1.1, 1.2]
        .iter()
        .map(|f| (f * g.tmax).min(cap))
        .collect();
    let hold = CREEP_HOLD_PERIODS * g.period;
    let mut stages = Vec::new();
    for l in &levels {
        stages.push(Stage::ShearRamp {
            to_kpa: *l,
            rate_kpa_s: g.ramp,
        });
        stages.push(Stage::Hold { duration_s: hold });
    }
    Candidate {
        name: "creep-holds".into(),
        kind: ProposalKind::Creep,
        description: format!(
            "traction ramped at {:.2} kPa/s and held {hold:.0} s at each of {} kPa",
            g.ramp,
            levels
                .iter()
                .map(|l| format!("{l:.1}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        scenario: g.scenario("creep-holds", g.p, stages),
    }
}

/// Two-way traction cycles to the largest imposed traction.
fn shear_cycles(g: &ShearGeometry) -> Candidate {
    let (tmax, period) = (g.tmax, g.period);
    Candidate {
        name: "shear-cycles".into(),
        kind: ProposalKind::ShearCycles,
        description: format!(
            "three two-way traction cycles of ±{tmax:.1} kPa, period {period:.0} s"
        ),
        scenario: g.scenario(
            "shear-cycles",
            g.p,
            vec![Stage::ShearCycles {
                amplitude_kpa: tmax,
                period_s: period,
                count: CYCLE_COUNT,
            }],
        ),
    }
}

/// The pulsating test under twice the normal stress, to twice the traction.
fn pulsating_double_normal_stress(g: &ShearGeometry) -> Candidate {
    let p = g.p;
    Candidate {
        name: "normal-stress-x2".into(),
        kind: ProposalKind::NormalStress,
        description: format!(
            "five pulsating cycles to {:.1} kPa under {:.0} kPa instead of {p:.0} kPa",
            2.0 * g.tmax,
            2.0 * p
        ),
        scenario: g.scenario(
            "normal-stress-x2",
            2.0 * p,
            vec![Stage::Pulsating {
                max_kpa: 2.0 * g.tmax,
                period_s: g.period,
                count: PULSE_COUNT,
            }],
        ),
    }
}
