//! The section of the diagnosis report that reads every event on its own: the velocity steps
//! fitted one by one (a, b, D_c, a − b with their 95 % intervals, and the change of steady
//! friction measured on the record), the holds (relaxation, peak on reloading, healing per
//! decade) and the reversals (backward against forward sliding).

use std::fmt::Write as _;
use subfric_diagnose::events::{Estimate, EventAnalysis};
use subfric_diagnose::Diagnosis;

/// Velocity steps listed one per line; beyond this many, the rest are summarised.
const STEPS_SHOWN: usize = 40;

fn interval(e: &Estimate, digits: usize) -> String {
    let end = |v: f64| {
        // An end beyond any value these parameters take is the data setting no bound.
        if v.is_finite() && v.abs() < 1e3 {
            format!("{v:.digits$}")
        } else {
            "open".into()
        }
    };
    format!("{:.digits$} [{}, {}]", e.value, end(e.lo), end(e.hi))
}

/// Section "1b": each event read on its own.
pub(crate) fn events_section(s: &mut String, d: &Diagnosis) {
    let e = &d.events;
    if e.steps.is_empty()
        && e.holds.is_empty()
        && e.reversals.is_empty()
        && e.levels.tests.is_empty()
    {
        return;
    }
    let _ = writeln!(
        s,
        "\n1b. each event read on its own, as friction labs read a record (95 % intervals):"
    );
    levels(s, &e.levels);
    steps(s, e);
    holds(s, e);
    reversals(s, e);
}

/// The tests' peak and residual stress ratios, and their change with the normal stress and
/// with slip.
pub(crate) fn levels(s: &mut String, l: &subfric_reading::LevelReadings) {
    if l.tests.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "   stress ratios of each test's first loading (peak from rest; residual where the excess has decayed):"
    );
    let _ = writeln!(
        s,
        "   {:<18} {:>10} {:>12} {:>26} {:>12} {:>26} {:>30}",
        "test", "σ_n [kPa]", "rate [mm/s]", "peak", "at [mm]", "residual", "residual slope [1/mm]"
    );
    let or_dash = |e: Option<subfric_reading::Estimate>, digits: usize| {
        e.map_or_else(|| "—".to_string(), |e| interval(&e, digits))
    };
    for t in &l.tests {
        let _ = writeln!(
            s,
            "   {:<18} {:>10.1} {:>12.3e} {:>26} {:>12} {:>26} {:>30}",
            crate::truncate(&t.test, 18),
            t.normal_kpa,
            t.rate_mm_s,
            or_dash(t.peak, 4),
            t.slip_to_peak_mm
                .map_or_else(|| "—".to_string(), |u| format!("{u:.3}")),
            or_dash(t.residual, 4),
            or_dash(t.slope_per_mm, 5)
        );
    }
    for (what, trend) in [("peak", &l.peak), ("residual", &l.residual)] {
        let Some(t) = trend else {
            continue;
        };
        let _ = writeln!(
            s,
            "   {what} stress ratio over {} tests at {} normal stresses: {} per e-fold of normal stress ({} relative: a power law's −β){}; Mohr–Coulomb envelope φ {} °, c {} kPa",
            t.tests,
            t.stresses,
            interval(&t.per_efold, 4),
            interval(&t.relative_per_efold, 4),
            if t.changes() {
                if t.per_efold.value < 0.0 {
                    ": FALLS with the normal stress"
                } else {
                    ": RISES with the normal stress"
                }
            } else {
                ": no change beyond the readings' uncertainty"
            },
            interval(&t.friction_angle_deg, 1),
            interval(&t.cohesion_kpa, 1)
        );
    }
    if let Some(g) = &l.slip_slope_per_mm {
        let _ = writeln!(
            s,
            "   residual stress ratio past the peak, together: {} per mm of slip{}",
            interval(g, 5),
            if g.excludes_zero() {
                if g.value > 0.0 {
                    " (hardening)"
                } else {
                    " (softening)"
                }
            } else {
                ""
            }
        );
    }
}

