//! The fit: sets loaded and checked, the request checked (tests, weights, fixed values,
//! bounds), the calibration run, its result withheld when it cannot be trusted, and `fit.json`.
//! Everything in the request is checked before any output folder is claimed or any fitting
//! done ([`setup`]); [`fit()`] returns the result, [`fit_to_folder`] writes it as `subfric fit`
//! does.

use crate::adequacy::Adequacy;
use crate::io::{write_json, write_text};
use crate::located;
use crate::output::{default_results_dir, Destination, ResultsDir};
use crate::posterior::{PosteriorRequest, Sampled};
use crate::progress::Progress;
use anyhow::{anyhow, bail, Result};
use std::path::{Path, PathBuf};
use subfric_data::{load_set, plausibility, Warning};
use subfric_fit::{
    calibrate_from, compare_with_published, prepare_set, typical_rate, FitOptions, FitReport,
    FitTest, Param, PreparedTest, Space,
};
use subfric_model::{Model, Params};

/// What to fit and how.
#[derive(Clone, Debug)]
pub struct FitRequest {
    /// Set folders (joint fit when several).
    pub dirs: Vec<PathBuf>,
    /// Only these tests (by name), all when empty.
    pub tests: Vec<String>,
    /// Free parameters (the five of the paper by default).
    pub free: Vec<Param>,
    /// Fixed values.
    pub fix: Vec<(Param, f64)>,
    /// Bounds in natural units, each honoured or refused.
    pub bounds: Vec<(Param, f64, f64)>,
    /// Per-test weights.
    pub weights: Vec<(String, f64)>,
    /// Sample the posterior after the fit (`--posterior`), and how.
    pub posterior: Option<PosteriorRequest>,
    /// Optimiser options.
    pub options: FitOptions,
    /// The model whose form is fitted (its extensions, with their values and its base
    /// parameters as one more start; α from it): e.g. the model a diagnosis chose. `None`:
    /// the base model of the paper, α from the published values.
    pub start: Option<Model>,
}

impl FitRequest {
    /// The default calibration of one set (as `reproduce`, `plan` and `bench` run it).
    pub fn of_set(dir: PathBuf, options: FitOptions) -> FitRequest {
        FitRequest {
            dirs: vec![dir],
            tests: vec![],
            free: Param::BASE.to_vec(),
            fix: vec![],
            bounds: vec![],
            weights: vec![],
            posterior: None,
            options,
            start: None,
        }
    }
}

/// A finished calibration with what produced it.
pub struct FitOutcome {
    /// The report.
    pub report: FitReport,
    /// Does the model describe the data: the misfit and where it misses most.
    pub adequacy: Adequacy,
    /// The set folders fitted (for the next-step lines).
    pub dirs: Vec<PathBuf>,
    /// Tests fitted.
    pub tests: Vec<PreparedTest>,
    /// Published model (single set with reference parameters).
    pub published: Option<Model>,
    /// Name used for output.
    pub name: String,
    /// Rig artifacts recognised in the record and what the fit did about them.
    pub artifacts: Vec<Artifact>,
    /// μ_s and μ_k beside the peak and residual stress ratios the record shows.
    pub read_off: Vec<subfric_fit::ReadOff>,
    /// Each test's peak and residual stress ratio, and their change with the normal stress.
    pub levels: subfric_fit::LevelReadings,
}

/// A rig artifact recognised in a record, and what the fit did about it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Artifact {
    /// The test it was found in (empty for the whole set).
    pub test: String,
    /// `seating-toe` or `compliance`.
    pub kind: &'static str,
    /// What was found and done, in words.
    pub detail: String,
}

