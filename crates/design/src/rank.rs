//! The ranking of the proposals: determines-share per lab hour, then shrink per hour, then
//! the shorter test.

use crate::outcome::Proposal;
use subfric_reading::FitTest;

pub(crate) const MIN_HOURS: f64 = 1e-9;

/// Drops (to `rejected`) the proposals that could not be simulated at the planning point and
/// orders the rest: those that narrow something first, then best score, then shrink per
/// hour, then the shorter.
pub(crate) fn rank(
    mut proposals: Vec<Proposal>,
    planning_index: usize,
    rejected: &mut Vec<(String, String)>,
) -> Vec<Proposal> {
    for p in proposals
        .iter()
        .filter(|p| p.valley.iter().all(|v| v.point != planning_index))
    {
        rejected.push((
            p.name.clone(),
            "cannot be simulated at the planning point".into(),
        ));
    }
    proposals.retain(|p| p.valley.iter().any(|v| v.point == planning_index));
    proposals.sort_by(|a, b| {
        b.narrows
            .cmp(&a.narrows)
            .then(b.score.total_cmp(&a.score))
            .then(b.shrink_per_hour.total_cmp(&a.shrink_per_hour))
            .then(a.hours.total_cmp(&b.hours))
    });
    proposals
}

/// Duration of a test [h].
pub(crate) fn scenario_hours(t: &FitTest) -> f64 {
    (t.time.last().unwrap_or(&0.0) - t.time.first().unwrap_or(&0.0)) / 3600.0
}
