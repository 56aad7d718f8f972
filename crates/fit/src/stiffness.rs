//! Whether the data resolve the elastic stiffness α_t, and a first guess of it.
//!
//! In the model, unloading after a reversal is elastic: the shear crosses zero after an imposed
//! travel τ/α. When the slip column is a load point's displacement, the machine's compliance
//! adds to it, and the crossing is spread over many resolution units of the record; then α_t is
//! a parameter the data determine (and must be fitted, or every unload and every hold would be
//! simulated against an infinitely stiff machine). On stiff generated or digitised curves the
//! crossing happens within a row or two, and α_t stays fixed. Reloads after a hold in which the
//! shear fell far count too, and a first loading from rest that rises as a straight line over
//! many resolution units (the model's own rise is curved from its start).

use crate::prepare::PreparedTest;
use serde::Serialize;
use subfric_model::params::KN_PER_MM3_IN_KPA_PER_MM;
use subfric_model::Control;

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

/// Imposed travel, in bands, that half the elastic change must need to count as resolved.
const RESOLVED_BANDS: f64 = 10.0;

/// Elastic slope estimates (kPa/mm) of one test: for each reversal, and each end of a hold in
/// which the shear fell by 30 % of its typical level, the travel over which the shear covers
/// half its change; kept when that travel spans `RESOLVED_BANDS` bands.
fn slopes(p: &PreparedTest) -> Vec<f64> {
    let t = &p.full;
    if t.control != Control::Slip || t.len() < 10 {
        return Vec::new();
    }
    let seg = &p.segmentation;
    let band = seg.conditioned.band;
    let u = &t.imposed;
    let tau = &t.measured;
    let mut mags: Vec<f64> = tau.iter().map(|v| v.abs()).collect();
    mags.sort_by(f64::total_cmp);
    let typical = mags[mags.len() / 2];
    let mut events: Vec<usize> = seg.reversals.clone();
    for &(s, e) in &seg.holds {
        let before = tau[s.saturating_sub(1)];
        let end = (e - 1).min(t.len() - 1);
        if (before - tau[end]).abs() >= 0.3 * typical && end + 1 < t.len() {
            events.push(end);
        }
    }
    let mut out = Vec::new();
    if let Some(k) = first_loading_slope(p) {
        out.push(k);
    }
    for &r in &events {
        // The transient: until the imposed column has moved 0.2 mm or the next event.
        let mut j = r + 1;
        while j + 1 < t.len() && (u[j] - u[r]).abs() < 0.2 && !seg.reversals.contains(&j) {
            j += 1;
        }
        if j <= r + 2 {
            continue;
        }
        let (from, to) = (tau[r], tau[j]);
        let change = to - from;
        if change.abs() < 0.3 * typical {
            continue;
        }
        let half = from + 0.5 * change;
        let Some(k) = (r + 1..=j).find(|&k| (tau[k] - half) * change.signum() >= 0.0) else {
            continue;
        };
        let travel = (u[k] - u[r]).abs();
        if travel >= RESOLVED_BANDS * band && k >= r + 4 {
            out.push(0.5 * change.abs() / travel);
        }
    }
    out
}

/// The loading slope of a test that starts at rest, when the record resolves it as elastic:
/// the shear rises to a fifth of the first peak over many resolution units, and as a straight
/// line (the second tenth needs no more than 1.5 times the travel of the first). The rise of
/// the subloading model itself is curved from the start (r grows from zero with cot(πr/2)),
/// so a straight rise is a spring in series: the machine's compliance in the slip column.
fn first_loading_slope(p: &PreparedTest) -> Option<f64> {
    let t = &p.full;
    let seg = &p.segmentation;
    if seg.start.kind != subfric_data::StartKind::Rest || t.len() < 10 {
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
    let (i10, i20) = (reach(0.1)?, reach(0.2)?);
    let first = (u[i10] - u[0]).abs();
    let second = (u[i20] - u[i10]).abs();
    let straight = second <= LINEAR_RISE * first;
    let resolved = first + second >= RESOLVED_BANDS * seg.conditioned.band && i20 >= 4;
    (straight && resolved).then(|| 0.2 * peak / (first + second))
}

/// The second tenth of a straight rise needs at most this many times the travel of the first.
const LINEAR_RISE: f64 = 1.5;

/// The elastic stiffness, when some test of the set resolves it.
pub fn resolved_stiffness(tests: &[PreparedTest]) -> Option<Stiffness> {
    let mut all: Vec<f64> = tests.iter().flat_map(slopes).collect();
    if all.is_empty() {
        return None;
    }
    all.sort_by(f64::total_cmp);
    let slope = all[all.len() / 2];
    let alpha_t = slope / KN_PER_MM3_IN_KPA_PER_MM;
    Some(Stiffness {
        alpha_t,
        events: all.len(),
        evidence: format!(
            "{} unload or reload{} spread over more than {RESOLVED_BANDS} resolution units of the imposed column: elastic stiffness about {:.3e} kN/mm³ (load-point compliance included)",
            all.len(),
            if all.len() == 1 { "" } else { "s" },
            alpha_t
        ),
    })
}