/// The rig artifacts of prepared tests: their seating toes (excluded), a normal-stress column
/// held at its levels (its scatter the reading's) and a series stiffness the loading slopes
/// resolve (fitted as α_t, unless the request fixes or frees α_t itself).
pub fn artifacts_of(
    tests: &[PreparedTest],
    stiffness: Option<&subfric_fit::Stiffness>,
) -> Vec<Artifact> {
    let mut out: Vec<Artifact> = tests
        .iter()
        .flat_map(|t| {
            let toe = t.toe.as_ref().map(|toe| Artifact {
                test: t.full.name.clone(),
                kind: "seating-toe",
                detail: toe.reason.clone(),
            });
            let held = t.segmentation.normal.held_because().map(|why| Artifact {
                test: t.full.name.clone(),
                kind: "normal-reading-noise",
                detail: why.to_string(),
            });
            toe.into_iter().chain(held)
        })
        .collect();
    if let Some(s) = stiffness {
        out.push(Artifact {
            test: String::new(),
            kind: "compliance",
            detail: format!("α_t fitted: {}", s.evidence),
        });
    }
    out
}

/// Sets loaded, checked and charted, ready for the long work.
pub struct FitSetup {
    tests: Vec<PreparedTest>,
    /// The CSV file of each test, by test name (for messages).
    files: Vec<(String, PathBuf)>,
    fits: Vec<FitTest>,
    space: Space,
    published: Option<Model>,
    names: Vec<String>,
    /// Plausibility warnings of the sets.
    pub warnings: Vec<Warning>,
    /// Rig artifacts recognised and what the fit does about them.
    pub artifacts: Vec<Artifact>,
    /// Starting models beside the informed guesses (the request's `start`).
    starts: Vec<Model>,
}

impl FitSetup {
    /// Name of the fit (set names joined by `+`).
    pub fn name(&self) -> String {
        self.names.join("+")
    }
}

/// The sets of a request as read: their tests prepared, what they publish and what they warn.
struct ReadSets {
    tests: Vec<PreparedTest>,
    /// The published model (of the one set; none in a joint fit).
    published: Option<Model>,
    /// Each set's name and the stiffness it publishes.
    stiffness: Vec<(String, Option<Params>)>,
    names: Vec<String>,
    warnings: Vec<Warning>,
    /// The CSV file of each test, by test name.
    files: Vec<(String, PathBuf)>,
    /// Each test's name, file and content hash (to refuse the same rows twice).
    contents: Vec<(String, PathBuf, u64)>,
}

/// Reads and segments every set of the request (tests named `set/test` in a joint fit).
fn read_sets(dirs: &[PathBuf], progress: &dyn Progress) -> Result<ReadSets> {
    let joint = dirs.len() > 1;
    let mut read = ReadSets {
        tests: Vec::new(),
        published: None,
        stiffness: Vec::new(),
        names: Vec::new(),
        warnings: Vec::new(),
        files: Vec::new(),
        contents: Vec::new(),
    };
    for d in dirs {
        progress.stage(&format!("reading {}", d.display()), None);
        let set = load_set(d)?;
        let reference = crate::sets::published(&set)?;
        read.stiffness
            .push((set.meta.name.clone(), reference.as_ref().map(|m| m.params)));
        if !joint {
            read.published = reference;
        }
        read.warnings.extend(plausibility(&set));
        read.names.push(set.meta.name.clone());
        for t in &set.tests {
            let name = if joint {
                format!("{}/{}", set.meta.name, t.spec.name)
            } else {
                t.spec.name.clone()
            };
            read.contents
                .push((name.clone(), t.path.clone(), t.content_hash()));
            read.files.push((name, t.path.clone()));
        }
        let rows: usize = set.tests.iter().map(|t| t.len()).sum();
        progress.stage(
            &format!("segmenting {} tests ({rows} rows)", set.tests.len()),
            None,
        );
        read.tests.extend(prepare_set(&set, joint));
    }
    Ok(read)
}

/// The parameters the request frees, less those it fixes.
fn free_not_fixed(req: &FitRequest) -> Vec<Param> {
    req.free
        .iter()
        .copied()
        .filter(|p| !req.fix.iter().any(|(q, _)| q == p))
        .collect()
}

