//! Running a checked setup: the calibration, its result withheld when it cannot be trusted
//! (ended outside its bounds, a number not finite) and its intervals when the noise is not
//! measured, and the stress ratios read off beside it.

use super::{FitOutcome, FitRequest, FitSetup};
use crate::located;
use crate::outcome::adequacy::Adequacy;
use crate::progress::Progress;
use anyhow::{bail, Result};
use subfric_fit::{calibrate_from, compare_with_published, FitReport};
use subfric_reading::{FitTest, PreparedTest};

/// Runs the calibration of a checked setup; a single set's errors name its folder.
pub fn run_setup(req: &FitRequest, setup: FitSetup, progress: &dyn Progress) -> Result<FitOutcome> {
    calibrate_setup(req, setup, progress).map_err(|e| match &req.dirs[..] {
        [one] => located(e, one),
        _ => e,
    })
}

fn calibrate_setup(
    req: &FitRequest,
    setup: FitSetup,
    progress: &dyn Progress,
) -> Result<FitOutcome> {
    let budget = setup.options.global_evaluations;
    let stage = |s| progress.calibration_stage(s, budget);
    let name = setup.name();
    let mut report = calibrate_from(
        &setup.fits,
        setup.space.clone(),
        &setup.starts,
        &setup.options,
        &stage,
    )?;
    // Fitted on bins of a long record: the misfit is reported on every row.
    let fulls: Vec<FitTest> = setup.tests.iter().map(|t| t.full.clone()).collect();
    report.tests = subfric_fit::misfits(&fulls, &report.model);
    for &(p, lo, hi) in &req.bounds {
        let v = p.get(&report.model).unwrap_or(f64::NAN);
        let slack = 1e-9 * lo.abs().max(hi.abs());
        if !(v >= lo - slack && v <= hi + slack) {
            bail!(
                "--bounds {}={lo}:{hi}: the fit ended at {} = {v}, outside the bounds (expected the optimiser to keep them; the result is withheld)",
                p.key(),
                p.key()
            );
        }
    }
    check_finite(&report, &setup, &fulls)?;
    if let Some(p) = &setup.published {
        compare_with_published(&mut report, p);
    }
    let adequacy = match noise_not_measured(&setup.tests, &report) {
        Some(reason) => {
            report.withhold_intervals();
            Adequacy::unjudged(report.reduced_chi2, reason)
        }
        None => Adequacy::of_fit(&report, &setup.tests),
    };
    let read_off = subfric_reading::read_off(&fulls, &report.model);
    for r in read_off.iter().filter(|r| r.departs) {
        let reads = report
            .param(r.param)
            .filter(|p| p.undetermined())
            .map(|p| p.reads());
        progress.warning(&r.sentence_reading(reads.as_deref()));
    }
    Ok(FitOutcome {
        levels: subfric_reading::read_levels(&setup.tests),
        read_off,
        report,
        adequacy,
        dirs: req.dirs.clone(),
        name,
        tests: setup.tests,
        published: setup.published,
        artifacts: setup.artifacts,
    })
}

/// Fewest degrees of freedom of the measured noise variance for a 95 % interval to be shown.
/// An interval computed as if the noise were known, with the noise estimated from m values,
/// covers the truth as often as Student's t with m degrees of freedom stays within ±1.96:
/// P(|T₅| ≤ 1.96) = 0.893, P(|T₆| ≤ 1.96) = 0.902. From 6 on it holds at least 90 % of the time
/// (95 % as m grows); below, it is no 95 % interval and none is shown.
pub const MIN_NOISE_DEGREES_OF_FREEDOM: usize = 6;

/// Why the intervals of a fit cannot be shown, if they cannot: every interval and the misfit
/// are in units of each test's noise, which the test's own record measures (second
/// differences, [`subfric_reading::NoiseEstimate::degrees_of_freedom`]) and which weighs its
/// rows; a fit of no more rows than free parameters leaves no residual to check it. A short
/// test gives a noise read off a handful of differences, or none (then a floor of 10⁻⁴ of the
/// scale stands in and its rows weigh without measure): intervals computed from it exclude the
/// truth. So every fitted test must measure its noise with [`MIN_NOISE_DEGREES_OF_FREEDOM`].
fn noise_not_measured(tests: &[PreparedTest], report: &FitReport) -> Option<String> {
    let (dof, test) = tests
        .iter()
        .map(|t| {
            let e = subfric_reading::estimate_noise(&t.full.time, &t.full.measured);
            (e.degrees_of_freedom(), t.full.name.as_str())
        })
        .min()?;
    let free = report
        .parameters
        .iter()
        .filter(|p| p.status != subfric_fit::Status::Fixed)
        .count();
    let rows: usize = tests.iter().map(|t| t.full.time.len()).sum();
    if rows <= free {
        return Some(format!(
            "{rows} rows for {free} free parameters leave no residual to measure the noise by (expected more rows than free parameters: longer tests, or --fix)"
        ));
    }
    (dof < MIN_NOISE_DEGREES_OF_FREEDOM).then(|| {
        format!(
            "test `{}` measures its noise with {dof} degree{} of freedom (expected at least {MIN_NOISE_DEGREES_OF_FREEDOM}, some 20 rows of a test: an interval from a noise read off fewer covers the truth less than 90 % of the time), so no interval is shown and the misfit is in units of a noise not known",
            crate::visible(test),
            if dof == 1 { "" } else { "s" }
        )
    })
}

/// A result with a number that is not finite is withheld: the error names the test's file and
/// why the fitted model cannot follow it.
fn check_finite(report: &FitReport, setup: &FitSetup, fulls: &[FitTest]) -> Result<()> {
    let file_of = |name: &str| {
        setup
            .files
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, p)| p.display().to_string())
            .unwrap_or_else(|| name.to_string())
    };
    for (t, m) in fulls.iter().zip(&report.tests) {
        if m.rms.is_finite() {
            continue;
        }
        let why = match t.predict(&report.model) {
            Err(e) => format!("{e} (row numbers count data rows from 0)"),
            Ok(_) => "its misfit is not a finite number".into(),
        };
        bail!(
            "{}: test `{}`: the best fit found cannot follow this test: {why} (expected data the model can simulate; check the units and the control column; the result is withheld)",
            file_of(&t.name),
            t.name
        );
    }
    let params = &report.model.params;
    if !(report.ssr.is_finite()
        && report.reduced_chi2.is_finite()
        && [
            params.mu_s,
            params.mu_k,
            params.kappa,
            params.xi,
            params.u_tilde,
            params.alpha_t,
        ]
        .iter()
        .all(|v| v.is_finite()))
    {
        let files: Vec<String> = setup.files.iter().map(|(n, _)| file_of(n)).collect();
        bail!(
            "{}: the fit ended with a number that is not finite (misfit {}, parameters {params:?}); the result is withheld",
            files.join(", "),
            report.ssr
        );
    }
    Ok(())
}
