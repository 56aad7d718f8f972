//! The setup of a fit: the sets read and segmented, the request checked against them (tests,
//! repeats, weights, fixed values, bounds), the rig's artifacts noted and the space charted.

use super::stiffness::{seated_stiffness, starting_stiffness};
use super::{artifacts_of, Artifact, FitRequest, FitSetup};
use crate::progress::Progress;
use anyhow::{anyhow, bail, Result};
use std::path::PathBuf;
use subfric_data::{load_set, plausibility, Warning};
use subfric_fit::{FitOptions, Param, Space};
use subfric_model::{Model, Params};
use subfric_reading::{prepare_set, typical_rate, FitTest, PreparedTest};

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
            for line in subfric_reading::reading_lines(t) {
                progress.note(&format!("{}: {line}", crate::visible(&name)));
            }
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

/// Loads the sets, selects and weights the tests, and checks fixed values and bounds: every
/// mistake in the request is found here, before any output is prepared or any fitting done.
/// The sets' plausibility warnings go to `progress` (and into the setup), and so does the
/// counter of the job's model runs ([`counted_options`]).
pub fn setup(req: &FitRequest, progress: &dyn Progress) -> Result<FitSetup> {
    if req.dirs.is_empty() {
        bail!("no set folder given");
    }
    crate::flags::conflicts(None, &req.fix, &req.bounds, &req.weights).map_err(|e| anyhow!(e))?;
    refuse_repeated_sets(&req.dirs)?;
    let options = counted_options(req, progress);
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
    let resolved = starting_stiffness(req, &options, &tests, &stiffness, &mut template, progress);
    for (p, v) in &req.fix {
        p.set(&mut template, *v);
    }
    Model::new(template.params, template.ext).map_err(|e| anyhow!("--fix: {e}"))?;
    let mut free = req.free_not_fixed();
    if resolved.is_some() {
        free.push(Param::AlphaT);
    }
    // Bedding: a closure of the rig on first loading is taken out of the travel, as the
    // diagnosis does (subfric_fit::bedding).
    let mut seated = subfric_fit::seat(&tests, &template, &free, &options);
    // A rise that stiffens is a closure of the rig and reads no stiffness: the closure first,
    // then the spring, tried again on the seated travel where nothing decided it before; where
    // that decides it, the bedding is read again against a base with that spring (as the
    // diagnosis does).
    let resolved = match resolved {
        None if !seated.bedding.is_empty() => {
            let again = seated_stiffness(req, &options, &seated.tests, &mut template);
            if again.is_some() {
                free.push(Param::AlphaT);
                seated = subfric_fit::seat(&tests, &template, &free, &options);
            }
            again
        }
        decided => decided,
    };
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
        options,
    })
}

/// The request's options counting the job's model runs: into the counter the caller put in
/// them (a job of several fits, as `reproduce` and `plan`), else into a new one, which is the
/// fit's own. `progress` is handed it, to show the runs as they go.
fn counted_options(req: &FitRequest, progress: &dyn Progress) -> FitOptions {
    let run_counter = req.options.run_counter.clone().unwrap_or_default();
    progress.watch_runs(&run_counter);
    FitOptions {
        run_counter: Some(run_counter),
        ..req.options.clone()
    }
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