/// The stiffness the fit starts from, into `template`, and whether α_t is fitted: a series
/// stiffness the loading slopes resolve (the machine's compliance in the slip column) is
/// fitted, from the slopes' estimate, unless the request says what to do with α_t; else, where
/// a first loading rises over several rows, from a trial (α_t free against α_t held, with the
/// request's other parameters), kept when the rise decides it; else the stiffness the sets
/// publish (`published`: each set's), with a note when they disagree. Returns the stiffness
/// fitted, if any.
fn starting_stiffness(
    req: &FitRequest,
    tests: &[PreparedTest],
    published: &[(String, Option<Params>)],
    template: &mut Model,
    progress: &dyn Progress,
) -> Option<subfric_fit::Stiffness> {
    let (alpha, why) = held_stiffness(published, template.params.alpha_t);
    if let (Some(p), None) = (alpha, &req.start) {
        template.params.alpha_t = p.alpha_t;
        template.params.alpha_n = p.alpha_n;
    }
    let alpha_given = req.start.is_some()
        || req.free.contains(&Param::AlphaT)
        || req.fix.iter().any(|(p, _)| *p == Param::AlphaT);
    let resolved = (!alpha_given)
        .then(|| {
            subfric_fit::resolved_stiffness(tests).or_else(|| {
                let mut held = *template;
                for (p, v) in &req.fix {
                    p.set(&mut held, *v);
                }
                subfric_fit::stiffness_by_trial(tests, &held, &free_not_fixed(req), &req.options)
            })
        })
        .flatten();
    match (&resolved, why) {
        (Some(s), _) => {
            template.params.alpha_t = s.alpha_t;
            template.params.alpha_n = s.alpha_t;
        }
        (None, Some(why)) if !alpha_given => progress.note(&why),
        _ => {}
    }
    resolved
}

/// Loads the sets, selects and weights the tests, and checks fixed values and bounds: every
/// mistake in the request is found here, before any output is prepared or any fitting done.
/// The sets' plausibility warnings go to `progress` (and into the setup).
pub fn setup(req: &FitRequest, progress: &dyn Progress) -> Result<FitSetup> {
    if req.dirs.is_empty() {
        bail!("no set folder given");
    }
    crate::flags::conflicts(None, &req.fix, &req.bounds, &req.weights).map_err(|e| anyhow!(e))?;
    refuse_repeated_sets(&req.dirs)?;
    let ReadSets {
        mut tests,
        published,
        stiffness,
        names,
        warnings,
        files,
        contents,
    } = read_sets(&req.dirs, progress)?;
    select_tests(&mut tests, &req.tests)?;
    refuse_repeated_tests(&tests, &contents)?;
    apply_weights(&mut tests, &req.weights)?;
    // Template: the given model, else the published α (which lab data rarely determine; in a
    // joint fit the value every set publishes) with the sample values.
    let mut template = match req.start {
        Some(m) => m,
        None => Model::base(Params::sample())?,
    };
    let resolved = starting_stiffness(req, &tests, &stiffness, &mut template, progress);
    for (p, v) in &req.fix {
        p.set(&mut template, *v);
    }
    Model::new(template.params, template.ext).map_err(|e| anyhow!("--fix: {e}"))?;
    let mut free = free_not_fixed(req);
    if resolved.is_some() {
        free.push(Param::AlphaT);
    }
    // Bedding: a closure of the rig on first loading is taken out of the travel, as the
    // diagnosis does (subfric_fit::bedding).
    let seated = subfric_fit::seat(&tests, &template, &free, &req.options);
    let tests = seated.tests;
    let mut artifacts = artifacts_of(&tests, resolved.as_ref());
    artifacts.extend(seated.bedding.iter().map(|b| Artifact {
        test: b.test.clone(),
        kind: "bedding",
        detail: b.describe(),
    }));
    for a in &artifacts {
        let place = if a.test.is_empty() {
            String::new()
        } else {
            format!("{}: ", crate::visible(&a.test))
        };
        progress.note(&format!("{place}{}", a.detail));
    }
    let fits: Vec<FitTest> = tests.iter().map(|t| t.fit.clone()).collect();
    let space = Space::try_with_rate(template, &free, &req.bounds, typical_rate(&fits))
        .map_err(|e| anyhow!("--bounds {e}"))?;
    if space.v_ref == 0.0 && !req.bounds.is_empty() && free_triple(&free) {
        progress.note(
            "with bounds on mu_k, kappa or xi the optimiser works in those parameters themselves, not in the combinations a single rate determines",
        );
    }
    for w in &warnings {
        progress.warning(&w.to_string());
    }
    Ok(FitSetup {
        tests,
        files,
        fits,
        space,
        published,
        names,
        warnings,
        artifacts,
        starts: req.start.iter().copied().collect(),
    })
}