fn steps(s: &mut String, e: &EventAnalysis) {
    if e.steps.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "   velocity steps, each fitted with a spring-slider and rate-and-state friction (linear trend removed):"
    );
    let _ = writeln!(
        s,
        "   {:<18} {:>9} {:>17}  {:<6} {:>26} {:>26} {:>30} {:>28} {:>26} {:>8} {:>6}",
        "test",
        "t [s]",
        "rate [mm/s]",
        "law",
        "a",
        "b",
        "D_c [mm]",
        "a − b",
        "measured Δμ_ss",
        "sign",
        "D"
    );
    for st in e.steps.iter().take(STEPS_SHOWN) {
        let sign = match st.sign_agrees {
            Some(true) => "agrees",
            Some(false) => "DIFFERS",
            None => "—",
        };
        let _ = writeln!(
            s,
            "   {:<18} {:>9.1} {:>8.2e}→{:<8.2e}  {:<6} {:>26} {:>26} {:>30} {:>28} {:>26} {:>8} {:>6.0}{}",
            crate::truncate(&st.test, 18),
            st.time_s,
            st.rate_before,
            st.rate_after,
            match st.law {
                subfric_diagnose::events::slider::StateLaw::Ageing => "ageing",
                subfric_diagnose::events::slider::StateLaw::Slip => "slip",
            },
            interval(&st.a, 5),
            interval(&st.b, 5),
            interval(&st.d_c_mm, 4),
            interval(&st.a_minus_b, 5),
            interval(&st.measured_steady_change, 5),
            sign,
            st.evidence,
            if st.stiffness_per_mm.is_finite() {
                format!("  spring {:.3e} kPa/mm", st.stiffness_per_mm * st.normal_kpa)
            } else {
                String::new()
            }
        );
    }
    if e.steps.len() > STEPS_SHOWN {
        let _ = writeln!(
            s,
            "   … and {} more (diagnosis.json)",
            e.steps.len() - STEPS_SHOWN
        );
    }
    if let Some(r) = &e.rate {
        let _ = writeln!(
            s,
            "   together: {} of {} steps show a direct effect (evidence D ≥ {} over a change without one){}; median a {:.4}, b {:.4}, D_c {:.4} mm; the sign of a − b agrees with the measured change of steady friction in {} of the {} steps where that change exceeds its uncertainty; the fit determines a − b (a direct effect shown, its interval clear of zero) in {} of them and agrees in {} ({} where it does not: no sign claimed){}",
            r.significant,
            r.steps,
            subfric_diagnose::events::STEP_EVIDENCE,
            if r.resolved < r.steps {
                format!(
                    " ({} too fast for their rows: a fit with or without a direct effect moves friction within a row, where the two look the same; they count neither way)",
                    r.steps - r.resolved
                )
            } else {
                String::new()
            },
            r.a,
            r.b,
            r.d_c_mm,
            r.changes_agree,
            r.changes_measured,
            r.signs_checked,
            r.signs_agree,
            r.signs_undetermined,
            if r.consistent {
                ": consistent evidence of rate and state"
            } else {
                ""
            }
        );
    }
}

fn holds(s: &mut String, e: &EventAnalysis) {
    if e.holds.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "   holds (friction before, relaxation during, peak gain on reloading):"
    );
    for h in &e.holds {
        let _ = writeln!(
            s,
            "   {:<18} {:>9.1} s hold   before {:.4}   relaxed {:+.4}   peak gain {}",
            crate::truncate(&h.test, 18),
            h.duration_s,
            h.before,
            -h.relaxation,
            interval(&h.peak_gain, 4)
        );
    }
    if let Some(t) = &e.healing {
        let _ = writeln!(
            s,
            "   healing: {} per decade of hold time over {} holds",
            interval(&t.per_decade, 4),
            t.holds
        );
    }
}

fn reversals(s: &mut String, e: &EventAnalysis) {
    if e.reversals.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "   reversals: {} read (steady |friction| before and after each; diagnosis.json lists them)",
        e.reversals.len()
    );
    if let Some(d) = &e.direction {
        let _ = writeln!(
            s,
            "   backward sliding weaker than forward by d = {} (1 − |μ backward| / μ forward)",
            interval(&d.backward_weakening, 4)
        );
    }
}
