//! Where the model misses: its residual on every row of the record, grouped per test, per kind
//! of segment, per test and segment, early against late cycles, and per normal-stress level, as
//! a share of the excess over the noise. `fit` says with it where a fitted model misses
//! ([`crate::adequacy`]), the diagnosis where its base and final models do.

use crate::dataset::FAILED_RESIDUAL;
use serde::Serialize;
use std::collections::BTreeMap;
use subfric_reading::PreparedTest;

/// Residuals of every row of each test, in noise units (NaN where the model failed).
pub type RowResiduals = Vec<Vec<f64>>;

/// Squared residual (noise units) counted for a row the model cannot simulate (NaN): large,
/// so a model that fails somewhere never looks better for it, but finite, so sums stay usable.
/// The square of the fit's [`FAILED_RESIDUAL`], so that such a row weighs the same wherever it
/// is counted (1e6).
pub const FAILED_ROW: f64 = FAILED_RESIDUAL * FAILED_RESIDUAL;

/// The squared residual `v`, or [`FAILED_ROW`] where the model failed.
pub fn squared_or_failed(v: f64) -> f64 {
    if v.is_finite() {
        v * v
    } else {
        FAILED_ROW
    }
}

/// Misfit of a group of rows.
#[derive(Clone, Debug, Serialize)]
pub struct GroupMisfit {
    /// Group label.
    pub group: String,
    /// Rows in the group.
    pub rows: usize,
    /// RMS residual / noise SD (1 = noise level).
    pub rms_over_noise: f64,
    /// Mean squared residual / noise variance (1 = noise level): the misfit as the reports
    /// give it ("× the noise variance"), the square of `rms_over_noise`.
    pub reduced_chi2: f64,
    /// Share of the total excess misfit (SSR − rows, in noise units) in this group.
    pub share_of_gap: f64,
}

/// Where the residual lies.
#[derive(Clone, Debug, Serialize)]
pub struct Localisation {
    /// Per test.
    pub by_test: Vec<GroupMisfit>,
    /// Per kind of segment, all tests together.
    pub by_segment: Vec<GroupMisfit>,
    /// Per test and kind of segment.
    pub by_test_segment: Vec<GroupMisfit>,
    /// Early vs late cycles (tests with cycles).
    pub by_cycle: Vec<GroupMisfit>,
    /// Per normal stress level.
    pub by_normal_stress: Vec<GroupMisfit>,
    /// Total excess misfit over the noise, in noise units.
    pub total_excess: f64,
}

fn group_misfit<F: Fn(usize, usize) -> Option<String>>(
    res: &RowResiduals,
    key: F,
) -> Vec<GroupMisfit> {
    let mut acc: BTreeMap<String, (usize, f64)> = BTreeMap::new();
    for (t, r) in res.iter().enumerate() {
        for (i, v) in r.iter().enumerate() {
            if let Some(k) = key(t, i) {
                let e = acc.entry(k).or_insert((0, 0.0));
                e.0 += 1;
                e.1 += squared_or_failed(*v);
            }
        }
    }
    let total: f64 = acc.values().map(|(n, s)| (s - *n as f64).max(0.0)).sum();
    acc.into_iter()
        .map(|(group, (rows, ssr))| GroupMisfit {
            group,
            rows,
            rms_over_noise: (ssr / rows.max(1) as f64).sqrt(),
            reduced_chi2: ssr / rows.max(1) as f64,
            share_of_gap: if total > 0.0 {
                (ssr - rows as f64).max(0.0) / total
            } else {
                0.0
            },
        })
        .collect()
}

/// Groups the residuals `res` of every row of each test (noise units).
pub fn localise(prepared: &[PreparedTest], res: &RowResiduals) -> Localisation {
    let name = |t: usize| prepared[t].full.name.clone();
    let kind = |t: usize, i: usize| {
        prepared[t]
            .segmentation
            .row_kind
            .get(i)
            .map(|k| k.name().to_string())
    };
    // Per-test figures are read once: the groupings below ask for them on every row, and a
    // record of 70 000 rows made that quadratic (3 s of a real record's diagnosis).
    let cycles: Vec<u32> = prepared.iter().map(|p| p.segmentation.cycles()).collect();
    let stresses: Vec<String> = prepared
        .iter()
        .map(|p| {
            let f = &p.full;
            let mean = f.normal.iter().sum::<f64>() / f.normal.len().max(1) as f64;
            format!("{mean:.0} kPa")
        })
        .collect();
    let cycle = |t: usize, i: usize| {
        let n = cycles[t];
        let c = *prepared[t].segmentation.cycle_of_row.get(i)?;
        (n >= 2).then(|| {
            if c <= n / 2 {
                "early cycles".to_string()
            } else {
                "late cycles".to_string()
            }
        })
    };
    let stress = |t: usize| stresses[t].clone();
    Localisation {
        by_test: group_misfit(res, |t, _| Some(name(t))),
        by_segment: group_misfit(res, kind),
        by_test_segment: group_misfit(res, |t, i| kind(t, i).map(|k| format!("{} / {k}", name(t)))),
        by_cycle: group_misfit(res, cycle),
        by_normal_stress: group_misfit(res, |t, _| Some(stress(t))),
        total_excess: res
            .iter()
            .map(|r| r.iter().map(|&v| squared_or_failed(v)).sum::<f64>() - r.len() as f64)
            .sum::<f64>()
            .max(0.0),
    }
}