/// Refuses a set folder given twice (`fit s s`, or `s` and `./s/`, or a link to it): its rows
/// would count twice, every standard error would shrink by √2 and the intervals would claim a
/// certainty the data do not give.
fn refuse_repeated_sets(dirs: &[PathBuf]) -> Result<()> {
    let mut seen: Vec<(PathBuf, &PathBuf)> = Vec::new();
    for d in dirs {
        let Ok(c) = std::fs::canonicalize(d) else {
            continue; // not there: load_set says so
        };
        if let Some((_, first)) = seen.iter().find(|(s, _)| *s == c) {
            bail!(
                "{} and {}: the same set folder given twice ({}); its rows would count twice and every interval would be too narrow by √2 (expected each set once)",
                first.display(),
                d.display(),
                c.display()
            );
        }
        seen.push((c, d));
    }
    Ok(())
}

/// Refuses two fitted tests that hold the same rows (`fit t1 t1copy` with `t1copy` a copy of
/// `t1` under another folder or name, or two sets sharing a CSV's bytes): as with a set given
/// twice, the rows would count twice. Compared by content ([`TestData::content_hash`]), not
/// by path; `--tests` leaves one of them out.
///
/// [`TestData::content_hash`]: subfric_data::TestData::content_hash
fn refuse_repeated_tests(
    tests: &[PreparedTest],
    contents: &[(String, PathBuf, u64)],
) -> Result<()> {
    let fitted: Vec<&(String, PathBuf, u64)> = contents
        .iter()
        .filter(|(n, _, _)| tests.iter().any(|t| &t.fit.name == n))
        .collect();
    for (j, (name, path, hash)) in fitted.iter().enumerate() {
        if let Some((first, first_path, _)) = fitted[..j].iter().find(|(_, _, h)| h == hash) {
            bail!(
                "{}: test `{}` holds the same rows as test `{}` ({}), value for value: one measurement given twice would count twice and every interval would be too narrow by √2 (expected each measured test once: leave one out with --tests, or remove the copy)",
                path.display(),
                crate::visible(name),
                crate::visible(first),
                first_path.display()
            );
        }
    }
    Ok(())
}

/// Sets the weights of `--weight` (each test named must be there), then scales every weight so
/// that their mean over the rows is 1: weights say how much each test counts against the
/// others, while the misfit stays a multiple of the noise variance and the intervals keep their
/// meaning (a single test weighted 10⁻³⁰ would otherwise read as a perfect fit).
fn apply_weights(tests: &mut [PreparedTest], weights: &[(String, f64)]) -> Result<()> {
    for (name, w) in weights {
        let Some(t) = tests.iter_mut().find(|t| &t.fit.name == name) else {
            bail!(
                "--weight {name}={w}: test `{name}` not found (the sets have: {})",
                test_names(tests)
            );
        };
        t.fit.weight = *w;
        t.full.weight = *w;
    }
    let rows: f64 = tests.iter().map(|t| t.full.time.len() as f64).sum();
    let weighted: f64 = tests
        .iter()
        .map(|t| t.full.weight * t.full.time.len() as f64)
        .sum();
    if weights.is_empty() || !(rows > 0.0 && weighted > 0.0) {
        return Ok(());
    }
    let scale = rows / weighted;
    for t in tests.iter_mut() {
        t.fit.weight *= scale;
        t.full.weight *= scale;
    }
    Ok(())
}

/// The contact stiffness a fit holds (α_t and α_n, which lab data rarely determine), from the
/// published parameters of the sets `(name, published)`: a single set's, or the value every set
/// of a joint fit publishes. Returns it (`None`: the sample values) and, when it does not come
/// from a single set's publication, a note saying what is held and why.
fn held_stiffness(
    sets: &[(String, Option<Params>)],
    sample: f64,
) -> (Option<Params>, Option<String>) {
    let published: Vec<(&String, Params)> =
        sets.iter().filter_map(|(n, p)| p.map(|p| (n, p))).collect();
    let agree = published.len() == sets.len()
        && published
            .windows(2)
            .all(|w| w[0].1.alpha_t == w[1].1.alpha_t && w[0].1.alpha_n == w[1].1.alpha_n);
    match (sets.len(), agree, published.first()) {
        (1, true, Some((_, p))) => (Some(*p), None),
        (_, true, Some((_, p))) => (
            Some(*p),
            Some(format!(
                "alpha_t held at {} kN/mm³, the value every set publishes (free it with --free …,alpha_t, or set it with --fix alpha_t=…)",
                p.alpha_t
            )),
        ),
        _ if published.is_empty() => (
            None,
            Some(format!(
                "alpha_t held at {sample} kN/mm³, a typical value: {} publish{} none (free it with --free …,alpha_t, or set it with --fix alpha_t=…)",
                if sets.len() == 1 { "the set" } else { "the sets" },
                if sets.len() == 1 { "es" } else { "" }
            )),
        ),
        _ => (
            None,
            Some(format!(
                "alpha_t held at {sample} kN/mm³, a typical value: the sets do not publish one value ({}) (free it with --free …,alpha_t, or set it with --fix alpha_t=…)",
                sets.iter()
                    .map(|(n, p)| match p {
                        Some(p) => format!("{} {}", crate::visible(n), p.alpha_t),
                        None => format!("{} none", crate::visible(n)),
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        ),
    }
}

fn free_triple(free: &[Param]) -> bool {
    [Param::MuK, Param::Kappa, Param::Xi]
        .iter()
        .all(|p| free.contains(p))
}

fn test_names(tests: &[PreparedTest]) -> String {
    tests
        .iter()
        .map(|t| t.fit.name.clone())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Keeps only the tests named in `want` (all when empty); an unknown name is an error.
fn select_tests(tests: &mut Vec<PreparedTest>, want: &[String]) -> Result<()> {
    if want.is_empty() {
        return Ok(());
    }
    for w in want {
        if !tests.iter().any(|t| &t.fit.name == w) {
            bail!(
                "--tests: test `{w}` not found (the sets have: {})",
                test_names(tests)
            );
        }
    }
    tests.retain(|t| want.contains(&t.fit.name));
    Ok(())
}

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
    let budget = req.options.global_evaluations;
    let stage = |s| progress.calibration_stage(s, budget);
    let name = setup.name();
    let mut report = calibrate_from(
        &setup.fits,
        setup.space.clone(),
        &setup.starts,
        &req.options,
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
    let read_off = subfric_fit::read_off(&fulls, &report.model);
    for r in read_off.iter().filter(|r| r.departs) {
        let reads = report
            .param(r.param)
            .filter(|p| p.undetermined())
            .map(|p| p.reads());
        progress.warning(&r.sentence_reading(reads.as_deref()));
    }
    Ok(FitOutcome {
        levels: subfric_fit::read_levels(&setup.tests),
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
/// differences, [`subfric_data::NoiseEstimate::degrees_of_freedom`]) and which weighs its
/// rows; a fit of no more rows than free parameters leaves no residual to check it. A short
/// test gives a noise read off a handful of differences, or none (then a floor of 10⁻⁴ of the
/// scale stands in and its rows weigh without measure): intervals computed from it exclude the
/// truth. So every fitted test must measure its noise with [`MIN_NOISE_DEGREES_OF_FREEDOM`].
fn noise_not_measured(tests: &[PreparedTest], report: &FitReport) -> Option<String> {
    let (dof, test) = tests
        .iter()
        .map(|t| {
            let e = subfric_data::estimate_noise(&t.full.time, &t.full.measured);
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

/// Loads, checks and calibrates, without the content of `fit.json` (`reproduce`, `bench`).
pub fn run_fit(req: &FitRequest, progress: &dyn Progress) -> Result<FitOutcome> {
    let setup = setup(req, progress)?;
    run_setup(req, setup, progress)
}

/// A calibration as `subfric fit` runs it, with the content of its `fit.json`.
pub struct Fitted {
    /// The calibration.
    pub outcome: FitOutcome,
    /// What `subfric fit` writes to `fit.json`.
    pub json: serde_json::Value,
    /// Plausibility warnings of the sets (also given to the progress).
    pub warnings: Vec<Warning>,
    /// The posterior, when the request asked for it (also in `json`, under `posterior`).
    pub posterior: Option<Sampled>,
}

/// Loads, checks and calibrates: `subfric fit` without output files (the same checks, the
/// same calibration, the same errors), then samples the posterior when asked.
pub fn fit(req: &FitRequest, progress: &dyn Progress) -> Result<Fitted> {
    let setup = setup(req, progress)?;
    let sampler = prepare_posterior(req, &setup)?;
    let warnings = setup.warnings.clone();
    let outcome = run_setup(req, setup, progress)?;
    let posterior = sampler.map(|s| s.sample(&outcome, progress)).transpose()?;
    let json = with_posterior(fit_json(&outcome)?, &outcome, posterior.as_ref())?;
    Ok(Fitted {
        outcome,
        json,
        warnings,
        posterior,
    })
}

/// The posterior request checked against the fit (prior file, budget) before any fitting.
fn prepare_posterior(
    req: &FitRequest,
    setup: &FitSetup,
) -> Result<Option<crate::posterior::Prepared>> {
    req.posterior
        .as_ref()
        .map(|p| crate::posterior::prepare(p, &setup.space, &setup.fits))
        .transpose()
}

/// `fit.json`'s content with the posterior's block, when there is one.
fn with_posterior(
    mut json: serde_json::Value,
    outcome: &FitOutcome,
    posterior: Option<&Sampled>,
) -> Result<serde_json::Value> {
    if let (Some(p), Some(o)) = (posterior, json.as_object_mut()) {
        o.insert("posterior".into(), p.json(&outcome.report)?);
    }
    Ok(json)
}

/// A fit written to its results folder.
pub struct FitWritten {
    /// The fit.
    pub fitted: Fitted,
    /// The `fit.json` written.
    pub file: PathBuf,
    /// Everything else written: `fit.txt`, one figure per test, `report.html` (with
    /// `--posterior` also the chain, the corner plot and the band figures).
    pub files: Vec<PathBuf>,
}

/// `subfric fit`: the request checked and the output folder (`fits/<set names>` unless
/// given) claimed before the fit runs; `fit.json`, `fit.txt`, one figure per test (measured,
/// published, fitted) and `report.html` written (with `--posterior` also the posterior's files,
/// all in the same claim), then the folder's record of its sets.
pub fn fit_to_folder(
    req: &FitRequest,
    to: &Destination,
    progress: &dyn Progress,
) -> Result<FitWritten> {
    let setup = setup(req, progress)?;
    let dir = to
        .dir
        .clone()
        .unwrap_or_else(|| default_results_dir(&setup.name()));
    let sampler = prepare_posterior(req, &setup)?;
    let mut files: Vec<String> = ["fit.json", "fit.txt", crate::report::REPORT_FILE]
        .map(String::from)
        .to_vec();
    files.extend(crate::figures::figure_files(&setup.tests));
    if sampler.is_some() {
        // fit.txt is already listed: the posterior's table goes into it.
        files.extend(
            crate::posterior::files(&setup.tests)
                .into_iter()
                .filter(|f| f != "fit.txt"),
        );
    }
    let claim = ResultsDir::claim(&dir, &req.dirs, &files, to.force)?;
    let warnings = setup.warnings.clone();
    let outcome = run_setup(req, setup, progress)?;
    let posterior = sampler.map(|s| s.sample(&outcome, progress)).transpose()?;
    let json = with_posterior(fit_json(&outcome)?, &outcome, posterior.as_ref())?;
    let file = dir.join("fit.json");
    write_json(&file, &json)?;
    progress.stage("drawing the figures and the report", None);
    let txt = dir.join("fit.txt");
    let table = crate::fit_report::report_table(&outcome);
    match &posterior {
        Some(p) => write_text(&txt, &format!("{table}\n\n{}", p.text(&outcome.report)))?,
        None => write_text(&txt, &(table + "\n"))?,
    }
    let (plots, notes) = crate::figures::plot_set(
        &outcome.name,
        &outcome.tests,
        outcome.published.as_ref(),
        Some(&outcome.report.model),
        &dir,
    )?;
    for n in &notes {
        progress.warning(n);
    }
    let html = dir.join(crate::report::REPORT_FILE);
    write_text(&html, &crate::report::fit_page(&outcome, &dir, &plots)?)?;
    let mut posterior_files = Vec::new();
    if let Some(p) = &posterior {
        progress.stage("drawing the posterior's figures", None);
        posterior_files = p.write(&outcome, &dir)?;
    }
    claim.commit()?;
    let mut written = vec![txt];
    written.extend(plots);
    written.push(html);
    written.extend(posterior_files);
    Ok(FitWritten {
        fitted: Fitted {
            outcome,
            json,
            warnings,
            posterior,
        },
        file,
        files: written,
    })
}

/// Writes `fit.json` under `dir` (atomically), without the wall time: a fit.json depends on the
/// data, the code and the seed only.
pub fn write_fit(dir: &Path, out: &FitOutcome) -> Result<PathBuf> {
    let file = dir.join("fit.json");
    write_json(&file, &fit_json(out)?)?;
    Ok(file)
}

/// The content of `fit.json`: the set, the tests, the fitted parameters and model, and the
/// report without the wall time (what `subfric fit` writes and the Python package returns).
pub fn fit_json(out: &FitOutcome) -> Result<serde_json::Value> {
    let mut report = serde_json::to_value(&out.report)?;
    if let Some(o) = report
        .get_mut("optimizer")
        .and_then(serde_json::Value::as_object_mut)
    {
        o.remove("elapsed_s");
    }
    let mut v = serde_json::json!({
        "set": out.name,
        "tests": out.tests.iter().map(|t| t.fit.name.clone()).collect::<Vec<_>>(),
        "verdict": out.adequacy.json("the model"),
        "params": out.report.model.params,
        "model": out.report.model,
        "report": report,
    });
    if !out.artifacts.is_empty() {
        v["artifacts"] = serde_json::to_value(&out.artifacts)?;
    }
    if !out.read_off.is_empty() {
        v["read_off"] = serde_json::to_value(&out.read_off)?;
    }
    // Only where tests at two normal stresses or more were compared.
    if out.levels.peak.is_some() || out.levels.residual.is_some() {
        v["levels"] = serde_json::to_value(&out.levels)?;
    }
    Ok(v)
}
